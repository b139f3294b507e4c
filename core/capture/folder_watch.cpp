#include "core/capture/folder_watch.h"

#include <algorithm>
#include <chrono>
#include <system_error>

#include "core/base/names.h"

namespace calibench {
namespace fs = std::filesystem;

bool FolderWatchOptions::Check(std::string* why) const {
  if (!(settle_s >= 0)) return *why = "settle_s must be >= 0 (seconds)", false;
  if (!(partner_timeout_s > 0)) return *why = "partner_timeout_s must be > 0 (seconds)", false;
  return true;
}

bool IsTemporaryFileName(const fs::path& name) {
  const std::string text = name.filename().string();
  if (text.empty() || text.front() == '.' || text.back() == '~') return true;
  for (const char* suffix : {".part", ".tmp", ".partial", ".crdownload"})
    if (text.size() > std::string(suffix).size() && text.ends_with(suffix)) return true;
  return false;
}

namespace {

// The name a temporary file will have: "pose1.pcd.part" -> "pose1.pcd"; "" when none.
std::string FinalName(const fs::path& name) {
  const std::string text = name.filename().string();
  const size_t dot = text.rfind('.');
  if (dot == std::string::npos || dot == 0) return "";
  return text.substr(0, dot);
}

std::int64_t ModificationTimeNs(const fs::path& path, std::error_code& error) {
  const auto time = fs::last_write_time(path, error);
  if (error) return 0;
  return std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count();
}

// How long ago the file was last written (by the file system's clock); 0 when unknown.
double SecondsSinceModified(const fs::path& path) {
  std::error_code error;
  const auto time = fs::last_write_time(path, error);
  if (error) return 0.0;
  return std::chrono::duration<double>(fs::file_time_type::clock::now() - time).count();
}

}  // namespace

GrowingFolder::GrowingFolder(fs::path folder, FolderWatchOptions options)
    : folder_(std::move(folder)), options_(options) {}

void GrowingFolder::MarkCompleted(const std::set<std::string>& stems) {
  completed_.insert(stems.begin(), stems.end());
}

void GrowingFolder::Scan(const char* sub, double now_s, std::map<std::string, FileState>* files,
                         std::vector<FolderEvent>* events) {
  std::map<std::string, FileState> seen;
  std::set<std::string> renamed_from_temporary;  // final names of temporary files seen now
  std::error_code error;
  for (fs::directory_iterator it(folder_ / sub, error), end; !error && it != end;
       it.increment(error)) {
    std::error_code entry_error;
    if (it->is_directory(entry_error)) continue;
    const fs::path& path = it->path();
    if (IsTemporaryFileName(path)) {
      renamed_from_temporary.insert(FinalName(path));
      continue;
    }
    FileState state;
    state.path = path;
    state.size = it->file_size(entry_error);
    if (entry_error) state.size = 0;  // a broken link: its pair's reading says why
    state.mtime_ns = ModificationTimeNs(path, entry_error);
    state.changed_s = now_s;
    seen[path.stem().string()] = state;
  }
  for (auto& [stem, state] : seen) {
    const auto before = files->find(stem);
    if (before != files->end() && before->second.path == state.path &&
        before->second.size == state.size && before->second.mtime_ns == state.mtime_ns) {
      state = before->second;  // unchanged: keep when it was first seen so
    } else if (before == files->end() &&
               (temporaries_[sub].count(state.path.filename().string()) > 0 ||
                SecondsSinceModified(state.path) >= options_.settle_s)) {
      // Renamed into place from a temporary name, or written before we looked: complete.
      state.changed_s = now_s - options_.settle_s;
    }
    if (!state.settled && now_s - state.changed_s >= options_.settle_s) {
      state.settled = true;
      state.settled_s = now_s;
    }
  }
  for (const auto& [stem, state] : *files) {
    if (seen.count(stem)) continue;
    FolderEvent removed;
    removed.kind = FolderEvent::Kind::kRemoved;
    removed.stem = stem;
    removed.reason = state.path.string() + " was removed while watched";
    events->push_back(removed);
  }
  temporaries_[sub] = std::move(renamed_from_temporary);
  *files = std::move(seen);
}

std::vector<FolderEvent> GrowingFolder::Poll(double now_s) {
  std::vector<FolderEvent> removals;
  Scan("clouds", now_s, &clouds_, &removals);
  Scan("images", now_s, &images_, &removals);
  std::vector<FolderEvent> events;
  struct Ready {
    double settled_s;
    std::string stem;
  };
  std::vector<Ready> ready;
  for (const auto& [stem, cloud] : clouds_) {
    if (completed_.count(stem)) continue;
    const auto image = images_.find(stem);
    const bool image_settled = image != images_.end() && image->second.settled;
    if (cloud.settled && image_settled) {
      ready.push_back({std::max(cloud.settled_s, image->second.settled_s), stem});
    } else if (cloud.settled && image == images_.end() &&
               now_s - cloud.settled_s >= options_.partner_timeout_s &&
               reported_incomplete_.insert(stem).second) {
      events.push_back({FolderEvent::Kind::kIncomplete,
                        stem,
                        {},
                        cloud.path.string() + " has no image after " +
                            std::to_string(static_cast<int>(options_.partner_timeout_s)) +
                            " s (expected images/" + stem + ".png or .jpg)"});
    }
  }
  for (const auto& [stem, image] : images_) {
    if (completed_.count(stem) || clouds_.count(stem) || !image.settled ||
        now_s - image.settled_s < options_.partner_timeout_s ||
        !reported_incomplete_.insert(stem).second)
      continue;
    events.push_back({FolderEvent::Kind::kIncomplete,
                      stem,
                      {},
                      image.path.string() + " has no cloud after " +
                          std::to_string(static_cast<int>(options_.partner_timeout_s)) +
                          " s (expected clouds/" + stem + ".pcd, .ply or .bin)"});
  }
  NaturalOrder natural;
  std::sort(ready.begin(), ready.end(), [&](const Ready& a, const Ready& b) {
    if (a.settled_s != b.settled_s) return a.settled_s < b.settled_s;
    return natural(a.stem, b.stem);
  });
  std::vector<FolderEvent> complete;
  for (const Ready& r : ready) {
    completed_.insert(r.stem);
    FolderEvent event;
    event.kind = FolderEvent::Kind::kPairComplete;
    event.stem = r.stem;
    event.pair.id = r.stem;
    event.pair.cloud = clouds_.at(r.stem).path;
    event.pair.image = images_.at(r.stem).path;
    complete.push_back(std::move(event));
  }
  complete.insert(complete.end(), events.begin(), events.end());
  complete.insert(complete.end(), removals.begin(), removals.end());
  return complete;
}

}  // namespace calibench
