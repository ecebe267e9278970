/*
 * facyl: the tabletop recognizer's result as JSON, written by facyl_detect (one line per
 * scene) and returned by the Python module's detect() (the same fields, parsed): one
 * vocabulary for both, one writer (json_writer.h).
 */
#pragma once

#include <facyl/tools/cylinder_json.h>
#include <facyl/tools/json_writer.h>

#include <facyl/recognition/cylinder_evidence.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace facyl_cli {

/** One object: id, support (index into "supports"; -1: none under it), centroid, n_points,
 * bbox (pixels; null without), the decision's evidence ("from_lid": fitted to its lid alone,
 * facyl::fitLid), "passes_gates" (facyl::passesGates
 * under \a decision), "features" (facyl::evidenceFeatures: what p_cylinder is computed from;
 * null when not fitted) and "cylinder" (cylinderObject, null when not fitted). */
inline Json
objectJson(std::size_t id, const facyl::RecognizedObject& o,
           const facyl::CylinderDecision& decision, int digits = 6)
{
  const auto& b = o.cluster.box;
  const auto& e = o.evidence;
  const auto num = [digits](float v) { return jsonNumber(v, digits); };
  Json j;
  j["id"] = id;
  j["support"] = o.cluster.support;
  j["centroid"] = jsonVector(o.cluster.centroid, digits);
  j["n_points"] = o.cluster.indices.indices.size();
  j["bbox"] = b[0] < 0 ? Json(nullptr) : Json::array({b[0], b[1], b[2], b[3]});
  j["p_cylinder"] = num(e.p_cylinder);
  j["p_network"] = num(e.p_network);
  j["inlier_ratio"] = num(e.inlier_ratio);
  j["surface_ratio"] = num(e.surface_ratio);
  j["curvature_ratio"] = num(e.curvature_ratio);
  j["angular_coverage"] = num(e.angular_coverage);
  j["taper"] = num(e.taper);
  j["arc_gap"] = num(e.arc_gap);
  j["normal_agreement"] = num(e.shape.normal_agreement);
  j["normal_concentration"] = num(e.shape.normal_concentration);
  j["profile_range"] = num(e.shape.profile_range);
  j["axis_bend"] = num(e.shape.axis_bend);
  j["inner_share"] = num(e.shape.inner_share);
  j["outside_share"] = num(e.shape.outside_share);
  j["aspect"] = num(e.shape.aspect);
  j["from_lid"] = e.from_lid;
  j["seen_through"] = num(e.seen_through);
  j["passes_gates"] = facyl::passesGates(e, decision);
  if (e.fitted) {
    j["features"] = Json::array();
    for (const float f : facyl::evidenceFeatures(e.p_network, e))
      j["features"].push_back(num(f));
  }
  else
    j["features"] = nullptr;
  j["is_cylinder"] = o.is_cylinder;
  j["cylinder"] = e.fitted ? cylinderObject(o.cylinder, false, digits) : Json(nullptr);
  return j;
}

/** The plane a x + b y + c z + d = 0 as [a, b, c, d]. */
inline Json
planeJson(const Eigen::Vector4f& c, int digits)
{
  return Json::array({jsonNumber(c[0], digits), jsonNumber(c[1], digits), jsonNumber(c[2], digits),
                      jsonNumber(c[3], digits)});
}

/** The scene's JSON object: "file" (when \a file is not empty), "organized", "table"
 * {"coefficients": a,b,c,d of the table plane in the cloud's frame, unit normal towards the
 * sensor, or null; "found"}, "supports", "objects", "timing_ms"; more fields may be added. */
template <typename PointT>
Json
sceneJson(const std::string& file, const pcl::PointCloud<PointT>& cloud,
          const facyl::TabletopCylinderRecognizer<PointT>& rec,
          const std::vector<facyl::RecognizedObject>& objects, const facyl::RecognitionTiming& t,
          int digits = 6)
{
  const auto& supports = rec.getSupports();
  const auto& tc = rec.getTableCoefficients().values;
  Json j;
  if (!file.empty())
    j["file"] = file;
  j["organized"] = cloud.isOrganized();
  j["table"]["coefficients"] =
    tc.size() == 4 ? planeJson(Eigen::Vector4f(tc[0], tc[1], tc[2], tc[3]), digits) : Json(nullptr);
  j["table"]["found"] = rec.tableFound();
  j["supports"] = Json::array();
  for (std::size_t k = 0; k < supports.size(); ++k) {
    // The objects reported on it (the recognizer joins and splits the segmentation's clusters).
    const auto on = std::count_if(objects.begin(), objects.end(), [k](const auto& o) {
      return o.cluster.support == static_cast<int>(k);
    });
    Json support;
    support["coefficients"] = planeJson(supports[k].plane, digits);
    support["objects"] = on;
    j["supports"].push_back(std::move(support));
  }
  j["objects"] = Json::array();
  for (std::size_t k = 0; k < objects.size(); ++k)
    j["objects"].push_back(objectJson(k, objects[k], rec.getParameters().decision, digits));
  j["timing_ms"]["segmentation"] = jsonNumber(t.segmentation, digits);
  j["timing_ms"]["segmentation_planes"] = jsonNumber(t.segmentation_steps.planes, digits);
  j["timing_ms"]["segmentation_points"] = jsonNumber(t.segmentation_steps.points, digits);
  j["timing_ms"]["segmentation_objects"] = jsonNumber(t.segmentation_steps.objects, digits);
  j["timing_ms"]["classification"] = jsonNumber(t.classification, digits);
  j["timing_ms"]["fitting"] = jsonNumber(t.fitting, digits);
  j["timing_ms"]["total"] = jsonNumber(t.total, digits);
  return j;
}

} // namespace facyl_cli
