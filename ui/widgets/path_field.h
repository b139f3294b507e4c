// A file path to edit and the button that uses it ("Export result", "Save session as").
#pragma once

#include <string>

namespace calibench::ui {

// id: the ImGui id of the text field ("##export"). True when the button is clicked.
bool PathField(const char* id, std::string* path, const char* button);

}  // namespace calibench::ui
