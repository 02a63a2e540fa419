#include "common/json_text.h"

#include <algorithm>
#include <optional>
#include <unordered_map>
#include <vector>

#include "common/message_text.h"

namespace treeanim {

namespace {

// An open array or object of the scan.
struct Container {
  bool object = false;
  std::string pointer;         // its JSON pointer
  size_t elements = 0;         // arrays: elements before the current one
  bool expecting_key = false;  // objects: the next string is a key
  std::string key;             // objects: the key of the current member
  std::unordered_map<std::string, size_t> key_lines;  // objects: key => line it first appeared on
};

struct Duplicate {
  size_t offset;       // of the repeated key
  std::string pointer;
  size_t first_line;
  size_t line;
};

// What the scan found: the first bracket past the depth limit, the first repeated key.
struct ScanResult {
  std::optional<size_t> too_deep;  // offset
  std::optional<Duplicate> duplicate;
};

// The key between the quotes at text[begin] and text[end - 1], escapes decoded, so that "a" and
// "\u0061" are one key.
std::string key_text(const std::string& text, size_t begin, size_t end) {
  const std::string quoted = text.substr(begin, end - begin);
  if (quoted.find('\\') == std::string::npos) return quoted.substr(1, quoted.size() - 2);
  try {
    return Json::parse(quoted).get<std::string>();
  } catch (const nlohmann::json::exception&) {
    return quoted;  // a bad escape: the parse reports it
  }
}

// One pass over the text with an explicit stack (no recursion). It trusts nothing: on text that
// is not JSON it stops or finds nothing, and the parse that follows names the syntax error.
ScanResult scan(const std::string& text, const std::string& at, int max_depth) {
  ScanResult result;
  std::vector<Container> open;
  size_t line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
    } else if (c == '"') {
      size_t end = i + 1;
      for (; end < text.size() && text[end] != '"'; ++end) {
        if (text[end] == '\\') ++end;
        else if (text[end] == '\n') ++line;
      }
      if (end >= text.size()) break;  // unterminated: a syntax error
      ++end;
      if (!open.empty() && open.back().expecting_key) {
        Container& object = open.back();
        object.key = key_text(text, i, end);
        object.expecting_key = false;
        const auto [first, inserted] = object.key_lines.try_emplace(object.key, line);
        if (!inserted && !result.duplicate)
          result.duplicate = Duplicate{i, object.pointer + "/" + escape_pointer_token(object.key), first->second, line};
      }
      i = end - 1;
    } else if (c == '[' || c == '{') {
      if (static_cast<int>(open.size()) >= max_depth) {
        result.too_deep = i;
        return result;
      }
      Container child;
      child.object = c == '{';
      child.expecting_key = child.object;
      if (open.empty()) child.pointer = at;
      else if (open.back().object) child.pointer = open.back().pointer + "/" + escape_pointer_token(open.back().key);
      else child.pointer = open.back().pointer + "/" + std::to_string(open.back().elements);
      open.push_back(std::move(child));
    } else if (c == ']' || c == '}') {
      if (!open.empty()) open.pop_back();
    } else if (c == ',' && !open.empty()) {
      if (open.back().object) open.back().expecting_key = true;
      else ++open.back().elements;
    }
  }
  return result;
}

}  // namespace

std::string line_column(const std::string& text, size_t offset) {
  const size_t end = std::min(offset, text.size());
  const size_t line = 1 + static_cast<size_t>(std::count(text.begin(), text.begin() + static_cast<long>(end), '\n'));
  const size_t line_start = text.rfind('\n', end == 0 ? 0 : end - 1);
  const size_t first = line_start == std::string::npos || end == 0 ? 0 : line_start + 1;
  const size_t column = 1 + static_cast<size_t>(std::count_if(text.begin() + static_cast<long>(first),
                                                              text.begin() + static_cast<long>(end),
                                                              [](char c) { return !continues_character(c); }));
  return std::to_string(line) + ":" + std::to_string(column);
}

Json parse_json_text(const std::string& text, const std::string& name, const std::string& at) {
  const int depth_used = static_cast<int>(std::count(at.begin(), at.end(), '/'));
  const ScanResult found = scan(text, at, kMaxJsonDepth - depth_used);
  if (found.too_deep)
    throw InputError(name + ":" + line_column(text, *found.too_deep) + ": JSON nested deeper than " +
                     std::to_string(kMaxJsonDepth) + " levels of arrays and objects" +
                     (depth_used > 0 ? " (counted from the scene's root; " + at + " takes " +
                                           std::to_string(depth_used) + " of them)"
                                     : std::string()) +
                     "; no scene needs more");
  // The parser takes a NUL byte for the end of the text and would ignore what follows it.
  if (const size_t nul = text.find('\0'); nul != std::string::npos)
    throw JsonSyntaxError(name + ":" + line_column(text, nul) + ": JSON syntax error: a NUL byte, which JSON text cannot hold");
  Json document;
  try {
    document = Json::parse(text, nullptr, true, /*ignore_comments=*/false);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is one past the offending character; what() repeats the position, so keep
    // only nlohmann's explanation after "parse error ...: ".
    std::string what = e.what();
    const size_t colon = what.find(": ", what.find("parse error"));
    if (colon != std::string::npos) what = what.substr(colon + 2);
    throw JsonSyntaxError(name + ":" + line_column(text, e.byte > 0 ? e.byte - 1 : 0) + ": JSON syntax error: " + what);
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond double range (1e400): nlohmann gives no offset, only the number's text
    // in quotes, so the place is where that text first occurs.
    const std::string what = e.what();
    const size_t open = what.find('\'');
    const size_t close = what.rfind('\'');
    const std::string number = open < close ? what.substr(open + 1, close - open - 1) : "";
    const size_t where = number.empty() ? std::string::npos : text.find(number);
    throw InputError(name + (where == std::string::npos ? "" : ":" + line_column(text, where)) +
                     ": JSON number out of range: " + (number.empty() ? what : number) +
                     " (expected a finite double)");
  }
  if (const auto& d = found.duplicate)
    throw InputError(name + ":" + line_column(text, d->offset) + ": " + d->pointer + ": duplicate key (first at line " +
                     std::to_string(d->first_line) + ", again at line " + std::to_string(d->line) +
                     "); keep one of them");
  return document;
}

bool pointer_within(const std::string& pointer, const std::string& target) {
  return pointer == target || (pointer.starts_with(target) && pointer[target.size()] == '/');
}

std::string escape_pointer_token(const std::string& token) {
  std::string out;
  for (char c : token) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

}  // namespace treeanim
