// rosbag2's messages read straight from the pages of a .db3 that SQLite itself refuses (internal to
// core/io, for bag_sqlite.cpp). A recorder killed mid-write (rosbag2 records with
// synchronous=OFF) or a copy that stopped leaves a file shorter than its header says; the b-tree's
// interior pages, written when the table last grew a level, are often among the pages lost, and
// with them every path to the rows. The rows are still in their leaf pages: every table leaf page
// is read, the records shaped like the messages table's (the rowid, then NULL, topic_id,
// timestamp, data) kept, each one's data followed through its overflow pages. What sqlite3's
// `.recover` does for any table, for this one table (https://www.sqlite.org/fileformat2.html).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace calibench::bag_internal {

class RandomAccessFile;

class SqliteSalvage {
 public:
  struct Row {
    std::int64_t id = 0;  // the rowid: the order rosbag2 wrote them in
    std::int64_t topic_id = 0;
    std::int64_t timestamp = 0;
    std::uint32_t page = 0;     // the leaf page holding the record
    std::uint32_t cell = 0;     // the record's offset in that page
    std::uint64_t payload = 0;  // the record's size
    std::uint32_t local = 0;    // its bytes on the leaf page (the rest on overflow pages)
    std::uint32_t data_at = 0;  // where `data` starts in the record
  };

  // Reads every page of `path` once. Throws IoError naming the file when it is no SQLite file.
  explicit SqliteSalvage(const std::filesystem::path& path);
  ~SqliteSalvage();

  // The rows in the order written, from the first up to the last before one is missing or cut
  // short (its overflow pages beyond the file's end).
  const std::vector<Row>& Rows() const { return rows_; }
  // Rows found beyond that point (after a gap): not used, said in the reader's note.
  std::int64_t RowsBeyond() const { return rows_beyond_; }
  // The row's data (the message), read from its pages. Throws IoError on a page that no longer
  // reads.
  void ReadData(const Row& row, std::vector<std::uint8_t>* out) const;

 private:
  std::filesystem::path path_;
  std::unique_ptr<RandomAccessFile> file_;
  std::uint32_t page_size_ = 0, usable_ = 0;
  std::uint32_t pages_ = 0;               // complete pages in the file
  std::vector<std::uint32_t> next_page_;  // each page's first 4 bytes: an overflow page's next
  std::vector<Row> rows_;
  std::int64_t rows_beyond_ = 0;
};

}  // namespace calibench::bag_internal
