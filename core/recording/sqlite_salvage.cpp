#include "core/recording/sqlite_salvage.h"

#include <algorithm>
#include <cstring>
#include <optional>

#include "core/recording/bag_internal.h"

namespace calibench::bag_internal {
namespace {

constexpr std::uint8_t kTableLeafPage = 0x0D;
constexpr std::uint32_t kFileHeaderBytes = 100;  // on page 1, before its b-tree page header
constexpr std::uint32_t kLeafHeaderBytes = 8;
// More overflow pages than this for one message (4 KiB pages: 512 MB) is damage, not data.
constexpr std::uint64_t kMaxPayloadBytes = kMaxChunkBytes;

std::uint32_t Big16(const std::uint8_t* p) { return (std::uint32_t(p[0]) << 8) | p[1]; }
std::uint32_t Big32(const std::uint8_t* p) {
  return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) |
         p[3];
}

// SQLite's varint: 1-9 bytes, big-endian, 7 bits a byte with the high bit saying more follow,
// the ninth byte's 8 bits whole. False when it runs past `end`.
bool Varint(const std::uint8_t*& p, const std::uint8_t* end, std::uint64_t* value) {
  std::uint64_t v = 0;
  for (int i = 0; i < 9; ++i) {
    if (p >= end) return false;
    const std::uint8_t byte = *p++;
    if (i == 8) {
      *value = (v << 8) | byte;
      return true;
    }
    v = (v << 7) | (byte & 0x7f);
    if (!(byte & 0x80)) {
      *value = v;
      return true;
    }
  }
  return false;
}

// A record's integer column of serial type 1-6, 8 or 9; false for another type.
bool IntegerOf(std::uint64_t type, const std::uint8_t* p, const std::uint8_t* end,
               std::int64_t* value) {
  static constexpr int kBytes[] = {0, 1, 2, 3, 4, 6, 8};
  if (type == 8 || type == 9) {
    *value = type == 9;
    return true;
  }
  if (type < 1 || type > 6 || p + kBytes[type] > end) return false;
  std::uint64_t v = (p[0] & 0x80) ? ~0ull : 0ull;  // sign-extended, big-endian
  for (int i = 0; i < kBytes[type]; ++i) v = (v << 8) | p[i];
  *value = static_cast<std::int64_t>(v);
  return true;
}

// The column's size in the record for serial type `type`.
std::uint64_t ColumnBytes(std::uint64_t type) {
  static constexpr std::uint64_t kBytes[] = {0, 1, 2, 3, 4, 6, 8, 8, 0, 0};
  if (type < 10) return kBytes[type];
  return type >= 12 ? (type - 12) / 2 : 0;
}

// The record at `cell` of a table leaf page when it has the messages table's shape: the rowid,
// then (NULL: the rowid alias), topic_id, timestamp, data (a blob); nullopt otherwise.
std::optional<SqliteSalvage::Row> MessageRecordAt(const std::vector<std::uint8_t>& page,
                                                  std::uint32_t cell, std::uint32_t usable,
                                                  std::uint32_t number) {
  const std::uint8_t* end = page.data() + usable;
  // A table leaf's local share of a payload (the file format's X, M and K).
  const std::uint64_t max_local = usable - 35;
  const std::uint64_t min_local = (usable - 12) * 32 / 255 - 23;
  const std::uint8_t* p = page.data() + cell;
  std::uint64_t payload = 0, rowid = 0;
  if (!Varint(p, end, &payload) || !Varint(p, end, &rowid) || payload > kMaxPayloadBytes)
    return std::nullopt;
  std::uint64_t local = payload;
  if (payload > max_local) {
    const std::uint64_t k = min_local + (payload - min_local) % (usable - 4);
    local = k <= max_local ? k : min_local;
  }
  const std::uint8_t* record = p;
  if (record + local + (local < payload ? 4 : 0) > end) return std::nullopt;
  // The messages table's shape: (NULL: the rowid alias), topic_id, timestamp, data (a blob).
  const std::uint8_t* h = record;
  std::uint64_t header_bytes = 0;
  if (!Varint(h, record + local, &header_bytes) || header_bytes > local) return std::nullopt;
  std::uint64_t types[5] = {};
  int columns = 0;
  while (h < record + header_bytes && columns < 5)
    if (!Varint(h, record + header_bytes, &types[columns++])) break;
  if (columns != 4 || types[0] != 0 || types[3] < 12 || types[3] % 2 != 0) return std::nullopt;
  const std::uint8_t* value = record + header_bytes;
  SqliteSalvage::Row row;
  if (!IntegerOf(types[1], value, record + local, &row.topic_id)) return std::nullopt;
  value += ColumnBytes(types[1]);
  if (!IntegerOf(types[2], value, record + local, &row.timestamp)) return std::nullopt;
  value += ColumnBytes(types[2]);
  if (header_bytes + ColumnBytes(types[1]) + ColumnBytes(types[2]) + ColumnBytes(types[3]) !=
      payload)
    return std::nullopt;
  row.id = static_cast<std::int64_t>(rowid);
  row.page = number;
  row.cell = static_cast<std::uint32_t>(record - page.data());
  row.payload = payload;
  row.local = static_cast<std::uint32_t>(local);
  row.data_at = static_cast<std::uint32_t>(value - record);
  return row;
}

}  // namespace

SqliteSalvage::SqliteSalvage(const std::filesystem::path& path)
    : path_(path), file_(std::make_unique<RandomAccessFile>(path)) {
  const RandomAccessFile& file = *file_;
  std::vector<std::uint8_t> header;
  file.ReadAt(0, kFileHeaderBytes, &header, "the SQLite header");
  if (std::memcmp(header.data(), "SQLite format 3", 16) != 0) Fail(path, "not an SQLite file");
  page_size_ = Big16(header.data() + 16);
  if (page_size_ == 1) page_size_ = 65536;
  if (page_size_ < 512 || (page_size_ & (page_size_ - 1)) != 0)
    Fail(path, "an SQLite page size of " + std::to_string(page_size_));
  usable_ = page_size_ - header[20];
  pages_ = static_cast<std::uint32_t>(file.Size() / page_size_);
  next_page_.assign(pages_ + 1, 0);
  std::vector<Row> found;
  std::vector<std::uint8_t> page;
  for (std::uint32_t number = 1; number <= pages_; ++number) {
    file.ReadAt(std::int64_t(number - 1) * page_size_, page_size_, &page, "a page");
    next_page_[number] = Big32(page.data());
    const std::uint32_t at = number == 1 ? kFileHeaderBytes : 0;
    if (page[at] != kTableLeafPage) continue;
    const std::uint32_t cells = Big16(page.data() + at + 3);
    for (std::uint32_t c = 0; c < cells; ++c) {
      const std::uint32_t pointer_at = at + kLeafHeaderBytes + 2 * c;
      if (pointer_at + 2 > usable_) break;
      const std::uint32_t cell = Big16(page.data() + pointer_at);
      if (cell < at + kLeafHeaderBytes || cell >= usable_) continue;
      if (const std::optional<Row> row = MessageRecordAt(page, cell, usable_, number))
        found.push_back(*row);
    }
  }
  std::sort(found.begin(), found.end(), [](const Row& a, const Row& b) { return a.id < b.id; });
  // The rows written before the first one missing or cut short: each with its overflow chain
  // within the file.
  for (const Row& row : found) {
    if (!rows_.empty() && row.id == rows_.back().id) continue;  // the same row twice
    const bool next = rows_.empty() || row.id == rows_.back().id + 1;
    bool whole = true;
    if (row.payload > row.local) {
      const std::uint64_t overflow = (row.payload - row.local + usable_ - 5) / (usable_ - 4);
      std::vector<std::uint8_t> first;
      file.ReadAt(std::int64_t(row.page - 1) * page_size_ + row.cell + row.local, 4, &first,
                  "an overflow pointer");
      std::uint32_t chain = Big32(first.data());
      for (std::uint64_t i = 0; i < overflow && whole; ++i) {
        whole = chain >= 2 && chain <= pages_;
        if (whole) chain = next_page_[chain];
      }
    }
    if (!next || !whole) {
      rows_beyond_ =
          static_cast<std::int64_t>(found.size()) - static_cast<std::int64_t>(rows_.size());
      break;
    }
    rows_.push_back(row);
  }
}

SqliteSalvage::~SqliteSalvage() = default;

void SqliteSalvage::ReadData(const Row& row, std::vector<std::uint8_t>* out) const {
  const RandomAccessFile& file = *file_;
  std::vector<std::uint8_t> bytes;
  const std::int64_t cell = std::int64_t(row.page - 1) * page_size_ + row.cell;
  const bool overflows = row.payload > row.local;
  file.ReadAt(cell, row.local + (overflows ? 4 : 0), &bytes, "a message record");
  std::vector<std::uint8_t> record(bytes.begin(), bytes.begin() + row.local);
  record.reserve(row.payload);
  std::uint32_t chain = overflows ? Big32(bytes.data() + row.local) : 0;
  while (record.size() < row.payload) {
    if (chain < 2 || chain > pages_) Fail(path_, "a message's overflow page is missing");
    file.ReadAt(std::int64_t(chain - 1) * page_size_, usable_, &bytes, "an overflow page");
    const std::size_t take = std::min<std::size_t>(usable_ - 4, row.payload - record.size());
    record.insert(record.end(), bytes.begin() + 4, bytes.begin() + 4 + take);
    chain = Big32(bytes.data());
  }
  out->assign(record.begin() + row.data_at, record.end());
}

}  // namespace calibench::bag_internal
