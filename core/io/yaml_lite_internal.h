// Internals of the YAML subset reader (core/yaml_lite.h) shared by its two source files: the
// lexical helpers for quotes and scalars, and the flow-collection parser.
#pragma once

#include <stdexcept>
#include <string>

#include "core/io/yaml_lite.h"

namespace calibench::yaml_lite_internal {

// Deeper nesting than this is not a camera file; the limit keeps recursion bounded on garbage.
constexpr int kMaxDepth = 64;

// A problem at a 1-based line; ParseYamlLite turns it into its `why`.
class ParseError : public std::runtime_error {
 public:
  ParseError(int line, const std::string& problem)
      : std::runtime_error("line " + std::to_string(line) + ": " + problem) {}
};

std::string Trim(const std::string& s);

// A quote opens a scalar only where a scalar can start: at the beginning, or after one of the
// indicators ": - [ { , ?" (so the apostrophe in "don't" is text).
bool QuoteCanStart(const std::string& s, size_t from, size_t i);

// Advances past one character of quoted text starting at s[*i] (inside `quote`); returns false
// at the closing quote. Handles \" in double quotes and '' in single quotes.
bool StepInsideQuote(const std::string& s, size_t* i, char quote);

// s[*i] is an opening quote; moves *i past the closing quote. False if the text ends first.
bool SkipQuoted(const std::string& s, size_t* i);

// Reads a quoted scalar starting at s[*pos] (the quote); *pos ends after the closing quote.
std::string ReadQuoted(const std::string& s, size_t* pos, int line);

// A scalar node; plain ~ / null are YAML's null.
YamlNode Scalar(const std::string& text, bool quoted, int line);

// Whether a flow text, starting at its opening bracket, has closed it (quotes respected).
bool FlowClosed(const std::string& s);

// Parses one flow collection ([..] or {..}) that makes up all of `text` (from `line`).
YamlNode ParseFlow(const std::string& text, int line, int depth);

}  // namespace calibench::yaml_lite_internal
