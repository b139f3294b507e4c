// Notes for the user that are not errors: a file read the way its format's own tool reads it
// though it is not quite what the format says (a PCD with bytes after its point data, as PCL
// reads it). Each kind is said once per process on stderr (never stdout: `--json` output stays
// the documented JSON), naming its first case; later cases of the kind are counted, not said.
#pragma once

#include <string>
#include <string_view>

namespace calibench {

// Says "note: <text>" on stderr the first time `kind` is noted in this process (thread-safe).
void NoteOnce(std::string_view kind, const std::string& text);
// How many times `kind` was noted so far (tests; a summary's "and N more").
int NotedCount(std::string_view kind);

}  // namespace calibench
