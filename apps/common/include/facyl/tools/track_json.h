/*
 * facyl: a stream's frame as JSON, written by facyl_detect --track (one line per frame) and
 * returned by the Python module's Tracker.update() (the same fields, parsed). The scene's
 * fields are facyl_detect's (detect_json.h); tracking adds per object "track_id", "track",
 * "is_cylinder_frame" and "cylinder_frame", and per frame "stream" and "tracks".
 */
#pragma once

#include <facyl/tools/cli.h>
#include <facyl/tools/cylinder_json.h>
#include <facyl/tools/detect_json.h>

#include <facyl/tracking/cylinder_tracker.h>

#include <sstream>
#include <string>
#include <vector>

namespace facyl_cli {

/** \a t's cylinder in the frame (CylinderTracker::cylinderInFrame) with the evidence fields
 * (inliers, ratios, rms) of the frame's own fit \a frame_fit (none when nullptr). */
inline facyl::CylinderModel
trackedCylinder(const facyl::CylinderTracker& tracker, const facyl::CylinderTrack& t,
                const facyl::RecognizedObject* frame_fit)
{
  facyl::CylinderModel m = tracker.cylinderInFrame(t);
  if (frame_fit && frame_fit->evidence.fitted) {
    const auto& f = frame_fit->cylinder;
    m.inliers = f.inliers;
    m.inlier_ratio = f.inlier_ratio;
    m.confidence = f.confidence;
    m.rms_error = f.rms_error;
    m.angular_coverage = f.angular_coverage;
    m.distance_threshold = f.distance_threshold;
  }
  return m;
}

/** "track":{...}: the track's state. */
inline std::string
trackStateJson(const facyl::CylinderTracker& tracker, const facyl::CylinderTrack& t, int digits)
{
  std::ostringstream out;
  out << "{\"confirmed\":" << (t.confirmed ? "true" : "false") << ",\"status\":\""
      << facyl::toString(t.status) << "\",\"age\":" << t.age << ",\"hits\":" << t.hits
      << ",\"misses\":" << t.misses << ",\"p_cylinder\":" << number(t.pCylinder(), digits)
      << ",\"is_cylinder\":" << (tracker.isCylinder(t) ? "true" : "false") << "}";
  return out.str();
}

/** The object as the tracked frame shows it: "is_cylinder" the track's decision (a confirmed
 * track, p_cylinder over time >= the tracker's min_probability) and "cylinder" the tracked
 * estimate in this frame (not fitted when the track has none). */
inline facyl::RecognizedObject
trackedView(const facyl::RecognizedObject& o, const facyl::TrackAssignment& a,
            const facyl::CylinderTracker& tracker)
{
  const facyl::CylinderTrack* t = tracker.findTrack(a.track_id);
  facyl::RecognizedObject shown;
  shown.cluster.support = o.cluster.support;
  shown.cluster.box = o.cluster.box;
  shown.cluster.centroid = o.cluster.centroid;
  shown.cluster.indices.indices.resize(o.cluster.indices.indices.size()); // objectJson: the count
  shown.evidence = o.evidence;
  shown.is_cylinder = t && tracker.isCylinder(*t);
  shown.evidence.fitted = t && t->has_cylinder;
  if (shown.evidence.fitted)
    shown.cylinder = trackedCylinder(tracker, *t, &o);
  return shown;
}

/** The fields a tracked object adds after objectJson's (of trackedView): "is_cylinder_frame"
 * and "cylinder_frame" (the frame's own decision and fit), "track_id" (null for an object the
 * tracker could not use), "role" (matched, started, fragment: a piece of an object matched in
 * the same frame; ignored), "merged" (ids of tracks whose place lies inside this object) and
 * "track" (trackStateJson). */
inline std::string
trackFieldsJson(const facyl::RecognizedObject& o, const facyl::TrackAssignment& a,
                const facyl::CylinderTracker& tracker, int digits = 6)
{
  const facyl::CylinderTrack* t = tracker.findTrack(a.track_id);
  std::ostringstream out;
  out << ",\"is_cylinder_frame\":" << (o.is_cylinder ? "true" : "false") << ",\"cylinder_frame\":"
      << (o.evidence.fitted ? cylinderJson(o.cylinder, false, digits) : std::string("null"))
      << ",\"track_id\":" << (a.track_id >= 0 ? std::to_string(a.track_id) : "null")
      << ",\"role\":\"" << facyl::toString(a.role) << "\",\"merged\":[";
  for (std::size_t k = 0; k < a.merged.size(); ++k)
    out << (k ? "," : "") << a.merged[k];
  out << "],\"track\":" << (t ? trackStateJson(tracker, *t, digits) : std::string("null"));
  return out.str();
}

/** ,"stream":{frame, scene, anchored, new_scene, skipped, registered},"tracks":[...]: where the
 * frame was and every live track (tentative ones too), each with "track_id", its state, the
 * object of this frame it was matched to (null: none), "merged_into", "centroid" and
 * "cylinder" (the tracked estimate in this frame, null without). */
inline std::string
streamJson(const facyl::CylinderTracker& tracker,
           const std::vector<facyl::RecognizedObject>* objects, int digits = 6)
{
  const auto& info = tracker.getFrameInfo();
  std::ostringstream out;
  out << ",\"stream\":{\"frame\":" << info.frame - 1 << ",\"scene\":" << info.scene
      << ",\"anchored\":" << (info.anchored ? "true" : "false")
      << ",\"new_scene\":" << (info.new_scene ? "true" : "false")
      << ",\"skipped\":" << (info.skipped ? "true" : "false")
      << ",\"registered\":" << info.registered << "},\"tracks\":[";
  bool first = true;
  for (const auto& t : tracker.getTracks()) {
    const facyl::RecognizedObject* seen =
      objects && t.object >= 0 && static_cast<std::size_t>(t.object) < objects->size()
        ? &(*objects)[static_cast<std::size_t>(t.object)]
        : nullptr;
    out << (first ? "" : ",") << "{\"track_id\":" << t.id
        << ",\"object\":" << (t.object >= 0 ? std::to_string(t.object) : "null")
        << ",\"merged_into\":" << (t.merged_into >= 0 ? std::to_string(t.merged_into) : "null")
        << ",\"state\":" << trackStateJson(tracker, t, digits)
        << ",\"centroid\":" << vector(tracker.centroidInFrame(t), digits) << ",\"cylinder\":"
        << (t.has_cylinder ? cylinderJson(trackedCylinder(tracker, t, seen), false, digits)
                           : std::string("null"))
        << "}";
    first = false;
  }
  out << "]";
  return out.str();
}

/** The tracked frame's JSON object without its closing brace: sceneJson's fields of the
 * objects as trackedView shows them, each with trackFieldsJson's fields, then streamJson. */
template <typename PointT>
std::string
trackedSceneJson(const std::string& file, const pcl::PointCloud<PointT>& cloud,
                 const facyl::TabletopCylinderRecognizer<PointT>& rec,
                 const std::vector<facyl::RecognizedObject>& objects,
                 const facyl::RecognitionTiming& timing, const facyl::CylinderTracker& tracker,
                 int digits = 6)
{
  const auto& assignments = tracker.getAssignments();
  std::vector<facyl::RecognizedObject> shown;
  shown.reserve(objects.size());
  for (std::size_t k = 0; k < objects.size(); ++k)
    shown.push_back(trackedView(
      objects[k], k < assignments.size() ? assignments[k] : facyl::TrackAssignment{}, tracker));
  // One writer for the scene's fields (sceneJson); each object's text, exactly as it wrote it,
  // gets the tracking fields before its closing brace.
  std::string scene = sceneJson(file, cloud, rec, shown, timing, digits);
  std::size_t from = scene.find("\"objects\":[");
  for (std::size_t k = 0; k < objects.size() && from != std::string::npos; ++k) {
    const std::string text = objectJson(k, shown[k], digits);
    const std::size_t at = scene.find(text, from);
    if (at == std::string::npos)
      break;
    const std::string extra = trackFieldsJson(
      objects[k], k < assignments.size() ? assignments[k] : facyl::TrackAssignment{}, tracker,
      digits);
    scene.insert(at + text.size() - 1, extra);
    from = at + text.size() + extra.size();
  }
  return scene + streamJson(tracker, &objects, digits);
}

} // namespace facyl_cli
