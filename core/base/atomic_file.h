// Writing files so that a reader never sees half a file, even when the writer is killed: the
// contents go to a temporary in the same folder, reach the disk (fsync), then replace the file by
// rename.
#pragma once

#include <filesystem>
#include <string>

namespace calibench {

// Throws IoError naming the file when the temporary cannot be written or renamed. The temporary
// is unnamed while it is written (Linux O_TMPFILE), so a process killed mid-write leaves nothing
// behind; it has a name (<file>.tmp.<pid>.<thread>.<n>) only for the instant between linking it
// and the rename, or throughout on filesystems without O_TMPFILE. Each successful write removes
// the temporaries that killed writers of the same file left (RemoveStaleTemporaries).
void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents);

// Removes the temporaries of `path` that processes no longer running left behind (killed in the
// instant above); those of live writers are kept. Returns how many it removed.
int RemoveStaleTemporaries(const std::filesystem::path& path);

}  // namespace calibench
