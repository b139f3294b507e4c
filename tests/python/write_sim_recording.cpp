// Writes a small simulated capture as a recording (tests/sim_recording.h: the board held still
// at each pose, a VLP-16 and a camera streaming), for the Python tests of import:
//   write_sim_recording OUT.{mcap,bag} POSES
#include <cstdio>
#include <filesystem>
#include <string>

#include "tests/bag_writers.h"
#include "tests/sim_recording.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: write_sim_recording OUT.{mcap,bag} POSES\n");
    return 1;
  }
  const std::filesystem::path path = argv[1];
  const bool bag = path.extension() == ".bag";
  auto writer = bag ? calibench::test::OpenRos1BagWriter(path, "lz4")
                    : calibench::test::OpenMcapWriter(path, "ros2", "zstd");
  calibench::test::WriteSimRecording(
      writer.get(), bag ? calibench::MessageEncoding::kRos1 : calibench::MessageEncoding::kCdr,
      calibench::test::SmallSimRecording(std::stoi(argv[2])));
  writer->Close();
  std::printf("wrote %s\n", path.c_str());
  return 0;
}
