// A ROS 2 recording in sqlite3 (rosbag2's default storage before Iron):
// its tables topics(id, name, type, serialization_format, ...) and
// messages(id, topic_id, timestamp, data), read with Debian's libsqlite3
// (read-only). A file that is not sqlite3, or lacks a table or column, is a
// clear error; a database damaged after its first messages ends the scan
// there, as a bag cut short (docs/import-bag.md, "ROS 2").
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include "message_source.h"

struct sqlite3;

namespace bims::bag
{
class Db3File : public MessageSource
{
 public:
	/** Opens \a path read-only and reads its topics. Throws
	 * std::runtime_error (not naming the file: the caller does) when it is
	 * no sqlite3 database or has no rosbag2 tables. */
	explicit Db3File(const std::string& path);
	~Db3File() override;
	Db3File(const Db3File&) = delete;
	Db3File& operator=(const Db3File&) = delete;

	/** The messages in their ids' order (the order they were written). */
	void scan(const MessageFn& message) override;
	/** A copy of the message's data (sqlite's blobs are not kept). */
	BagBytes message(const BagMessageRef& m) override;
	const std::vector<BagConnection>& connections() const override
	{
		return connections_;
	}
	std::vector<BagTopicInfo> indexTopics() const override;
	const std::string& damage() const override { return damage_; }
	bool damageLosesMessages() const override { return !damage_.empty(); }

 private:
	/** Throws "what: sqlite's message". */
	[[noreturn]] void fail(const std::string& what) const;

	sqlite3* db_ = nullptr;
	std::mutex mutex_;
	std::vector<BagConnection> connections_;
	std::vector<int64_t> topicIds_;  ///< the topics table's id of each
	std::string damage_;
};

}  // namespace bims::bag
