// rosbag2's sqlite3 storage (.db3): a `topics` table (id, name, type, serialization_format, ...)
// and a `messages` table (id, topic_id, timestamp, data). Every layout since Dashing has these
// columns; newer ones add tables (schema, metadata, message_definitions) we do not need.
//
// The file is opened read-only and immutable: a recording may sit on a read-only medium, in WAL
// mode with no -wal file beside it, and must never be changed by being looked at.
#include <sqlite3.h>

#include <map>

#include "core/recording/bag_internal.h"
#include "core/recording/sqlite_salvage.h"

namespace calibench::bag_internal {
namespace {
namespace fs = std::filesystem;

// sqlite3's URI form needs '%', '?' and '#' escaped in the path.
std::string ImmutableUri(const fs::path& path) {
  std::string uri = "file:";
  for (const char c : fs::absolute(path).string()) {
    if (c == '%' || c == '?' || c == '#') {
      static const char* hex = "0123456789ABCDEF";
      uri += '%';
      uri += hex[(static_cast<unsigned char>(c) >> 4) & 15];
      uri += hex[static_cast<unsigned char>(c) & 15];
    } else {
      uri += c;
    }
  }
  return uri + "?immutable=1";
}

// The same file read while rosbag2 writes it: read-only, but not immutable, so that each
// connection sees what was committed since.
std::string LiveUri(const fs::path& path) {
  std::string uri = ImmutableUri(path);
  return uri.substr(0, uri.size() - std::string("?immutable=1").size()) + "?mode=ro";
}

class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const fs::path& path) : path_(path) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK)
      Fail(path, std::string("not a rosbag2 recording (") + sqlite3_errmsg(db) + ")");
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  // True while rows come; throws IoError naming the file when reading fails.
  bool Step() {
    const int status = sqlite3_step(statement_);
    if (status == SQLITE_ROW) return true;
    if (status == SQLITE_DONE) return false;
    Fail(path_, std::string("cannot read the recording (") +
                    sqlite3_errmsg(sqlite3_db_handle(statement_)) + ")");
  }
  std::int64_t Integer(int column) { return sqlite3_column_int64(statement_, column); }
  std::string Text(int column) {
    const auto* text = sqlite3_column_text(statement_, column);
    return text ? reinterpret_cast<const char*>(text) : "";
  }
  std::span<const std::uint8_t> Blob(int column) {
    const void* blob = sqlite3_column_blob(statement_, column);
    const int size = sqlite3_column_bytes(statement_, column);
    return {static_cast<const std::uint8_t*>(blob), static_cast<std::size_t>(size)};
  }

 private:
  sqlite3_stmt* statement_ = nullptr;
  fs::path path_;
};

class SqliteBag final : public BagReader {
 public:
  SqliteBag(const fs::path& path, bool follow) {
    path_ = path;
    if (follow) {
      format_ = "rosbag2 sqlite3, followed";
      return;
    }
    size_bytes_ = static_cast<std::int64_t>(fs::file_size(path));
    if (sqlite3_open_v2(ImmutableUri(path).c_str(), &db_, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI,
                        nullptr) != SQLITE_OK) {
      const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      Fail(path, "cannot open as sqlite3: " + why);
    }
    try {
      ReadTopics();
    } catch (const IoError& refused) {
      try {
        Salvage(refused.what());
      } catch (const IoError&) {
        sqlite3_close(db_);
        throw refused;
      }
    }
    format_ = "rosbag2 sqlite3";
  }
  ~SqliteBag() override { sqlite3_close(db_); }

  void ForEachMessage(const std::vector<bool>& wanted, const BagVisitor& visit,
                      const BagProgress& progress) override {
    std::int64_t total = 0, done = 0;
    for (std::size_t t = 0; t < topics_.size(); ++t)
      if (wanted.empty() || wanted[t]) total += topics_[t].message_count;
    if (salvage_) return ForEachSalvaged(wanted, visit, progress);
    Statement rows(db_, "SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp", path_);
    while (rows.Step()) {
      const auto topic = topic_index_.find(rows.Integer(0));
      if (topic == topic_index_.end())
        Fail(path_, "a message of topic id " + std::to_string(rows.Integer(0)) +
                        ", which the topics table does not list");
      if (!wanted.empty() && !wanted[topic->second]) continue;
      BagMessage message;
      message.topic = topic->second;
      message.log_time_ns = rows.Integer(1);
      message.data = rows.Blob(2);
      if (!visit(message)) return;
      ++done;
      // Rows do not map to bytes; spread the file's size over the wanted messages.
      if (progress && total > 0) progress(size_bytes_ * done / total, size_bytes_);
    }
  }

  // rosbag2 commits messages in transactions: each call opens the file afresh and reads the rows
  // committed since the last. A bare .db3 never says it is closed (its folder's metadata.yaml
  // does: the folder reader).
  bool FollowNewMessages(const BagVisitor& visit) override {
    sqlite3* db = nullptr;
    if (sqlite3_open_v2(LiveUri(path_).c_str(), &db, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI,
                        nullptr) != SQLITE_OK) {
      sqlite3_close(db);
      return false;  // not created yet, or locked: the next call
    }
    sqlite3_busy_timeout(db, 200);
    try {
      while (ReadNewRows(db, visit) > 0) {
      }
    } catch (const IoError&) {
      // The tables may not exist yet (a recording just begun) or a write is under way.
    }
    sqlite3_close(db);
    size_bytes_ = static_cast<std::int64_t>(fs::file_size(path_));
    return false;
  }

 private:
  // One batch of rows committed since the last; how many.
  int ReadNewRows(sqlite3* db, const BagVisitor& visit) {
    Statement topics(db, "SELECT id, name, type, serialization_format FROM topics ORDER BY id",
                     path_);
    while (topics.Step())
      if (!topic_index_.count(topics.Integer(0)))
        topic_index_[topics.Integer(0)] =
            AddTopic(&topics_, topics.Text(1), topics.Text(2), topics.Text(3));
    // In batches: each statement holds a shared lock, which a recorder in rollback-journal mode
    // must wait for to commit (in WAL mode it never waits).
    Statement rows(db,
                   "SELECT id, topic_id, timestamp, data FROM messages WHERE id > " +
                       std::to_string(last_row_) + " ORDER BY id LIMIT 64",
                   path_);
    int read = 0;
    while (rows.Step()) {
      ++read;
      last_row_ = rows.Integer(0);
      const auto topic = topic_index_.find(rows.Integer(1));
      if (topic == topic_index_.end()) continue;
      BagMessage message;
      message.topic = topic->second;
      message.log_time_ns = rows.Integer(2);
      message.data = rows.Blob(3);
      ++topics_[topic->second].message_count;
      visit(message);
    }
    return read;
  }

  void ReadTopics() {
    Statement topics(db_, "SELECT id, name, type, serialization_format FROM topics ORDER BY id",
                     path_);
    while (topics.Step())
      topic_index_[topics.Integer(0)] =
          AddTopic(&topics_, topics.Text(1), topics.Text(2), topics.Text(3));
    Statement counts(db_, "SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id", path_);
    while (counts.Step()) {
      const auto topic = topic_index_.find(counts.Integer(0));
      if (topic != topic_index_.end()) topics_[topic->second].message_count += counts.Integer(1);
    }
  }

  // SQLite refuses a file shorter than its header says (a recorder killed mid-write with
  // synchronous=OFF, a copy that stopped), and the b-tree pages it lost may hide every row: the
  // topics are read with the schema made readable, the messages from the pages themselves
  // (sqlite_salvage.h), in the order written up to the first one lost.
  void Salvage(const std::string& refused) {
    sqlite3_exec(db_, "PRAGMA writable_schema=ON", nullptr, nullptr, nullptr);
    topics_.clear();
    topic_index_.clear();
    Statement topics(db_, "SELECT id, name, type, serialization_format FROM topics ORDER BY id",
                     path_);
    while (topics.Step())
      topic_index_[topics.Integer(0)] =
          AddTopic(&topics_, topics.Text(1), topics.Text(2), topics.Text(3));
    salvage_ = std::make_unique<SqliteSalvage>(path_);
    for (const SqliteSalvage::Row& row : salvage_->Rows()) {
      const auto topic = topic_index_.find(row.topic_id);
      if (topic != topic_index_.end()) ++topics_[topic->second].message_count;
    }
    // SQLite's own words, the innermost parenthesis of the refusal ("database disk image is
    // malformed").
    std::string why = refused;
    if (const auto open = why.rfind('('); open != std::string::npos)
      why = why.substr(open + 1, why.find(')', open) - open - 1);
    cut_short_ = "cut short (SQLite: " + why + "): " + std::to_string(salvage_->Rows().size()) +
                 " messages read from its pages in the order written";
    if (salvage_->RowsBeyond() > 0)
      cut_short_ += ", " + std::to_string(salvage_->RowsBeyond()) +
                    " more beyond the first one lost left out";
  }

  void ForEachSalvaged(const std::vector<bool>& wanted, const BagVisitor& visit,
                       const BagProgress& progress) {
    std::vector<std::uint8_t> data;
    const std::vector<SqliteSalvage::Row>& rows = salvage_->Rows();
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto topic = topic_index_.find(rows[i].topic_id);
      if (topic == topic_index_.end() || (!wanted.empty() && !wanted[topic->second])) continue;
      salvage_->ReadData(rows[i], &data);
      BagMessage message;
      message.topic = topic->second;
      message.log_time_ns = rows[i].timestamp;
      message.data = data;
      if (!visit(message)) return;
      if (progress)
        progress(size_bytes_ * static_cast<std::int64_t>(i + 1) / rows.size(), size_bytes_);
    }
  }

  sqlite3* db_ = nullptr;
  std::map<std::int64_t, int> topic_index_;
  std::int64_t last_row_ = 0;               // FollowNewMessages: the last message row read
  std::unique_ptr<SqliteSalvage> salvage_;  // a file SQLite refuses: its rows from the pages
};

}  // namespace

std::unique_ptr<BagReader> OpenSqliteBag(const fs::path& path, bool follow) {
  return std::make_unique<SqliteBag>(path, follow);
}

}  // namespace calibench::bag_internal
