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

#include "core/board/charuco_board.h"
#include "core/io/dataset.h"
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

// The ruler's millimetre ticks along a line 1 mm below its baseline (a row for a ruler below the
// pattern, a column for one beside it): 101 dark runs whose first and last centres lie 100 mm
// apart.
void ExpectRulerReads100Mm(const Raster& r, const TargetSheet& sheet) {
  ASSERT_TRUE(sheet.has_ruler);
  const Vec2 along = sheet.ruler_vertical ? Vec2(0.0, -1.0) : Vec2(1.0, 0.0);
  const Vec2 below = sheet.ruler_vertical ? Vec2(1.0, 0.0) : Vec2(0.0, 1.0);  // the ticks' side
  const Vec2 start_px = (sheet.ruler_start_mm + 1.0 * below) * r.px_per_mm;
  const int samples = static_cast<int>(std::lround(106.0 * r.px_per_mm));
  std::vector<double> centres;
  int start = -1;
  for (int i = 0; i <= samples; ++i) {
    const Vec2 at = start_px + (i - 3.0 * r.px_per_mm) * along;
    const int x = static_cast<int>(std::lround(at.x())), y = static_cast<int>(std::lround(at.y()));
    ASSERT_TRUE(x > 0 && x < r.gray.cols && y > 0 && y < r.gray.rows) << x << ", " << y;
    const bool dark = r.gray.at<std::uint8_t>(y, x) < 128;
    if (dark && start < 0) start = i;
    if (!dark && start >= 0) centres.push_back(0.5 * (start + i - 1)), start = -1;
  }
  ASSERT_EQ(centres.size(), 101u) << "the ruler's millimetre ticks";
  const double length_mm = (centres.back() - centres.front()) / r.px_per_mm;
  EXPECT_NEAR(length_mm, 100.0, 0.2) << "the ruler";
  std::printf("ruler %.3f mm (%s)\n", length_mm, sheet.ruler_vertical ? "beside" : "below");
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

  // The target file beside the print, named after it: the pattern, and the sheet as board_size.
  const BoardSpec board = LoadTargetFile(dir / ("board" + std::string(".target.json")));
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
    ::testing::Values(PrintCase{"a4_side_ruler_pdf",  // 240 x 180 mm: the ruler goes beside it
                                {"--inner-corners 7 5", "--square-size 30mm", "--paper a4"},
                                Paper::kA4,
                                ".pdf"},
                      PrintCase{"a4_side_ruler_svg",
                                {"--inner-corners 7 5", "--square-size 30mm", "--paper a4"},
                                Paper::kA4,
                                ".svg"},
                      PrintCase{"a4_checker_pdf",
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
  // 10 x 7 squares on the printable 285 x 198 mm of A4 landscape: min(28.5, 28.28) mm.
  EXPECT_NE(output.find("the largest square that fits A4 is 28.2 mm"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "b.pdf"));
  EXPECT_FALSE(fs::exists(dir / "b.target.json"));
  EXPECT_EQ(RunCommand(CalibenchExe() + " target --inner-corners 9 6 --square-size 40 --out " +
                           (dir / "b.pdf").string(),
                       &output),
            1);
  EXPECT_NE(output.find("write 40mm for millimetres"), std::string::npos) << output;
  EXPECT_EQ(
      RunCommand(CalibenchExe() + " target --preset a4 --out " + (dir / "b.png").string(), &output),
      1);
  EXPECT_NE(output.find(".pdf or .svg"), std::string::npos) << output;
  // Two targets into one folder: each its own target file, named after its print.
  ASSERT_EQ(RunCommand(CalibenchExe() + " target --preset a4 --out " + (dir / "a4.pdf").string(),
                       &output),
            0)
      << output;
  ASSERT_EQ(
      RunCommand(CalibenchExe() + " target --preset charuco-a4 --out " + (dir / "c.pdf").string(),
                 &output),
      0)
      << output;
  EXPECT_EQ(LoadTargetFile(dir / "a4.target.json").type, BoardType::kCheckerboard);
  EXPECT_EQ(LoadTargetFile(dir / "c.target.json").type, BoardType::kCharuco);
  // A different target file already there under the same name is kept, and named.
  const std::string before = test::ReadFileBytes(dir / "a4.target.json");
  EXPECT_EQ(
      RunCommand(CalibenchExe() + " target --preset charuco-a4 --out " + (dir / "a4.pdf").string(),
                 &output),
      2);
  EXPECT_NE(output.find("a different target file is already there"), std::string::npos) << output;
  EXPECT_EQ(test::ReadFileBytes(dir / "a4.target.json"), before);
}

// The issue's board: 7 x 5 inner corners of 30 mm (240 x 180 mm) on A4 (297 x 210 mm) leaves 9 mm
// above and below, 22.5 mm beside: the ruler goes beside it, nothing is refused.
TEST(TargetLayout, ABoardThatFitsThePaperIsNeverRefused) {
  BoardSpec board;
  board.type = BoardType::kCheckerboard;
  board.cols = 7;
  board.rows = 5;
  board.square_size = 0.030;
  const TargetSheet sheet = LayoutTargetSheet(board, TargetSheetOptions{Paper::kA4});
  EXPECT_TRUE(sheet.landscape);
  ASSERT_TRUE(sheet.has_ruler);
  EXPECT_TRUE(sheet.ruler_vertical);
  EXPECT_TRUE(sheet.note.empty()) << sheet.note;
  // The ruler lies in the right margin strip: right of the pattern, inside the printable area,
  // and its 100 mm within the page's height.
  const double pattern_right = sheet.pattern_top_left_mm.x() + 240.0;
  EXPECT_GT(sheet.ruler_start_mm.x(), pattern_right + 1.0);
  EXPECT_LT(sheet.ruler_start_mm.x() + 2.0 * sheet.ruler_tick_mm + 2.6, 297.0 - 6.0);
  EXPECT_LT(sheet.ruler_start_mm.y(), 210.0 - 6.0);
  EXPECT_GT(sheet.ruler_start_mm.y() - 100.0, 6.0);
  EXPECT_GT(sheet.caption_anchor_mm.x(), sheet.ruler_start_mm.x());
  EXPECT_LT(sheet.title_anchor_mm.x(), sheet.pattern_top_left_mm.x());
}

// Every preset paper: the largest square is what the printable area (the paper less 6 mm margins)
// holds, in the better orientation; a pattern of that size is laid out (with its ruler where a
// strip beside it holds one, else a note saying to measure a square), and one 0.2 mm larger is
// refused naming it.
TEST(TargetLayout, TheLargestSquareOfEveryPaperComesFromItsPrintableArea) {
  BoardSpec checker;
  checker.type = BoardType::kCheckerboard;
  checker.cols = 7;
  checker.rows = 5;
  BoardSpec charuco;
  charuco.type = BoardType::kCharuco;
  charuco.cols = 7;
  charuco.rows = 5;
  charuco.dictionary = "DICT_4X4_50";
  for (const Paper paper :
       {Paper::kA4, Paper::kA3, Paper::kA2, Paper::kA1, Paper::kA0, Paper::kLetter}) {
    for (BoardSpec board : {checker, charuco}) {
      SCOPED_TRACE(PaperName(paper) +
                   (board.type == BoardType::kCharuco ? " charuco" : " checker"));
      const Vec2 page = PaperSizeMm(paper);
      const double portrait =
          std::min((page.x() - 12.0) / board.SquaresX(), (page.y() - 12.0) / board.SquaresY());
      const double landscape =
          std::min((page.y() - 12.0) / board.SquaresX(), (page.x() - 12.0) / board.SquaresY());
      const double largest = std::max(portrait, landscape);
      EXPECT_NEAR(LargestSquareThatFitsMm(board, TargetSheetOptions{paper}), largest, 1e-9);
      board.square_size = std::floor(largest * 10.0) / 10.0 / 1000.0;
      board.marker_size = 0.75 * board.square_size;
      TargetSheet sheet;
      ASSERT_NO_THROW(sheet = LayoutTargetSheet(board, TargetSheetOptions{paper}));
      EXPECT_EQ(sheet.has_ruler, sheet.note.empty()) << sheet.note;
      if (!sheet.has_ruler) {
        EXPECT_NE(sheet.note.find("measuring a square"), std::string::npos);
      }
      std::printf("%-6s %-8s largest square %.1f mm, ruler %s\n", PaperName(paper).c_str(),
                  board.type == BoardType::kCharuco ? "charuco" : "checker", largest,
                  !sheet.has_ruler       ? "none (measure a square)"
                  : sheet.ruler_vertical ? "beside"
                                         : "below");
      board.square_size += 0.0002;
      board.marker_size = 0.75 * board.square_size;
      try {
        LayoutTargetSheet(board, TargetSheetOptions{paper});
        ADD_FAILURE() << "a pattern larger than the printable area was laid out";
      } catch (const std::invalid_argument& error) {
        char expected[64];
        std::snprintf(expected, sizeof(expected), "is %.1f mm", std::floor(largest * 10.0) / 10.0);
        EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
      }
    }
  }
}

}  // namespace
}  // namespace calibench
