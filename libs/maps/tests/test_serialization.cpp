// Versioned serialisation round trips (polymorphic, through CArchive).
#include <bims/maps/motion_grids.h>

#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <gtest/gtest.h>

#include "scene_raycaster.h"
#include "test_util.h"

using namespace bims::maps;

namespace
{
template <class T>
std::shared_ptr<T> roundTrip(const T& m)
{
	mrpt::io::CMemoryStream buf;
	auto arch = mrpt::serialization::archiveFrom(buf);
	arch << m;
	buf.Seek(0);
	auto obj = arch.ReadObject();
	auto out = std::dynamic_pointer_cast<T>(obj);
	EXPECT_TRUE(out) << "ReadObject returned "
	                 << (obj ? obj->GetRuntimeClass()->className : "null");
	return out;
}

void feed(MotionGrids& mg, int frames, int first = 0)
{
	using namespace bims::maps::test;
	auto scene = room();
	for (int f = first; f < first + frames; ++f)
	{
		scene.push_back({{2.0, -1.0 + 0.2 * f, 0}, {2.3, -0.7 + 0.2 * f, 1.5}});
		const mrpt::poses::CPose3D T(0.05 * f, 0, 1, 0.1 * f, 0, 0);
		PixelLabels lab(48, 36, 1);
		mg.processFrame(*renderScan(scene, T, 48, 36, 60, f), T, &lab);
		scene.pop_back();
	}
}
}  // namespace

TEST(Serialization, OccupancyRoundTripIsExactAndKeepsWorking)
{
	for (auto mode : {DecayMode::All, DecayMode::Frustum, DecayMode::Raycast})
	{
		GridParams p = test::paperGrids();
		p.decay = mode;
		p.voxel_size = 0.1;
		p.raycast_margin = 0.15;  // not the default: read back, not assumed
		MotionGrids mg(p);
		feed(mg, 3);
		const auto& a = *mg.occupancy();
		auto b = roundTrip(a);
		ASSERT_TRUE(b);
		EXPECT_EQ(b->params(), a.params());
		EXPECT_EQ(b->frameCount(), a.frameCount());
		size_t n = 0;
		a.storage().forEachCell(
		    [&](const VoxelKey& k, const auto& c)
		    {
			    const auto* d = b->storage().find(k);
			    ASSERT_NE(d, nullptr);
			    ASSERT_EQ(d->l, c.l);
			    ASSERT_EQ(d->lPrev, c.lPrev);
			    ASSERT_EQ(d->stamp, c.stamp);
			    ++n;
		    });
		EXPECT_GT(n, 1000u);
		EXPECT_EQ(b->storage().numBlocks(), a.storage().numBlocks());
	}
}

TEST(Serialization, MotionTiersRoundTrip)
{
	GridParams p = test::paperGrids();
	p.voxel_size = 0.1;
	MotionGrids mg(p);
	feed(mg, 4);
	auto t1 = roundTrip(*mg.background());
	auto t2 = roundTrip(*mg.flowConsistency());
	ASSERT_TRUE(t1 && t2);
	EXPECT_EQ(t1->lastPosterior(), mg.background()->lastPosterior());
	EXPECT_EQ(t2->lastPosterior(), mg.flowConsistency()->lastPosterior());
	EXPECT_EQ(t2->lastMovingMask().data,
	          mg.flowConsistency()->lastMovingMask().data);
	EXPECT_EQ(t2->lastMovingMask().width, 48);
	EXPECT_EQ(t1->movingCells().size(), mg.background()->movingCells().size());
	EXPECT_EQ(t1->frameCount(), 4u);
	// Every stored decision, and nothing more.
	for (const CMotionGridBase* m :
	     {static_cast<const CMotionGridBase*>(mg.background().get()),
	      static_cast<const CMotionGridBase*>(mg.flowConsistency().get())})
	{
		auto b = roundTrip(*m);
		size_t n = 0, moving = 0;
		m->storage().forEachCell(
		    [&](const VoxelKey& k, const auto& c)
		    {
			    const auto* d = b->storage().find(k);
			    ASSERT_NE(d, nullptr);
			    ASSERT_EQ(d->moving, c.moving);
			    ASSERT_EQ(b->wasMovingAtLastHit(k), c.moving != 0);
			    ++n;
			    moving += c.moving;
		    });
		EXPECT_GT(n, 100u);
		EXPECT_GT(moving, 0u);
		EXPECT_EQ(b->storage().numBlocks(), m->storage().numBlocks());
	}
}

namespace
{
// Writes a tier-1 map in the layout of version 2 (before the cells kept
// only the decision): posterior log-odds and the frame of the last hit per
// cell. Same class name in the stream, so ReadObject() reads it back as a
// CBackgroundSubtractionGrid of version 2.
class Tier1WrittenAsVersion2 : public CBackgroundSubtractionGrid
{
 public:
	using CBackgroundSubtractionGrid::CBackgroundSubtractionGrid;

 protected:
	uint8_t serializeGetVersion() const override { return 2; }
	void serializeTo(mrpt::serialization::CArchive& out) const override
	{
		writeBase(out, 2);
		const uint64_t nb = grid_.numBlocks();
		out << nb;
		constexpr size_t N = Storage::kCellsPerBlock;
		std::vector<float> l(N);
		std::vector<uint32_t> st(N);
		for (size_t b = 0; b < nb; ++b)
		{
			const auto& blk = grid_.block(b);
			for (size_t c = 0; c < N; ++c)
			{
				// Moving: a positive posterior; static: a negative one; never
				// hit: 0 at stamp 0.
				l[c] = blk.cells[c].moving ? 1.5f : -0.25f * float(c % 3);
				st[c] = c % 3 ? 1 : 0;
			}
			out << grid_.blockKey(b);
			out.WriteBufferFixEndianness(l.data(), N);
			out.WriteBufferFixEndianness(st.data(), N);
		}
		const auto& cells = lastCells();
		out << uint64_t(cells.size());
		for (size_t i = 0; i < cells.size(); ++i)
			out << cells[i].x << cells[i].y << cells[i].z << lastPosterior()[i];
		out << int32_t(lastMask_.width) << int32_t(lastMask_.height);
		if (!lastMask_.data.empty())
			out.WriteBuffer(lastMask_.data.data(), lastMask_.data.size());
		out << false;  // no private tier-0 map
	}
};
}  // namespace

TEST(Serialization, Tier1OfVersion2IsRead)
{
	GridParams p = test::paperGrids();
	p.voxel_size = 0.1;
	MotionGrids mg(p);
	feed(mg, 4);
	// The stored state of the pipeline's tier 1, in the version-2 writer.
	Tier1WrittenAsVersion2 old(p);
	{
		mrpt::io::CMemoryStream buf;
		auto arch = mrpt::serialization::archiveFrom(buf);
		arch << *mg.background();
		buf.Seek(0);
		arch >> old;  // old now holds tier 1's state
	}
	auto b = roundTrip(static_cast<const CBackgroundSubtractionGrid&>(old));
	ASSERT_TRUE(b);
	// A map of version 2 was built without a ray margin.
	EXPECT_EQ(b->params().raycast_margin, 0);
	EXPECT_EQ(b->frameCount(), old.frameCount());
	EXPECT_EQ(b->lastCells(), old.lastCells());
	EXPECT_EQ(b->lastPosterior(), old.lastPosterior());
	EXPECT_EQ(b->lastMovingMask().data, old.lastMovingMask().data);
	size_t n = 0, moving = 0;
	old.storage().forEachCell(
	    [&](const VoxelKey& k, const auto& c)
	    {
		    ASSERT_EQ(b->wasMovingAtLastHit(k), c.moving != 0);
		    ++n;
		    moving += c.moving;
	    });
	EXPECT_GT(n, 100u);
	EXPECT_GT(moving, 0u);
}

TEST(Serialization, StandaloneTier1KeepsItsPrivateTier0)
{
	using namespace bims::maps::test;
	GridParams p = test::paperGrids();
	p.voxel_size = 0.1;
	CBackgroundSubtractionGrid a(p);
	const auto scene = room();
	const mrpt::poses::CPose3D T(0, 0, 1, 0, 0, 0);
	for (int f = 0; f < 3; ++f)
		a.insertObservation(*renderScan(scene, T, 40, 30, 60, f), T);
	auto b = roundTrip(a);
	ASSERT_TRUE(b);
	// Both continue identically: the private tier 0 came along.
	auto scan = renderScan(scene, T, 40, 30, 60, 3);
	a.insertObservation(*scan, T);
	b->insertObservation(*scan, T);
	EXPECT_EQ(a.lastPosterior(), b->lastPosterior());
	EXPECT_EQ(b->occupancySource().frameCount(), 4u);
}

TEST(Serialization, CorruptStreamThrows)
{
	GridParams p = test::paperGrids();
	p.voxel_size = 0.1;
	MotionGrids mg(p);
	feed(mg, 1);
	mrpt::io::CMemoryStream buf;
	auto arch = mrpt::serialization::archiveFrom(buf);
	arch << *mg.occupancy();
	// Truncate the stream.
	std::vector<uint8_t> bytes(
	    static_cast<const uint8_t*>(buf.getRawBufferData()),
	    static_cast<const uint8_t*>(buf.getRawBufferData()) +
	        buf.getTotalBytesCount() / 2);
	mrpt::io::CMemoryStream half;
	half.assignMemoryNotOwn(bytes.data(), bytes.size());
	auto a2 = mrpt::serialization::archiveFrom(half);
	EXPECT_ANY_THROW(a2.ReadObject());
}

namespace
{
// An empty tier-0 map whose parameters are written as the given key = value
// rows (the layout of version 4), to test how the rows are read.
class Tier0WithRows : public COccupancyBayesGrid
{
 public:
	std::vector<std::pair<std::string, std::string>> rows;

 protected:
	uint8_t serializeGetVersion() const override { return 4; }
	void serializeTo(mrpt::serialization::CArchive& out) const override
	{
		out << uint32_t(rows.size());
		for (const auto& [k, v] : rows) out << k << v;
		out << uint32_t(0) << int64_t(0);  // frames, last stamp
		out << uint64_t(0);                // no blocks
	}
};

std::shared_ptr<COccupancyBayesGrid> readRows(
    std::vector<std::pair<std::string, std::string>> rows)
{
	Tier0WithRows w;
	w.rows = std::move(rows);
	mrpt::io::CMemoryStream buf;
	auto arch = mrpt::serialization::archiveFrom(buf);
	arch << w;
	buf.Seek(0);
	return std::dynamic_pointer_cast<COccupancyBayesGrid>(arch.ReadObject());
}

std::string errorReadingRows(
    std::vector<std::pair<std::string, std::string>> rows)
{
	try
	{
		readRows(std::move(rows));
	}
	catch (const std::exception& e)
	{
		return e.what();
	}
	return {};
}
}  // namespace

TEST(Serialization, EveryParameterRoundTripsAsItsRow)
{
	GridParams p = test::paperGrids();
	p.voxel_size = 0.1;
	p.decay = DecayMode::Frustum;
	p.bg_neighbourhood = BgNeighbourhood::Ray;
	p.exclude_by = ExcludeBy::Either;
	p.flow_evidence = FlowEvidence::Veto;
	p.raycast_target = RayTarget::Points;
	p.p_unknown = 0.3;
	p.raycast_margin = 0.07;
	p.max_memory_mb = 123.5;
	p.raycast_decimation = 3;
	MotionGrids mg(p);
	feed(mg, 2);
	auto t0 = roundTrip(*mg.occupancy());
	auto t2 = roundTrip(*mg.flowConsistency());
	ASSERT_TRUE(t0 && t2);
	EXPECT_TRUE(t0->params() == p);
	EXPECT_TRUE(t2->params() == p);
}

TEST(Serialization, ParameterRowsAreReadAsAGridsSection)
{
	// a key the stream lacks (a map written before it existed) keeps its
	// default
	const auto m = readRows({{"voxel_size", "0.1"}, {"decay", "frustum"}});
	ASSERT_TRUE(m);
	EXPECT_EQ(m->params().voxel_size, 0.1);
	EXPECT_EQ(m->params().decay, DecayMode::Frustum);
	EXPECT_EQ(m->params().p_miss, GridParams{}.p_miss);
	// what a [grids] section may not hold is a corrupt stream, named
	const std::string unknown = errorReadingRows({{"voxel_sise", "0.1"}});
	EXPECT_NE(unknown.find("corrupt serialised grid"), std::string::npos)
	    << unknown;
	EXPECT_NE(unknown.find("voxel_sise"), std::string::npos) << unknown;
	const std::string range = errorReadingRows({{"voxel_size", "20"}});
	EXPECT_NE(range.find("voxel_size"), std::string::npos) << range;
	const std::string choice = errorReadingRows({{"decay", "sometimes"}});
	EXPECT_NE(choice.find("sometimes"), std::string::npos) << choice;
	EXPECT_NE(errorReadingRows({{"decay\n[other]\nx", "all"}}), "");
	EXPECT_NE(errorReadingRows({{"decay", "all\nx=1"}}), "");
}
