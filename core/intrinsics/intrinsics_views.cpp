// DetectIntrinsicsViews: the board in each image by the pipeline's own detection (DetectBoard).
#include <mutex>

#include "core/base/parallel.h"
#include "core/intrinsics/intrinsics.h"
#include "core/io/image_io.h"

namespace calibench {

std::vector<IntrinsicsView> DetectIntrinsicsViews(const std::vector<IntrinsicsImageFile>& files,
                                                  const BoardSpec& board, int threads, int* width,
                                                  int* height,
                                                  std::vector<IntrinsicsImage>* skipped,
                                                  const BoardDetectionOptions& detection_options) {
  std::vector<std::optional<IntrinsicsView>> found(files.size());
  std::vector<std::string> failures(files.size());
  std::vector<std::pair<int, int>> sizes(files.size(), {0, 0});
  ParallelFor(files.size(), threads, [&](size_t i) {
    try {
      const ImageU8 image = LoadImage(files[i].path);
      sizes[i] = {image.width, image.height};
      std::string why;
      if (auto detection = DetectBoard(image, board, detection_options, &why))
        found[i] = IntrinsicsView{files[i].name, std::move(*detection)};
      else
        failures[i] = "no board: " + why;
    } catch (const IoError& e) {
      failures[i] = e.what();
    }
  });
  std::vector<IntrinsicsView> views;
  *width = *height = 0;
  for (size_t i = 0; i < files.size(); ++i) {
    if (sizes[i].first > 0 && *width == 0) *width = sizes[i].first, *height = sizes[i].second;
    if (sizes[i].first > 0 && (sizes[i].first != *width || sizes[i].second != *height))
      throw IoError(files[i].path.string() + ": " + std::to_string(sizes[i].first) + "x" +
                    std::to_string(sizes[i].second) + " pixels, the other images are " +
                    std::to_string(*width) + "x" + std::to_string(*height) +
                    ": one camera's images only");
    if (found[i]) {
      views.push_back(std::move(*found[i]));
    } else if (skipped) {
      skipped->push_back(IntrinsicsImage{files[i].name, 0, 0.0, false, failures[i]});
    }
  }
  return views;
}

}  // namespace calibench
