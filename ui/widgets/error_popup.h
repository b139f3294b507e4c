// The modal that says why something did not open: both windows' "Cannot open".
#pragma once

#include <string>

namespace calibench::ui {

// Opens the modal `title` when *show is set (and clears it), then draws it while open: `message`
// in red, wrapped, `hint` (if any) greyed below it, and OK.
void ErrorPopup(const char* title, const std::string& message, bool* show,
                const char* hint = nullptr);

}  // namespace calibench::ui
