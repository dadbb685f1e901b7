// Fuzz target: a whole Stray Scanner capture as bims-import-stray imports
// it (eval::importStray into a plain rawlog and its reference): the input's
// three parts, separated by lines "--", are odometry.csv, imu.csv and
// camera_matrix.csv (an empty part: the file is absent) of a capture
// folder whose depth/ and confidence/ hold frames 0 and 1 (8 x 6, made
// once), as the seeds' odometry.csv does. Beyond the CSV readers (target stray)
// it reaches the pairing of rows and images, the stamps on the rawlog's clock,
// the IMU's span, the intrinsics' check and the output rule.
#include <bims/eval/stray_import.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "fuzz_common.h"

namespace
{
/** The capture folder with its images (made once per process). */
const std::string& captureDir()
{
	static const std::string dir = []
	{
		const std::string d = bims::fuzz::scratchDir() + "/capture";
		std::filesystem::create_directories(d + "/depth");
		std::filesystem::create_directories(d + "/confidence");
		for (int k = 0; k < 2; k++)
		{
			char name[32];
			std::snprintf(name, sizeof(name), "/%06d.png", k);
			cv::imwrite(d + "/depth" + name,
			            cv::Mat(6, 8, CV_16UC1, cv::Scalar(700 + 10 * k)));
			cv::imwrite(d + "/confidence" + name,
			            cv::Mat(6, 8, CV_8UC1, cv::Scalar(k % 3)));
		}
		return d;
	}();
	return dir;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	const std::string& dir = captureDir();
	const auto parts = bims::fuzz::splitParts(data, size, 3);
	const char* names[] = {"odometry.csv", "imu.csv", "camera_matrix.csv"};
	for (size_t i = 0; i < 3; i++)
	{
		const std::string path = dir + "/" + names[i];
		std::error_code ec;
		std::filesystem::remove(path, ec);
		if (parts[i].empty()) continue;
		if (FILE* f = std::fopen(path.c_str(), "wb"))
		{
			std::fwrite(parts[i].data(), 1, parts[i].size(), f);
			std::fclose(f);
		}
	}
	const std::string out = bims::fuzz::scratchDir() + "/out.rawlog";
	try
	{
		bims::eval::StrayImportOptions o;
		o.gzLevel = 0;
		(void)bims::eval::importStray(dir, out, {}, o);
	}
	catch (const std::exception& e)
	{
		// (BIMS_FUZZ_VERBOSE: each input's error, to see what seeds reach)
		if (std::getenv("BIMS_FUZZ_VERBOSE"))
			std::fprintf(stderr, "fuzz_stray_capture: %s\n", e.what());
	}
	return 0;
}
