// A walk over a ROS 1 bag's records (format 2.0) before Debian's
// rosbag_storage opens it: rosbag trusts the lengths a file declares and
// allocates them (a record header declaring 4 GB is allocated before
// anything is read), so every length is checked here against the bytes
// the file holds (docs/fuzz.md, "bag").
#pragma once

#include <string>

namespace bims::bag
{
/** Checks the records of the bag \a path: each record's header and data
 * lengths within the file (inside an uncompressed chunk: within the
 * chunk), each header's fields within the header, a chunk's uncompressed
 * size (its own length when uncompressed; at most 1 GiB), the bag header's
 * index position within the file and its connection and chunk counts not
 * beyond the records at that position, index records' entry counts within
 * their data. Throws std::runtime_error saying what is wrong and at which
 * byte (not naming the file: the caller does). A file that does not start
 * with "#ROSBAG V2.0\n" is left to rosbag (which refuses it). */
void checkBagRecords(const std::string& path);

}  // namespace bims::bag
