// A reader for the small YAML subset that camera files use (ROS camera_info, Kalibr camchain),
// which cv::FileStorage rejects (it wants an OpenCV "%YAML:1.0" header).
//
// Supported: block maps and sequences nested by indentation (including "- key: value" items and
// sequences written at their key's indentation), flow sequences and maps ([..], {..}, across
// lines), plain, single- and double-quoted scalars (across lines), literal/folded block scalars
// (| and >; inside them " #" still starts a comment and blank lines are dropped), comments,
// directives (%...), document markers (--- and ...), tags (!!...) and anchors (&...), which are
// ignored. Not supported: aliases (*...), complex keys (? ...), several documents (reading stops at
// the second ---), tabs in indentation.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace calibench {

struct YamlNode {
  enum class Kind { kNull, kScalar, kSequence, kMap };

  Kind kind = Kind::kNull;
  std::string scalar;           // kScalar: the text, quotes removed and escapes resolved
  bool quoted = false;          // kScalar written in quotes
  std::vector<YamlNode> items;  // kSequence
  std::vector<std::pair<std::string, YamlNode>> entries;  // kMap, in file order, unique keys
  int line = 0;  // 1-based line where the node starts; 0 when not from a text

  // The value stored under `key` in a map; nullptr when absent or when this is not a map.
  const YamlNode* Find(const std::string& key) const;
  // A scalar read as a number: decimal or exponent notation, an optional sign, .inf / .nan.
  // nullopt for anything else (including "1.0abc" and empty text).
  std::optional<double> AsDouble() const;
};

// Parses a whole text. nullopt, with the problem and its line in *why, for text outside the
// subset above (bad indentation, unbalanced brackets or quotes, duplicate keys, binary data).
// An empty document gives a kNull node.
std::optional<YamlNode> ParseYamlLite(const std::string& text, std::string* why);

}  // namespace calibench
