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
                  ": a different target file is already there (another board?); move it away or "
                  "name another file with --target-json");
}

// The pattern flags of `target`, as given.
struct PatternFlags {
  std::string type = "checkerboard", preset, square, marker, dictionary = "DICT_4X4_50";
  bool type_given = false;
  std::vector<int> inner_corners, squares;
};

// The board the flags describe (a preset, with the flags given overriding it); nullopt with *why
// naming the flag that is wrong or missing.
std::optional<BoardSpec> BoardFromPatternFlags(const PatternFlags& f, std::string* why) {
  BoardSpec board;
  if (!f.preset.empty()) {
    try {
      board = BoardPreset(f.preset);
    } catch (const std::invalid_argument& e) {
      *why = std::string("--preset: ") + e.what();
      return std::nullopt;
    }
  }
  if (f.preset.empty() || f.type_given) {
    if (f.type != "checkerboard" && f.type != "charuco") {
      *why = "--type must be checkerboard or charuco, got '" + f.type + "'";
      return std::nullopt;
    }
    board.type = f.type == "charuco" ? BoardType::kCharuco : BoardType::kCheckerboard;
  }
  const bool checker = board.type == BoardType::kCheckerboard;
  if (!f.inner_corners.empty() && !f.squares.empty()) {
    *why = "give --inner-corners or --squares, not both";
    return std::nullopt;
  }
  if (!f.inner_corners.empty()) {
    if (!checker) {
      *why = "a ChArUco board is given by --squares C R, not --inner-corners";
      return std::nullopt;
    }
    board.cols = f.inner_corners[0], board.rows = f.inner_corners[1];
  } else if (!f.squares.empty()) {
    board.cols = checker ? f.squares[0] - 1 : f.squares[0];
    board.rows = checker ? f.squares[1] - 1 : f.squares[1];
  } else if (f.preset.empty()) {
    *why = checker ? "the pattern: --inner-corners C R (or --squares C R)"
                   : "the pattern: --squares C R";
    return std::nullopt;
  }
  if (!f.square.empty()) {
    const auto size = ParseLength(f.square, why);
    if (!size) {
      *why = "--square-size: " + *why;
      return std::nullopt;
    }
    board.square_size = *size;
  } else if (f.preset.empty()) {
    *why = "the square's side: --square-size (0.04 or 40mm)";
    return std::nullopt;
  }
  if (checker) return board;
  board.dictionary = f.dictionary;
  if (!f.marker.empty()) {
    const auto size = ParseLength(f.marker, why);
    if (!size) {
      *why = "--marker-size: " + *why;
      return std::nullopt;
    }
    board.marker_size = *size;
  } else if (f.preset.empty() || !f.square.empty()) {
    board.marker_size = 0.75 * board.square_size;
  }
  return board;
}

// The pattern's flags (BoardFromPatternFlags reads them).
void AddPatternFlags(CLI::App& app, PatternFlags& pattern) {
  app.add_option("--type", pattern.type, "checkerboard | charuco")->capture_default_str();
  app.add_option("--preset", pattern.preset,
                 "start from a named board (a3, a4, charuco-a3, charuco-a4); other flags override "
                 "its pattern");
  app.add_option("--inner-corners", pattern.inner_corners, "checkerboard: inner corners C R")
      ->expected(2);
  app.add_option("--squares", pattern.squares,
                 "charuco: squares C R (checkerboard: C-1 R-1 corners)")
      ->expected(2);
  app.add_option("--square-size", pattern.square, "side of one square (0.04, 40mm)");
  app.add_option("--marker-size", pattern.marker,
                 "charuco: side of one marker (default 0.75 of the square)");
  app.add_option("--dictionary", pattern.dictionary, "charuco: OpenCV's ArUco dictionary")
      ->capture_default_str();
}

// `target --list-presets`: one line per named board (bash completion reads the first column).
int PrintBoardPresets() {
  for (const std::string& name : BoardPresetNames()) {
    const BoardSpec preset = BoardPreset(name);
    const bool charuco = preset.type == BoardType::kCharuco;
    std::printf("%-11s %s %d x %d %s of %.0f mm, sheet %.0f x %.0f mm\n", name.c_str(),
                charuco ? "charuco" : "checkerboard", preset.cols, preset.rows,
                charuco ? "squares" : "inner corners", preset.square_size * 1e3,
                preset.board_width * 1e3, preset.board_height * 1e3);
  }
  return kOk;
}

}  // namespace

int RunTarget(int argc, char** argv) {
  CLI::App app{
      "Write a printable calibration board at exact scale (PDF or SVG through cairo) with a "
      "100 mm ruler and a caption, and beside it the target file that `calibrate` reads "
      "(board_size = the sheet; board.pdf -> board.target.json). ChArUco boards are OpenCV's for "
      "the same parameters. Lengths "
      "are metres or carry a unit: 0.04, 40mm, 4cm.",
      "calibench target"};
  PatternFlags pattern;
  std::string paper_name = "a4", orientation_name = "auto", out, target_json;
  AddPatternFlags(app, pattern);
  app.add_option("--paper", paper_name, PaperNames())->capture_default_str();
  app.add_option("--orientation", orientation_name,
                 "auto (the one the pattern fits best) | portrait | landscape")
      ->capture_default_str();
  bool list_presets = false;
  app.add_flag("--list-presets", list_presets,
               "print the named boards (name, pattern, sheet) and exit");
  app.add_option("--out,-o", out, "board.pdf or board.svg (required unless --list-presets)");
  app.add_option("--target-json", target_json,
                 "where the matching target file goes (default: beside --out, named after it: "
                 "board.pdf -> board.target.json)");
  if (const auto code = ParseFlags(app, argc, argv)) return *code;
  if (list_presets) return PrintBoardPresets();
  if (out.empty()) {
    std::fprintf(stderr, "calibench target: --out is required (board.pdf or board.svg)\n");
    return kUsage;
  }
  pattern.type_given = app.count("--type") > 0;

  auto usage = [](const std::string& why) {
    std::fprintf(stderr, "calibench target: %s\n", why.c_str());
    return kUsage;
  };
  std::string why;
  const std::optional<BoardSpec> board = BoardFromPatternFlags(pattern, &why);
  if (!board) return usage(why);
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
    sheet = LayoutTargetSheet(*board, options);
  } catch (const std::invalid_argument& e) {
    return usage(e.what());
  }
  const fs::path out_path(out);
  // Named after the print, so that two targets printed into one folder keep their own files;
  // import and watch find <recording>.target.json, target.json, or the only *.target.json.
  const fs::path json_path =
      target_json.empty() ? out_path.parent_path() / (out_path.stem().string() + ".target.json")
                          : fs::path(target_json);
  const std::string json_text = json_io::TargetToJson(sheet.board).dump(2) + "\n";
  CheckTargetJsonFree(json_path, json_text);
  try {
    WriteTargetSheet(sheet, out_path);
  } catch (const std::invalid_argument& e) {
    return usage(e.what());
  }
  WriteFileAtomically(json_path, json_text);
  if (!sheet.note.empty()) std::fprintf(stderr, "calibench target: note: %s\n", sheet.note.c_str());
  std::printf("%s\n  %s\n  %s (%.0f x %.0f mm)\nwrote %s and %s\n", sheet.title.c_str(),
              sheet.caption.c_str(), PaperName(sheet.paper).c_str(), sheet.sheet_mm.x(),
              sheet.sheet_mm.y(), out_path.string().c_str(), json_path.string().c_str());
  return kOk;
}

}  // namespace calibench::app
