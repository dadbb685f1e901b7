// bims-grab's run without devices (grab_run.h): the preview image and
// what is done with each grabbed frame, fed the bundled sample's
// observations as a grab hands them over (a scan and the IMU before it).
#include <bims/apps/grab_run.h>
#include <bims/io/rawlog.h>
#include <gtest/gtest.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationIMU.h>

#include <regex>

using namespace bims::apps;

namespace
{
const std::string kSrc = BIMS_SOURCE_DIR;

/** The first \a n scans of the sample, each with the IMU samples before
 * it, handed to \a g. Returns the last scan. */
mrpt::obs::CObservation3DRangeScan::Ptr feed(GrabbedFrames& g, size_t n)
{
	bims::RawlogReader r(kSrc + "/rawlogs/pendulum_slow.rawlog");
	std::vector<mrpt::obs::CObservationIMU::Ptr> imu;
	mrpt::obs::CObservation3DRangeScan::Ptr last;
	size_t scans = 0;
	while (scans < n)
	{
		auto o = r.next();
		if (!o) break;
		if (auto m = std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o))
			imu.push_back(m);
		else if (auto s = std::dynamic_pointer_cast<
		             mrpt::obs::CObservation3DRangeScan>(o))
		{
			g.add(s, imu);
			imu.clear();
			last = s;
			++scans;
		}
	}
	return last;
}

std::unique_ptr<bims::pipeline::LiveSegmentation> segmentation()
{
	bims::pipeline::ExperimentConfig exp;
	exp.loadFromFile(kSrc + "/config/default.ini");
	return std::make_unique<bims::pipeline::LiveSegmentation>(exp, "bims-grab",
	                                                          "live input");
}
}  // namespace

TEST(GrabPreview, TheMaskIsHalfRedOverTheImage)
{
	mrpt::obs::CObservation3DRangeScan scan;
	EXPECT_TRUE(preview(scan, cv::Mat()).isEmpty());  // no image
	scan.hasIntensityImage = true;
	scan.intensityImage = mrpt::img::CImage(
	    cv::Mat(40, 60, CV_8UC1, cv::Scalar(100)), mrpt::img::DEEP_COPY);
	cv::Mat mask(40, 60, CV_8UC1, cv::Scalar(0));
	mask(cv::Rect(10, 10, 5, 5)).setTo(255);
	const cv::Mat p = preview(scan, mask).asCvMatRef();
	ASSERT_EQ(p.type(), CV_8UC3);
	EXPECT_EQ(p.at<cv::Vec3b>(0, 0), cv::Vec3b(100, 100, 100));
	EXPECT_EQ(p.at<cv::Vec3b>(12, 12), cv::Vec3b(50, 50, 178));  // 50+127.5
	// a mask of another size is scaled to the image
	const cv::Mat q =
	    preview(scan, cv::Mat(20, 30, CV_8UC1, cv::Scalar(255))).asCvMatRef();
	EXPECT_EQ(q.at<cv::Vec3b>(0, 0), cv::Vec3b(50, 50, 178));
}

TEST(GrabbedFrames, CountsFramesWithoutSegmentation)
{
	GrabbedFrames g(nullptr, nullptr, 5, false);
	feed(g, 5);
	EXPECT_EQ(g.frames(), 5u);
	EXPECT_EQ(g.lastSegmented(), "");
}

TEST(GrabbedFrames, SegmentsFramesAsTheyComeAndSurvivesItsErrors)
{
	GrabbedFrames g(segmentation(), nullptr, 0, false);
	auto last = feed(g, 8);
	EXPECT_EQ(g.frames(), 8u);
	const std::regex words(R"(^\d+ moving voxels, \d+ ms$)");
	EXPECT_TRUE(std::regex_match(g.lastSegmented(), words))
	    << g.lastSegmented();
	// a scan of another size: the segmentation's error is printed, the
	// grab goes on
	auto odd = std::make_shared<mrpt::obs::CObservation3DRangeScan>(*last);
	odd->timestamp = last->timestamp + std::chrono::milliseconds(33);
	odd->rangeImage.resize(10, 10);
	odd->rangeImage.fill(1000);
	testing::internal::CaptureStderr();
	g.add(odd, {});
	g.finishSegmentation();
	const std::string err = testing::internal::GetCapturedStderr();
	EXPECT_EQ(g.frames(), 9u);
	EXPECT_NE(err.find("bims-grab: segmentation: live input: 3D scan #8 has a "
	                   "10x10 depth image"),
	          std::string::npos)
	    << err;
}
