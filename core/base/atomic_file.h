// Writing files so that a reader never sees half a file: write a sibling temporary, then rename.
#pragma once

#include <filesystem>
#include <string>

namespace calibench {

// Throws IoError naming the file when the temporary cannot be written or renamed.
void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents);

}  // namespace calibench
