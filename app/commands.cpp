#include "app/commands.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <vector>

#include "core/base/atomic_file.h"

namespace calibench::app {

namespace {

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// "did you mean --threads?" for each unknown flag among the arguments left over.
void SuggestFlags(const CLI::App& app) {
  std::vector<std::string> flags;
  for (const CLI::Option* option : app.get_options())
    for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
  for (const std::string& extra : app.remaining()) {
    if (extra.rfind("-", 0) != 0) continue;
    const std::string flag = extra.substr(0, extra.find('='));
    const std::string closest = Closest(flag, flags);
    if (!closest.empty())
      std::fprintf(stderr, "calibench: unknown flag %s; did you mean %s?\n", flag.c_str(),
                   closest.c_str());
  }
}

}  // namespace

std::string Closest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_distance = std::max<size_t>(2, word.size() / 3) + 1;
  for (const std::string& candidate : candidates) {
    const size_t distance = EditDistance(word, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  return best;
}

std::optional<int> ParseFlags(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e) == 0 ? kOk : kUsage;
    if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr) SuggestFlags(app);
    return code;
  }
  return std::nullopt;
}

CLI::Option* AddDatasetOption(CLI::App& app, std::string* path, const std::string& what) {
  return app.add_option("--dataset,-d", *path,
                        what +
                            ": its manifest under any name, or the folder holding it "
                            "(dataset.json, manifest.json, another *.json, or the folder form)");
}

CLI::Option* AddBoardOption(CLI::App& app, std::string* board, const std::string& what) {
  return app.add_option(
      "--board", *board,
      what +
          ": a3 | a4 | charuco-a3 | charuco-a4 | paper, or a target.json (default: "
          "the target.json beside the recording, else the preset that fits the "
          "images)");
}

int PrintAndWriteTable(const std::string& table, const std::string& path, const char* command) {
  std::printf("%s", table.c_str());
  if (path.empty()) return kOk;
  try {
    WriteFileAtomically(path, table);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: cannot write the table to %s: %s\n", command, path.c_str(), e.what());
    return kInputError;
  }
  return kOk;
}

}  // namespace calibench::app
