// The line at the bottom of a workbench: "working" while its controller is busy, the last
// message (red for an error) and, on the right, what is open.
#pragma once

#include <string>

#include "ui/widgets/view_window.h"

namespace calibench::ui {

// right_text: e.g. "session: work.session.json".
void StatusLine(const Rect& r, bool busy, bool is_error, const std::string& message,
                const std::string& right_text);

}  // namespace calibench::ui
