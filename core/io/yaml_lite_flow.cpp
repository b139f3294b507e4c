// The lexical half of the YAML subset reader: quotes, scalars and flow collections.
#include <string>

#include "core/io/yaml_lite_internal.h"

namespace calibench::yaml_lite_internal {

std::string Trim(const std::string& s) {
  const size_t first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

bool QuoteCanStart(const std::string& s, size_t from, size_t i) {
  while (i > from && s[i - 1] == ' ') --i;
  if (i == from) return true;
  const char c = s[i - 1];
  return c == ':' || c == '-' || c == '[' || c == '{' || c == ',' || c == '?';
}

bool StepInsideQuote(const std::string& s, size_t* i, char quote) {
  const char c = s[*i];
  if (quote == '"' && c == '\\') {
    *i += 2;
    return true;
  }
  if (c != quote) {
    ++*i;
    return true;
  }
  if (quote == '\'' && *i + 1 < s.size() && s[*i + 1] == '\'') {
    *i += 2;
    return true;
  }
  ++*i;
  return false;
}

bool SkipQuoted(const std::string& s, size_t* i) {
  const char quote = s[(*i)++];
  while (*i < s.size()) {
    if (!StepInsideQuote(s, i, quote)) return true;
  }
  return false;
}

bool FlowClosed(const std::string& s) {
  int depth = 0;
  size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if ((c == '"' || c == '\'') && QuoteCanStart(s, 0, i)) {
      if (!SkipQuoted(s, &i)) return false;
      continue;
    }
    if (c == '[' || c == '{') ++depth;
    if ((c == ']' || c == '}') && --depth <= 0) return true;
    ++i;
  }
  return false;
}

std::string ReadQuoted(const std::string& s, size_t* pos, int line) {
  const char quote = s[(*pos)++];
  std::string out;
  while (*pos < s.size()) {
    const char c = s[(*pos)++];
    if (c == quote) {
      if (quote == '\'' && *pos < s.size() && s[*pos] == '\'') {
        out += '\'';
        ++*pos;
        continue;
      }
      return out;
    }
    if (quote == '"' && c == '\\' && *pos < s.size()) {
      const char e = s[(*pos)++];
      switch (e) {
        case 'n':
          out += '\n';
          break;
        case 't':
          out += '\t';
          break;
        case 'r':
          out += '\r';
          break;
        case '0':
          out += '\0';
          break;
        default:
          out += e;  // \\ \" \/ and anything else stand for themselves
      }
      continue;
    }
    out += c;
  }
  throw ParseError(line, "unclosed quote");
}

YamlNode Scalar(const std::string& text, bool quoted, int line) {
  YamlNode node;
  node.line = line;
  if (!quoted && (text == "~" || text == "null" || text == "Null" || text == "NULL")) return node;
  node.kind = YamlNode::Kind::kScalar;
  node.scalar = text;
  node.quoted = quoted;
  return node;
}

namespace {

// Flow collections: [a, b], {k: v}, nested, with quoted or plain scalars.
class FlowParser {
 public:
  FlowParser(const std::string& text, int line) : s_(text), line_(line) {}

  YamlNode Parse(int depth) {
    YamlNode node = Node(depth);
    SkipSpaces();
    if (pos_ < s_.size()) Fail("unexpected text after the closing bracket");
    return node;
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const { throw ParseError(line_, problem); }
  void SkipSpaces() {
    while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\t')) ++pos_;
  }
  bool Peek(char c) {
    SkipSpaces();
    return pos_ < s_.size() && s_[pos_] == c;
  }
  // Plain scalar up to a flow indicator, or up to ':' followed by a separator (a key).
  std::string Plain() {
    const size_t start = pos_;
    while (pos_ < s_.size()) {
      const char c = s_[pos_];
      if (c == ',' || c == '[' || c == ']' || c == '{' || c == '}') break;
      if (c == ':' &&
          (pos_ + 1 == s_.size() || std::string(" ,]}").find(s_[pos_ + 1]) != std::string::npos)) {
        break;
      }
      ++pos_;
    }
    return Trim(s_.substr(start, pos_ - start));
  }

  YamlNode Node(int depth) {
    if (depth > kMaxDepth) Fail("nesting deeper than " + std::to_string(kMaxDepth));
    SkipSpaces();
    if (pos_ < s_.size() && (s_[pos_] == '!' || s_[pos_] == '&')) {
      while (pos_ < s_.size() && s_[pos_] != ' ') ++pos_;
      SkipSpaces();
    }
    if (pos_ >= s_.size()) Fail("unclosed bracket");
    const char c = s_[pos_];
    if (c == '[') return Sequence(depth);
    if (c == '{') return Map(depth);
    if (c == '"' || c == '\'') return Scalar(ReadQuoted(s_, &pos_, line_), true, line_);
    if (c == '*') Fail("aliases (*name) are not supported");
    const std::string text = Plain();
    if (text.empty()) Fail(std::string("unexpected '") + c + "'");
    return Scalar(text, false, line_);
  }

  YamlNode Sequence(int depth) {
    YamlNode node;
    node.kind = YamlNode::Kind::kSequence;
    node.line = line_;
    ++pos_;
    while (!Peek(']')) {
      node.items.push_back(Node(depth + 1));
      if (Peek(',')) {
        ++pos_;
      } else if (!Peek(']')) {
        Fail("expected ',' or ']'");
      }
    }
    ++pos_;
    return node;
  }

  YamlNode Map(int depth) {
    YamlNode node;
    node.kind = YamlNode::Kind::kMap;
    node.line = line_;
    ++pos_;
    while (!Peek('}')) {
      if (pos_ >= s_.size()) Fail("unclosed '{'");
      const std::string key =
          s_[pos_] == '"' || s_[pos_] == '\'' ? ReadQuoted(s_, &pos_, line_) : Plain();
      if (key.empty()) Fail("empty key in '{ }'");
      YamlNode value;
      value.line = line_;
      if (Peek(':')) {
        ++pos_;
        if (!Peek(',') && !Peek('}')) value = Node(depth + 1);
      }
      for (const auto& entry : node.entries) {
        if (entry.first == key) Fail("duplicate key '" + key + "'");
      }
      node.entries.emplace_back(key, std::move(value));
      if (Peek(',')) {
        ++pos_;
      } else if (!Peek('}')) {
        Fail("expected ',' or '}'");
      }
    }
    ++pos_;
    return node;
  }

  const std::string& s_;
  int line_;
  size_t pos_ = 0;
};

}  // namespace

YamlNode ParseFlow(const std::string& text, int line, int depth) {
  return FlowParser(text, line).Parse(depth);
}

}  // namespace calibench::yaml_lite_internal
