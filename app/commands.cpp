#include "app/commands.h"

#include <CLI/CLI.hpp>

namespace calibench::app {

std::optional<int> ParseFlags(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  }
  return std::nullopt;
}

}  // namespace calibench::app
