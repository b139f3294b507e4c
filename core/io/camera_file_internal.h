// LoadCameraFile's text layer (camera_file_text.cpp): reading a camera file safely and parsing
// it into one YAML::Node tree, whatever its syntax (YAML, OpenCV's %YAML:1.0, OpenCV XML). The
// interpretation of the tree (which format, which keys) is camera_file.cpp's.
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace calibench::camera_file {

// A problem with the file's content; LoadCameraFile adds the file name.
class Problem : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline std::string Quote(const std::string& s) { return "'" + s + "'"; }

// The file's text: at most 16 MiB, no binary data. Throws Problem.
std::string ReadText(const std::filesystem::path& path);
// Refuses YAML nested deeper than the parsers may recurse, and quoted text left open at the end.
void CheckYamlText(std::string_view text);
// Refuses XML whose elements nest deeper than that.
void CheckXmlNesting(std::string_view text);
YAML::Node ParseYaml(const std::string& text);
// An OpenCV FileStorage XML file as the YAML tree of the same file.
YAML::Node ReadOpenCvXml(const std::string& text);

}  // namespace calibench::camera_file
