// The temporary folder of the common library's tests.
#pragma once

#include <filesystem>
#include <string>

namespace bims::test
{
/** \a name inside a temporary folder of the common tests (created). */
inline std::string tmpPath(const std::string& name)
{
	const auto dir =
	    std::filesystem::temp_directory_path() / "bims_test_common";
	std::filesystem::create_directories(dir);
	return (dir / name).string();
}
}  // namespace bims::test
