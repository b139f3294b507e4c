// calibench: one executable, a table of subcommands (COLMAP style; app/command_table.cpp).
#include "app/command_table.h"
#include "core/base/allocator.h"

int main(int argc, char** argv) {
  calibench::KeepFreedMemoryForReuse();
  return calibench::app::RunCalibench(argc, argv);
}
