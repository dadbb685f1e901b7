// A file mapped read-only, as every reader of a recording reads it
// (bag_file.h, mcap_file.h): its bytes in place, no copy.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace bims::bag
{
struct MappedFile
{
	std::shared_ptr<const void> owner;  ///< unmaps when the last goes
	const uint8_t* bytes = nullptr;     ///< null when the file is empty
	uint64_t size = 0;
};

/** Maps \a path (advised sequential). Throws std::runtime_error, not naming
 * the file (the caller does), when it cannot be opened, is not a regular
 * file or cannot be mapped. */
MappedFile mapFile(const std::string& path);

}  // namespace bims::bag
