/*
 * facyl: the tabletop recognizer's result as JSON, written by facyl_detect (one line per
 * scene) and returned by the Python module's detect() (the same fields, parsed): one
 * vocabulary for both.
 */
#pragma once

#include <facyl/tools/cli.h>
#include <facyl/tools/cylinder_json.h>

#include <facyl/recognition/tabletop_cylinder_recognizer.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace facyl_cli {

/** One object: id, support (index into "supports"; -1: none under it), centroid, n_points,
 * bbox (pixels; null without), the decision's evidence and "cylinder" (cylinderJson, null when
 * not fitted). */
inline std::string
objectJson(std::size_t id, const facyl::RecognizedObject& o, int digits = 6)
{
  const auto& b = o.cluster.box;
  const auto& e = o.evidence;
  const auto num = [digits](float v) { return number(v, digits); };
  std::ostringstream out;
  out << "{\"id\":" << id << ",\"support\":" << o.cluster.support
      << ",\"centroid\":" << vector(o.cluster.centroid, digits)
      << ",\"n_points\":" << o.cluster.indices.indices.size() << ",\"bbox\":";
  if (b[0] < 0)
    out << "null";
  else
    out << "[" << b[0] << "," << b[1] << "," << b[2] << "," << b[3] << "]";
  out << ",\"p_cylinder\":" << num(e.p_cylinder) << ",\"p_network\":" << num(e.p_network)
      << ",\"inlier_ratio\":" << num(e.inlier_ratio)
      << ",\"surface_ratio\":" << num(e.surface_ratio)
      << ",\"curvature_ratio\":" << num(e.curvature_ratio)
      << ",\"angular_coverage\":" << num(e.angular_coverage) << ",\"taper\":" << num(e.taper)
      << ",\"arc_gap\":" << num(e.arc_gap)
      << ",\"is_cylinder\":" << (o.is_cylinder ? "true" : "false") << ",\"cylinder\":";
  if (e.fitted)
    out << cylinderJson(o.cylinder, false, digits);
  else
    out << "null";
  out << "}";
  return out.str();
}

inline std::string
planeJson(const Eigen::Vector4f& c, int digits)
{
  return "[" + number(c[0], digits) + "," + number(c[1], digits) + "," + number(c[2], digits) +
         "," + number(c[3], digits) + "]";
}

/** The scene's JSON object without its closing brace (more fields may follow): "file" (when
 * \a file is not empty), "organized", "table" {"coefficients": a,b,c,d of the table plane in
 * the cloud's frame, unit normal towards the sensor, or null; "found"}, "supports",
 * "objects", "timing_ms". */
template <typename PointT>
std::string
sceneJson(const std::string& file, const pcl::PointCloud<PointT>& cloud,
          const facyl::TabletopCylinderRecognizer<PointT>& rec,
          const std::vector<facyl::RecognizedObject>& objects, const facyl::RecognitionTiming& t,
          int digits = 6)
{
  const auto& supports = rec.getSupports();
  const auto& tc = rec.getTableCoefficients().values;
  std::ostringstream out;
  out << "{";
  if (!file.empty())
    out << "\"file\":" << quote(file) << ",";
  out << "\"organized\":" << (cloud.isOrganized() ? "true" : "false")
      << ",\"table\":{\"coefficients\":"
      << (tc.size() == 4 ? planeJson(Eigen::Vector4f(tc[0], tc[1], tc[2], tc[3]), digits)
                         : std::string("null"))
      << ",\"found\":" << (rec.tableFound() ? "true" : "false") << "},\"supports\":[";
  for (std::size_t k = 0; k < supports.size(); ++k) {
    // The objects reported on it (the recognizer joins and splits the segmentation's clusters).
    const auto on = std::count_if(objects.begin(), objects.end(), [k](const auto& o) {
      return o.cluster.support == static_cast<int>(k);
    });
    out << (k ? "," : "") << "{\"coefficients\":" << planeJson(supports[k].plane, digits)
        << ",\"objects\":" << on << "}";
  }
  out << "],\"objects\":[";
  for (std::size_t k = 0; k < objects.size(); ++k)
    out << (k ? "," : "") << objectJson(k, objects[k], digits);
  out << "],\"timing_ms\":{\"segmentation\":" << number(t.segmentation, digits)
      << ",\"classification\":" << number(t.classification, digits)
      << ",\"fitting\":" << number(t.fitting, digits) << ",\"total\":" << number(t.total, digits)
      << "}";
  return out.str();
}

} // namespace facyl_cli
