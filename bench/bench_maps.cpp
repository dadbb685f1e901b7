// Voxel grid benchmark: tier 0/1/2 update time per frame for each decay
// mode, MRPT's COccupancyGridMap3D and COctoMap on the same clouds, memory
// per million occupied cells, the storage choice (hashed voxels vs hashed
// blocks), and the growth of the update with the readings (scale_points:
// the frame thinned) and with the map (scale_extent: the frame among copies
// of itself elsewhere; scale_explore: into unseen space, memory per frame),
// and the ray cast's walk alone per instruction set (walk/.../lanesN).
// One JSON object per measurement on stdout (see
// json_reporter.h); run through scripts/bench.sh.
//
//   bench_maps [--bonn_depth=PNG] [--sim_rawlog=RAWLOG] [--sim_frame=N]
//              [--voxels=0.02,0.05] [benchmark flags]
#include <bims/eval/tum_import.h>
#include <bims/io/json.h>
#include <bims/io/rawlog.h>
#include <bims/maps/dda.h>
#include <bims/maps/motion_grids.h>
#include <bims/maps/ray_marks.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/COccupancyGridMap3D.h>
#include <mrpt/maps/COctoMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/system/filesystem.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <random>
#include <unordered_map>

#include "json_reporter.h"

using namespace bims::maps;
namespace bm = benchmark;

namespace
{
struct Cloud
{
	std::string name;
	mrpt::obs::CObservation3DRangeScan::Ptr scan;
	mrpt::poses::CPose3D T_WS;
};

// A Bonn RGB-D depth PNG (config/bonn.ini's camera, the PNG's values kept).
Cloud loadBonn(const std::string& path)
{
	bims::eval::ImportParams p;
	p.loadFromConfigFile(mrpt::config::CConfigFile(
	    std::string(BIMS_SOURCE_DIR) + "/config/bonn.ini"));
	p.rangeUnits = 1.0 / p.camera.depthScale;
	return {"bonn", bims::eval::loadDepthFrame(path, 0, p),
	        mrpt::poses::CPose3D(0, 0, 1.5, 0, 0, 0)};
}

Cloud loadSim(const std::string& path, int frame)
{
	bims::RawlogReader r(path);
	int i = 0;
	while (auto obs = r.next())
		if (auto s =
		        std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(
		            obs))
			if (i++ == frame)
				return {"sim", s, mrpt::poses::CPose3D(0, 0, 1.3, 0, 0, 0)};
	throw std::runtime_error("rawlog '" + path + "' has fewer range scans");
}

std::vector<Cloud> g_clouds;
std::vector<double> g_voxels = {0.02, 0.05};

GridParams paramsFor(double voxel, const std::string& decay)
{
	// the paper's model (config/paper.ini), the baselines' model
	GridParams p;
	p.loadFromConfigFile(
	    mrpt::config::CConfigFile(std::string(BIMS_SOURCE_DIR) +
	                              "/config/paper.ini"),
	    "grids");
	p.voxel_size = voxel;
	p.max_range = 8;
	p.decay = decay == "all"       ? DecayMode::All
	          : decay == "frustum" ? DecayMode::Frustum
	                               : DecayMode::Raycast;
	if (decay == "raycast_voxels") p.raycast_target = RayTarget::Voxels;
	if (decay == "raycast_mt2") p.raycast_threads = 2;
	return p;
}

PixelLabels randomLabels(int w, int h)
{
	PixelLabels l(w, h, 0);
	std::mt19937 r(1);
	for (auto& x : l.label)
	{
		const int k = int(r() % 10);
		x = k == 0 ? 1 : (k == 1 ? -1 : 0);
	}
	return l;
}

void setCounters(bm::State& st, const Cloud& c, double voxel,
                 const FrameCloud& f)
{
	st.counters["voxel_m"] = voxel;
	st.counters["points"] = double(f.numPoints());
	st.counters["hit_voxels"] = double(f.numCells());
	st.counters["width"] = c.scan->rangeImage.cols();
}

// ---- our grids -------------------------------------------------------------
void benchBuild(bm::State& st, const Cloud& c, double voxel)
{
	FrameCloudBuilder b(paramsFor(voxel, "all"));
	FrameCloud f;
	for (auto _ : st) b.build(*c.scan, c.T_WS, f);
	setCounters(st, c, voxel, f);
}

// The ray cast's walk alone (markRays), one ray per reading in the image's
// row order, with the walker of \a lanes, every block stored (a map in its
// steady state): how the instruction sets compare on this CPU.
void benchWalk(bm::State& st, const Cloud& c, double voxel, RayLanes lanes)
{
	if (!rayLanesSupported(lanes))
	{
		st.SkipWithError("this CPU does not run these lanes");
		return;
	}
	FrameCloudBuilder b(paramsFor(voxel, "raycast"));
	FrameCloud f;
	b.build(*c.scan, c.T_WS, f);
	const double inv = 1 / voxel;
	const double a[3] = {f.origin_W.x * inv, f.origin_W.y * inv,
	                     f.origin_W.z * inv};
	std::vector<RayEnd> ends;
	for (const auto& p : f.points_W)
		ends.push_back({{p.x * inv, p.y * inv, p.z * inv}});
	const RayBox box = RayBox::around(a, ends.data(), ends.size());
	const BlockStored all = [](const void*, int32_t, int32_t, int32_t)
	{ return true; };
	RayMarks m;
	for (auto _ : st)
	{
		m.reset(box);
		markRays(a, ends.data(), 0, ends.size(), box, all, nullptr, m, lanes);
	}
	setCounters(st, c, voxel, f);
	st.counters["rays"] = double(ends.size());
	st.counters["blocks_touched"] = double(m.touched.size());
}

enum class Stage
{
	Tier0,
	Tier1,
	Tier2,
	All3
};

void benchTier(bm::State& st, const Cloud& c, double voxel, std::string decay,
               Stage s)
{
	const auto p = paramsFor(voxel, decay);
	MotionGrids mg(p);
	// As the pipeline does: the grids' own frame (its cells go to tiers 1
	// and 2 without a copy), built outside the timed loop ("build/...").
	const FrameCloud& f = mg.buildFrame(*c.scan, c.T_WS);
	const auto labels = randomLabels(f.K.width, f.K.height);
	for (int i = 0; i < 3; ++i) mg.processFrame(f, &labels);  // warm up
	std::vector<float> prior, p1, p2;
	mg.occupancy()->priorLogOdds(f, prior);
	mg.background()->posterior(f, prior, p1);
	for (auto _ : st)
	{
		switch (s)
		{
			case Stage::Tier0:
				mg.occupancy()->integrate(f, &prior);
				break;
			case Stage::Tier1:
				mg.background()->posterior(f, prior, p1);
				mg.background()->store(f, p1);
				break;
			case Stage::Tier2:
				mg.flowConsistency()->posterior(f, labels, p1, p2);
				mg.flowConsistency()->store(f, p2);
				break;
			case Stage::All3:
				mg.processFrame(f, &labels);
				break;
		}
	}
	setCounters(st, c, voxel, f);
	if (s == Stage::Tier0 || s == Stage::All3)
	{
		const double occ = double(mg.occupancy()->keysAbove(0.5).size());
		st.counters["occupied_voxels"] = occ;
		st.counters["storage_MiB"] = mg.occupancy()->memoryBytes() / 1048576.0;
		st.counters["MiB_per_million_occupied"] =
		    occ > 0 ? mg.occupancy()->memoryBytes() / 1048576.0 / (occ / 1e6)
		            : 0;
		size_t stored = 0;
		mg.occupancy()->storage().forEachCell(
		    [&](const VoxelKey&, const auto& cell)
		    { stored += cell.stamp != 0; });
		st.counters["touched_voxels"] = double(stored);
		st.counters["MiB_per_million_touched"] =
		    mg.occupancy()->memoryBytes() / 1048576.0 / (stored / 1e6);
	}
}

// ---- growth with point count and grid extent ------------------------------
// The cloud thinned to every s-th pixel in both directions (1/s^2 of the
// readings, same image size and intrinsics).
mrpt::obs::CObservation3DRangeScan::Ptr thinned(const Cloud& c, int s)
{
	auto o = std::make_shared<mrpt::obs::CObservation3DRangeScan>(*c.scan);
	for (int v = 0; v < int(o->rangeImage.rows()); ++v)
		for (int u = 0; u < int(o->rangeImage.cols()); ++u)
			if (u % s || v % s) o->rangeImage(v, u) = 0;
	return o;
}

size_t gridsBytes(const MotionGrids& mg)
{
	return mg.occupancy()->memoryBytes() + mg.background()->memoryBytes() +
	       mg.flowConsistency()->memoryBytes();
}

// The cloud seen from the k-th place of a 7 x 7 lattice 12 m apart in x, y
// (k = 0: the cloud's own pose): disjoint regions of the map, all inside the
// default extent.
mrpt::poses::CPose3D placeOf(const Cloud& c, int k)
{
	const int i = k % 7, j = (k / 7) % 7;
	return mrpt::poses::CPose3D(12.0 * (i - 3), 12.0 * (j - 3), 0, 0, 0, 0) +
	       c.T_WS;
}

// FrameCloud build and tiers 0+1+2 (decay = all, with labels) of the
// thinned cloud: time against readings.
void benchScalePoints(bm::State& st, const Cloud& c, double voxel, int s)
{
	const auto p = paramsFor(voxel, "all");
	const auto scan = thinned(c, s);
	MotionGrids mg(p);
	const FrameCloud& f = mg.buildFrame(*scan, c.T_WS);
	const auto labels = randomLabels(f.K.width, f.K.height);
	for (int i = 0; i < 3; ++i) mg.processFrame(mg.lastFrame(), &labels);
	for (auto _ : st) mg.processFrame(mg.lastFrame(), &labels);
	setCounters(st, c, voxel, f);
	st.counters["pixel_stride"] = s;
	FrameCloudBuilder b(p);
	FrameCloud g;
	std::vector<double> ms;
	for (int r = 0; r < 5; ++r)
	{
		const auto t0 = std::chrono::steady_clock::now();
		b.build(*scan, c.T_WS, g);
		ms.push_back(std::chrono::duration<double, std::milli>(
		                 std::chrono::steady_clock::now() - t0)
		                 .count());
	}
	std::sort(ms.begin(), ms.end());
	st.counters["build_ms_median"] = ms[2];
}

// Tiers 0+1+2 at the cloud's own place while the map also holds the cloud
// at n other places: the cost of a larger map (index size) per frame.
void benchExtentSteady(bm::State& st, const Cloud& c, double voxel, int n)
{
	const auto p = paramsFor(voxel, "all");
	MotionGrids mg(p);
	const auto labels = randomLabels(int(c.scan->rangeImage.cols()),
	                                 int(c.scan->rangeImage.rows()));
	for (int k = 1; k <= n; ++k)
	{
		mg.buildFrame(*c.scan, placeOf(c, k));
		mg.processFrame(mg.lastFrame(), &labels);
	}
	mg.buildFrame(*c.scan, placeOf(c, 0));
	for (int i = 0; i < 3; ++i) mg.processFrame(mg.lastFrame(), &labels);
	for (auto _ : st) mg.processFrame(mg.lastFrame(), &labels);
	setCounters(st, c, voxel, mg.lastFrame());
	st.counters["places_in_map"] = n + 1;
	st.counters["grids_MiB"] = gridsBytes(mg) / 1048576.0;
	st.counters["blocks_tier0"] = double(mg.occupancy()->storage().numBlocks());
}

// Tiers 0+1+2 of a frame into space the map has not seen (every block
// created): one new place per iteration; the grids' memory per frame.
void benchExtentExplore(bm::State& st, const Cloud& c, double voxel)
{
	const auto p = paramsFor(voxel, "all");
	MotionGrids mg(p);
	const auto labels = randomLabels(int(c.scan->rangeImage.cols()),
	                                 int(c.scan->rangeImage.rows()));
	int k = 0;
	for (auto _ : st)
	{
		st.PauseTiming();
		mg.buildFrame(*c.scan, placeOf(c, k++));
		st.ResumeTiming();
		mg.processFrame(mg.lastFrame(), &labels);
	}
	setCounters(st, c, voxel, mg.lastFrame());
	st.counters["places_in_map"] = k;
	st.counters["grids_MiB_per_frame"] = gridsBytes(mg) / 1048576.0 / k;
}

// ---- MRPT baselines --------------------------------------------------------
void benchGrid3D(bm::State& st, const Cloud& c, double voxel, int decimation)
{
	// The grid must contain the sensor: bounds around cloud and origin.
	FrameCloudBuilder b(paramsFor(voxel, "all"));
	FrameCloud f;
	b.build(*c.scan, c.T_WS, f);
	mrpt::math::TPoint3D lo = f.origin_W, hi = f.origin_W;
	for (const auto& q : f.points_W)
	{
		lo.x = std::min<double>(lo.x, q.x), lo.y = std::min<double>(lo.y, q.y),
		lo.z = std::min<double>(lo.z, q.z);
		hi.x = std::max<double>(hi.x, q.x), hi.y = std::max<double>(hi.y, q.y),
		hi.z = std::max<double>(hi.z, q.z);
	}
	const mrpt::math::TPoint3D m(0.1, 0.1, 0.1);
	mrpt::maps::COccupancyGridMap3D g(lo - m, hi + m, float(voxel));
	g.insertionOptions.maxDistanceInsertion = 8;
	if (decimation > 0) g.insertionOptions.decimation_3d_range = decimation;
	st.counters["decimation_3d_range"] = g.insertionOptions.decimation_3d_range;
	for (auto _ : st) g.insertObservation(*c.scan, c.T_WS);
	setCounters(st, c, voxel, f);
}

void benchOctoMap(bm::State& st, const Cloud& c, double voxel)
{
	FrameCloudBuilder b(paramsFor(voxel, "all"));
	FrameCloud f;
	b.build(*c.scan, c.T_WS, f);
	mrpt::maps::COctoMap m(voxel);
	m.insertionOptions.maxrange = 8;
	// COctoMap::insertObservation() of a range scan uses its embedded
	// points3D (absent here); insert the same cloud as our grids, in {W}.
	mrpt::maps::CSimplePointsMap pts;
	for (const auto& q : f.points_W) pts.insertPoint(q.x, q.y, q.z);
	const auto& o = f.origin_W;
	for (auto _ : st)
		m.insertPointCloud(pts, float(o.x), float(o.y), float(o.z));
	setCounters(st, c, voxel, f);
	// The octree behind COctoMap is private (pimpl): leaves (occupied + free)
	// are what its API counts.
	st.counters["leaf_voxels"] = double(m.getNumLeafNodes());
	st.counters["storage_MiB"] = m.memoryUsage() / 1048576.0;
	st.counters["MiB_per_million_leaves"] =
	    m.memoryUsage() / 1048576.0 / (m.getNumLeafNodes() / 1e6);
}

// ---- storage choice: the same full-resolution ray casting workload ---------
struct RayCell
{
	float l = 0;
	uint32_t stamp = 0;
};

template <int L>
void benchStorageBlocks(bm::State& st, const Cloud& c, double voxel)
{
	FrameCloudBuilder b(paramsFor(voxel, "all"));
	FrameCloud f;
	b.build(*c.scan, c.T_WS, f);
	SparseVoxelGrid<RayCell, L> g;
	const double inv = 1 / voxel;
	const double a[3] = {f.origin_W.x * inv, f.origin_W.y * inv,
	                     f.origin_W.z * inv};
	uint32_t F = 0;
	size_t steps = 0;
	for (auto _ : st)
	{
		++F;
		steps = 0;
		typename SparseVoxelGrid<RayCell, L>::Accessor acc(g);
		for (const auto& p : f.points_W)
		{
			const double e[3] = {p.x * inv, p.y * inv, p.z * inv};
			traverseRay(a, e,
			            [&](int32_t x, int32_t y, int32_t z)
			            {
				            RayCell* cell = acc.get(x, y, z);
				            ++steps;
				            if (cell->stamp != F)
				            {
					            cell->stamp = F;
					            cell->l = std::max(cell->l - 0.64f, -2.f);
				            }
			            });
		}
	}
	setCounters(st, c, voxel, f);
	st.counters["storage_MiB"] = g.memoryBytes() / 1048576.0;
	st.counters["ray_steps"] = double(steps);
}

void benchStorageUnordered(bm::State& st, const Cloud& c, double voxel)
{
	FrameCloudBuilder b(paramsFor(voxel, "all"));
	FrameCloud f;
	b.build(*c.scan, c.T_WS, f);
	std::unordered_map<uint64_t, RayCell> g;
	const double inv = 1 / voxel;
	const double a[3] = {f.origin_W.x * inv, f.origin_W.y * inv,
	                     f.origin_W.z * inv};
	uint32_t F = 0;
	for (auto _ : st)
	{
		++F;
		for (const auto& p : f.points_W)
		{
			const double e[3] = {p.x * inv, p.y * inv, p.z * inv};
			traverseRay(a, e,
			            [&](int32_t x, int32_t y, int32_t z)
			            {
				            RayCell& cell = g[packKey(x, y, z)];
				            if (cell.stamp != F)
				            {
					            cell.stamp = F;
					            cell.l = std::max(cell.l - 0.64f, -2.f);
				            }
			            });
		}
	}
	setCounters(st, c, voxel, f);
	// node: key + value + next pointer + cached hash, plus the bucket array
	st.counters["storage_MiB"] =
	    (g.size() * (8 + sizeof(RayCell) + 16) + g.bucket_count() * 8) /
	    1048576.0;
}

// The speed-ups of our ray casts over MRPT's two maps on the same cloud,
// from the measurements of this run: one JSON object per ray cast, cloud
// and voxel size ("ratio/tier0/raycast/bonn/2cm": MRPT's time / ours, CPU
// and wall), and a table on stderr.
void printRatios(const bims::bench::Results& res)
{
	auto find =
	    [&](const std::string& n) -> const std::map<std::string, double>*
	{
		auto it = res.find(n);
		return it == res.end() ? nullptr : &it->second;
	};
	for (const auto& [name, f] : res)
	{
		if (name.rfind("tier0/raycast", 0) != 0) continue;
		// tier0/<decay>/<cloud>/<voxel>: the MRPT maps of /<cloud>/<voxel>
		const std::string where = name.substr(name.find('/', 6));
		const auto* grid3d = find("mrpt_grid3d_dec1" + where);
		const auto* octo = find("mrpt_octomap" + where);
		if (!grid3d && !octo) continue;
		bims::Json j;
		j["name"] = "ratio/" + name;
		std::cerr << name << ": " << f.at("cpu_ms_median") << " ms CPU, "
		          << f.at("ms_median") << " ms wall";
		auto add = [&](const char* key, const auto* m)
		{
			if (!m) return;
			const double cpu = m->at("cpu_ms_median") / f.at("cpu_ms_median");
			const double wall = m->at("ms_median") / f.at("ms_median");
			j[std::string(key) + "_over_ours_cpu"] = bims::jsonNumber(cpu);
			j[std::string(key) + "_over_ours_wall"] = bims::jsonNumber(wall);
			std::cerr << "; " << key << " / ours " << cpu << "x CPU, " << wall
			          << "x wall";
		};
		add("grid3d_dec1", grid3d);
		add("octomap", octo);
		std::cerr << "\n";
		std::cout << bims::jsonLine(j) << std::endl;
	}
}

std::string findFirstPng(const std::string& dir)
{
	std::vector<std::string> f;
	if (!std::filesystem::is_directory(dir)) return {};
	for (const auto& e : std::filesystem::directory_iterator(dir))
		if (e.path().extension() == ".png") f.push_back(e.path().string());
	std::sort(f.begin(), f.end());
	return f.empty() ? std::string() : f.front();
}

// Milliseconds of wall time, a fixed number of iterations per repetition,
// the aggregates of the repetitions only.
bm::internal::Benchmark* timed(bm::internal::Benchmark* b, int iterations,
                               int repetitions)
{
	b->Unit(bm::kMillisecond)
	    ->UseRealTime()
	    ->Iterations(iterations)
	    ->Repetitions(repetitions);
	if (repetitions > 1) b->ReportAggregatesOnly();
	return b;
}

void registerAll()
{
	for (const auto& c : g_clouds)
		for (double v : g_voxels)
		{
			const std::string sfx = "/" + c.name + "/" +
			                        std::to_string(int(std::lround(v * 100))) +
			                        "cm";
			timed(bm::RegisterBenchmark(("build" + sfx).c_str(), benchBuild, c,
			                            v),
			      10, 5);
			for (std::string d :
			     {"all", "frustum", "raycast", "raycast_mt2", "raycast_voxels"})
			{
				const bool slow = d.rfind("raycast", 0) == 0;
				const int it = slow ? 2 : 20;
				const std::pair<const char*, Stage> stages[] = {
				    {"tier0", Stage::Tier0},
				    {"tier1", Stage::Tier1},
				    {"tier2", Stage::Tier2},
				    {"tiers012", Stage::All3}};
				for (const auto& [sn, s] : stages)
				{
					if (slow && (s == Stage::Tier1 || s == Stage::Tier2))
						continue;  // decay-independent
					auto* b =
					    timed(bm::RegisterBenchmark(
					              (std::string(sn) + "/" + d + sfx).c_str(),
					              benchTier, c, v, d, s),
					          it, 5);
					// CPU time of all threads, not only the calling one.
					if (d == "raycast_mt2") b->MeasureProcessCPUTime();
				}
			}
			for (const auto& [ln, l] :
			     {std::pair{"1", RayLanes::One}, std::pair{"4", RayLanes::Four},
			      std::pair{"8", RayLanes::Eight}})
				timed(bm::RegisterBenchmark(
				          ("walk" + sfx + "/lanes" + ln).c_str(), benchWalk, c,
				          v, l),
				      5, 5);
			for (int stride : {4, 2, 1})
				timed(bm::RegisterBenchmark(("scale_points" + sfx + "/stride" +
				                             std::to_string(stride))
				                                .c_str(),
				                            benchScalePoints, c, v, stride),
				      20, 5);
			for (int n : {0, 8, 48})
				timed(bm::RegisterBenchmark(("scale_extent" + sfx + "/places" +
				                             std::to_string(n + 1))
				                                .c_str(),
				                            benchExtentSteady, c, v, n),
				      20, 5);
			// 48 new places: the lattice has 49, the cloud's own is left.
			timed(bm::RegisterBenchmark(("scale_explore" + sfx).c_str(),
			                            benchExtentExplore, c, v),
			      48, 1);
			timed(bm::RegisterBenchmark(("mrpt_grid3d_dec1" + sfx).c_str(),
			                            benchGrid3D, c, v, 1),
			      1, 3);
			timed(bm::RegisterBenchmark(("mrpt_grid3d_default" + sfx).c_str(),
			                            benchGrid3D, c, v, 0),
			      3, 3);
			timed(bm::RegisterBenchmark(("mrpt_octomap" + sfx).c_str(),
			                            benchOctoMap, c, v),
			      1, 3);
			timed(bm::RegisterBenchmark(
			          ("storage_raycast_hash_voxels_std" + sfx).c_str(),
			          benchStorageUnordered, c, v),
			      1, 3);
			timed(bm::RegisterBenchmark(
			          ("storage_raycast_hash_voxels_flat" + sfx).c_str(),
			          benchStorageBlocks<0>, c, v),
			      1, 3);
			timed(
			    bm::RegisterBenchmark(("storage_raycast_blocks8" + sfx).c_str(),
			                          benchStorageBlocks<3>, c, v),
			    1, 3);
			timed(bm::RegisterBenchmark(
			          ("storage_raycast_blocks16" + sfx).c_str(),
			          benchStorageBlocks<4>, c, v),
			      1, 3);
		}
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		std::string bonn = findFirstPng(std::string(BIMS_SHARED_DATA_DIR) +
		                                "/bonn_crowd_f150_349/depth");
		std::string sim;
		int simFrame = 3;
		std::vector<char*> rest = {argv[0]};
		for (int i = 1; i < argc; ++i)
		{
			auto val = [&](const char* k)
			{ return bims::bench::flagValue(argv[i], k); };
			if (auto v = val("--bonn_depth"))
				bonn = v;
			else if (auto v = val("--sim_rawlog"))
				sim = v;
			else if (auto v = val("--sim_frame"))
				simFrame = std::stoi(v);
			else if (auto v = val("--voxels"))
			{
				g_voxels.clear();
				std::stringstream ss(v);
				std::string t;
				while (std::getline(ss, t, ','))
					g_voxels.push_back(std::stod(t));
			}
			else
				rest.push_back(argv[i]);
		}
		if (!bonn.empty()) g_clouds.push_back(loadBonn(bonn));
		if (!sim.empty()) g_clouds.push_back(loadSim(sim, simFrame));
		if (g_clouds.empty())
			throw std::runtime_error(
			    "no cloud: give --bonn_depth and/or --sim_rawlog");
		for (const auto& c : g_clouds)
			std::cerr << "cloud " << c.name << ": " << c.scan->rangeImage.cols()
			          << "x" << c.scan->rangeImage.rows() << "\n";
		registerAll();
		int n = int(rest.size());
		bims::bench::Results res;
		const int rc = bims::bench::runWithJsonLines(n, rest.data(), &res);
		printRatios(res);
		return rc;
	}
	catch (const std::exception& e)
	{
		std::cerr << "bench_maps: error: " << e.what() << "\n";
		return 1;
	}
}
