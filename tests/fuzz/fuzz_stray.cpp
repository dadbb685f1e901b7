// Fuzz target: a Stray Scanner capture's CSV files as bims-import-stray
// reads them (odometry.csv, imu.csv, camera_matrix.csv: the input's parts,
// separated by lines "--"; an empty part is not read), through
// eval::readStrayOdometry, readStrayImu and readStrayCameraMatrix.
#include <bims/eval/stray_import.h>

#include <exception>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	const auto parts = bims::fuzz::splitParts(data, size, 3);
	const char* names[] = {"odometry.csv", "imu.csv", "camera_matrix.csv"};
	for (size_t i = 0; i < 3; i++)
	{
		if (parts[i].empty()) continue;
		const std::string path = bims::fuzz::writeFile(
		    names[i], reinterpret_cast<const uint8_t*>(parts[i].data()),
		    parts[i].size());
		try
		{
			if (i == 0) (void)bims::eval::readStrayOdometry(path);
			if (i == 1) (void)bims::eval::readStrayImu(path);
			if (i == 2)
			{
				double K[3][3];
				bims::eval::readStrayCameraMatrix(path, K);
			}
		}
		catch (const std::exception&)
		{
		}
	}
	return 0;
}
