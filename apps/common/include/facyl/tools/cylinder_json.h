/*
 * facyl: a fitted cylinder as the tools print it. One set of fields everywhere: facyl_fit's
 * "cylinders", facyl_detect's "cylinder" of each object and the Python module (Cylinder's
 * attributes, detect()'s dicts) use these names with these meanings.
 */
#pragma once

#include <facyl/tools/json_writer.h>

#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <string>

namespace facyl_cli {

/** The JSON object of \a m: point_on_axis, axis (unit, base to top), radius, height, base and
 * top (centres of the lowest and highest inlier sections), inlier_ratio (paper eq. 4),
 * n_inliers, confidence, rms_error, angular_coverage; with \a inliers also "inliers", the
 * indices. Lengths in the cloud's units. */
inline Json
cylinderObject(const facyl::CylinderModel& m, bool inliers = false, int digits = 6)
{
  Json j;
  j["point_on_axis"] = jsonVector(m.point_on_axis, digits);
  j["axis"] = jsonVector(m.axis, digits);
  j["radius"] = jsonNumber(m.radius, digits);
  j["height"] = jsonNumber(m.height, digits);
  j["base"] = jsonVector(m.base, digits);
  j["top"] = jsonVector(m.top, digits);
  j["inlier_ratio"] = jsonNumber(m.inlier_ratio, digits);
  j["n_inliers"] = m.inliers.size();
  j["confidence"] = jsonNumber(m.confidence, digits);
  j["rms_error"] = jsonNumber(m.rms_error, digits);
  j["angular_coverage"] = jsonNumber(m.angular_coverage, digits);
  if (inliers)
    j["inliers"] = m.inliers;
  return j;
}

/** cylinderObject as one line. */
inline std::string
cylinderJson(const facyl::CylinderModel& m, bool inliers = false, int digits = 6)
{
  return dumpJson(cylinderObject(m, inliers, digits));
}

} // namespace facyl_cli
