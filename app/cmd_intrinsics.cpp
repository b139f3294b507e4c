// calibench intrinsics: the camera from the board images of a calibration folder or manifest, or
// of a plain folder of images (core/intrinsics: our detection, OpenCV's calibration).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "core/base/names.h"
#include "core/base/parallel.h"
#include "core/io/camera_file.h"
#include "core/io/dataset.h"
#include "core/io/dataset_source.h"

namespace calibench::app {

namespace {

namespace fs = std::filesystem;

bool IsImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".pgm" ||
         ext == ".ppm" || ext == ".tif" || ext == ".tiff";
}

struct ImageSet {
  std::vector<IntrinsicsImageFile> files;
  BoardSpec board;
};

// A plain folder of board images (or its images/ folder), natural order; the board from
// --board, else the folder's target.json.
ImageSet PlainFolder(const fs::path& dir, const std::string& board_flag) {
  ImageSet set;
  const fs::path images = fs::is_directory(dir / "images") ? dir / "images" : dir;
  std::vector<fs::path> paths;
  for (const auto& entry : fs::directory_iterator(images))
    if (entry.is_regular_file() && IsImageFile(entry.path())) paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end(), [](const fs::path& a, const fs::path& b) {
    return NaturalLess(a.filename().string(), b.filename().string());
  });
  for (const fs::path& p : paths) set.files.push_back({p.filename().string(), p});
  if (set.files.empty()) throw IoError(images.string() + ": no images (.png .jpg .bmp ...)");
  if (auto board = BoardFromFlag(board_flag)) {
    set.board = *board;
  } else if (fs::exists(dir / "target.json")) {
    set.board = LoadTargetFile(dir / "target.json");
  } else {
    throw IoError(dir.string() +
                  ": which board? give --board (a preset or a target.json) or put target.json "
                  "in the folder");
  }
  return set;
}

ImageSet ImagesOf(const fs::path& path, const std::string& board_flag) {
  const bool plain =
      fs::is_directory(path) && !fs::exists(path / "clouds") && !fs::exists(path / "dataset.json");
  if (plain) return PlainFolder(path, board_flag);
  const Dataset dataset = LoadDataset(path, CameraFile::kOptional);
  ImageSet set;
  set.board = dataset.target;
  if (auto board = BoardFromFlag(board_flag)) set.board = *board;
  for (const PairEntry& pair : dataset.pairs) set.files.push_back({pair.id, pair.image});
  return set;
}

}  // namespace

std::optional<CameraModelType> ParseIntrinsicsModel(const std::string& name) {
  if (name == "pinhole") return CameraModelType::kPinholeRadTan;
  if (name == "fisheye") return CameraModelType::kKannalaBrandt;
  return std::nullopt;
}

IntrinsicsResult EstimateIntrinsicsFromImages(const std::vector<IntrinsicsImageFile>& files,
                                              const BoardSpec& board,
                                              const IntrinsicsOptions& options) {
  int width = 0, height = 0;
  std::vector<IntrinsicsImage> skipped;
  const std::vector<IntrinsicsView> views =
      DetectIntrinsicsViews(files, board, DefaultThreads(), &width, &height, &skipped);
  IntrinsicsResult result = CalibrateIntrinsics(views, width, height, options);
  result.images.insert(result.images.end(), skipped.begin(), skipped.end());
  return result;
}

int RunIntrinsics(int argc, char** argv) {
  CLI::App app{
      "Estimate the camera's intrinsics from board images: our board detection (checkerboard, "
      "ChArUco, partial ChArUco views), OpenCV's calibrateCamera or fisheye::calibrate, bad "
      "images rejected and the camera refitted. Reports RMS, sigma per parameter, per-image "
      "error and the coverage of the image, with OpenCV's interactive stop rule in words.",
      "calibench intrinsics"};
  std::string dataset, model = "pinhole", out, format = "ros", board;
  bool fix_k3 = false;
  AddDatasetOption(app, &dataset,
                   "a calibration folder or manifest (its pairs' images), or a plain folder of "
                   "board images")
      ->required();
  AddBoardOption(app, &board,
                 "the board in the images (default: the dataset's or the folder's "
                 "target.json)");
  app.add_option("--model", model, "pinhole (rad-tan, k1 k2 p1 p2 k3) | fisheye (Kannala-Brandt)")
      ->capture_default_str();
  app.add_flag("--fix-k3", fix_k3, "pinhole: keep k3 at 0 (few images, an ordinary lens)");
  app.add_option("--out,-o", out, "camera file to write (camera.yaml)");
  app.add_option("--format", format,
                 "ros (camera_info YAML) | opencv (FileStorage YAML) | kalibr (camchain)")
      ->capture_default_str();
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  IntrinsicsOptions options;
  const auto camera_model = ParseIntrinsicsModel(model);
  if (!camera_model) {
    std::fprintf(stderr, "calibench intrinsics: --model must be pinhole or fisheye, got '%s'\n",
                 model.c_str());
    return kUsage;
  }
  options.model = *camera_model;
  options.estimate_k3 = !fix_k3;
  const auto file_format = ParseCameraFileFormat(format);
  if (!file_format) {
    std::fprintf(stderr, "calibench intrinsics: --format must be ros, opencv or kalibr, got '%s'\n",
                 format.c_str());
    return kUsage;
  }
  const ImageSet set = ImagesOf(dataset, board);
  IntrinsicsResult result;
  try {
    result = EstimateIntrinsicsFromImages(set.files, set.board, options);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "calibench intrinsics: %s: %s\n", dataset.c_str(), e.what());
    return kNoCalibration;
  }
  std::printf("%s", FormatIntrinsics(result).c_str());
  if (!out.empty()) {
    SaveCameraFile(out, result.camera, *file_format);
    std::printf("wrote %s (%s)\n", out.c_str(), format.c_str());
  }
  return kOk;
}

// --estimate-intrinsics: the pairs' images calibrate the camera first; said on stdout.
int EstimateDatasetIntrinsics(const char* command, const std::string& model, Dataset* dataset,
                              std::optional<IntrinsicsResult>* result, std::FILE* out) {
  IntrinsicsOptions options;
  const auto camera_model = ParseIntrinsicsModel(model);
  if (!camera_model) {
    std::fprintf(stderr, "calibench %s: --intrinsics-model must be pinhole or fisheye, got '%s'\n",
                 command, model.c_str());
    return kUsage;
  }
  options.model = *camera_model;
  std::vector<IntrinsicsImageFile> files;
  for (const PairEntry& pair : dataset->pairs) files.push_back({pair.id, pair.image});
  try {
    *result = EstimateIntrinsicsFromImages(files, dataset->target, options);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "calibench %s: --estimate-intrinsics: %s\n", command, e.what());
    return kNoCalibration;
  }
  std::fprintf(out, "intrinsics estimated from the pairs' images (--estimate-intrinsics%s):\n%s\n",
               dataset->missing_camera_file.empty()
                   ? ("; " + (dataset->manifest / "camera.yaml").string() + " is not used").c_str()
                   : "",
               FormatIntrinsics(**result).c_str());
  dataset->camera = (*result)->camera;
  return kOk;
}

}  // namespace calibench::app
