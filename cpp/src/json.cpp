// The strict JSON reader of detail/json.hpp: recursive descent over the grammar of RFC 8259,
// one function per production, keeping the path of the value being read for messages.
#include "dynid/detail/json.hpp"

#include <charconv>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <system_error>

namespace dynid::detail {

const JsonValue* JsonValue::find(std::string_view key) const {
  if (kind != Kind::Object) return nullptr;
  for (std::size_t k = 0; k < keys.size(); ++k)
    if (keys[k] == key) return &items[k];
  return nullptr;
}

const char* json_kind_name(JsonValue::Kind kind) {
  switch (kind) {
    case JsonValue::Kind::Null:
      return "null";
    case JsonValue::Kind::Bool:
      return "true or false";
    case JsonValue::Kind::Number:
      return "a number";
    case JsonValue::Kind::String:
      return "a string";
    case JsonValue::Kind::Array:
      return "a list";
    case JsonValue::Kind::Object:
      return "an object";
  }
  return "?";
}

namespace {

class Reader {
 public:
  Reader(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  JsonValue document() {
    check_utf8();
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") fail("a byte order mark (BOM) before the value");
    JsonValue value = read_value(0);
    skip_space();
    if (pos_ != text_.size()) fail("extra data after the value");
    return value;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    // Line and column (1-based, in bytes) of the offending position, counted only now.
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < pos_ && i < text_.size(); ++i) {
      if (text_[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    const std::string where = path_.empty() ? std::string() : path_ + ": ";
    throw std::invalid_argument(source_ + ": " + where + "not valid JSON: " + what + " (line " +
                                std::to_string(line) + ", column " + std::to_string(column) + ")");
  }

  // A text file is UTF-8 (Python reads it as text first: "not a text file" otherwise).
  void check_utf8() {
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text_[i]); };
    for (pos_ = 0; pos_ < text_.size();) {
      const unsigned char c = byte(pos_);
      std::size_t length = c < 0x80           ? 1
                           : (c >> 5) == 0x6  ? 2
                           : (c >> 4) == 0xE  ? 3
                           : (c >> 3) == 0x1E ? 4
                                              : 0;
      bool valid = length != 0 && pos_ + length <= text_.size();
      std::uint32_t code = length == 1   ? c
                           : length == 2 ? (c & 0x1F)
                           : length == 3 ? (c & 0x0F)
                                         : (c & 0x07);
      for (std::size_t k = 1; valid && k < length; ++k) {
        valid = (byte(pos_ + k) >> 6) == 0x2;
        code = (code << 6) | (byte(pos_ + k) & 0x3F);
      }
      // No overlong forms, no surrogates, nothing beyond U+10FFFF.
      static const std::uint32_t smallest[] = {0, 0, 0x80, 0x800, 0x10000};
      if (valid && length > 1)
        valid = code >= smallest[length] && code <= 0x10FFFF && (code < 0xD800 || code > 0xDFFF);
      if (!valid) fail("not UTF-8 text (byte " + std::to_string(pos_) + ")");
      pos_ += length;
    }
    pos_ = 0;
  }

  bool at_end() const { return pos_ >= text_.size(); }
  char peek() const { return at_end() ? '\0' : text_[pos_]; }

  void skip_space() {
    while (!at_end() && (peek() == ' ' || peek() == '\t' || peek() == '\n' || peek() == '\r'))
      ++pos_;
  }

  void expect(char c, const char* what) {
    skip_space();
    if (at_end()) fail(std::string("unexpected end of the file, expected ") + what);
    if (peek() != c) fail(std::string("expected ") + what);
    ++pos_;
  }

  bool literal(std::string_view word) {
    if (text_.substr(pos_, word.size()) != word) return false;
    pos_ += word.size();
    return true;
  }

  JsonValue read_value(int depth) {
    skip_space();
    if (at_end()) fail("unexpected end of the file, expected a value");
    JsonValue value;
    const char c = peek();
    if (c == '{' || c == '[') {
      if (depth >= kJsonMaxDepth)
        fail("nested more than " + std::to_string(kJsonMaxDepth) + " levels deep");
      if (c == '{')
        read_object(value, depth + 1);
      else
        read_array(value, depth + 1);
    } else if (c == '"') {
      value.kind = JsonValue::Kind::String;
      value.text = read_string();
    } else if (literal("true") || literal("false")) {
      value.kind = JsonValue::Kind::Bool;
      value.boolean = c == 't';
    } else if (literal("null")) {
      value.kind = JsonValue::Kind::Null;
    } else {
      read_number(value);
    }
    return value;
  }

  void read_object(JsonValue& value, int depth) {
    value.kind = JsonValue::Kind::Object;
    ++pos_;  // '{'
    skip_space();
    if (peek() == '}') {
      ++pos_;
      return;
    }
    const std::size_t outer = path_.size();
    for (;;) {
      skip_space();
      if (at_end()) fail("unexpected end of the file, expected a key in quotes");
      if (peek() != '"') fail("expected a key in quotes");
      std::string key = read_string();
      path_.resize(outer);
      path_ += (outer == 0 ? "" : ".") + key;
      if (value.find(key) != nullptr) fail("the key '" + key + "' appears twice");
      expect(':', "':' after the key");
      value.items.push_back(read_value(depth));
      value.keys.push_back(std::move(key));
      skip_space();
      if (at_end()) fail("unexpected end of the file, expected ',' or '}'");
      const char c = text_[pos_++];
      if (c == '}') break;
      if (c != ',') {
        --pos_;
        fail("expected ',' or '}'");
      }
    }
    path_.resize(outer);
  }

  void read_array(JsonValue& value, int depth) {
    value.kind = JsonValue::Kind::Array;
    ++pos_;  // '['
    skip_space();
    if (peek() == ']') {
      ++pos_;
      return;
    }
    const std::size_t outer = path_.size();
    for (;;) {
      path_.resize(outer);
      path_ += "[" + std::to_string(value.items.size()) + "]";
      value.items.push_back(read_value(depth));
      skip_space();
      if (at_end()) fail("unexpected end of the file, expected ',' or ']'");
      const char c = text_[pos_++];
      if (c == ']') break;
      if (c != ',') {
        --pos_;
        fail("expected ',' or ']'");
      }
    }
    path_.resize(outer);
  }

  // A number by the grammar -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?, or NaN, Infinity,
  // -Infinity (as Python's json reads them).
  void read_number(JsonValue& value) {
    value.kind = JsonValue::Kind::Number;
    if (literal("NaN")) {
      value.number = std::numeric_limits<double>::quiet_NaN();
      return;
    }
    if (literal("Infinity")) {
      value.number = std::numeric_limits<double>::infinity();
      return;
    }
    if (literal("-Infinity")) {
      value.number = -std::numeric_limits<double>::infinity();
      return;
    }
    const std::size_t start = pos_;
    auto digits = [&] {
      const std::size_t first = pos_;
      while (!at_end() && peek() >= '0' && peek() <= '9') ++pos_;
      return pos_ - first;
    };
    if (peek() == '-') ++pos_;
    const std::size_t int_start = pos_;
    const std::size_t int_digits = digits();
    if (int_digits == 0) {
      if (at_end()) fail("unexpected end of the file inside a number");
      pos_ = start;
      fail("expected a value (a number, a string, a list, an object, true, false or null)");
    }
    if (int_digits > 1 && text_[int_start] == '0') {
      pos_ = int_start;
      fail("a number with a leading zero");
    }
    value.integer = true;
    if (peek() == '.') {
      ++pos_;
      value.integer = false;
      if (digits() == 0)
        fail(at_end() ? "unexpected end of the file inside a number"
                      : "expected digits after the decimal point");
    }
    if (peek() == 'e' || peek() == 'E') {
      ++pos_;
      value.integer = false;
      if (peek() == '+' || peek() == '-') ++pos_;
      if (digits() == 0)
        fail(at_end() ? "unexpected end of the file inside a number"
                      : "expected digits in the exponent");
    }
    const char* first = text_.data() + start;
    const char* last = text_.data() + pos_;
    const std::from_chars_result r = std::from_chars(first, last, value.number);
    if (r.ec == std::errc::result_out_of_range) {
      // Beyond the range of a double: +-inf for a large magnitude, +-0 for a tiny one, as
      // Python's float() gives.
      const bool negative = *first == '-';
      const double big = std::numeric_limits<double>::infinity();
      value.number =
          magnitude_exponent(first, last) > 0 ? (negative ? -big : big) : (negative ? -0.0 : 0.0);
    } else if (r.ec != std::errc() || r.ptr != last) {
      pos_ = start;
      fail("a malformed number");
    }
  }

  // The decimal exponent of the first significant digit of a valid number token (0 when all
  // its digits are zeros): above 0 the number is large, below 0 tiny.
  static long magnitude_exponent(const char* first, const char* last) {
    const char* p = first + (*first == '-' ? 1 : 0);
    long integer_digits = 0, leading = 0;  // digits before the point; zeros before the first
    bool significant = false, fraction = false;
    for (; p != last && *p != 'e' && *p != 'E'; ++p) {
      if (*p == '.') {
        fraction = true;
        continue;
      }
      if (!fraction) ++integer_digits;
      if (!significant && *p != '0') significant = true;
      if (!significant) ++leading;
    }
    if (!significant) return 0;
    long exponent = 0;
    if (p != last) {
      const char* e = p + 1;
      const bool negative = *e == '-';
      if (*e == '-' || *e == '+') ++e;
      for (; e != last; ++e)
        exponent = exponent < 100000000 ? exponent * 10 + (*e - '0') : exponent;
      if (negative) exponent = -exponent;
    }
    // The first significant digit is digit number `leading` (0-based) counted from the left.
    return integer_digits - 1 - leading + exponent;
  }

  std::string read_string() {
    ++pos_;  // '"'
    std::string out;
    for (;;) {
      if (at_end()) fail("unexpected end of the file inside a string");
      const unsigned char c = static_cast<unsigned char>(text_[pos_]);
      if (c == '"') {
        ++pos_;
        return out;
      }
      if (c < 0x20) fail("a control character inside a string (write it as an escape)");
      if (c == '\\') {
        ++pos_;
        read_escape(out);
      } else {
        out += static_cast<char>(c);
        ++pos_;
      }
    }
  }

  void read_escape(std::string& out) {
    if (at_end()) fail("unexpected end of the file inside a string");
    const char c = text_[pos_++];
    switch (c) {
      case '"':
      case '\\':
      case '/':
        out += c;
        return;
      case 'b':
        out += '\b';
        return;
      case 'f':
        out += '\f';
        return;
      case 'n':
        out += '\n';
        return;
      case 'r':
        out += '\r';
        return;
      case 't':
        out += '\t';
        return;
      case 'u':
        break;
      default:
        --pos_;
        fail("an invalid escape in a string");
    }
    std::uint32_t code = read_hex4();
    if (code >= 0xDC00 && code <= 0xDFFF) fail("an unpaired UTF-16 surrogate in a \\u escape");
    if (code >= 0xD800 && code <= 0xDBFF) {
      if (!literal("\\u")) fail("an unpaired UTF-16 surrogate in a \\u escape");
      const std::uint32_t low = read_hex4();
      if (low < 0xDC00 || low > 0xDFFF) fail("an unpaired UTF-16 surrogate in a \\u escape");
      code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
    }
    append_utf8(out, code);
  }

  std::uint32_t read_hex4() {
    std::uint32_t code = 0;
    for (int k = 0; k < 4; ++k) {
      if (at_end()) fail("unexpected end of the file inside a \\u escape");
      const char h = text_[pos_];
      int digit = -1;
      if (h >= '0' && h <= '9') digit = h - '0';
      if (h >= 'a' && h <= 'f') digit = h - 'a' + 10;
      if (h >= 'A' && h <= 'F') digit = h - 'A' + 10;
      if (digit < 0) fail("expected 4 hexadecimal digits after \\u");
      code = code * 16 + static_cast<std::uint32_t>(digit);
      ++pos_;
    }
    return code;
  }

  static void append_utf8(std::string& out, std::uint32_t code) {
    if (code < 0x80) {
      out += static_cast<char>(code);
    } else if (code < 0x800) {
      out += static_cast<char>(0xC0 | (code >> 6));
      out += static_cast<char>(0x80 | (code & 0x3F));
    } else if (code < 0x10000) {
      out += static_cast<char>(0xE0 | (code >> 12));
      out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (code & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (code >> 18));
      out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (code & 0x3F));
    }
  }

  std::string_view text_;
  const std::string& source_;
  std::size_t pos_ = 0;
  std::string path_;
};

}  // namespace

JsonValue parse_json(std::string_view text, const std::string& source) {
  return Reader(text, source).document();
}

}  // namespace dynid::detail
