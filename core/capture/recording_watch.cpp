#include "core/capture/recording_watch.h"

#include "core/io/camera_file.h"
#include "core/recording/ros_messages.h"

namespace calibench {
namespace fs = std::filesystem;

namespace {

// Messages kept while the topics are not all there yet (a recorder announces a topic with its
// first message); beyond this many the oldest go.
constexpr std::size_t kMaxPending = 2000;

}  // namespace

struct GrowingRecording::Pending {
  int topic = 0;
  std::int64_t log_time_ns = 0;
  std::vector<std::uint8_t> data;
};

GrowingRecording::GrowingRecording(fs::path recording, fs::path out_dir,
                                   std::optional<BoardSpec> board, BagImportOptions options)
    : recording_(std::move(recording)),
      out_dir_(std::move(out_dir)),
      board_(std::move(board)),
      options_(std::move(options)) {
  std::string why;
  if (!options_.Check(&why)) throw IoError(recording_.string() + ": import options: " + why);
}

GrowingRecording::~GrowingRecording() = default;

RecordingUpdate GrowingRecording::Poll() {
  RecordingUpdate update;
  if (finished_) {
    update.closed = true;
    return update;
  }
  if (!reader_) {
    try {
      reader_ = OpenBagToFollow(recording_);
    } catch (const IoError& error) {
      if (!said_waiting_) update.notes.push_back(std::string("waiting: ") + error.what());
      said_waiting_ = true;
      return update;
    }
  }
  const bool closed = reader_->FollowNewMessages([&](const BagMessage& message) {
    update.data_arrived = true;
    // The topics are chosen as soon as they are all there, within the call: a finished recording
    // is read in one call, and kept pending its messages would lose all but the last kMaxPending.
    if (!finder_) ChooseTopicsWhenPresent(/*closed=*/false, &update);
    if (finder_) {
      Route(message.topic, message.log_time_ns, message.data);
    } else {
      if (pending_.size() == kMaxPending) pending_.erase(pending_.begin());
      pending_.push_back({message.topic, message.log_time_ns,
                          std::vector<std::uint8_t>(message.data.begin(), message.data.end())});
    }
    return true;
  });
  if (!finder_) ChooseTopicsWhenPresent(closed, &update);
  if (finder_) WatchForTheBoard(&update);
  if (finder_ && closed) {
    finder_->Finish();
    finished_ = true;
  }
  if (finder_) WritePairs(&update);
  update.closed = closed;
  if (closed && !finder_)
    throw IoError(recording_.string() +
                  ": the recording was closed without a PointCloud2 and an image topic");
  return update;
}

void GrowingRecording::ChooseTopicsWhenPresent(bool closed, RecordingUpdate* update) {
  if (!PairTopicsPresent(*reader_, options_.camera.has_value()) && !closed) return;
  ChooseTopics(*reader_, &options_);
  cloud_topic_ = reader_->FindTopic(options_.cloud_topic);
  image_topic_ = reader_->FindTopic(options_.image_topic);
  info_topic_ = options_.camera ? -1 : reader_->FindTopic(options_.camera_info_topic);
  board_ = RecordingBoard(recording_, board_, &board_source_);
  // Followed, a board no preset explains is said and waited for (a target file put beside the
  // recording, the workbench's pick), not the end of the watch.
  PairSelectionOptions selection = options_;
  selection.stop_on_unknown_board = false;
  finder_ = std::make_unique<RecordingPairFinder>(recording_.string(),
                                                  ChosenPairTopics(*reader_, options_), board_,
                                                  options_.camera, selection);
  if (given_board_) finder_->SetBoard(given_board_->first, given_board_->second);
  update->notes.push_back("topics: clouds " + options_.cloud_topic + ", images " +
                          options_.image_topic + ", camera " +
                          (options_.camera ? "from --camera" : options_.camera_info_topic) +
                          (board_source_.empty() ? "" : "; board from " + board_source_));
  for (const Pending& message : pending_) Route(message.topic, message.log_time_ns, message.data);
  pending_.clear();
}

void GrowingRecording::SetBoard(const BoardSpec& board, const std::string& source) {
  if (finder_)
    finder_->SetBoard(board, source);
  else
    given_board_ = std::make_pair(board, source);
}

std::string GrowingRecording::BoardProblem() const {
  return finder_ ? finder_->BoardProblem() : "";
}

// While no board is known though one is visibly there: said once, live, as soon as the presets
// rule themselves out; a target file put beside the recording meanwhile is taken.
void GrowingRecording::WatchForTheBoard(RecordingUpdate* update) {
  const std::string problem = finder_->BoardProblem();
  if (problem.empty()) return;
  if (problem != said_board_problem_) {
    update->notes.push_back("board: " + problem +
                            "; still following: the pairs come once the board is given");
    said_board_problem_ = problem;
  }
  if (const std::optional<fs::path> file = TargetBesideRecording(recording_)) {
    try {
      finder_->SetBoard(LoadTargetFile(*file), file->string() + " (beside the recording)");
      update->notes.push_back("board: from " + file->string());
    } catch (const IoError& error) {
      if (said_target_error_ != error.what())
        update->notes.push_back(std::string("board: ") + error.what());
      said_target_error_ = error.what();
    }
  }
}

void GrowingRecording::Route(int topic, std::int64_t log_time_ns,
                             std::span<const std::uint8_t> data) {
  if (topic == cloud_topic_) {
    finder_->AddCloud(data, log_time_ns);
  } else if (topic == image_topic_) {
    finder_->AddImage(data, log_time_ns);
  } else if (topic == info_topic_ && info_topic_ >= 0) {
    finder_->AddCameraInfo(data);
  }
}

void GrowingRecording::WritePairs(RecordingUpdate* update) {
  std::vector<FoundPair> found = finder_->TakePairs();
  if (found.empty()) return;
  const std::optional<CameraModel> camera = finder_->Camera();
  const std::optional<BoardSpec> board = finder_->Board();
  for (const FoundPair& pair : found) {
    char id[24];
    std::snprintf(id, sizeof(id), "%04zu", dataset_.pairs.size());
    dataset_.pairs.push_back(WriteFoundPair(pair, out_dir_, id));
    if (pair.cloud.HasRing())
      dataset_.lidar_rings =
          std::max(dataset_.lidar_rings,
                   *std::max_element(pair.cloud.ring.begin(), pair.cloud.ring.end()) + 1);
    update->pairs.push_back(dataset_.pairs.back());
  }
  if (board && dataset_.target.cols == 0) {
    const PairFinderStats stats = finder_->Stats();
    if (!stats.board_choice.empty()) update->notes.push_back("board: " + stats.board_choice);
  }
  dataset_.camera = *camera;
  dataset_.target = *board;
  dataset_.manifest = out_dir_ / "dataset.json";
  SaveCameraInfoYaml(out_dir_ / "camera.yaml", *camera, "camera");
  SaveDataset(dataset_.manifest, dataset_);
}

std::optional<Dataset> GrowingRecording::Setup() const {
  if (dataset_.pairs.empty()) return std::nullopt;
  Dataset setup = dataset_;
  setup.pairs.clear();
  setup.manifest = out_dir_;
  return setup;
}

bool IsRecordingSource(const std::filesystem::path& source) {
  std::error_code error;
  const std::string extension = source.extension().string();
  if (extension == ".bag" || extension == ".mcap" || extension == ".db3") return true;
  if (std::filesystem::is_regular_file(source, error)) return LooksLikeBag(source);
  if (!std::filesystem::is_directory(source, error)) return false;
  if (std::filesystem::exists(source / "metadata.yaml", error)) return true;
  if (std::filesystem::exists(source / "clouds", error) ||
      std::filesystem::exists(source / "images", error))
    return false;
  for (const std::filesystem::directory_entry& entry :
       std::filesystem::directory_iterator(source, error)) {
    const std::string file_extension = entry.path().extension().string();
    if (file_extension == ".mcap" || file_extension == ".db3") return true;
  }
  return false;
}

}  // namespace calibench
