#pragma once
// JSON text => document, with the two checks nlohmann's parser does not make: nesting depth and
// repeated keys. Every walk over a parsed document (copies, dump(), the unknown-key check) is
// recursive, so a document nested tens of thousands deep would overflow the stack; the depth is
// therefore checked on the text, by a scan that keeps its own stack, before anything parses it.
#include <nlohmann/json.hpp>
#include <string>

#include "common/errors.h"

namespace treeanim {

using Json = nlohmann::ordered_json;

// Deepest nesting of arrays and objects in a scene, counted from its root. The deepest key a
// scene reads is six levels down (/forest/variants/0/tree/leaf/size); 256 leaves room for any free-form value.
constexpr int kMaxJsonDepth = 256;

// Text that is not JSON at all (as opposed to JSON that breaks a limit).
struct JsonSyntaxError : InputError {
  using InputError::InputError;
};

// Parses `text`, the value that goes at JSON pointer `at` of a scene ("" for a whole file).
// Throws, with `name` first:
//   JsonSyntaxError "<name>:<line>:<col>: JSON syntax error: ..."
//   InputError "<name>:<line>:<col>: JSON nested deeper than 256 levels ..."
//   InputError "<name>:<line>:<col>: <pointer>: duplicate key (first at line L1, again at line L2)"
//   InputError "<name>:<line>:<col>: JSON number out of range: ..."
// Neither the scan nor the parse recurses, whatever the depth of the text.
Json parse_json_text(const std::string& text, const std::string& name, const std::string& at = "");

// Byte offset => "line:column" (1-based).
std::string line_column(const std::string& text, size_t offset);

// JSON-pointer escaping of one reference token ("~" => "~0", "/" => "~1").
std::string escape_pointer_token(const std::string& token);

// Does `pointer` name `target` or a value below it ("/a/b" is within "/a", "/ab" is not)?
bool pointer_within(const std::string& pointer, const std::string& target);

}  // namespace treeanim
