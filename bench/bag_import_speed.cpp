// bims-import-bag's speed: the bundled sample's frames upscaled to 640x480
// (depth nearest, colour bilinear; the camera scaled), repeated to N frames
// with their IMU, written as realsense-ros bags (uncompressed, LZ4, BZ2),
// then imported (bims::bag::importBag) into a plain and a gzip rawlog.
// Prints the frames per second of each, the best of 3 runs.
//   build/bin/bag_import_speed [N=300] [WORK_DIR=/tmp/bims_bag_bench]
#include <bims/bag/bag_import.h>
#include <bims/io/rawlog.h>
#include <bims_test/bag_writer.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgproc.hpp>

namespace
{
using namespace bims;
using mrpt::obs::CObservation3DRangeScan;
using mrpt::obs::CObservationIMU;

/** \a f at twice its size (640x480 for the sample's 320x240). */
CObservation3DRangeScan::Ptr upscaled(const CObservation3DRangeScan& f,
                                      double shift)
{
	auto o = CObservation3DRangeScan::Create();
	*o = f;
	const int W = 2 * static_cast<int>(f.rangeImage.cols()),
	          H = 2 * static_cast<int>(f.rangeImage.rows());
	o->rangeImage_setSize(H, W);
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
			o->rangeImage(v, u) = f.rangeImage(v / 2, u / 2);
	cv::Mat bgr;
	cv::resize(f.intensityImage.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY), bgr,
	           cv::Size(W, H), 0, 0, cv::INTER_LINEAR);
	o->intensityImage = mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
	o->cameraParams.scaleToResolution(W, H);
	o->cameraParamsIntensity = o->cameraParams;
	o->timestamp =
	    mrpt::Clock::fromDouble(mrpt::Clock::toDouble(f.timestamp) + shift);
	return o;
}
}  // namespace

int main(int argc, char** argv)
{
	const size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 300;
	const std::string dir = argc > 2 ? argv[2] : "/tmp/bims_bag_bench";
	std::filesystem::create_directories(dir);

	std::vector<CObservation3DRangeScan::Ptr> base;
	std::vector<CObservationIMU::Ptr> baseImu;
	{
		RawlogReader in(std::string(BIMS_SOURCE_DIR) +
		                "/rawlogs/pendulum_slow.rawlog");
		while (auto o = in.next())
			if (auto f = std::dynamic_pointer_cast<CObservation3DRangeScan>(o))
			{
				f->load();
				base.push_back(f);
			}
			else if (auto m = std::dynamic_pointer_cast<CObservationIMU>(o))
				baseImu.push_back(m);
	}
	const double span = mrpt::Clock::toDouble(base.back()->timestamp) -
	                    mrpt::Clock::toDouble(base.front()->timestamp) +
	                    1.0 / 30;
	std::vector<CObservation3DRangeScan::Ptr> frames;
	std::vector<CObservationIMU::Ptr> imu;
	for (size_t k = 0; frames.size() < n; k++)
	{
		const double shift = double(k / base.size()) * span;
		frames.push_back(upscaled(*base[k % base.size()], shift));
		if (k % base.size() == 0)
			for (const auto& m : baseImu)
			{
				auto c = CObservationIMU::Create();
				*c = *m;
				c->timestamp = mrpt::Clock::fromDouble(
				    mrpt::Clock::toDouble(m->timestamp) + shift);
				imu.push_back(c);
			}
	}
	std::printf("%zu frames of %ux%u, %zu IMU samples\n", frames.size(),
	            frames[0]->rangeImage.cols(), frames[0]->rangeImage.rows(),
	            imu.size());
	std::printf("%-13s %10s %12s %12s\n", "bag", "MB", "plain fps",
	            "gzip-1 fps");
	const struct
	{
		const char* name;
		rosbag::compression::CompressionType c;
	} kinds[] = {{"uncompressed", rosbag::compression::Uncompressed},
	             {"lz4", rosbag::compression::LZ4},
	             {"bz2", rosbag::compression::BZ2}};
	for (const auto& k : kinds)
	{
		test::BagSpec spec;
		spec.compression = k.c;
		spec.frames = frames.size();
		const std::string bag = dir + "/" + k.name + ".bag";
		test::writeBag(bag, spec, frames, imu);
		double fps[2] = {0, 0};
		for (int gz : {0, 1})
			for (int run = 0; run < 3; run++)
			{
				bag::BagImportOptions o;
				o.gzLevel = gz;
				const auto t0 = std::chrono::steady_clock::now();
				const auto sum = bag::importBag({bag}, dir + "/out.rawlog",
				                                bag::BagImportParams{}, o);
				const double s = std::chrono::duration<double>(
				                     std::chrono::steady_clock::now() - t0)
				                     .count();
				fps[gz] = std::max(fps[gz], double(sum.frames) / s);
			}
		std::printf("%-13s %10.1f %12.1f %12.1f\n", k.name,
		            double(std::filesystem::file_size(bag)) / 1e6, fps[0],
		            fps[1]);
	}
	return 0;
}
