// The block (indentation) half of the YAML subset reader; flow collections and quoted scalars
// are in yaml_lite_flow.cpp.
#include "core/io/yaml_lite.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/io/yaml_lite_internal.h"

namespace calibench {
namespace {

using yaml_lite_internal::FlowClosed;
using yaml_lite_internal::kMaxDepth;
using yaml_lite_internal::ParseError;
using yaml_lite_internal::ParseFlow;
using yaml_lite_internal::QuoteCanStart;
using yaml_lite_internal::ReadQuoted;
using yaml_lite_internal::Scalar;
using yaml_lite_internal::SkipQuoted;
using yaml_lite_internal::StepInsideQuote;
using yaml_lite_internal::Trim;

struct Line {
  int indent = 0;    // leading spaces
  std::string text;  // without indentation, comment and trailing spaces
  int number = 0;    // 1-based
};

bool StartsSequenceItem(const std::string& text) {
  return text == "-" || (text.size() > 1 && text[0] == '-' && text[1] == ' ');
}

// The content of raw[from..] without its comment; `quote` carries an open quote across lines.
std::string StripComment(const std::string& raw, size_t from, char* quote) {
  size_t i = from;
  while (i < raw.size()) {
    if (*quote) {
      if (!StepInsideQuote(raw, &i, *quote)) *quote = 0;
      continue;
    }
    const char c = raw[i];
    if (c == '#' && (i == from || raw[i - 1] == ' ' || raw[i - 1] == '\t')) break;
    if ((c == '"' || c == '\'') && QuoteCanStart(raw, from, i)) *quote = c;
    ++i;
  }
  const std::string body = raw.substr(from, std::min(i, raw.size()) - from);
  return body.substr(0, body.find_last_not_of(" \t") + 1);
}

std::vector<Line> SplitLines(const std::string& text) {
  if (text.find('\0') != std::string::npos) throw ParseError(1, "binary data, not text");
  std::vector<Line> lines;
  char quote = 0;
  int number = 0;
  for (size_t start = 0; start <= text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string raw = text.substr(start, end - start);
    start = end + 1;
    ++number;
    if (!raw.empty() && raw.back() == '\r') raw.pop_back();
    const bool continues_quote = quote != 0;
    size_t indent = 0;
    while (indent < raw.size() && raw[indent] == ' ') ++indent;
    const std::string body = StripComment(raw, indent, &quote);
    if (body.empty()) continue;
    if (!continues_quote && body[0] == '\t') throw ParseError(number, "tab used for indentation");
    if (!continues_quote && indent == 0) {
      if (body[0] == '%' && lines.empty()) continue;  // directive (%YAML, %TAG)
      if (body == "...") break;
      if (body == "---" || body.rfind("--- ", 0) == 0) {
        if (!lines.empty()) break;  // a second document: only the first is read
        const std::string rest = Trim(body.substr(3));
        if (rest.empty() || rest[0] == '!') continue;
        lines.push_back({4, rest, number});
        continue;
      }
    }
    lines.push_back({static_cast<int>(indent), body, number});
  }
  return lines;
}

// Drops tags (!!opencv-matrix) and anchors (&a) in front of a value.
std::string StripProperties(std::string text, int line) {
  while (!text.empty() && (text[0] == '!' || text[0] == '&')) {
    const size_t space = text.find(' ');
    text = space == std::string::npos ? "" : Trim(text.substr(space));
  }
  if (!text.empty() && text[0] == '*') throw ParseError(line, "aliases (*name) are not supported");
  return text;
}

// Splits "key: value" / "key:" (key plain or quoted). False when the text is not a map entry.
bool SplitKey(const std::string& text, int line, std::string* key, std::string* rest) {
  if (text.empty() || text[0] == '[' || text[0] == '{') return false;
  if (text[0] == '?') throw ParseError(line, "complex keys (? ...) are not supported");
  size_t colon = 0;
  if (text[0] == '"' || text[0] == '\'') {
    size_t pos = 0;
    *key = ReadQuoted(text, &pos, line);
    while (pos < text.size() && text[pos] == ' ') ++pos;
    if (pos >= text.size() || text[pos] != ':') return false;
    colon = pos;
  } else {
    colon = text.find(": ");
    if (colon == std::string::npos) {
      if (text.back() != ':') return false;
      colon = text.size() - 1;
    }
    *key = Trim(text.substr(0, colon));
    if (key->empty()) return false;
  }
  if (colon + 1 < text.size() && text[colon + 1] != ' ') return false;
  *rest = Trim(text.substr(colon + 1));
  return true;
}

// Block structure by indentation over the pre-split lines.
class BlockParser {
 public:
  explicit BlockParser(std::vector<Line> lines) : lines_(std::move(lines)) {}

  YamlNode Document() {
    if (lines_.empty()) return YamlNode{};
    YamlNode root = Node(0, 0);
    if (pos_ < lines_.size()) throw ParseError(lines_[pos_].number, "unexpected indentation");
    return root;
  }

 private:
  Line* Current() { return pos_ < lines_.size() ? &lines_[pos_] : nullptr; }

  // The block node starting at the current line, which must be indented at least min_indent.
  YamlNode Node(int min_indent, int depth) {
    if (depth > kMaxDepth) throw ParseError(lines_[pos_].number, "nesting too deep");
    const Line& line = lines_[pos_];
    if (StartsSequenceItem(line.text)) return Sequence(line.indent, depth);
    std::string key, rest;
    if (SplitKey(line.text, line.number, &key, &rest)) return Map(line.indent, depth);
    ++pos_;
    return Value(line.text, min_indent - 1, line.number, false, depth);
  }

  YamlNode Map(int indent, int depth) {
    YamlNode map;
    map.kind = YamlNode::Kind::kMap;
    map.line = lines_[pos_].number;
    while (const Line* line = Current()) {
      if (line->indent < indent) break;
      if (line->indent > indent) throw ParseError(line->number, "unexpected indentation");
      std::string key, rest;
      if (StartsSequenceItem(line->text) || !SplitKey(line->text, line->number, &key, &rest)) {
        throw ParseError(line->number, "expected 'key: value'");
      }
      for (const auto& entry : map.entries) {
        if (entry.first == key) throw ParseError(line->number, "duplicate key '" + key + "'");
      }
      const int number = line->number;
      ++pos_;
      map.entries.emplace_back(key, Value(rest, indent, number, true, depth + 1));
    }
    return map;
  }

  YamlNode Sequence(int indent, int depth) {
    YamlNode sequence;
    sequence.kind = YamlNode::Kind::kSequence;
    sequence.line = lines_[pos_].number;
    while (Line* line = Current()) {
      if (line->indent < indent || !StartsSequenceItem(line->text)) break;
      if (line->indent > indent) throw ParseError(line->number, "unexpected indentation");
      size_t offset = 1;
      while (offset < line->text.size() && line->text[offset] == ' ') ++offset;
      const std::string rest = line->text.substr(offset);
      std::string key, value;
      if (StartsSequenceItem(rest) || SplitKey(rest, line->number, &key, &value)) {
        // "- key: value" or "- - x": the rest is a block node at the column where it starts.
        line->indent += static_cast<int>(offset);
        line->text = rest;
        sequence.items.push_back(Node(line->indent, depth + 1));
      } else {
        const int number = line->number;
        ++pos_;
        sequence.items.push_back(Value(rest, indent, number, false, depth + 1));
      }
    }
    return sequence;
  }

  // The value after "key:" or "- " on a line owned by a node at `owner` indentation; following
  // lines indented deeper belong to it (and, for a map value, a sequence at the key's indent).
  YamlNode Value(const std::string& rest, int owner, int number, bool map_value, int depth) {
    const std::string text = StripProperties(rest, number);
    if (text.empty()) {
      const Line* next = Current();
      if (next && next->indent > owner) return Node(owner + 1, depth);
      if (next && map_value && next->indent == owner && StartsSequenceItem(next->text)) {
        return Sequence(owner, depth);
      }
      return Scalar("~", false, number);
    }
    if (text[0] == '[' || text[0] == '{') {
      const std::string joined = JoinUntil(text, owner, number, FlowClosed, "unclosed bracket");
      return ParseFlow(joined, number, depth);
    }
    if (text[0] == '"' || text[0] == '\'') return Quoted(text, owner, number);
    if (text[0] == '|' || text[0] == '>') return BlockScalar(text, owner, number);
    return Plain(text, owner, number);
  }

  YamlNode Quoted(const std::string& text, int owner, int number) {
    const auto closed = [](const std::string& s) {
      size_t i = 0;
      return SkipQuoted(s, &i);
    };
    const std::string joined = JoinUntil(text, owner, number, closed, "unclosed quote");
    size_t pos = 0;
    const std::string value = ReadQuoted(joined, &pos, number);
    if (!Trim(joined.substr(pos)).empty()) {
      throw ParseError(number, "unexpected text after a quoted scalar");
    }
    return Scalar(value, true, number);
  }

  // A plain scalar, possibly continued on deeper lines (joined by spaces).
  YamlNode Plain(const std::string& text, int owner, int number) {
    std::string value = text;
    while (const Line* next = Current()) {
      if (next->indent <= owner) break;
      std::string key, ignored;
      if (StartsSequenceItem(next->text) || SplitKey(next->text, next->number, &key, &ignored)) {
        throw ParseError(next->number, "unexpected indentation");
      }
      value += ' ' + next->text;
      ++pos_;
    }
    return Scalar(value, false, number);
  }

  // Appends deeper lines (joined by spaces) until `done` holds.
  template <typename Done>
  std::string JoinUntil(std::string text, int owner, int number, Done done, const char* problem) {
    while (!done(text)) {
      const Line* next = Current();
      if (!next || next->indent <= owner) throw ParseError(number, problem);
      text += ' ' + next->text;
      ++pos_;
    }
    return text;
  }

  // | keeps line breaks, > folds them into spaces; a '-' in the header drops the final break.
  YamlNode BlockScalar(const std::string& header, int owner, int number) {
    std::string value;
    int block_indent = -1;
    while (const Line* next = Current()) {
      if (next->indent <= owner) break;
      if (block_indent < 0) block_indent = next->indent;
      if (!value.empty()) value += header[0] == '|' ? '\n' : ' ';
      value += std::string(std::max(0, next->indent - block_indent), ' ') + next->text;
      ++pos_;
    }
    if (header.find('-') == std::string::npos && !value.empty()) value += '\n';
    return Scalar(value, true, number);
  }

  std::vector<Line> lines_;
  size_t pos_ = 0;
};

}  // namespace

const YamlNode* YamlNode::Find(const std::string& key) const {
  if (kind != Kind::kMap) return nullptr;
  for (const auto& entry : entries) {
    if (entry.first == key) return &entry.second;
  }
  return nullptr;
}

std::optional<double> YamlNode::AsDouble() const {
  if (kind != Kind::kScalar || scalar.empty()) return std::nullopt;
  const bool negative = scalar[0] == '-';
  const std::string body = scalar[0] == '-' || scalar[0] == '+' ? scalar.substr(1) : scalar;
  if (body.empty() || body[0] == '-' || body[0] == '+') return std::nullopt;
  double value = 0;
  if (body == ".inf" || body == ".Inf" || body == ".INF") {
    value = std::numeric_limits<double>::infinity();
  } else if (body == ".nan" || body == ".NaN" || body == ".NAN") {
    value = std::numeric_limits<double>::quiet_NaN();
  } else {
    const char* end = body.data() + body.size();
    const auto [ptr, error] = std::from_chars(body.data(), end, value);
    if (error != std::errc() || ptr != end) return std::nullopt;
  }
  return negative ? -value : value;
}

std::optional<YamlNode> ParseYamlLite(const std::string& text, std::string* why) {
  try {
    return BlockParser(SplitLines(text)).Document();
  } catch (const ParseError& e) {
    if (why) *why = e.what();
    return std::nullopt;
  }
}

}  // namespace calibench
