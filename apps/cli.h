/*
 * facyl: small helpers shared by the command-line tools (strict option parsing, JSON).
 */
#pragma once

#include <Eigen/Core>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace facyl_cli {

/** The largest seed an option accepts (seeds are read as signed 64-bit integers). */
constexpr long long kMaxSeed = std::numeric_limits<long long>::max();

/** Options "--name value" and switches "--name"; everything else is a positional argument.
 * Unknown options and malformed values are errors (std::invalid_argument), never ignored. */
class Arguments {
public:
  Arguments(int argc, char** argv, const std::set<std::string>& with_value,
            const std::set<std::string>& switches)
  {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a.size() > 1 && a[0] == '-' && !(a.size() > 1 && (std::isdigit(a[1]) || a[1] == '.'))) {
        if (switches.count(a)) {
          switches_.insert(a);
          continue;
        }
        if (!with_value.count(a))
          throw std::invalid_argument("unknown option " + a + " (see -h)");
        if (i + 1 >= argc)
          throw std::invalid_argument("option " + a + " needs a value");
        values_[a] = argv[++i];
        continue;
      }
      positional_.push_back(a);
    }
  }
  bool
  has(const std::string& s) const
  {
    return switches_.count(s) > 0 || values_.count(s) > 0;
  }
  const std::vector<std::string>&
  positional() const
  {
    return positional_;
  }
  std::string
  text(const std::string& name, const std::string& fallback) const
  {
    const auto it = values_.find(name);
    return it == values_.end() ? fallback : it->second;
  }
  /** The value of \a name as a finite number in [\a min_value, \a max_value]. */
  double
  number(const std::string& name, double fallback,
         double min_value = -std::numeric_limits<double>::max(),
         double max_value = std::numeric_limits<double>::max()) const
  {
    const auto it = values_.find(name);
    if (it == values_.end())
      return fallback;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(it->second.c_str(), &end);
    if (end == it->second.c_str() || *end != '\0' || !std::isfinite(v) || errno == ERANGE)
      throw std::invalid_argument("option " + name + ": '" + it->second + "' is not a number");
    if (v < min_value || v > max_value)
      throw std::invalid_argument("option " + name + ": " + it->second + " is not in [" +
                                  shortNumber(min_value) + ", " + shortNumber(max_value) + "]");
    return v;
  }
  /** The value of \a name as an integer in [\a min_value, \a max_value]: digits only (an
   * optional minus sign), no wrap-around, no saturation. */
  long long
  integer(const std::string& name, long long fallback, long long min_value,
          long long max_value) const
  {
    const auto it = values_.find(name);
    if (it == values_.end())
      return fallback;
    const std::string& t = it->second;
    const std::size_t first = !t.empty() && t[0] == '-' ? 1 : 0;
    if (t.size() == first || t.find_first_not_of("0123456789", first) != std::string::npos)
      throw std::invalid_argument("option " + name + ": '" + t + "' is not an integer");
    errno = 0;
    const long long v = std::strtoll(t.c_str(), nullptr, 10);
    if (errno == ERANGE || v < min_value || v > max_value)
      throw std::invalid_argument("option " + name + ": " + t + " is not in [" +
                                  std::to_string(min_value) + ", " + std::to_string(max_value) +
                                  "]");
    return v;
  }
  Eigen::Vector3f
  vector3(const std::string& name, const Eigen::Vector3f& fallback) const
  {
    const auto it = values_.find(name);
    if (it == values_.end())
      return fallback;
    Eigen::Vector3f v;
    char comma1, comma2;
    std::istringstream in(it->second);
    if (!(in >> v.x() >> comma1 >> v.y() >> comma2 >> v.z()) || comma1 != ',' || comma2 != ',' ||
        !v.allFinite())
      throw std::invalid_argument("option " + name + ": expected x,y,z, got '" + it->second + "'");
    return v;
  }

private:
  static std::string
  shortNumber(double v)
  {
    std::ostringstream s;
    s << v;
    return s.str();
  }
  std::map<std::string, std::string> values_;
  std::set<std::string> switches_;
  std::vector<std::string> positional_;
};

/** "A,B" option as two numbers (\a a, \a b when absent). */
inline std::pair<double, double>
pairOption(const Arguments& args, const std::string& name, double a, double b)
{
  const std::string text = args.text(name, "");
  if (text.empty())
    return {a, b};
  std::istringstream in(text);
  char comma = 0;
  if (!(in >> a >> comma >> b) || comma != ',' || !in.eof() || !std::isfinite(a) ||
      !std::isfinite(b))
    throw std::invalid_argument("option " + name + ": expected A,B, got '" + text + "'");
  return {a, b};
}

/** The union of option name sets. */
inline std::set<std::string>
joined(std::set<std::string> a, const std::set<std::string>& b)
{
  a.insert(b.begin(), b.end());
  return a;
}

/** True if -h or --help is among the arguments. */
inline bool
wantsHelp(int argc, char** argv)
{
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "-h" || std::string(argv[i]) == "--help")
      return true;
  return false;
}

/** Length of the valid UTF-8 sequence at \a s[i], or 0 when the bytes there are not one. */
inline std::size_t
utf8Length(const std::string& s, std::size_t i)
{
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = byte(i);
  const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
  if (n == 0 || i + n > s.size() || (n == 2 && c < 0xc2))
    return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((byte(i + k) >> 6) != 0x2)
      return 0;
  return n;
}

/** JSON string literal (bytes that are not UTF-8, e.g. from a corrupt file, become U+FFFD). */
inline std::string
quote(const std::string& text)
{
  std::string s;
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8Length(text, i);
    if (n == 0) {
      s += "\xef\xbf\xbd";
      ++i;
    }
    else {
      s.append(text, i, n);
      i += n;
    }
  }
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
    case '"':
      out += "\\\"";
      break;
    case '\\':
      out += "\\\\";
      break;
    case '\n':
      out += "\\n";
      break;
    case '\t':
      out += "\\t";
      break;
    default:
      if (static_cast<unsigned char>(c) < 0x20) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\u%04x", c);
        out += buf;
      }
      else
        out += c;
    }
  }
  return out + "\"";
}

/** JSON number (null when not finite). */
inline std::string
number(double v)
{
  if (!std::isfinite(v))
    return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

inline std::string
vector(const Eigen::Vector3f& v)
{
  return "[" + number(v.x()) + "," + number(v.y()) + "," + number(v.z()) + "]";
}

} // namespace facyl_cli
