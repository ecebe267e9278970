/*
 * facyl: the one JSON writer of the tools, the Python module and the simulation's ground truth
 * (nlohmann-json, fields in the order written; the simulation library includes it privately).
 * Numbers carry a given number of significant digits and read as printf's %g writes them
 * (0.0362165, 1e-05, 3); not finite: null.
 */
#pragma once

#include <nlohmann/json.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace facyl_cli {

/** A JSON value as the tools write it: objects keep their fields in the order written. */
using Json = nlohmann::ordered_json;

/** \a v with \a digits significant digits (null when not finite). */
inline Json
jsonNumber(double v, int digits = 6)
{
  if (!std::isfinite(v))
    return nullptr;
  char text[40];
  std::snprintf(text, sizeof text, "%.*g", digits, v);
  const double rounded = std::strtod(text, nullptr);
  // An integral value prints without a decimal point, as %g writes it ("3", not "3.0").
  if (std::strpbrk(text, ".e") == nullptr && std::abs(rounded) < 9e15)
    return static_cast<std::int64_t>(rounded);
  return rounded; // the shortest decimal that reads back as it: the %g text
}

/** [x, y, z], each with \a digits significant digits. */
inline Json
jsonVector(const Eigen::Vector3f& v, int digits = 6)
{
  return Json::array(
    {jsonNumber(v.x(), digits), jsonNumber(v.y(), digits), jsonNumber(v.z(), digits)});
}

/** \a j as one compact line; bytes of strings that are not UTF-8 (a corrupt file's name)
 * become U+FFFD. */
inline std::string
dumpJson(const Json& j)
{
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

namespace detail {
inline void
appendJson(std::string& out, const Json& j, int digits)
{
  switch (j.type()) {
  case Json::value_t::object: {
    out += '{';
    bool first = true;
    for (const auto& item : j.items()) {
      out += first ? "" : ",";
      first = false;
      out += dumpJson(Json(item.key()));
      out += ':';
      appendJson(out, item.value(), digits);
    }
    out += '}';
    break;
  }
  case Json::value_t::array: {
    out += '[';
    for (std::size_t k = 0; k < j.size(); ++k) {
      out += k ? "," : "";
      appendJson(out, j[k], digits);
    }
    out += ']';
    break;
  }
  case Json::value_t::number_float: {
    const double v = j.get<double>();
    if (!std::isfinite(v)) {
      out += "null";
      break;
    }
    char text[40];
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    out += text;
    break;
  }
  default:
    out += dumpJson(j);
  }
}
} // namespace detail

/** \brief \a j as one compact line, as dumpJson writes it, but every floating-point number
 * as printf's %.<digits>g writes it (what a stream with setprecision(digits) writes; not
 * finite: null). dumpJson writes the shortest text nlohmann's Grisu2 finds for a number that
 * jsonNumber rounded, which is the same digits except now and then 17 of them
 * (0.2154446 as 0.21544460000000001); the simulation's ground truth is written this way. */
inline std::string
dumpJsonWithDigits(const Json& j, int digits)
{
  std::string out;
  detail::appendJson(out, j, digits);
  return out;
}

} // namespace facyl_cli
