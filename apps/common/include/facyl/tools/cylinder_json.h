/*
 * facyl: a fitted cylinder as the tools print it. One set of fields everywhere: facyl_fit's
 * "cylinders", facyl_detect's "cylinder" of each object and the Python module (Cylinder's
 * attributes, detect()'s dicts) use these names with these meanings.
 */
#pragma once

#include <facyl/tools/cli.h>

#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <cstdio>
#include <string>

namespace facyl_cli {

/** \a v with \a digits significant digits (JSON null when not finite). */
inline std::string
number(double v, int digits)
{
  if (!std::isfinite(v))
    return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

inline std::string
vector(const Eigen::Vector3f& v, int digits)
{
  return "[" + number(v.x(), digits) + "," + number(v.y(), digits) + "," + number(v.z(), digits) +
         "]";
}

/** The JSON object of \a m: point_on_axis, axis (unit, base to top), radius, height, base and
 * top (centres of the lowest and highest inlier sections), inlier_ratio (paper eq. 4),
 * n_inliers, confidence, rms_error, angular_coverage; with \a inliers also "inliers", the
 * indices. Lengths in the cloud's units. */
inline std::string
cylinderJson(const facyl::CylinderModel& m, bool inliers = false, int digits = 6)
{
  std::string out =
    "{\"point_on_axis\":" + vector(m.point_on_axis, digits) +
    ",\"axis\":" + vector(m.axis, digits) + ",\"radius\":" + number(m.radius, digits) +
    ",\"height\":" + number(m.height, digits) + ",\"base\":" + vector(m.base, digits) +
    ",\"top\":" + vector(m.top, digits) + ",\"inlier_ratio\":" + number(m.inlier_ratio, digits) +
    ",\"n_inliers\":" + std::to_string(m.inliers.size()) +
    ",\"confidence\":" + number(m.confidence, digits) +
    ",\"rms_error\":" + number(m.rms_error, digits) +
    ",\"angular_coverage\":" + number(m.angular_coverage, digits);
  if (inliers) {
    out += ",\"inliers\":[";
    for (std::size_t i = 0; i < m.inliers.size(); ++i)
      out += (i ? "," : "") + std::to_string(m.inliers[i]);
    out += "]";
  }
  return out + "}";
}

} // namespace facyl_cli
