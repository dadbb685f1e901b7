#include "db3_file.h"

#include <sqlite3.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <stdexcept>

namespace bims::bag
{
namespace
{
using std::runtime_error;

/** A prepared statement, finalized when it goes. */
using Statement = std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)>;

std::string text(sqlite3_stmt* s, int col)
{
	const auto* p = sqlite3_column_text(s, col);
	return p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
}
}  // namespace

void Db3File::fail(const std::string& what) const
{
	throw runtime_error(what + ": " +
	                    (db_ ? sqlite3_errmsg(db_) : "sqlite3 failed"));
}

Db3File::Db3File(const std::string& path)
{
	{
		char head[16] = {};
		std::ifstream in(path, std::ios::binary);
		if (!in) throw runtime_error("cannot be opened");
		in.read(head, sizeof(head));
		if (in.gcount() != 16 || std::memcmp(head, "SQLite format 3", 16) != 0)
			throw runtime_error(
			    "not a ROS 2 sqlite3 bag (it does not start with sqlite3's "
			    "header 'SQLite format 3')");
	}
	if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) !=
	    SQLITE_OK)
	{
		const std::string e = db_ ? sqlite3_errmsg(db_) : "sqlite3 failed";
		sqlite3_close(db_);
		db_ = nullptr;
		throw runtime_error("cannot be opened by sqlite3: " + e);
	}
	try
	{
		for (const char* table : {"topics", "messages"})
		{
			sqlite3_stmt* raw = nullptr;
			const std::string q =
			    std::string(
			        "SELECT count(*) FROM sqlite_master WHERE "
			        "type='table' AND name='") +
			    table + "'";
			if (sqlite3_prepare_v2(db_, q.c_str(), -1, &raw, nullptr) !=
			    SQLITE_OK)
				fail("its tables cannot be listed (not a sqlite3 database?)");
			const Statement s(raw, sqlite3_finalize);
			if (sqlite3_step(raw) != SQLITE_ROW ||
			    sqlite3_column_int(raw, 0) != 1)
				throw runtime_error(
				    std::string("a sqlite3 database without the table '") +
				    table + "' of rosbag2: not a ROS 2 bag");
		}
		sqlite3_stmt* raw = nullptr;
		if (sqlite3_prepare_v2(db_,
		                       "SELECT id, name, type, serialization_format "
		                       "FROM topics ORDER BY id",
		                       -1, &raw, nullptr) != SQLITE_OK)
			fail("its table 'topics' cannot be read");
		const Statement s(raw, sqlite3_finalize);
		int rc = 0;
		while ((rc = sqlite3_step(raw)) == SQLITE_ROW)
		{
			BagConnection c;
			topicIds_.push_back(sqlite3_column_int64(raw, 0));
			c.topic = text(raw, 1);
			c.type = text(raw, 2);
			c.wire = Wire::Cdr;
			const std::string format = text(raw, 3);
			if (format != "cdr")
				c.unreadable = "topic " + c.topic +
				               ": its serialization format is '" + format +
				               "', not ROS 2's cdr: not read";
			connections_.push_back(std::move(c));
		}
		if (rc != SQLITE_DONE) fail("its table 'topics' cannot be read");
	}
	catch (...)
	{
		sqlite3_close(db_);
		db_ = nullptr;
		throw;
	}
}

Db3File::~Db3File()
{
	sqlite3_close(db_);
}

void Db3File::scan(const MessageFn& message)
{
	std::map<int64_t, uint32_t> index;
	for (size_t k = 0; k < topicIds_.size(); k++)
		index[topicIds_[k]] = static_cast<uint32_t>(k);
	sqlite3_stmt* raw = nullptr;
	if (sqlite3_prepare_v2(db_,
	                       "SELECT id, topic_id, timestamp, data FROM messages "
	                       "ORDER BY id",
	                       -1, &raw, nullptr) != SQLITE_OK)
	{
		damage_ = std::string("its table 'messages' cannot be read: ") +
		          sqlite3_errmsg(db_);
		return;
	}
	const Statement s(raw, sqlite3_finalize);
	int rc = 0;
	int64_t last = -1;
	while ((rc = sqlite3_step(raw)) == SQLITE_ROW)
	{
		const int64_t id = sqlite3_column_int64(raw, 0);
		last = id;
		const auto t = index.find(sqlite3_column_int64(raw, 1));
		if (t == index.end())
		{
			damage_ = "its message " + std::to_string(id) + " is of topic " +
			          std::to_string(sqlite3_column_int64(raw, 1)) +
			          ", which its table 'topics' does not have";
			return;
		}
		const void* data = sqlite3_column_blob(raw, 3);
		const int n = sqlite3_column_bytes(raw, 3);
		static const uint8_t none = 0;
		BagMessageRef ref;
		ref.connection = t->second;
		ref.time = static_cast<uint64_t>(sqlite3_column_int64(raw, 2));
		ref.offset = static_cast<uint64_t>(id);
		ref.size = static_cast<uint32_t>(std::max(n, 0));
		message(ref, data ? static_cast<const uint8_t*>(data) : &none);
	}
	if (rc != SQLITE_DONE)
		damage_ = "its table 'messages' cannot be read after its message " +
		          std::to_string(last) + ": " + sqlite3_errmsg(db_) +
		          ": damaged";
}

BagBytes Db3File::message(const BagMessageRef& m)
{
	const std::lock_guard<std::mutex> lock(mutex_);
	sqlite3_stmt* raw = nullptr;
	if (sqlite3_prepare_v2(db_, "SELECT data FROM messages WHERE id = ?", -1,
	                       &raw, nullptr) != SQLITE_OK)
		fail("its message " + std::to_string(m.offset) + " cannot be read");
	const Statement s(raw, sqlite3_finalize);
	sqlite3_bind_int64(raw, 1, static_cast<sqlite3_int64>(m.offset));
	if (sqlite3_step(raw) != SQLITE_ROW)
		fail("its message " + std::to_string(m.offset) + " cannot be read");
	const void* data = sqlite3_column_blob(raw, 0);
	const size_t n =
	    static_cast<size_t>(std::max(sqlite3_column_bytes(raw, 0), 0));
	if (n != m.size)
		throw runtime_error("its message " + std::to_string(m.offset) +
		                    " changed size since it was read");
	auto copy = std::shared_ptr<uint8_t[]>(new uint8_t[std::max<size_t>(n, 1)]);
	if (n > 0) std::memcpy(copy.get(), data, n);
	return {copy, copy.get(), n};
}

std::vector<BagTopicInfo> Db3File::indexTopics() const
{
	sqlite3_stmt* raw = nullptr;
	if (sqlite3_prepare_v2(db_,
	                       "SELECT topic_id, count(*) FROM messages GROUP BY "
	                       "topic_id",
	                       -1, &raw, nullptr) != SQLITE_OK)
		return {};
	const Statement s(raw, sqlite3_finalize);
	std::map<int64_t, size_t> counts;
	int rc = 0;
	while ((rc = sqlite3_step(raw)) == SQLITE_ROW)
		counts[sqlite3_column_int64(raw, 0)] =
		    static_cast<size_t>(sqlite3_column_int64(raw, 1));
	if (rc != SQLITE_DONE) return {};  // damaged: scan() counts them
	std::map<std::string, BagTopicInfo> topics;
	for (size_t k = 0; k < connections_.size(); k++)
	{
		auto& t = topics[connections_[k].topic];
		t.name = connections_[k].topic;
		if (t.type.empty()) t.type = connections_[k].type;
		const auto c = counts.find(topicIds_[k]);
		t.messages += c == counts.end() ? 0 : c->second;
	}
	std::vector<BagTopicInfo> out;
	for (auto& [n, t] : topics) out.push_back(t);
	return out;
}

}  // namespace bims::bag
