// `calibench target` as a user checks a print: the PDF rasterised by poppler's pdftoppm at 300 dpi
// (the SVG by headless Chromium), OpenCV finds the pattern, the squares measure what was asked,
// the 100 mm ruler reads 100 mm, the page is the paper's size, and target.json matches.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <set>
#include <string>

#include "core/io/dataset.h"
#include "core/target/charuco_board.h"
#include "core/target/target_sheet.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;
using test::CalibenchExe;
using test::RunCommand;
using test::TempDir;

// pdftoppm and chromium come from scripts/install_deps.sh; without them the test skips with the
// reason, unless CALIBENCH_REQUIRE_SHARED=1 (CI) makes every check mandatory.
bool HaveTool(const std::string& tool) {
  if (RunCommand("command -v " + tool + " >/dev/null 2>&1") == 0) return true;
  const char* require = std::getenv("CALIBENCH_REQUIRE_SHARED");
  if (require && std::string(require) == "1")
    ADD_FAILURE() << tool << " is required under CALIBENCH_REQUIRE_SHARED=1 (install_deps.sh)";
  return false;
}

struct Raster {
  cv::Mat gray;
  double px_per_mm = 0.0;
};

Raster RasterisePdf(const fs::path& pdf) {
  const fs::path stem = pdf.parent_path() / (pdf.stem().string() + "_300dpi");
  std::string output;
  EXPECT_EQ(RunCommand("pdftoppm -r 300 -gray -png -singlefile '" + pdf.string() + "' '" +
                           stem.string() + "'",
                       &output),
            0)
      << output;
  return {cv::imread(stem.string() + ".png", cv::IMREAD_GRAYSCALE), 300.0 / 25.4};
}

// Chromium draws the SVG at its own size in CSS pixels (96 per inch), here 3x: 288 dpi.
Raster RasteriseSvg(const fs::path& svg, const Vec2& sheet_mm) {
  constexpr double kScale = 3.0;
  const int width = static_cast<int>(std::ceil(sheet_mm.x() / 25.4 * 96.0));
  const int height = static_cast<int>(std::ceil(sheet_mm.y() / 25.4 * 96.0));
  const fs::path png = svg.parent_path() / (svg.stem().string() + "_svg.png");
  std::string output;
  EXPECT_EQ(
      // Its own profile: tests run in parallel, and two Chromiums never share one.
      RunCommand("chromium --headless --no-sandbox --disable-gpu --hide-scrollbars "
                 "--user-data-dir='" +
                     (svg.parent_path() / "chromium").string() +
                     "' "
                     "--force-device-scale-factor=3 --window-size=" +
                     std::to_string(width) + "," + std::to_string(height) + " --screenshot='" +
                     png.string() + "' 'file://" + fs::absolute(svg).string() + "'",
                 &output),
      0)
      << output;
  cv::Mat colour = cv::imread(png.string());
  cv::Mat gray;
  if (!colour.empty()) cv::cvtColor(colour, gray, cv::COLOR_BGR2GRAY);
  return {gray, kScale * 96.0 / 25.4};
}

// Mean distance (mm) between neighbouring corners of a grid; corner(i, j) nullopt where missing.
template <typename CornerAt>
double MeanNeighbourMm(int cols, int rows, const CornerAt& corner, double px_per_mm) {
  double sum = 0.0;
  int n = 0;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const auto here = corner(i, j);
      if (!here) continue;
      for (const auto next : {corner(i + 1, j), corner(i, j + 1)}) {
        if (!next) continue;
        sum += cv::norm(*next - *here), ++n;
      }
    }
  }
  return n ? sum / n / px_per_mm : 0.0;
}

double CheckerSquareMm(const Raster& r, const BoardSpec& board) {
  std::vector<cv::Point2f> corners;
  const cv::Size pattern(board.cols, board.rows);
  const bool found = cv::findChessboardCorners(r.gray, pattern, corners);
  EXPECT_TRUE(found) << "OpenCV did not find the " << board.cols << "x" << board.rows << " corners";
  if (!found) return 0.0;
  EXPECT_EQ(corners.size(), static_cast<size_t>(board.cols * board.rows));
  cv::cornerSubPix(r.gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
  auto at = [&](int i, int j) -> std::optional<cv::Point2f> {
    if (i >= board.cols || j >= board.rows) return std::nullopt;
    return corners[static_cast<size_t>(j * board.cols + i)];
  };
  return MeanNeighbourMm(board.cols, board.rows, at, r.px_per_mm);
}

double CharucoSquareMm(const Raster& r, const BoardSpec& board) {
  const auto cv_board = MakeCharucoBoard(board, static_cast<float>(board.square_size),
                                         static_cast<float>(board.marker_size));
  std::vector<std::vector<cv::Point2f>> markers;
  std::vector<int> ids;
  cv::aruco::detectMarkers(r.gray, cv_board->dictionary, markers, ids);
  const std::set<int> board_ids(cv_board->ids.begin(), cv_board->ids.end());
  int right = 0;
  for (const int id : ids) right += board_ids.count(id) ? 1 : 0;
  EXPECT_EQ(right, static_cast<int>(ids.size())) << "markers with ids not on the board";
  EXPECT_GE(right, std::ceil(0.95 * board_ids.size())) << right << " of " << board_ids.size();
  std::vector<cv::Point2f> corners;
  std::vector<int> corner_ids;
  cv::aruco::interpolateCornersCharuco(markers, ids, r.gray, cv_board, corners, corner_ids);
  const int cols = board.cols - 1, rows = board.rows - 1;  // inner corners, id = j * cols + i
  EXPECT_EQ(corners.size(), static_cast<size_t>(cols * rows));
  std::map<int, cv::Point2f> by_id;
  for (size_t k = 0; k < corners.size(); ++k) by_id[corner_ids[k]] = corners[k];
  auto at = [&](int i, int j) -> std::optional<cv::Point2f> {
    if (i >= cols || j >= rows || !by_id.count(j * cols + i)) return std::nullopt;
    return by_id[j * cols + i];
  };
  return MeanNeighbourMm(cols, rows, at, r.px_per_mm);
}

// The ruler's millimetre ticks along a row 1 mm below its baseline: 101 dark runs whose first and
// last centres lie 100 mm apart.
void ExpectRulerReads100Mm(const Raster& r, const TargetSheet& sheet) {
  const int row = static_cast<int>(std::lround((sheet.ruler_start_mm.y() + 1.0) * r.px_per_mm));
  const int x0 = static_cast<int>((sheet.ruler_start_mm.x() - 3.0) * r.px_per_mm);
  const int x1 = static_cast<int>((sheet.ruler_start_mm.x() + 103.0) * r.px_per_mm);
  ASSERT_TRUE(row > 0 && row < r.gray.rows && x0 > 0 && x1 < r.gray.cols);
  std::vector<double> centres;
  int start = -1;
  for (int x = x0; x <= x1; ++x) {
    const bool dark = r.gray.at<std::uint8_t>(row, x) < 128;
    if (dark && start < 0) start = x;
    if (!dark && start >= 0) centres.push_back(0.5 * (start + x - 1)), start = -1;
  }
  ASSERT_EQ(centres.size(), 101u) << "the ruler's millimetre ticks";
  const double length_mm = (centres.back() - centres.front()) / r.px_per_mm;
  EXPECT_NEAR(length_mm, 100.0, 0.2) << "the ruler";
  std::printf("ruler %.3f mm\n", length_mm);
}

struct PrintCase {
  std::string name;
  std::vector<std::string> flags;
  Paper paper;
  std::string extension;
};

// ctest names the case, not its bytes.
void PrintTo(const PrintCase& c, std::ostream* os) { *os << c.name; }

class TargetPrint : public ::testing::TestWithParam<PrintCase> {};

TEST_P(TargetPrint, OpenCvFindsThePatternAtTheRequestedScale) {
  const PrintCase& c = GetParam();
  if (!HaveTool(c.extension == ".pdf" ? "pdftoppm" : "chromium")) GTEST_SKIP() << "no rasteriser";
  const fs::path dir = TempDir("target_print_" + c.name);
  const fs::path out = dir / ("board" + c.extension);
  std::string command = CalibenchExe() + " target --out '" + out.string() + "'";
  for (const std::string& flag : c.flags) command += " " + flag;
  std::string output;
  ASSERT_EQ(RunCommand(command, &output), 0) << output;

  // target.json beside the print: the pattern, and the sheet as board_size.
  const BoardSpec board = LoadTargetFile(dir / "target.json");
  const TargetSheet sheet = LayoutTargetSheet(board, TargetSheetOptions{c.paper});
  EXPECT_NEAR(board.board_width * 1000.0, sheet.sheet_mm.x(), 1e-9);
  EXPECT_NEAR(board.board_height * 1000.0, sheet.sheet_mm.y(), 1e-9);
  const Vec2 paper = PaperSizeMm(c.paper);
  EXPECT_NEAR(std::max(sheet.sheet_mm.x(), sheet.sheet_mm.y()), paper.maxCoeff(), 1e-9);

  Raster raster;
  if (c.extension == ".pdf") {
    // The page is the paper: pdfinfo's size in points.
    std::string info;
    ASSERT_EQ(RunCommand("pdfinfo '" + out.string() + "'", &info), 0) << info;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(info, m, std::regex(R"(Page size:\s+([0-9.]+) x ([0-9.]+) pts)")))
        << info;
    EXPECT_NEAR(std::stod(m[1]), sheet.sheet_mm.x() * 72.0 / 25.4, 0.01);
    EXPECT_NEAR(std::stod(m[2]), sheet.sheet_mm.y() * 72.0 / 25.4, 0.01);
    raster = RasterisePdf(out);
  } else {
    const std::string svg = test::ReadFileBytes(out);
    std::smatch m;
    ASSERT_TRUE(
        std::regex_search(svg, m, std::regex(R"(width="([0-9.]+)pt" height="([0-9.]+)pt")")));
    EXPECT_NEAR(std::stod(m[1]), sheet.sheet_mm.x() * 72.0 / 25.4, 0.01);
    EXPECT_NEAR(std::stod(m[2]), sheet.sheet_mm.y() * 72.0 / 25.4, 0.01);
    raster = RasteriseSvg(out, sheet.sheet_mm);
  }
  ASSERT_FALSE(raster.gray.empty());
  EXPECT_NEAR(raster.gray.cols / raster.px_per_mm, sheet.sheet_mm.x(), 1.0);
  EXPECT_NEAR(raster.gray.rows / raster.px_per_mm, sheet.sheet_mm.y(), 1.0);

  const double square_mm = board.type == BoardType::kCheckerboard ? CheckerSquareMm(raster, board)
                                                                  : CharucoSquareMm(raster, board);
  EXPECT_NEAR(square_mm, board.square_size * 1000.0, 0.002 * board.square_size * 1000.0)
      << "measured square (mm)";
  std::printf("%s: square %.3f mm (asked %.1f mm)\n", c.name.c_str(), square_mm,
              board.square_size * 1000.0);
  ExpectRulerReads100Mm(raster, sheet);
}

INSTANTIATE_TEST_SUITE_P(
    Boards, TargetPrint,
    ::testing::Values(PrintCase{"a4_checker_pdf",
                                {"--inner-corners 7 5", "--square-size 25mm", "--paper a4"},
                                Paper::kA4,
                                ".pdf"},
                      PrintCase{"a4_checker_svg",
                                {"--inner-corners 7 5", "--square-size 25mm", "--paper a4"},
                                Paper::kA4,
                                ".svg"},
                      PrintCase{"a3_charuco_pdf",
                                {"--type charuco", "--squares 7 5", "--square-size 50mm",
                                 "--marker-size 37mm", "--paper a3"},
                                Paper::kA3,
                                ".pdf"},
                      PrintCase{"a3_charuco_svg",
                                {"--type charuco", "--squares 7 5", "--square-size 50mm",
                                 "--marker-size 37mm", "--paper a3"},
                                Paper::kA3,
                                ".svg"}),
    [](const auto& info) { return info.param.name; });

TEST(TargetCli, ABoardTooLargeNamesTheLargestSquareThatFits) {
  const fs::path dir = TempDir("target_cli");
  std::string output;
  EXPECT_EQ(RunCommand(CalibenchExe() + " target --inner-corners 9 6 --square-size 40mm " +
                           "--paper a4 --out " + (dir / "b.pdf").string(),
                       &output),
            1)
      << output;
  // 10 x 7 squares on 297 x 210 mm: (210 - 2 x (6 + 11)) / 7 = 25.1 mm.
  EXPECT_NE(output.find("the largest square that fits A4 is 25.1 mm"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "b.pdf"));
  EXPECT_FALSE(fs::exists(dir / "target.json"));
  EXPECT_EQ(RunCommand(CalibenchExe() + " target --inner-corners 9 6 --square-size 40 --out " +
                           (dir / "b.pdf").string(),
                       &output),
            1);
  EXPECT_NE(output.find("write 40mm for millimetres"), std::string::npos) << output;
  EXPECT_EQ(
      RunCommand(CalibenchExe() + " target --preset a4 --out " + (dir / "b.png").string(), &output),
      1);
  EXPECT_NE(output.find(".pdf or .svg"), std::string::npos) << output;
  // A different target.json already there is kept, and named.
  ASSERT_EQ(RunCommand(CalibenchExe() + " target --preset a4 --out " + (dir / "a4.pdf").string(),
                       &output),
            0)
      << output;
  const std::string before = test::ReadFileBytes(dir / "target.json");
  EXPECT_EQ(
      RunCommand(CalibenchExe() + " target --preset charuco-a4 --out " + (dir / "c.pdf").string(),
                 &output),
      2);
  EXPECT_NE(output.find("a different target.json is already there"), std::string::npos) << output;
  EXPECT_EQ(test::ReadFileBytes(dir / "target.json"), before);
}

}  // namespace
}  // namespace calibench
