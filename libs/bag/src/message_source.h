// A recording's messages as the importer reads them, whatever holds them: a
// ROS 1 bag (bag_file.h), a ROS 2 MCAP file (mcap_file.h) or a ROS 2 sqlite3
// file (db3_file.h). Each hands over its messages with their bytes and
// connection (topic, type, wire format); bag_import.cpp reads them with one
// set of rules (messages.h: the same message-level code for every format).
#pragma once

#include <bims/bag/bag_import.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace bims::bag
{
/** Bytes of a recording, kept valid by their owner (the mapped file, a
 * decompressed chunk, a copy of a database's blob). */
struct BagBytes
{
	std::shared_ptr<const void> owner;
	const uint8_t* data = nullptr;
	size_t size = 0;
};

/** How a connection's messages are serialized. */
enum class Wire
{
	Ros1,  ///< ROS 1's serialization (little-endian, no alignment)
	Cdr    ///< ROS 2's: CDR with its encapsulation header (cdr.h)
};

/** A connection (ROS 1) or channel (MCAP) or topic (db3): one topic's
 * messages and their type. */
struct BagConnection
{
	/** the type as the file names it: "sensor_msgs/Image" (ROS 1),
	 * "sensor_msgs/msg/Image" (ROS 2) */
	std::string topic, type, md5;
	Wire wire = Wire::Ros1;
	/** Not empty: why its messages cannot be read (a channel whose schema
	 * is not ros2msg or whose encoding is not cdr), said when one is. */
	std::string unreadable;
};

/** One message: where its data is. */
struct BagMessageRef
{
	uint32_t connection = 0;  ///< index into connections()
	uint64_t time = 0;        ///< its record (log) time [ns] (not its stamp)
	uint32_t chunk = 0;       ///< its chunk, in file order
	uint64_t offset = 0;      ///< its data within the chunk's bytes (or id)
	uint32_t size = 0;        ///< its data's length
};

class MessageSource
{
 public:
	using MessageFn =
	    std::function<void(const BagMessageRef&, const uint8_t* data)>;
	virtual ~MessageSource() = default;

	/** Every message in file order, with its data (valid during the call).
	 * Damage ends the scan (damage()); the whole messages before it are
	 * handed over. Connections are known as their records come. */
	virtual void scan(const MessageFn& message) = 0;
	/** The data of a message the scan handed over. Throws
	 * std::runtime_error when it cannot be read again. */
	virtual BagBytes message(const BagMessageRef& m) = 0;
	virtual const std::vector<BagConnection>& connections() const = 0;
	/** The topics the file's index or summary lists, with their message
	 * counts; empty when it has none whole (then scan() counts them). */
	virtual std::vector<BagTopicInfo> indexTopics() const = 0;
	/** Where and why the file stops being readable; empty when whole. */
	virtual const std::string& damage() const = 0;
	/** The damage is where messages are: messages after it are lost. */
	virtual bool damageLosesMessages() const = 0;
};

}  // namespace bims::bag
