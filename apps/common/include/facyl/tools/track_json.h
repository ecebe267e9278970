/*
 * facyl: a stream's frame as JSON, written by facyl_detect --track (one line per frame) and
 * returned by the Python module's Tracker.update() (the same fields, parsed). The scene's
 * fields are facyl_detect's (detect_json.h); tracking adds per object "track_id", "track",
 * "is_cylinder_frame" and "cylinder_frame", and per frame "stream" and "tracks".
 */
#pragma once

#include <facyl/tools/cylinder_json.h>
#include <facyl/tools/detect_json.h>
#include <facyl/tools/json_writer.h>

#include <facyl/tracking/cylinder_tracker.h>

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
inline Json
trackStateJson(const facyl::CylinderTracker& tracker, const facyl::CylinderTrack& t, int digits)
{
  Json j;
  j["confirmed"] = t.confirmed;
  j["status"] = facyl::toString(t.status);
  j["age"] = t.age;
  j["hits"] = t.hits;
  j["misses"] = t.misses;
  j["p_cylinder"] = jsonNumber(t.pCylinder(), digits);
  j["is_cylinder"] = tracker.isCylinder(t);
  return j;
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

/** The fields a tracked object adds to \a object (objectJson of trackedView):
 * "is_cylinder_frame" and "cylinder_frame" (the frame's own decision and fit), "track_id" (null
 * for an object the tracker could not use), "role" (matched, started, fragment: a piece of an
 * object matched in the same frame; ignored), "merged" (ids of tracks whose place lies inside
 * this object) and "track" (trackStateJson). */
inline void
addTrackFields(Json& object, const facyl::RecognizedObject& o, const facyl::TrackAssignment& a,
               const facyl::CylinderTracker& tracker, int digits = 6)
{
  const facyl::CylinderTrack* t = tracker.findTrack(a.track_id);
  object["is_cylinder_frame"] = o.is_cylinder;
  object["cylinder_frame"] =
    o.evidence.fitted ? cylinderObject(o.cylinder, false, digits) : Json(nullptr);
  object["track_id"] = a.track_id >= 0 ? Json(a.track_id) : Json(nullptr);
  object["role"] = facyl::toString(a.role);
  object["merged"] = a.merged;
  object["track"] = t ? trackStateJson(tracker, *t, digits) : Json(nullptr);
}

/** Adds "stream":{frame, scene, anchored, new_scene, skipped, registered} and "tracks":[...] to
 * \a frame: where the frame was and every live track (tentative ones too), each with
 * "track_id", its state, the object of this frame it was matched to (null: none),
 * "merged_into", "centroid" and "cylinder" (the tracked estimate in this frame, null
 * without). */
inline void
addStreamFields(Json& frame, const facyl::CylinderTracker& tracker,
                const std::vector<facyl::RecognizedObject>* objects, int digits = 6)
{
  const auto& info = tracker.getFrameInfo();
  Json& stream = frame["stream"];
  stream["frame"] = info.frame - 1;
  stream["scene"] = info.scene;
  stream["anchored"] = info.anchored;
  stream["new_scene"] = info.new_scene;
  stream["skipped"] = info.skipped;
  stream["registered"] = info.registered;
  Json& prior = stream["support_prior"];
  prior["held"] = info.prior_held;
  prior["given"] = info.prior_given;
  prior["challenged"] = info.prior_challenged;
  prior["predicted"] = info.prior_predicted;
  prior["unseen_frames"] = info.prior_unseen_frames;
  prior["challenged_frames"] = info.prior_challenged_frames;
  Json& tracks = frame["tracks"] = Json::array();
  for (const auto& t : tracker.getTracks()) {
    const facyl::RecognizedObject* seen =
      objects && t.object >= 0 && static_cast<std::size_t>(t.object) < objects->size()
        ? &(*objects)[static_cast<std::size_t>(t.object)]
        : nullptr;
    Json j;
    j["track_id"] = t.id;
    j["object"] = t.object >= 0 ? Json(t.object) : Json(nullptr);
    j["merged_into"] = t.merged_into >= 0 ? Json(t.merged_into) : Json(nullptr);
    j["state"] = trackStateJson(tracker, t, digits);
    j["centroid"] = jsonVector(tracker.centroidInFrame(t), digits);
    j["cylinder"] = t.has_cylinder
                      ? cylinderObject(trackedCylinder(tracker, t, seen), false, digits)
                      : Json(nullptr);
    tracks.push_back(std::move(j));
  }
}

/** The tracked frame's JSON object: sceneJson of the objects as trackedView shows them, each
 * with addTrackFields' fields, then addStreamFields'. */
template <typename PointT>
Json
trackedSceneJson(const std::string& file, const pcl::PointCloud<PointT>& cloud,
                 const facyl::TabletopCylinderRecognizer<PointT>& rec,
                 const std::vector<facyl::RecognizedObject>& objects,
                 const facyl::RecognitionTiming& timing, const facyl::CylinderTracker& tracker,
                 int digits = 6)
{
  const auto& assignments = tracker.getAssignments();
  const auto assignment = [&](std::size_t k) {
    return k < assignments.size() ? assignments[k] : facyl::TrackAssignment{};
  };
  std::vector<facyl::RecognizedObject> shown;
  shown.reserve(objects.size());
  for (std::size_t k = 0; k < objects.size(); ++k)
    shown.push_back(trackedView(objects[k], assignment(k), tracker));
  Json scene = sceneJson(file, cloud, rec, shown, timing, digits);
  for (std::size_t k = 0; k < objects.size(); ++k)
    addTrackFields(scene["objects"][k], objects[k], assignment(k), tracker, digits);
  addStreamFields(scene, tracker, &objects, digits);
  return scene;
}

} // namespace facyl_cli
