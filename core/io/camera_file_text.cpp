// LoadCameraFile's text layer (camera_file_internal.h): the file read with its size and content
// checked, its nesting measured before a recursive parser meets it, and YAML or OpenCV XML
// parsed into one YAML::Node tree.
#include <tinyxml2.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/io/camera_file_internal.h"

namespace calibench::camera_file {
namespace {

// Camera files are a few kilobytes; anything far larger is not one.
constexpr std::uintmax_t kMaxFileBytes = 16 << 20;
// Camera files nest four levels; deeper text is refused before a recursive parser sees it.
constexpr int kMaxNesting = 64;

Problem TooDeep(int line) {
  return Problem("nested deeper than " + std::to_string(kMaxNesting) + " levels (line " +
                 std::to_string(line) + "); not a camera file");
}

// An upper bound on the nesting of YAML text, measured line by line without parsing: block
// collections by indentation (plus "- ", "? " and ": " indicators, and sequences written at
// their key's indentation), flow collections by unclosed brackets. Quoted text, comments and
// block scalars (| and >) are skipped. Throws at the first line nested deeper than kMaxNesting.
class YamlNesting {
 public:
  // The line of a quote still open at the end of the text; 0 when none is.
  int OpenQuoteLine() const { return quote_ ? quote_line_ : 0; }

  void Line(std::string_view line, int number) {
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (quote_ || flow_ > 0) {
      Scan(line, 0, flow_base_, number);  // a flow collection or quoted text going on
      return;
    }
    const size_t indent = line.find_first_not_of(' ');
    if (indent == std::string_view::npos || line[indent] == '#') return;
    if (block_scalar_owner_ >= 0 && static_cast<int>(indent) > block_scalar_owner_) return;
    block_scalar_owner_ = -1;
    if (indent == 0 && line[0] == '%') return;  // a directive
    if (indent == 0 && (line.starts_with("---") || line.starts_with("...")) &&
        (line.size() == 3 || line[3] == ' ')) {
      levels_.clear();  // a document marker; what follows it is at column 4
      Line(std::string(3, ' ') + std::string(line.substr(3)), number);
      return;
    }
    const Block block = EnterBlock(line, indent);
    const size_t end = Scan(line, block.content, block.depth, number);
    if (!quote_ && flow_ == 0) NoteBlockScalar(line, block, end);
  }

 private:
  struct Level {
    int indent = 0;
    int base = 0;          // the depth this line's collections nest in
    int depth = 0;         // the depth of its innermost collection
    int sibling_base = 0;  // the base of map keys that follow at this indentation
    bool dash = false;     // a sequence entry
  };
  struct Block {
    int depth = 0;
    size_t content = 0;  // where the text after the indicators starts
    int owner = 0;       // the column a block scalar starting here must be indented beyond
  };

  Block EnterBlock(std::string_view line, size_t indent) {
    Block block{0, indent, static_cast<int>(indent)};
    int indicators = 0;
    while (block.content < line.size() &&
           std::string_view("-?:").find(line[block.content]) != std::string_view::npos &&
           (block.content + 1 == line.size() || line[block.content + 1] == ' ')) {
      ++indicators;
      block.owner = static_cast<int>(block.content);
      block.content = std::min(line.size(), line.find_first_not_of(' ', block.content + 1));
    }
    while (!levels_.empty() && levels_.back().indent > static_cast<int>(indent)) levels_.pop_back();
    std::optional<Level> sibling;
    if (!levels_.empty() && levels_.back().indent == static_cast<int>(indent)) {
      sibling = levels_.back();
      levels_.pop_back();
    }
    Level level{static_cast<int>(indent), 0, 0, 0, indicators > 0 && line[indent] == '-'};
    level.sibling_base = sibling           ? sibling->sibling_base
                         : levels_.empty() ? 0
                                           : levels_.back().depth;
    level.base = level.sibling_base;
    // "key:" then "- item" at the same indentation: the sequence is the key's value.
    if (sibling && level.dash) level.base = sibling->dash ? sibling->base : sibling->depth;
    level.depth = level.base + 1 + indicators;
    levels_.push_back(level);
    block.depth = level.depth;
    return block;
  }

  // Follows quotes and brackets from line[from]; returns where the content ends (a comment).
  size_t Scan(std::string_view line, size_t from, int depth, int number) {
    if (depth > kMaxNesting) throw TooDeep(number);
    char previous = 0;  // the last character outside quotes that was not a space
    for (size_t i = from; i < line.size(); ++i) {
      const char c = line[i];
      if (quote_) {
        if (quote_ == '"' && c == '\\') {
          ++i;
        } else if (quote_ == '\'' && c == '\'' && i + 1 < line.size() && line[i + 1] == '\'') {
          ++i;  // '' is a quote inside single quotes
        } else if (c == quote_) {
          quote_ = 0;
          previous = c;
        }
        continue;
      }
      if (c == '#' && (i == from || line[i - 1] == ' ' || line[i - 1] == '\t')) return i;
      // A quote opens a scalar only where one can start: first on the line (after "- "), after
      // ": ", or after [ { , : in a flow collection; the apostrophe in "don't" is text.
      const bool scalar_start =
          !previous || (previous == ':' && line[i - 1] == ' ') ||
          (flow_ > 0 && std::string_view(":[{,").find(previous) != std::string_view::npos);
      if ((c == '"' || c == '\'') && scalar_start) {
        quote_ = c;
        quote_line_ = number;
      } else if (c == '[' || c == '{') {
        if (depth + ++flow_ > kMaxNesting) throw TooDeep(number);
      } else if ((c == ']' || c == '}') && flow_ > 0) {
        --flow_;
      }
      if (c != ' ' && c != '\t') previous = c;
    }
    flow_base_ = depth;
    return line.size();
  }

  // After "key: |" or "- >-", the more indented lines are text.
  void NoteBlockScalar(std::string_view line, const Block& block, size_t end) {
    const std::string_view content = line.substr(0, line.find_last_not_of(" \t", end - 1) + 1);
    const size_t space = content.find_last_of(' ');
    const size_t start = space == std::string_view::npos ? 0 : space + 1;
    if (start < block.content || start >= content.size()) return;
    if (content[start] != '|' && content[start] != '>') return;
    if (content.find_first_not_of("+-0123456789", start + 1) != std::string_view::npos) return;
    block_scalar_owner_ = start == block.content ? block.owner : static_cast<int>(block.content);
  }

  std::vector<Level> levels_;
  int flow_ = 0;        // unclosed [ and {
  char quote_ = 0;      // the open quote, across lines
  int quote_line_ = 0;  // where it opened
  int flow_base_ = 0;   // the block depth the open flow collection or quote is in
  int block_scalar_owner_ = -1;
};

}  // namespace

// Refuses YAML nested deeper than kMaxNesting, and quoted text left open at the end of the file
// (which yaml-cpp 0.7 takes as running to the end when the file ends in a line break).
void CheckYamlText(std::string_view text) {
  YamlNesting nesting;
  int number = 0;
  for (size_t start = 0; start <= text.size();) {
    const size_t end = std::min(text.size(), text.find('\n', start));
    nesting.Line(text.substr(start, end - start), ++number);
    start = end + 1;
  }
  if (const int line = nesting.OpenQuoteLine()) {
    throw Problem("not valid YAML: line " + std::to_string(line) + ": the quote is never closed");
  }
}

namespace {

// Where the markup starting at text[i] ('<') ends: its '>' (quotes respected), or the end of a
// comment or CDATA section; npos when it does not end.
size_t MarkupEnd(std::string_view text, size_t i) {
  if (text.substr(i).starts_with("<!--")) return text.find("-->", i);
  if (text.substr(i).starts_with("<![CDATA[")) return text.find("]]>", i);
  char quote = 0;
  for (size_t end = i + 1; end < text.size(); ++end) {
    const char c = text[end];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '>') {
      return end;
    }
  }
  return std::string_view::npos;
}

}  // namespace

// Element nesting of XML text, measured before the parser (which recurses) meets it.
void CheckXmlNesting(std::string_view text) {
  int depth = 0;
  for (size_t i = text.find('<'); i != std::string_view::npos; i = text.find('<', i + 1)) {
    const size_t end = MarkupEnd(text, i);
    if (end == std::string_view::npos) return;  // unclosed: the parser will say so
    const char kind = text[i + 1];
    if (kind == '/') {
      depth = std::max(0, depth - 1);
    } else if (kind != '?' && kind != '!' && text[end - 1] != '/' && ++depth > kMaxNesting) {
      throw TooDeep(1 + static_cast<int>(std::count(text.begin(), text.begin() + i, '\n')));
    }
    i = end;
  }
}

YAML::Node ParseYaml(const std::string& text) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    if (e.mark.is_null()) throw Problem("not valid YAML: " + e.msg);
    throw Problem("not valid YAML: line " + std::to_string(e.mark.line + 1) + ", column " +
                  std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

namespace {

// One token of an OpenCV XML value: numbers in their shortest exact text (as the YAML files give
// them), strings without OpenCV's quotes.
YAML::Node XmlToken(std::string_view token) {
  if (token.size() >= 2 && token.front() == '"' && token.back() == '"')
    return YAML::Node(std::string(token.substr(1, token.size() - 2)));
  double value = 0.0;
  const auto parsed = std::from_chars(token.data(), token.data() + token.size(), value);
  if (parsed.ec == std::errc() && parsed.ptr == token.data() + token.size()) {
    char buffer[64];
    const auto written = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return YAML::Node(std::string(buffer, written.ptr));
  }
  return YAML::Node(std::string(token));
}

// An element of OpenCV's XML storage format as the YAML tree of the same file: child elements
// named "_" are a list, other children a map (a repeated name kept visible); text is one value,
// or a list when it holds several (matrix data, which is always a list).
YAML::Node FromXmlElement(const tinyxml2::XMLElement& element) {
  const tinyxml2::XMLElement* child = element.FirstChildElement();
  if (child != nullptr) {
    const bool list = std::string_view(child->Name()) == "_";
    YAML::Node out(list ? YAML::NodeType::Sequence : YAML::NodeType::Map);
    for (; child != nullptr; child = child->NextSiblingElement()) {
      if (list)
        out.push_back(FromXmlElement(*child));
      else
        out.force_insert(std::string(child->Name()), FromXmlElement(*child));
    }
    return out;
  }
  const char* text = element.GetText();
  std::vector<std::string_view> tokens;
  for (std::string_view rest = text ? text : ""; !rest.empty();) {
    const size_t start = rest.find_first_not_of(" \t\r\n");
    if (start == std::string_view::npos) break;
    const size_t end = std::min(rest.size(), rest.find_first_of(" \t\r\n", start));
    tokens.push_back(rest.substr(start, end - start));
    rest = rest.substr(end);
  }
  if (tokens.size() == 1 && std::string_view(element.Name()) != "data") return XmlToken(tokens[0]);
  YAML::Node out(YAML::NodeType::Sequence);
  for (const std::string_view token : tokens) out.push_back(XmlToken(token));
  return out;
}

}  // namespace

// An OpenCV FileStorage XML file (<opencv_storage> ...), read with tinyxml2. Not with
// cv::FileStorage: OpenCV 4.6's XML parser dereferences null on malformed text (found by
// fuzzing: "<?xml ver4=" crashes it).
YAML::Node ReadOpenCvXml(const std::string& text) {
  tinyxml2::XMLDocument document;
  if (document.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    throw Problem("not valid XML: line " + std::to_string(document.ErrorLineNum()) + ": " +
                  document.ErrorName());
  }
  const tinyxml2::XMLElement* root = document.RootElement();
  if (root == nullptr || std::string_view(root->Name()) != "opencv_storage")
    throw Problem("an XML camera file must be OpenCV FileStorage (<opencv_storage>)");
  YAML::Node tree = FromXmlElement(*root);
  if (!tree.IsMap() && !(tree.IsSequence() && tree.size() == 0))
    throw Problem("<opencv_storage> holds no named fields");
  return tree.IsMap() ? tree : YAML::Node(YAML::NodeType::Map);
}

std::string ReadText(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw Problem("no such file");
  if (!std::filesystem::is_regular_file(path, error)) throw Problem("not a regular file");
  if (std::filesystem::file_size(path, error) > kMaxFileBytes) {
    throw Problem("larger than 16 MiB, not a camera file");
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw Problem("cannot be read");
  // YAML and XML allow no control characters but tab and line breaks.
  const auto binary = std::find_if(text.view().begin(), text.view().end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return (byte < 0x20 && c != '\t' && c != '\n' && c != '\r') || byte == 0x7f;
  });
  if (binary != text.view().end()) throw Problem("binary data, not a text file");
  return text.str();
}

}  // namespace calibench::camera_file
