#include "ros2_metadata.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bims::bag
{
std::vector<std::string> ros2BagFiles(const std::string& folder)
{
	namespace fs = std::filesystem;
	const std::string meta = (fs::path(folder) / "metadata.yaml").string();
	auto bad = [&](const std::string& why)
	{ return std::runtime_error(meta + ": " + why); };
	std::error_code ec;
	const auto size = fs::file_size(meta, ec);
	if (ec) throw bad("cannot be read: " + ec.message());
	if (size > (1u << 20))
		throw bad(std::to_string(size) +
		          " bytes: more than rosbag2's metadata (1 MB at most)");
	std::ifstream in(meta);
	std::stringstream text;
	text << in.rdbuf();
	YAML::Node info;
	try
	{
		info = YAML::Load(text.str())["rosbag2_bagfile_information"];
	}
	catch (const std::exception& e)
	{
		throw bad(std::string("not YAML: ") + e.what());
	}
	if (!info || !info.IsMap())
		throw bad("no rosbag2_bagfile_information: not a ROS 2 bag's metadata");
	auto scalar = [&](const char* key) -> std::string
	{
		const YAML::Node n = info[key];
		if (!n || n.IsNull()) return "";
		if (!n.IsScalar()) throw bad(std::string(key) + " is not a value");
		return n.Scalar();
	};
	const std::string storage = scalar("storage_identifier");
	if (storage != "mcap" && storage != "sqlite3")
		throw bad("storage_identifier '" + storage +
		          "': only mcap and sqlite3 are read");
	const std::string compression = scalar("compression_format");
	if (!compression.empty())
		throw bad("compression_format '" + compression + "' (mode '" +
		          scalar("compression_mode") +
		          "'): a bag compressed by rosbag2 is not read; decompress it "
		          "first (ros2 bag convert)");
	const YAML::Node files = info["relative_file_paths"];
	if (!files || !files.IsSequence() || files.size() == 0)
		throw bad("no relative_file_paths: which files hold the messages?");
	std::vector<std::string> out;
	for (const auto& f : files)
	{
		if (!f.IsScalar()) throw bad("relative_file_paths holds a non-name");
		const fs::path p = fs::path(folder) / f.Scalar();
		if (!fs::is_regular_file(p, ec))
			throw bad("relative_file_paths names " + f.Scalar() +
			          ", which is not in the folder (" + p.string() + ")");
		out.push_back(p.string());
	}
	return out;
}

}  // namespace bims::bag
