// Proves the registration fix: this executable links bims::maps but names
// none of its symbols (only MRPT's API). The grids must still be creatable
// by name from an .ini through CMultiMetricMap, usable through
// insertObservation(), and deserialisable with CArchive::ReadObject().
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/serialization/CArchive.h>

#include <gtest/gtest.h>

namespace
{
const char* kIni = R"(
[map]
occupancyBayesGrid_count=1
backgroundSubtractionGrid_count=1
bims::maps::CFlowConsistencyGrid_count=1

[map_occupancyBayesGrid_00_creationOpts]
voxel_size=0.04
decay=raycast
p_miss=0.2
enableSaveAs3DObject=true

[map_backgroundSubtractionGrid_00_creationOpts]
voxel_size=0.04
bg_transition_eps=0.02

[map_bims::maps::CFlowConsistencyGrid_00_creationOpts]
voxel_size=0.04
flow_lambda=3
flow_evidence=veto
)";

mrpt::obs::CObservation3DRangeScan::Ptr flatWall()
{
	auto o = mrpt::obs::CObservation3DRangeScan::Create();
	o->hasRangeImage = true;
	o->range_is_depth = true;
	o->rangeUnits = 0.001f;
	o->rangeImage_setSize(24, 32);
	o->rangeImage.fill(2000);  // a wall 2 m ahead
	o->cameraParams.ncols = 32;
	o->cameraParams.nrows = 24;
	o->cameraParams.setIntrinsicParamsFromValues(30, 30, 15.5, 11.5);
	o->timestamp = mrpt::Clock::time_point(mrpt::Clock::duration(12345));
	return o;
}
}  // namespace

TEST(IniCreation, GridsAreCreatedByNameWithoutNamingAnySymbol)
{
	mrpt::config::CConfigFileMemory cfg(kIni);
	mrpt::maps::TSetOfMetricMapInitializers inits;
	inits.loadFromConfigFile(cfg, "map");
	mrpt::maps::CMultiMetricMap mm(inits);
	ASSERT_EQ(mm.maps.size(), 3u);
	std::multiset<std::string> names;
	for (const auto& m : mm.maps) names.insert(m->GetRuntimeClass()->className);
	EXPECT_EQ(names.count("bims::maps::COccupancyBayesGrid"), 1u);
	EXPECT_EQ(names.count("bims::maps::CBackgroundSubtractionGrid"), 1u);
	EXPECT_EQ(names.count("bims::maps::CFlowConsistencyGrid"), 1u);
	// Parameters arrived (asString names voxel size and decay).
	for (const auto& m : mm.maps)
		if (std::string(m->GetRuntimeClass()->className) ==
		    "bims::maps::COccupancyBayesGrid")
		{
			EXPECT_NE(m->asString().find("decay=raycast"), std::string::npos)
			    << m->asString();
			EXPECT_NE(m->asString().find("0.04"), std::string::npos);
		}

	// MRPT's normal insertion path reaches every grid.
	auto scan = flatWall();
	EXPECT_TRUE(
	    mm.insertObservation(*scan, mrpt::poses::CPose3D(0, 0, 1, 0, 0, 0)));
	for (const auto& m : mm.maps) EXPECT_FALSE(m->isEmpty()) << m->asString();

	// Polymorphic serialisation round trip by class name.
	for (const auto& m : mm.maps)
	{
		mrpt::io::CMemoryStream buf;
		auto arch = mrpt::serialization::archiveFrom(buf);
		arch << *m;
		buf.Seek(0);
		auto back = arch.ReadObject();
		ASSERT_TRUE(back);
		EXPECT_STREQ(back->GetRuntimeClass()->className,
		             m->GetRuntimeClass()->className);
	}
}

TEST(IniCreation, UnknownKeyIsAnErrorNamingIt)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[map]\noccupancyBayesGrid_count=1\n"
	    "[map_occupancyBayesGrid_00_creationOpts]\nvoxel_sise=0.04\n");
	mrpt::maps::TSetOfMetricMapInitializers inits;
	try
	{
		inits.loadFromConfigFile(cfg, "map");
		FAIL() << "no exception for a mistyped key";
	}
	catch (const std::exception& e)
	{
		EXPECT_NE(std::string(e.what()).find("voxel_sise"), std::string::npos)
		    << e.what();
	}
}

TEST(IniCreation, OutOfRangeValueIsAnError)
{
	mrpt::config::CConfigFileMemory cfg(
	    "[map]\nflowConsistencyGrid_count=1\n"
	    "[map_flowConsistencyGrid_00_creationOpts]\nflow_lambda=1\n");
	mrpt::maps::TSetOfMetricMapInitializers inits;
	EXPECT_ANY_THROW(inits.loadFromConfigFile(cfg, "map"));
}
