// Progress of a running command, for whoever runs the command in-process (the Python module's
// callback, python/module.cpp) besides the lines the command prints on stderr.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace calibench::app {

// phase: what is being done ("extracted", "reading", ...); done of total; item: the pair's id, or
// "" for progress by bytes. May be called from the pipeline's worker threads.
using ProgressListener = std::function<void(const std::string& phase, std::int64_t done,
                                            std::int64_t total, const std::string& item)>;

// The one listener of this process (empty: none). Set it before a command runs and clear it after;
// not for several commands at once.
void SetProgressListener(ProgressListener listener);
// Called by the commands' progress printers (StderrProgress, import's progress bar).
void NotifyProgress(const std::string& phase, std::int64_t done, std::int64_t total,
                    const std::string& item);

}  // namespace calibench::app
