/*
 * facyl: a small JSON reader for the tools that read facyl's own JSON lines (facyl_viewer's
 * --detections). Objects, arrays, numbers, strings (with \uXXXX kept as '?'), true, false,
 * null; errors name the offset.
 */
#pragma once

#include <cctype>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace facyl_cli {

struct JsonValue {
  enum class Type { Null, Bool, Number, String, Array, Object } type{Type::Null};
  bool boolean{false};
  double number{0.0};
  std::string text;
  std::vector<JsonValue> items;                          ///< Array
  std::vector<std::pair<std::string, JsonValue>> fields; ///< Object, in order

  /** The field \a key of an object; nullptr when absent or not an object. */
  const JsonValue* get(const std::string& key) const
  {
    for (const auto& [k, v] : fields)
      if (k == key)
        return &v;
    return nullptr;
  }
};

/** Parses one JSON text. \throws std::invalid_argument naming the offset. */
class JsonReader {
public:
  static JsonValue parse(const std::string& text)
  {
    JsonReader r(text);
    JsonValue v = r.value();
    r.space();
    if (r.i_ != text.size())
      r.fail("unexpected text after the value");
    return v;
  }

private:
  explicit JsonReader(const std::string& s)
      : s_(s)
  {
  }

  [[noreturn]] void fail(const std::string& what) const
  {
    throw std::invalid_argument("JSON at offset " + std::to_string(i_) + ": " + what);
  }
  void space()
  {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_])))
      ++i_;
  }
  bool eat(char c)
  {
    space();
    if (i_ < s_.size() && s_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  void expect(char c)
  {
    if (!eat(c))
      fail(std::string("expected '") + c + "'");
  }
  JsonValue value()
  {
    if (++depth_ > 64)
      fail("nested too deeply");
    space();
    if (i_ >= s_.size())
      fail("unexpected end");
    JsonValue v;
    const char c = s_[i_];
    if (c == '{')
      v = object();
    else if (c == '[')
      v = array();
    else if (c == '"') {
      v.type = JsonValue::Type::String;
      v.text = string();
    }
    else if (s_.compare(i_, 4, "true") == 0 || s_.compare(i_, 5, "false") == 0) {
      v.type = JsonValue::Type::Bool;
      v.boolean = s_[i_] == 't';
      i_ += v.boolean ? 4 : 5;
    }
    else if (s_.compare(i_, 4, "null") == 0)
      i_ += 4;
    else
      v = number();
    --depth_;
    return v;
  }
  JsonValue object()
  {
    JsonValue v;
    v.type = JsonValue::Type::Object;
    expect('{');
    if (eat('}'))
      return v;
    do {
      space();
      if (i_ >= s_.size() || s_[i_] != '"')
        fail("expected a key");
      std::string key = string();
      expect(':');
      v.fields.emplace_back(std::move(key), value());
    } while (eat(','));
    expect('}');
    return v;
  }
  JsonValue array()
  {
    JsonValue v;
    v.type = JsonValue::Type::Array;
    expect('[');
    if (eat(']'))
      return v;
    do
      v.items.push_back(value());
    while (eat(','));
    expect(']');
    return v;
  }
  std::string string()
  {
    std::string out;
    ++i_; // opening quote
    while (i_ < s_.size() && s_[i_] != '"') {
      char c = s_[i_++];
      if (c == '\\') {
        if (i_ >= s_.size())
          fail("unfinished escape");
        const char e = s_[i_++];
        if (e == 'u') {
          if (i_ + 4 > s_.size())
            fail("unfinished \\u escape");
          i_ += 4;
          c = '?';
        }
        else
          c = e == 'n'
                ? '\n'
                : (e == 't' ? '\t' : (e == 'r' ? '\r' : (e == 'b' ? '\b' : (e == 'f' ? '\f' : e))));
      }
      out += c;
    }
    if (i_ >= s_.size())
      fail("unfinished string");
    ++i_;
    return out;
  }
  JsonValue number()
  {
    const char* start = s_.c_str() + i_;
    char* end = nullptr;
    const double x = std::strtod(start, &end);
    if (end == start)
      fail("expected a value");
    i_ += static_cast<std::size_t>(end - start);
    JsonValue v;
    v.type = JsonValue::Type::Number;
    v.number = x;
    return v;
  }

  const std::string& s_;
  std::size_t i_{0};
  int depth_{0};
};

} // namespace facyl_cli
