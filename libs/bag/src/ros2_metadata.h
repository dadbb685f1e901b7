// A ROS 2 bag folder: its metadata.yaml (rosbag2_bagfile_information:
// storage_identifier, relative_file_paths, compression) read with Debian's
// yaml-cpp, within a size limit, every field checked.
#pragma once

#include <string>
#include <vector>

namespace bims::bag
{
/** The files of the ROS 2 bag folder \a folder, in its metadata.yaml's
 * order, each checked to be there. Throws std::runtime_error naming the
 * folder's metadata.yaml (and the file) when it is not rosbag2's metadata,
 * names a storage other than mcap or sqlite3, a compression (a file or
 * message compressed by rosbag2: not read), or a file that is not there. */
std::vector<std::string> ros2BagFiles(const std::string& folder);

}  // namespace bims::bag
