#include "ui/state/session_opening.h"

#include <system_error>

#include "core/session/session.h"

namespace calibench::ui {

OpenedSessionFile OpenSessionFileBeside(
    const std::filesystem::path& path, ExistingSession existing,
    const std::optional<FileLock>& held,
    const std::function<void(const std::filesystem::path&)>& load) {
  OpenedSessionFile opened;
  if (existing == ExistingSession::kInMemory) return opened;
  opened.path = path;
  opened.lock = LockSessionFile(path, held, &opened.note);  // throws when another has it open
  std::error_code error;
  if (existing == ExistingSession::kReplace || !std::filesystem::exists(path, error)) return opened;
  std::string resume_note;
  opened.resumed =
      !ResumeSessionBeside(path, existing == ExistingSession::kStartFresh, load, &resume_note)
           .empty();
  opened.note += (opened.note.empty() ? "" : "; ") + resume_note;
  return opened;
}

}  // namespace calibench::ui
