// Internal (dynid::detail, not API): a small strict JSON reader (RFC 8259) for the model and
// result files Python writes (dynid::load_model, model_file.hpp). No dependency: the C++ core has
// only Eigen. What it accepts is what Python's json.loads accepts, with three refusals that keep
// a file from meaning two things: duplicate keys in an object (Python keeps the last one),
// unpaired UTF-16 surrogates in \u escapes, and nesting deeper than kJsonMaxDepth (Python's own
// limit is its recursion limit). Like Python it reads the literals NaN, Infinity and -Infinity
// and turns a number too large for a double into +-inf, so that the field that holds one can say
// "contains NaN or inf" as Python's loader does. Numbers are read with std::from_chars (no
// locale). Every error is a std::invalid_argument
//   "<source>: <path>: not valid JSON: <what> (line L, column C)"
// whose path names the value being read ("rows[3].alpha"; "" at the top level).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::detail {

// Deep enough for any file dynid writes (3 levels in a model file, 5 in a result) and for
// free-form metadata; shallow enough that the recursive reader cannot exhaust the stack.
constexpr int kJsonMaxDepth = 256;

struct JsonValue {
  enum class Kind { Null, Bool, Number, String, Array, Object };
  Kind kind = Kind::Null;
  bool boolean = false;
  double number = 0.0;
  // A Number written without fraction or exponent (Python reads it as an int).
  bool integer = false;
  std::string text;
  // Array items; for an Object its values, keys[k] naming items[k] (in the file's order).
  std::vector<JsonValue> items;
  std::vector<std::string> keys;

  // The value of `key` in an Object, nullptr when absent (or not an Object).
  const JsonValue* find(std::string_view key) const;
};

// "null", "true or false", "a number", "a string", "a list", "an object": what a message says
// a value was.
const char* json_kind_name(JsonValue::Kind kind);

// The value of the JSON text `text` (one value, surrounded by white space only). `source` names
// the text in messages (a file path).
JsonValue parse_json(std::string_view text, const std::string& source);

}  // namespace dynid::detail
