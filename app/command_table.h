// The calibench command line as a function: the executable's main and the Python module
// (python/module.cpp) run the same table of subcommands with the same error handling.
#pragma once

#include <string>
#include <vector>

namespace calibench::app {

// argv[0] is the program's name, argv[1] the command ("calibrate", "--help", "--version", ...).
// Returns the exit code (commands.h ExitCode); errors that escape a command are printed on stderr
// as "calibench <command>: error: ..." and give kInputError.
int RunCalibench(int argc, char** argv);

// The commands' names, in the order `calibench --help` lists them (bash completion, man page).
std::vector<std::string> CommandNames();

}  // namespace calibench::app
