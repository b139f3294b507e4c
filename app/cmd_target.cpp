// calibench target: a printable board at exact scale (PDF or SVG) and the target.json that
// `calibrate` reads for it.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "app/commands.h"
#include "core/base/atomic_file.h"
#include "core/io/dataset.h"
#include "core/io/json_io.h"
#include "core/target/target_sheet.h"

namespace calibench::app {

namespace {

namespace fs = std::filesystem;

// A length flag: metres ("0.04", "0.04m") or with a unit ("40mm", "4cm"). A bare number above
// 1 is refused: it is almost always millimetres meant, and a board 40 m wide is not.
std::optional<double> ParseLength(const std::string& text, std::string* why) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  const std::string unit = end ? std::string(end) : "";
  if (end == text.c_str() || !(value > 0.0)) {
    *why = "'" + text + "' is not a positive length (write 0.04, 0.04m, 40mm or 4cm)";
    return std::nullopt;
  }
  if (unit == "mm") return value / 1000.0;
  if (unit == "cm") return value / 100.0;
  if (unit == "m") return value;
  if (!unit.empty()) {
    *why = "'" + text + "': unknown unit '" + unit + "' (use mm, cm or m)";
    return std::nullopt;
  }
  if (value > 1.0) {
    *why = "'" + text + "' would be metres: write " + text + "mm for millimetres";
    return std::nullopt;
  }
  return value;
}

// An existing target file that says something else is kept and named, never overwritten: it may
// describe the board a dataset was captured with.
void CheckTargetJsonFree(const fs::path& path, const std::string& text) {
  if (!fs::exists(path)) return;
  std::ifstream in(path, std::ios::binary);
  std::stringstream existing;
  existing << in.rdbuf();
  if (existing.str() != text)
    throw IoError(path.string() +
                  ": a different target.json is already there (another board?); move it away or "
                  "name another file with --target-json");
}

}  // namespace

int RunTarget(int argc, char** argv) {
  CLI::App app{
      "Write a printable calibration board at exact scale (PDF or SVG through cairo) with a "
      "100 mm ruler and a caption, and beside it the target.json that `calibrate` reads "
      "(board_size = the sheet). ChArUco boards are OpenCV's for the same parameters. Lengths "
      "are metres or carry a unit: 0.04, 40mm, 4cm.",
      "calibench target"};
  std::string type = "checkerboard", square_text, marker_text, dictionary = "DICT_4X4_50";
  std::string paper_name = "a4", orientation_name = "auto", out, target_json, preset;
  std::vector<int> inner_corners, squares;
  app.add_option("--type", type, "checkerboard | charuco")->capture_default_str();
  app.add_option("--preset", preset,
                 "start from a named board (a3, a4, charuco-a3, charuco-a4); other flags override "
                 "its pattern");
  app.add_option("--inner-corners", inner_corners, "checkerboard: inner corners C R")->expected(2);
  app.add_option("--squares", squares, "charuco: squares C R (checkerboard: C-1 R-1 corners)")
      ->expected(2);
  app.add_option("--square-size", square_text, "side of one square (0.04, 40mm)");
  app.add_option("--marker-size", marker_text,
                 "charuco: side of one marker (default 0.75 of the square)");
  app.add_option("--dictionary", dictionary, "charuco: OpenCV's ArUco dictionary")
      ->capture_default_str();
  app.add_option("--paper", paper_name, PaperNames())->capture_default_str();
  app.add_option("--orientation", orientation_name,
                 "auto (the one the pattern fits best) | portrait | landscape")
      ->capture_default_str();
  app.add_option("--out,-o", out, "board.pdf or board.svg")->required();
  app.add_option("--target-json", target_json,
                 "where the matching target file goes (default: target.json beside --out)");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;

  auto usage = [](const std::string& why) {
    std::fprintf(stderr, "calibench target: %s\n", why.c_str());
    return kUsage;
  };
  BoardSpec board;
  try {
    if (!preset.empty()) board = BoardPreset(preset);
  } catch (const std::invalid_argument& e) {
    return usage(std::string("--preset: ") + e.what());
  }
  if (preset.empty() || app.count("--type")) {
    if (type == "checkerboard") {
      board.type = BoardType::kCheckerboard;
    } else if (type == "charuco") {
      board.type = BoardType::kCharuco;
    } else {
      return usage("--type must be checkerboard or charuco, got '" + type + "'");
    }
  }
  const bool checker = board.type == BoardType::kCheckerboard;
  if (!inner_corners.empty() && !squares.empty())
    return usage("give --inner-corners or --squares, not both");
  if (!inner_corners.empty()) {
    if (!checker) return usage("a ChArUco board is given by --squares C R, not --inner-corners");
    board.cols = inner_corners[0], board.rows = inner_corners[1];
  } else if (!squares.empty()) {
    board.cols = checker ? squares[0] - 1 : squares[0];
    board.rows = checker ? squares[1] - 1 : squares[1];
  } else if (preset.empty()) {
    return usage(checker ? "the pattern: --inner-corners C R (or --squares C R)"
                         : "the pattern: --squares C R");
  }
  std::string why;
  if (!square_text.empty()) {
    const auto size = ParseLength(square_text, &why);
    if (!size) return usage("--square-size: " + why);
    board.square_size = *size;
  } else if (preset.empty()) {
    return usage("the square's side: --square-size (0.04 or 40mm)");
  }
  if (!checker) {
    board.dictionary = dictionary;
    if (!marker_text.empty()) {
      const auto size = ParseLength(marker_text, &why);
      if (!size) return usage("--marker-size: " + why);
      board.marker_size = *size;
    } else if (preset.empty() || !square_text.empty()) {
      board.marker_size = 0.75 * board.square_size;
    }
  }
  TargetSheetOptions options;
  const auto paper = ParsePaperName(paper_name);
  const auto orientation = ParseSheetOrientation(orientation_name);
  if (!paper) return usage("--paper must be " + PaperNames() + ", got '" + paper_name + "'");
  if (!orientation)
    return usage("--orientation must be auto, portrait or landscape, got '" + orientation_name +
                 "'");
  options.paper = *paper;
  options.orientation = *orientation;

  TargetSheet sheet;
  try {
    sheet = LayoutTargetSheet(board, options);
  } catch (const std::invalid_argument& e) {
    return usage(e.what());
  }
  const fs::path out_path(out);
  const fs::path json_path =
      target_json.empty() ? out_path.parent_path() / "target.json" : fs::path(target_json);
  const std::string json_text = json_io::TargetToJson(sheet.board).dump(2) + "\n";
  CheckTargetJsonFree(json_path, json_text);
  try {
    WriteTargetSheet(sheet, out_path);
  } catch (const std::invalid_argument& e) {
    return usage(e.what());
  }
  WriteFileAtomically(json_path, json_text);
  std::printf("%s\n  %s\n  %s (%.0f x %.0f mm)\nwrote %s and %s\n", sheet.title.c_str(),
              sheet.caption.c_str(), PaperName(sheet.paper).c_str(), sheet.sheet_mm.x(),
              sheet.sheet_mm.y(), out_path.string().c_str(), json_path.string().c_str());
  return kOk;
}

}  // namespace calibench::app
