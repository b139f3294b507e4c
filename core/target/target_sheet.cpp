// The printable sheet: layout in millimetres, drawn by cairo into PDF or SVG.
#include "core/target/target_sheet.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/base/atomic_file.h"
#include "core/base/names.h"
#include "core/target/board_print.h"

namespace calibench {
namespace {

constexpr EnumName<Paper> kPaperNames[] = {
    {Paper::kA4, "a4"}, {Paper::kA3, "a3"}, {Paper::kA2, "a2"},
    {Paper::kA1, "a1"}, {Paper::kA0, "a0"}, {Paper::kLetter, "letter"},
};

constexpr double kPointsPerMm = 72.0 / 25.4;

std::string Mm(double metres) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f mm", metres * 1000.0);
  return text;
}

std::string Upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// The pattern's largest square size (mm) that fits the printable area of a page of `sheet` mm.
double LargestSquareMm(const BoardSpec& board, const Vec2& sheet, const TargetSheetOptions& o) {
  const double width = sheet.x() - 2.0 * o.margin_mm;
  const double height = sheet.y() - 2.0 * o.margin_mm;
  return std::min(width / board.SquaresX(), height / board.SquaresY());
}

// The ruler needs its 100 mm and a few for the "10 cm" label along the strip it lies in.
constexpr double kRulerRunMm = 112.0;
// The short caption, where no ruler fits, needs a line of 2.4 mm text.
constexpr double kCaptionLineMm = 3.5;

std::string PatternWords(const BoardSpec& board) {
  char text[256];
  if (board.type == BoardType::kCheckerboard) {
    std::snprintf(text, sizeof(text), "checkerboard, %d x %d inner corners (%d x %d squares)",
                  board.cols, board.rows, board.SquaresX(), board.SquaresY());
  } else {
    std::snprintf(text, sizeof(text), "ChArUco, %d x %d squares, markers %s, %s (ids 0-%d)",
                  board.cols, board.rows, Mm(board.marker_size).c_str(), board.dictionary.c_str(),
                  board.cols * board.rows / 2 - 1);
  }
  return text;
}

cairo_status_t AppendToString(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

void DrawText(cairo_t* cr, const std::string& text, double x, double baseline, double size_mm,
              bool centred) {
  cairo_set_font_size(cr, size_mm);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  cairo_move_to(cr, centred ? x - 0.5 * extents.x_advance : x, baseline);
  cairo_show_text(cr, text.c_str());
}

// Text centred on `anchor`'s baseline, upright or reading up the page.
void DrawAnchoredText(cairo_t* cr, const std::string& text, const Vec2& anchor, bool vertical,
                      double size_mm) {
  cairo_save(cr);
  cairo_translate(cr, anchor.x(), anchor.y());
  if (vertical) cairo_rotate(cr, -90.0 * kDegToRad);
  DrawText(cr, text, 0.0, 0.0, size_mm, true);
  cairo_restore(cr);
}

// The 100 mm ruler: a baseline with a tick every millimetre below it (longer every 5 and 10 mm)
// and the centimetres numbered; drawn in its own frame (turned up the page when vertical).
void DrawRuler(cairo_t* cr, const TargetSheet& sheet) {
  cairo_save(cr);
  cairo_translate(cr, sheet.ruler_start_mm.x(), sheet.ruler_start_mm.y());
  if (sheet.ruler_vertical) cairo_rotate(cr, -90.0 * kDegToRad);  // along: up; ticks: to the right
  const Vec2 o = Vec2::Zero();
  cairo_set_line_width(cr, 0.2);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  cairo_move_to(cr, o.x(), o.y());
  cairo_line_to(cr, o.x() + sheet.ruler_length_mm, o.y());
  const int ticks = static_cast<int>(std::lround(sheet.ruler_length_mm));
  for (int mm = 0; mm <= ticks; ++mm) {
    const double length = mm % 10 == 0  ? 2.0 * sheet.ruler_tick_mm
                          : mm % 5 == 0 ? 1.5 * sheet.ruler_tick_mm
                                        : sheet.ruler_tick_mm;  // 4, 3 and 2 mm
    cairo_move_to(cr, o.x() + mm, o.y());
    cairo_line_to(cr, o.x() + mm, o.y() + length);
  }
  cairo_stroke(cr);
  for (int cm = 0; cm * 10 <= ticks; ++cm) {
    DrawText(cr, cm * 10 == ticks ? std::to_string(cm) + " cm" : std::to_string(cm),
             o.x() + cm * 10.0 - (cm * 10 == ticks ? 1.0 : 0.0),
             o.y() + 2.0 * sheet.ruler_tick_mm + 2.6, 2.2, cm * 10 != ticks);
  }
  cairo_restore(cr);
}

void DrawSheet(cairo_t* cr, const TargetSheet& sheet) {
  cairo_scale(cr, kPointsPerMm, kPointsPerMm);  // user units: millimetres
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  // The ink as one path filled once: touching rectangles merge without hairline seams.
  const Vec2 centre = 0.5 * sheet.sheet_mm;
  for (const InkRect& r : BoardPrint(sheet.board).Ink()) {
    const Vec2 min = centre + 1000.0 * r.min, size = 1000.0 * (r.max - r.min);
    cairo_rectangle(cr, min.x(), min.y(), size.x(), size.y());
  }
  cairo_set_fill_rule(cr, CAIRO_FILL_RULE_WINDING);
  cairo_fill(cr);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  if (sheet.draw_title)
    DrawAnchoredText(cr, sheet.title, sheet.title_anchor_mm, sheet.title_vertical, 2.8);
  if (sheet.has_ruler) DrawRuler(cr, sheet);
  if (sheet.draw_caption)
    DrawAnchoredText(cr, sheet.caption, sheet.caption_anchor_mm, sheet.caption_vertical, 2.4);
}

}  // namespace

std::string PaperName(Paper paper) { return NameIn(kPaperNames, paper); }
std::optional<Paper> ParsePaperName(const std::string& name) { return ValueIn(kPaperNames, name); }
std::string PaperNames() {
  std::string names = NamesIn(kPaperNames);
  for (size_t at = names.find(", "); at != std::string::npos; at = names.find(", "))
    names.replace(at, 2, "|");
  return names;
}

Vec2 PaperSizeMm(Paper paper) {
  switch (paper) {
    case Paper::kA4:
      return {210, 297};
    case Paper::kA3:
      return {297, 420};
    case Paper::kA2:
      return {420, 594};
    case Paper::kA1:
      return {594, 841};
    case Paper::kA0:
      return {841, 1189};
    case Paper::kLetter:
      return {215.9, 279.4};
  }
  return {210, 297};
}

std::optional<SheetOrientation> ParseSheetOrientation(const std::string& name) {
  if (name == "auto") return SheetOrientation::kAuto;
  if (name == "portrait") return SheetOrientation::kPortrait;
  if (name == "landscape") return SheetOrientation::kLandscape;
  return std::nullopt;
}

bool TargetSheetOptions::Check(std::string* why) const {
  if (!(margin_mm >= 0.0 && margin_mm < 50.0)) {
    *why = "margin_mm must be in [0, 50) mm";
    return false;
  }
  if (!(band_mm >= 11.0 && band_mm < 100.0)) {
    *why = "band_mm must be in [11, 100) mm: the ruler and its caption need 11 mm";
    return false;
  }
  return true;
}

namespace {

// Where the ruler, the caption and the title go around a pattern centred on the sheet: below and
// above it when that band has room, else right and left of it (reading up the page), else no
// ruler (the caption, where a line fits, says to measure a square instead).
void PlaceAnnotations(const TargetSheetOptions& options, TargetSheet* sheet) {
  const Vec2 page = sheet->sheet_mm;
  const BoardSpec& board = sheet->board;
  const double m = options.margin_mm;
  const double above_below = 0.5 * (page.y() - 1000.0 * board.PatternHeight()) - m;
  const double beside = 0.5 * (page.x() - 1000.0 * board.PatternWidth()) - m;
  const std::string square = Mm(board.square_size);
  sheet->caption = "square " + square +
                   " - measure the ruler after printing: it must read 100 mm; print at 100 %, no "
                   "fit-to-page";
  if (above_below >= options.band_mm && page.x() - 2.0 * m >= kRulerRunMm) {
    // The ruler and caption at the bottom of the band, as far from the pattern as the margin
    // lets them: the detector likes a quiet white border around the squares.
    sheet->caption_anchor_mm = Vec2(0.5 * page.x(), page.y() - m - 0.8);
    sheet->title_anchor_mm = Vec2(0.5 * page.x(), m + 3.0);
    sheet->ruler_start_mm =
        Vec2(0.5 * (page.x() - sheet->ruler_length_mm), sheet->caption_anchor_mm.y() - 9.6);
    return;
  }
  if (beside >= options.band_mm && page.y() - 2.0 * m >= kRulerRunMm) {
    // The same band turned a quarter: x' = up the page, y' = to the right; the caption at the
    // right margin, the ruler inside it, the title in the left margin.
    sheet->ruler_vertical = sheet->caption_vertical = sheet->title_vertical = true;
    sheet->caption_anchor_mm = Vec2(page.x() - m - 0.8, 0.5 * page.y());
    sheet->ruler_start_mm =
        Vec2(sheet->caption_anchor_mm.x() - 9.6, 0.5 * (page.y() + sheet->ruler_length_mm));
    sheet->title_anchor_mm = Vec2(m + 3.0, 0.5 * page.y());
    return;
  }
  // No strip beside the pattern holds the ruler: the squares themselves are the scale.
  sheet->has_ruler = false;
  sheet->note = "no room for the 100 mm ruler beside this pattern on " +
                Upper(PaperName(sheet->paper)) + ": check the print by measuring a square, it " +
                "must be " + square + " (print at 100 %, no fit-to-page)";
  sheet->caption = "square " + square + " - measure a square after printing; print at 100 %";
  const double gap = std::max(above_below, beside);
  if (gap < kCaptionLineMm) {
    sheet->draw_caption = sheet->draw_title = false;
    return;
  }
  const bool vertical = beside > above_below;
  sheet->caption_vertical = sheet->title_vertical = vertical;
  sheet->caption_anchor_mm = vertical ? Vec2(page.x() - m - 0.8, 0.5 * page.y())
                                      : Vec2(0.5 * page.x(), page.y() - m - 0.8);
  sheet->title_anchor_mm = vertical ? Vec2(m + 3.0, 0.5 * page.y()) : Vec2(0.5 * page.x(), m + 3.0);
  sheet->draw_title = gap >= 4.0;  // the title's 2.8 mm letters need a little more
}

// Whether the pattern, centred on `page`, leaves a strip beside it for the ruler.
bool RulerFits(const BoardSpec& board, const Vec2& page, const TargetSheetOptions& o) {
  const double above_below = 0.5 * (page.y() - 1000.0 * board.PatternHeight()) - o.margin_mm;
  const double beside = 0.5 * (page.x() - 1000.0 * board.PatternWidth()) - o.margin_mm;
  return (above_below >= o.band_mm && page.x() - 2.0 * o.margin_mm >= kRulerRunMm) ||
         (beside >= o.band_mm && page.y() - 2.0 * o.margin_mm >= kRulerRunMm);
}

}  // namespace

double LargestSquareThatFitsMm(const BoardSpec& board, const TargetSheetOptions& options) {
  const Vec2 portrait = PaperSizeMm(options.paper);
  const Vec2 landscape(portrait.y(), portrait.x());
  const double fits_portrait = LargestSquareMm(board, portrait, options);
  const double fits_landscape = LargestSquareMm(board, landscape, options);
  switch (options.orientation) {
    case SheetOrientation::kPortrait:
      return fits_portrait;
    case SheetOrientation::kLandscape:
      return fits_landscape;
    case SheetOrientation::kAuto:
      break;
  }
  return std::max(fits_portrait, fits_landscape);
}

TargetSheet LayoutTargetSheet(const BoardSpec& pattern, const TargetSheetOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument(why);
  BoardSpec board = pattern;
  board.board_width = board.board_height = 0.0;  // the sheet is set below
  if (!board.Check(&why)) throw std::invalid_argument("the board: " + why);
  const Vec2 portrait = PaperSizeMm(options.paper);
  const Vec2 landscape(portrait.y(), portrait.x());
  const double square_mm = 1000.0 * board.square_size;
  const double fits_portrait = LargestSquareMm(board, portrait, options);
  const double fits_landscape = LargestSquareMm(board, landscape, options);
  bool use_landscape = options.orientation == SheetOrientation::kLandscape;
  if (options.orientation == SheetOrientation::kAuto) {
    // Where the pattern fits both ways, the way that keeps a ruler beside it; else the better fit.
    const bool in_portrait = square_mm <= fits_portrait + 1e-9;
    const bool in_landscape = square_mm <= fits_landscape + 1e-9;
    if (in_portrait && in_landscape) {
      const bool ruler_portrait = RulerFits(board, portrait, options);
      const bool ruler_landscape = RulerFits(board, landscape, options);
      use_landscape =
          ruler_portrait != ruler_landscape ? ruler_landscape : fits_landscape > fits_portrait;
    } else {
      use_landscape = fits_landscape > fits_portrait;
    }
  }
  const double fits = use_landscape ? fits_landscape : fits_portrait;
  const std::string paper = Upper(PaperName(options.paper));
  if (square_mm > fits + 1e-9) {
    const std::string where = options.orientation == SheetOrientation::kAuto
                                  ? paper
                                  : paper + (use_landscape ? " landscape" : " portrait");
    char text[256];
    std::snprintf(text, sizeof(text),
                  "a %s with %.1f mm squares does not fit %s (%.0f mm margins): the largest "
                  "square that fits %s is %.1f mm",
                  board.type == BoardType::kCheckerboard ? "checkerboard" : "ChArUco board",
                  square_mm, where.c_str(), options.margin_mm, where.c_str(),
                  std::floor(fits * 10.0) / 10.0);
    throw std::invalid_argument(text);
  }
  TargetSheet sheet;
  sheet.paper = options.paper;
  sheet.landscape = use_landscape;
  sheet.sheet_mm = use_landscape ? landscape : portrait;
  board.board_width = sheet.sheet_mm.x() / 1000.0;
  board.board_height = sheet.sheet_mm.y() / 1000.0;
  sheet.board = board;
  sheet.pattern_top_left_mm =
      0.5 * sheet.sheet_mm - 500.0 * Vec2(board.PatternWidth(), board.PatternHeight());
  sheet.title = "Calibench target: " + PatternWords(board) + ", square " + Mm(board.square_size) +
                ", " + paper + (use_landscape ? " landscape" : " portrait");
  PlaceAnnotations(options, &sheet);
  return sheet;
}

void WriteTargetSheet(const TargetSheet& sheet, const std::filesystem::path& path) {
  const std::string extension = path.extension().string();
  if (extension != ".pdf" && extension != ".svg")
    throw std::invalid_argument(path.string() + ": the target is written as .pdf or .svg, not '" +
                                extension + "'");
  std::string bytes;
  const double width_pt = sheet.sheet_mm.x() * kPointsPerMm;
  const double height_pt = sheet.sheet_mm.y() * kPointsPerMm;
  cairo_surface_t* surface =
      extension == ".pdf"
          ? cairo_pdf_surface_create_for_stream(AppendToString, &bytes, width_pt, height_pt)
          : cairo_svg_surface_create_for_stream(AppendToString, &bytes, width_pt, height_pt);
  if (extension == ".pdf") {
    cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE, sheet.title.c_str());
    cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "Calibench");
  } else {
    cairo_svg_surface_restrict_to_version(surface, CAIRO_SVG_VERSION_1_1);
  }
  cairo_t* cr = cairo_create(surface);
  DrawSheet(cr, sheet);
  cairo_show_page(cr);
  const cairo_status_t drawn = cairo_status(cr);
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t finished = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (drawn != CAIRO_STATUS_SUCCESS || finished != CAIRO_STATUS_SUCCESS)
    throw IoError(path.string() + ": cairo could not draw the target: " +
                  cairo_status_to_string(drawn != CAIRO_STATUS_SUCCESS ? drawn : finished));
  WriteFileAtomically(path, bytes);
}

}  // namespace calibench
