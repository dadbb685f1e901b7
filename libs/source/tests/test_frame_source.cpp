// The one ordering rule (bims/source/frame_source.h) on hand-made streams:
// when a frame is released, with which IMU samples, and which scans are
// skipped and why.
#include <bims/source/frame_source.h>
#include <bims_test/sample.h>
#include <gtest/gtest.h>

#include <mrpt/core/Clock.h>

#include <cmath>
#include <string>
#include <vector>

using namespace bims::source;
using mrpt::obs::CObservation;
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

namespace
{
const std::string kFile = "test.rawlog";

CObservation::Ptr scan(double t, int w = 4, int h = 3,
                       const std::string& label = "RGBD")
{
	auto o = CObservation3DRangeScan::Create();
	o->timestamp = mrpt::Clock::fromDouble(t);
	o->sensorLabel = label;
	o->hasRangeImage = true;
	o->rangeImage.setZero(h, w);
	return o;
}

CObservation::Ptr imu(double t, double wz = 0.1,
                      const std::string& label = "IMU")
{
	auto o = CObservationIMU::Create();
	o->timestamp = mrpt::Clock::fromDouble(t);
	o->sensorLabel = label;
	o->set(mrpt::obs::IMU_WZ, wz);
	return o;
}

/** Collects the warnings into \a said, one line each as a program named
 * "test" words them (bims/apps/warnings.h). */
bims::WarningCallback collectInto(std::string& said)
{
	return [&said](const bims::Warning& w)
	{
		const char* kind = w.kind == bims::Warning::Kind::Warning ? "warning: "
		                   : w.kind == bims::Warning::Kind::Note  ? "note: "
		                                                          : "";
		said += "test: " + std::string(kind) + w.where + ": " + w.text + "\n";
	};
}

FrameOrderParams params()
{
	FrameOrderParams p;
	p.program = "test";
	p.warn = {};  // silent unless a test listens
	p.imuWaitS = 0.2;
	return p;
}

/** Pushes \a in (entries numbered in order), then the end; the frames. */
std::vector<SourceFrame> run(FrameOrder& order,
                             const std::vector<CObservation::Ptr>& in)
{
	std::vector<SourceFrame> out;
	size_t k = 0;
	for (const auto& o : in)
	{
		if (!order.push(o, {&kFile, k++})) break;
		while (auto f = order.pop()) out.push_back(std::move(*f));
	}
	order.finish({&kFile, k});
	while (auto f = order.pop()) out.push_back(std::move(*f));
	return out;
}

double stamp(const CObservation::Ptr& o)
{
	return mrpt::Clock::toDouble(o->timestamp);
}
}  // namespace

TEST(FrameOrder, AFrameWaitsUntilTheImuHasPassedItsTime)
{
	FrameOrder order(params());
	ASSERT_TRUE(order.push(imu(0.95), {&kFile, 0}));
	ASSERT_TRUE(order.push(scan(1.0), {&kFile, 1}));
	EXPECT_FALSE(order.pop()) << "the IMU has not reached t=1.0 yet";
	ASSERT_TRUE(order.push(imu(0.99), {&kFile, 2}));
	EXPECT_FALSE(order.pop());
	ASSERT_TRUE(order.push(imu(1.01), {&kFile, 3}));
	auto f = order.pop();
	ASSERT_TRUE(f);
	EXPECT_EQ(f->index, 0u);
	EXPECT_DOUBLE_EQ(f->t, 1.0);
	// every usable sample read so far, in input order, the one past it too
	ASSERT_EQ(f->imu.size(), 3u);
	EXPECT_DOUBLE_EQ(stamp(f->imu[0]), 0.95);
	EXPECT_DOUBLE_EQ(stamp(f->imu[2]), 1.01);
	EXPECT_FALSE(f->imuRejected);
}

TEST(FrameOrder, TheImuOffsetShiftsWhenAFrameIsReady)
{
	auto p = params();
	p.imuOffsetS = 0.05;  // the IMU stamps the same instant 50 ms later
	FrameOrder order(p);
	order.push(scan(1.0), {&kFile, 0});
	order.push(imu(1.03), {&kFile, 1});
	EXPECT_FALSE(order.pop());
	order.push(imu(1.05), {&kFile, 2});
	EXPECT_TRUE(order.pop());
}

TEST(FrameOrder, WithoutImuAFrameIsReleasedOnceDataImuWaitNewerIsRead)
{
	FrameOrder order(params());
	order.push(scan(1.0), {&kFile, 0});
	order.push(scan(1.1), {&kFile, 1});
	order.push(scan(1.2), {&kFile, 2});
	EXPECT_FALSE(order.pop()) << "0.2 s newer is not more than imu_wait_s";
	order.push(scan(1.3), {&kFile, 3});
	auto f = order.pop();
	ASSERT_TRUE(f);
	EXPECT_EQ(f->index, 0u);
	EXPECT_FALSE(order.pop());
	order.finish({&kFile, 4});
	for (size_t i = 1; i < 4; ++i)
	{
		auto g = order.pop();
		ASSERT_TRUE(g) << "the end releases every frame";
		EXPECT_EQ(g->index, i);
	}
}

TEST(FrameOrder, AScanNotAfterThePreviousIsSkippedAndCounted)
{
	FrameOrder order(params());
	const auto frames = run(order, {scan(1.0), scan(1.1), scan(1.05), scan(1.1),
	                                scan(1.2), imu(1.3)});
	ASSERT_EQ(frames.size(), 3u);
	EXPECT_EQ(frames[0].index, 0u);
	EXPECT_EQ(frames[1].index, 1u);
	EXPECT_EQ(frames[2].index, 4u) << "indices count every scan read";
	EXPECT_EQ(order.stats().scansRead, 5u);
	EXPECT_EQ(order.stats().scansOutOfOrder, 2u);
}

TEST(FrameOrder, AStrayStampIsSkippedAndAJumpOfTheRecordingIsKept)
{
	{
		FrameOrder order(params());
		// 50 s ahead, then back on time: a stray stamp
		const auto frames =
		    run(order, {scan(1.0), scan(51.0), scan(1.1), scan(1.2)});
		ASSERT_EQ(frames.size(), 3u);
		EXPECT_EQ(frames[1].index, 2u);
		EXPECT_EQ(order.stats().scansBadStamp, 1u);
	}
	{
		FrameOrder order(params());
		// 50 s ahead, and the recording goes on from there: a jump
		const auto frames =
		    run(order, {scan(1.0), scan(51.0), scan(51.1), scan(51.2)});
		ASSERT_EQ(frames.size(), 4u);
		EXPECT_DOUBLE_EQ(frames[1].t, 51.0);
		EXPECT_EQ(order.stats().scansBadStamp, 0u);
	}
	{
		FrameOrder order(params());
		const auto frames = run(order, {scan(1.0), scan(1.1), scan(99.0)});
		EXPECT_EQ(frames.size(), 2u) << "a far last scan is stray";
		EXPECT_EQ(order.stats().scansBadStamp, 1u);
	}
}

TEST(FrameOrder, ObservationsOfOtherLabelsAndClassesAreSkipped)
{
	auto p = params();
	p.sensors.rgbd_label = "RGBD";
	p.sensors.imu_label = "IMU";
	FrameOrder order(p);
	const auto frames =
	    run(order, {imu(0.9, 0.1, "IMU2"), scan(1.0, 4, 3, "OTHER"), scan(1.1),
	                imu(1.2), CObservationIMU::Create(), imu(1.3, 0.1, "IMU")});
	ASSERT_EQ(frames.size(), 1u);
	EXPECT_EQ(frames[0].index, 0u) << "scans of another label get no index";
	EXPECT_EQ(frames[0].imu.size(), 1u) << "released at the sample at 1.2";
	EXPECT_EQ(order.stats().otherSkipped, 3u);
	EXPECT_EQ(order.stats().imuRead, 2u);
}

// Issue 35: at the start a run says which IMU it uses and what it measures
// (at its first sample), or that none of the label came before the second
// scan; the counts follow in the summary (imuNotes).
TEST(FrameOrder, TheImuInUseIsSaidAtTheStart)
{
	auto p = params();
	p.sensors.imu_label = "IMU";
	const auto stderrOf = [&](const std::vector<CObservation::Ptr>& in)
	{
		std::string said;
		p.warn = collectInto(said);
		FrameOrder order(p);
		run(order, in);
		return said;
	};
	const auto gyro = [](double t)
	{
		auto o = CObservationIMU::Create();
		o->timestamp = mrpt::Clock::fromDouble(t);
		o->sensorLabel = "IMU";
		for (auto i : {mrpt::obs::IMU_WX, mrpt::obs::IMU_WY, mrpt::obs::IMU_WZ})
			o->set(i, 0.1);
		return o;
	};
	EXPECT_EQ(
	    stderrOf({gyro(0.9), scan(1.0), gyro(1.05), scan(1.1), gyro(1.2)}),
	    "test: test.rawlog: using the IMU labelled 'IMU' (gyro)\n");
	EXPECT_EQ(
	    stderrOf({scan(1.0), scan(1.1), scan(1.2)}),
	    "test: test.rawlog: no IMU sample labelled 'IMU' before the second 3D "
	    "scan (none in the input so far): frames without one run "
	    "without IMU data (imu_missing)\n");
	const std::string other =
	    stderrOf({imu(0.9, 0.1, "GYRO"), scan(1.0), scan(1.1)});
	EXPECT_NE(other.find("IMU samples labelled 'GYRO' (no gyro, accel or mag) "
	                     "are not used: "
	                     "[sensors] imu_label is 'IMU'"),
	          std::string::npos)
	    << other;
	EXPECT_NE(other.find("no IMU sample labelled 'IMU' before the second 3D "
	                     "scan (only under other labels so far: [sensors] "
	                     "imu_label)"),
	          std::string::npos)
	    << other;
	p.warnings = false;  // an indexing pass says nothing
	EXPECT_EQ(stderrOf({scan(1.0), scan(1.1), scan(1.2)}), "");
}

// No IMU is left unused silently: the samples of other labels are counted
// by label with what they measure, and the notes of a run say which IMU was
// used, what it measures, and what was not used and how to use it.
TEST(FrameOrder, ImuSamplesOfOtherLabelsAreCountedAndNamed)
{
	auto accel = [](double t, const std::string& label)
	{
		auto o = CObservationIMU::Create();
		o->timestamp = mrpt::Clock::fromDouble(t);
		o->sensorLabel = label;
		o->set(mrpt::obs::IMU_X_ACC, 0.1);
		o->set(mrpt::obs::IMU_Y_ACC, -9.8);
		o->set(mrpt::obs::IMU_Z_ACC, 0.2);
		return o;
	};
	auto full = [](double t)
	{
		auto o = CObservationIMU::Create();
		o->timestamp = mrpt::Clock::fromDouble(t);
		o->sensorLabel = "IMU_SYNTH";
		for (auto i :
		     {mrpt::obs::IMU_WX, mrpt::obs::IMU_WY, mrpt::obs::IMU_WZ,
		      mrpt::obs::IMU_X_ACC, mrpt::obs::IMU_Y_ACC, mrpt::obs::IMU_Z_ACC,
		      mrpt::obs::IMU_MAG_X, mrpt::obs::IMU_MAG_Y, mrpt::obs::IMU_MAG_Z})
			o->set(i, 0.5);
		return o;
	};
	auto p = params();
	p.warnings = false;
	p.sensors.imu_label = "IMU_SYNTH";
	{
		FrameOrder order(p);
		run(order, {accel(0.9, "ACCEL"), full(0.95), accel(1.0, "ACCEL"),
		            scan(1.0), imu(1.05, 0.1, "GYRO"), full(1.2)});
		const auto& s = order.stats();
		EXPECT_EQ(s.imuRead, 2u);
		EXPECT_EQ(s.imuChannels, kImuGyro | kImuAccel | kImuMag);
		ASSERT_EQ(s.imuOtherLabels.size(), 2u);
		EXPECT_EQ(s.imuOtherLabels.at("ACCEL").samples, 2u);
		EXPECT_EQ(s.imuOtherLabels.at("ACCEL").channels, kImuAccel);
		EXPECT_EQ(s.imuOtherLabels.at("GYRO").channels, 0)
		    << "one gyro axis is not a gyro";
		EXPECT_EQ(
		    imuNotes(s, "IMU_SYNTH"),
		    (std::vector<std::string>{
		        "IMU labelled 'IMU_SYNTH': 2 samples (gyro + accel + mag)",
		        "2 IMU samples labelled 'ACCEL' (accel) were not used: "
		        "[sensors] imu_label is 'IMU_SYNTH'",
		        "1 IMU samples labelled 'GYRO' (no gyro, accel or mag) were "
		        "not "
		        "used: [sensors] imu_label is 'IMU_SYNTH'"}));
	}
	{
		// The configured label matches none: the note says how to use them.
		FrameOrder order(p);
		run(order, {accel(0.9, "ACCEL"), scan(1.0), accel(1.2, "ACCEL")});
		EXPECT_EQ(imuNotes(order.stats(), "IMU_SYNTH"),
		          (std::vector<std::string>{
		              "2 IMU samples labelled 'ACCEL' (accel) were not used: "
		              "[sensors] imu_label is 'IMU_SYNTH' (set it to 'ACCEL' "
		              "to use them)"}));
	}
	{
		// An accelerometer alone: used, and said to give the egomotion
		// nothing.
		p.sensors.imu_label = "ACCEL";
		FrameOrder order(p);
		run(order, {accel(0.9, "ACCEL"), scan(1.0), accel(1.2, "ACCEL")});
		const auto n = imuNotes(order.stats(), "ACCEL");
		ASSERT_EQ(n.size(), 1u);
		EXPECT_EQ(n[0].rfind("IMU labelled 'ACCEL': 2 samples (accel); without "
		                     "a gyro the egomotion cannot use them",
		                     0),
		          0u)
		    << n[0];
	}
}

// IMU stamps as scan stamps: one stamp shifted far ahead is stray (skipped,
// counted; it must not release every frame at once nor push the others out
// of order), a recording that jumps keeps its samples, stamps that go back
// or repeat are skipped and counted.
TEST(FrameOrder, ImuSamplesWithStrayOrOutOfOrderStampsAreSkippedAndCounted)
{
	auto p = params();
	p.warnings = false;
	auto stamps = [](const std::vector<SourceFrame>& frames)
	{
		std::vector<double> t;
		for (const auto& f : frames)
			for (const auto& m : f.imu)
				t.push_back(mrpt::Clock::toDouble(m->timestamp));
		return t;
	};
	{
		FrameOrder order(p);
		const auto frames = run(
		    order, {imu(0.95), scan(1.0), imu(1.05), imu(1.07 + 1e5), imu(1.1),
		            scan(1.1), imu(1.15), imu(1.2), scan(1.2), imu(1.25)});
		ASSERT_EQ(frames.size(), 3u);
		EXPECT_EQ(stamps(frames),
		          (std::vector<double>{0.95, 1.05, 1.1, 1.15, 1.2}));
		EXPECT_EQ(order.stats().imuBadStamp, 1u);
		EXPECT_EQ(order.stats().imuOutOfOrder, 0u);
		EXPECT_EQ(order.stats().imuRead, 7u);
	}
	{
		// a far stamp followed by one within the gap: the recording jumped
		FrameOrder order(p);
		const auto frames =
		    run(order, {imu(0.95), scan(1.0), imu(31.0), imu(31.05),
		                scan(31.05), imu(31.1), scan(31.1), imu(31.15)});
		ASSERT_EQ(frames.size(), 3u);
		EXPECT_EQ(stamps(frames),
		          (std::vector<double>{0.95, 31.0, 31.05, 31.1}));
		EXPECT_EQ(order.stats().imuBadStamp, 0u);
	}
	{
		// stamps that go back or repeat, and a far one as the last sample
		FrameOrder order(p);
		const auto frames =
		    run(order, {imu(0.95), scan(1.0), imu(1.05), imu(1.05), imu(1.02),
		                imu(1.1), scan(1.1), imu(1.2), imu(500.0)});
		ASSERT_EQ(frames.size(), 2u);
		EXPECT_EQ(stamps(frames), (std::vector<double>{0.95, 1.05, 1.1}));
		EXPECT_EQ(order.stats().imuOutOfOrder, 2u);
		EXPECT_EQ(order.stats().imuBadStamp, 1u);
		const auto n = imuNotes(order.stats(), "IMU");
		ASSERT_FALSE(n.empty());
		EXPECT_EQ(n[0].rfind("IMU labelled 'IMU': 7 samples", 0), 0u) << n[0];
	}
	{
		// all in reverse order: most of the IMU unusable, and said so
		FrameOrder order(p);
		run(order, {imu(1.3), imu(1.2), imu(1.1), scan(1.0), imu(1.0),
		            scan(1.1), imu(0.9)});
		EXPECT_EQ(order.stats().imuOutOfOrder, 4u);
		const auto n = imuNotes(order.stats(), "IMU");
		ASSERT_FALSE(n.empty());
		EXPECT_EQ(n[0].rfind("the IMU was mostly unusable: 4 of its 5 samples "
		                     "skipped (4 out of order or repeated",
		                     0),
		          0u)
		    << n[0];
	}
}

TEST(FrameOrder, ReadingStopsAfterTheLastFrameOfTheRange)
{
	auto p = params();
	p.frames = FrameRange::parse("1:2");
	FrameOrder order(p);
	EXPECT_TRUE(order.push(scan(1.0), {&kFile, 0}));
	EXPECT_TRUE(order.push(scan(1.1), {&kFile, 1}));
	EXPECT_TRUE(order.push(scan(1.2), {&kFile, 2}));
	EXPECT_FALSE(order.push(scan(1.3), {&kFile, 3})) << "past 2: stop";
	order.finish({&kFile, 4});
	std::vector<size_t> got;
	while (auto f = order.pop()) got.push_back(f->index);
	EXPECT_EQ(got, (std::vector<size_t>{1, 2}));
	EXPECT_TRUE(order.error().empty());
}

TEST(FrameOrder, AnotherImageSizeEndsTheInputWithAnErrorAfterTheFramesBefore)
{
	FrameOrder order(params());
	const auto frames =
	    run(order, {scan(1.0), scan(1.1), scan(1.2, 8, 6), scan(1.3)});
	EXPECT_EQ(frames.size(), 2u);
	EXPECT_NE(order.error().find("test.rawlog: 3D scan #2 has a 8x6 depth "
	                             "image where the run's first had 4x3"),
	          std::string::npos)
	    << order.error();
}

TEST(FrameOrder, ARejectedImuSampleIsNotFedAndFlagsItsFrame)
{
	FrameOrder order(params());
	const auto frames = run(order, {imu(0.9), scan(1.0), imu(1.05, NAN),
	                                scan(1.1), imu(1.2), scan(1.3), imu(1.4)});
	ASSERT_EQ(frames.size(), 3u);
	EXPECT_FALSE(frames[0].imuRejected);
	EXPECT_TRUE(frames[1].imuRejected) << "the NaN sample at 1.05 <= 1.1";
	EXPECT_FALSE(frames[2].imuRejected);
	size_t fed = 0;
	for (const auto& f : frames) fed += f.imu.size();
	EXPECT_EQ(fed, 3u);
	EXPECT_EQ(order.stats().imuRejected, 1u);
}

TEST(FrameOrder, KeptInputWrittenBeforeEachFrameIsTheInputOrder)
{
	auto p = params();
	p.keepInput = true;
	FrameOrder order(p);
	const std::vector<CObservation::Ptr> in = {
	    imu(0.9), scan(1.0),  imu(1.05, NAN), scan(51.0), imu(51.05), scan(1.1),
	    imu(1.2), scan(1.05), imu(1.3),       scan(1.4),  imu(1.5)};
	const auto frames = run(order, in);
	// written: before-list, frame, ..., then the trailing observations
	std::vector<CObservation::Ptr> written;
	for (const auto& f : frames)
	{
		written.insert(written.end(), f.before.begin(), f.before.end());
		written.push_back(f.scan);
	}
	for (const auto& o : order.takeTrailing()) written.push_back(o);
	// the input without the stray (51.0) and out-of-order (1.05) scans, the
	// rejected IMU sample kept
	std::vector<CObservation::Ptr> want;
	for (const auto& o : in)
		if (o != in[3] && o != in[7]) want.push_back(o);
	EXPECT_EQ(written, want);
}

TEST(FrameOrder, WithoutWarningsTheSameFramesAndCountsAndNothingOnStderr)
{
	// an out-of-order scan, a stray stamp and a NaN IMU sample: warned of
	// by default, counted in silence for a pass that only indexes the input
	const std::vector<CObservation::Ptr> in = {
	    imu(0.9),   scan(1.0), imu(1.05, NAN), scan(1.1),
	    scan(1.05), scan(40.), scan(1.2),      imu(1.3)};
	auto once = [&](bool warnings, std::string& err)
	{
		FrameOrderParams p = params();
		p.warnings = warnings;
		err.clear();
		p.warn = collectInto(err);
		FrameOrder order(p);
		const auto frames = run(order, in);
		std::vector<size_t> idx;
		for (const auto& f : frames) idx.push_back(f.index);
		const auto& s = order.stats();
		idx.push_back(1000 + s.scansOutOfOrder);
		idx.push_back(2000 + s.scansBadStamp);
		idx.push_back(3000 + s.imuRejected);
		return idx;
	};
	std::string loud, quiet;
	const auto a = once(true, loud), b = once(false, quiet);
	EXPECT_EQ(a, b);
	EXPECT_EQ(a, (std::vector<size_t>{0, 1, 4, 1001, 2001, 3001}));
	EXPECT_NE(loud.find("not after the previous one"), std::string::npos);
	EXPECT_NE(loud.find("a stray timestamp"), std::string::npos);
	EXPECT_NE(loud.find("sample not used"), std::string::npos);
	EXPECT_EQ(quiet, "");
}

TEST(FrameRange, ARangeBeyondTheInputIsAPlainErrorNamingItAndTheCount)
{
	// the library's error: std::invalid_argument (bims/apps makes it a
	// usage error with the same message)
	const std::string in = bims::test::kSample;
	EXPECT_NO_THROW(
	    checkFrameRangeInInputs(FrameRange::parse("0:149"), {in}, "RGBD"));
	try
	{
		checkFrameRangeInInputs(FrameRange::parse("140:160"), {in}, "RGBD");
		ADD_FAILURE() << "no error for a range beyond the input";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_EQ(std::string(e.what()),
		          "--frames 140:160: the input (" + in +
		              ") has 150 3D scans (0 to 149) with label 'RGBD'; "
		              "--frames 140: runs to its end");
	}
	try
	{
		FrameRange::parse("7:3");
		ADD_FAILURE() << "no error for A > B";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_EQ(std::string(e.what()), "--frames '7:3': A > B");
	}
}
