// Reviewing pairs, as both workbenches' measurements lists do it: the loading progress, Accept /
// Reject for the selected pair, the table of pairs (one selectable row each, its status in
// colour) and the keys (A, R, arrows, Enter / F5).
#pragma once

#include <initializer_list>
#include <optional>
#include <string>

#include "core/results/pair_status.h"

namespace calibench::ui {

// "<verb> 3 / 6 pairs" as a progress bar across the panel while done < total; nothing after.
void PairProgress(const char* verb, int done, int total);
// "Accept (A)" and "Reject (R)" (disabled without a selection), then `hint` greyed on the same
// line. The status clicked, if any.
std::optional<PairStatus> ReviewButtons(bool has_selection, const char* hint);

// A column of the pairs table: its header and its width in pixels (0: takes what is left).
struct PairColumn {
  const char* name;
  float width = 0;
};
// ImGui::BeginTable of the pairs with these columns and their header row (frozen), filling the
// rest of the panel; call ImGui::EndTable() when it returns true.
bool BeginPairsTable(std::initializer_list<PairColumn> columns);
// The row's selectable, spanning all columns (row_height 0: one text line). True when clicked.
bool PairSelectable(int index, const std::string& id, bool selected, float row_height = 0);
// `text` (the status's name, or what the pair waits for) in the status's colour.
void PairStatusText(PairStatus status, const std::string& text);

// Keys of the review pressed this frame. Dear ImGui 1.86 keys are the platform backend's codes:
// GLFW uses ASCII for letters and brackets, and the headless host maps the same codes.
struct ReviewKeys {
  bool accept = false;    // A
  bool reject = false;    // R
  bool next = false;      // down or right arrow
  bool previous = false;  // up or left arrow
  bool run = false;       // Enter or F5: run the solver
};
ReviewKeys ReadReviewKeys();
// A key pressed this frame (not repeated): an ASCII letter or bracket, or a GLFW key code.
bool KeyPressed(int key);

}  // namespace calibench::ui
