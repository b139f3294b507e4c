// Image I/O: the real palette PNG from ../shared, lossless round trips, and errors naming the file.
#include <gtest/gtest.h>

#include <fstream>

#include "core/base/image.h"
#include "core/base/types.h"
#include "core/io/image_io.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

ImageU8 Gradient(int width, int height, int channels) {
  ImageU8 image{width, height, channels, {}};
  image.data.resize(static_cast<size_t>(width) * height * channels);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        image.Row(y)[x * channels + c] = static_cast<std::uint8_t>((x * 7 + y * 13 + c * 61) % 256);
      }
    }
  }
  return image;
}

// Expects `f` to throw IoError whose message contains `text`.
template <typename F>
void ExpectIoErrorMentioning(F f, const std::string& text) {
  try {
    f();
    ADD_FAILURE() << "no IoError thrown";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(ImageIoTest, LoadsThePalettePngOfTheVlp16DatasetAsBgr) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  const ImageU8 image =
      LoadImage(shared / "datasets" / "acfr-vlp16-chessboard" / "images" / "pose16.png");
  EXPECT_EQ(image.width, 1920);
  EXPECT_EQ(image.height, 1208);
  EXPECT_EQ(image.channels, 3);
  EXPECT_EQ(image.data.size(), 1920u * 1208u * 3u);
  // A chessboard photo: both dark and bright pixels are present.
  int dark = 0, bright = 0;
  for (std::uint8_t v : image.data) {
    dark += v < 60;
    bright += v > 180;
  }
  EXPECT_GT(dark, 10000);
  EXPECT_GT(bright, 10000);
}

TEST(ImageIoTest, PngRoundTripIsExactAndGreyLoadsAsThreeChannels) {
  const std::filesystem::path dir = test::TempDir("image_io_round_trip");
  const ImageU8 colour = Gradient(37, 21, 3);
  SaveImage(dir / "colour.png", colour);
  const ImageU8 loaded = LoadImage(dir / "colour.png");
  EXPECT_EQ(loaded.width, 37);
  EXPECT_EQ(loaded.height, 21);
  ASSERT_EQ(loaded.channels, 3);
  EXPECT_EQ(loaded.data, colour.data);

  const ImageU8 grey = Gradient(16, 9, 1);
  SaveImage(dir / "grey.png", grey);
  const ImageU8 grey_loaded = LoadImage(dir / "grey.png");
  ASSERT_EQ(grey_loaded.channels, 3);
  ASSERT_EQ(grey_loaded.data.size(), grey.data.size() * 3);
  for (size_t i = 0; i < grey.data.size(); ++i) {
    for (int c = 0; c < 3; ++c) ASSERT_EQ(grey_loaded.data[3 * i + c], grey.data[i]);
  }

  SaveImage(dir / "colour.jpg", colour);
  EXPECT_EQ(LoadImage(dir / "colour.jpg").width, 37);
}

TEST(ImageIoTest, ErrorsNameTheFile) {
  const std::filesystem::path dir = test::TempDir("image_io_errors");
  ExpectIoErrorMentioning([&] { LoadImage(dir / "missing.png"); }, "missing.png");
  std::ofstream(dir / "garbage.png") << "this is not a PNG";
  ExpectIoErrorMentioning([&] { LoadImage(dir / "garbage.png"); }, "garbage.png");
  ExpectIoErrorMentioning([&] { LoadImage(dir); }, dir.string());

  const ImageU8 image = Gradient(4, 3, 3);
  ExpectIoErrorMentioning([&] { SaveImage(dir / "no_folder" / "out.png", image); }, "out.png");
  ExpectIoErrorMentioning([&] { SaveImage(dir / "out.unknown_extension", image); },
                          "out.unknown_extension");
  ImageU8 broken = image;
  broken.data.pop_back();
  ExpectIoErrorMentioning([&] { SaveImage(dir / "broken.png", broken); }, "broken.png");
  ExpectIoErrorMentioning([&] { SaveImage(dir / "empty.png", ImageU8{}); }, "empty.png");
}

}  // namespace
}  // namespace calibench
