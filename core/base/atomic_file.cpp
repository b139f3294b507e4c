#include "core/base/atomic_file.h"

#include <fstream>

#include "core/base/types.h"

namespace calibench {

void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(path.string() + ": cannot write (is the folder there and writable?)");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) throw IoError(path.string() + ": write failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw IoError(path.string() + ": cannot replace the file: " + ec.message());
  }
}

}  // namespace calibench
