/*
 * facyl: fast cylinder detection for PCL.
 * CylinderTracker, and explicit instantiations of trackerViewOf for the common point types.
 */
#include <facyl/tracking/impl/cylinder_tracker.hpp>
#include <facyl/tracking/tracker_steps.h>

#include <facyl/features/polygon.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace facyl {

namespace {

/** True when \a rotation (the old world into the new plane's frame) keeps the old world's
 * plane (z = 0) within \a max_angle of the new one. */
bool
parallelPlanes(const Eigen::Matrix3f& rotation, float max_angle)
{
  return std::acos(std::min(1.f, std::abs(rotation(2, 2)))) <= max_angle;
}

float
square(float v)
{
  return v * v;
}

} // namespace

std::string
validate(const CylinderTrackerParameters& p)
{
  std::ostringstream why;
  const auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };
  if (!in(p.confirm_hits, 1, 100))
    why << "confirm_hits " << p.confirm_hits << " is not in [1, 100]; ";
  if (!in(p.max_misses, 1, 1000))
    why << "max_misses " << p.max_misses << " is not in [1, 1000]; ";
  if (!in(p.max_tentative_misses, 0, 100))
    why << "max_tentative_misses " << p.max_tentative_misses << " is not in [0, 100]; ";
  if (!in(p.max_occluded, 0, 100000))
    why << "max_occluded " << p.max_occluded << " is not in [0, 100000]; ";
  if (!in(p.max_out_of_view, 0, 1000000))
    why << "max_out_of_view " << p.max_out_of_view << " is not in [0, 1000000]; ";
  if (!in(p.see_through_misses, 1, 1000))
    why << "see_through_misses " << p.see_through_misses << " is not in [1, 1000]; ";
  if (!(p.max_plane_angle > 0.f && p.max_plane_angle <= 1.5708f))
    why << "max_plane_angle " << p.max_plane_angle << " is not in (0, pi/2]; ";
  if (!(p.max_plane_offset > 0.f && std::isfinite(p.max_plane_offset)))
    why << "max_plane_offset " << p.max_plane_offset << " must be > 0; ";
  if (!in(p.support_switch_frames, 1, 1000))
    why << "support_switch_frames " << p.support_switch_frames << " is not in [1, 1000]; ";
  if (!in(p.min_overlap, 0, 1))
    why << "min_overlap " << p.min_overlap << " is not in [0, 1]; ";
  const auto& r = p.registration;
  if (!(r.search_radius > 0.f && std::isfinite(r.search_radius)))
    why << "registration.search_radius " << r.search_radius << " must be > 0; ";
  if (!(r.pair_tolerance > 0.f && std::isfinite(r.pair_tolerance)))
    why << "registration.pair_tolerance " << r.pair_tolerance << " must be > 0; ";
  if (!(r.max_yaw_change > 0.f && r.max_yaw_change <= 3.1416f))
    why << "registration.max_yaw_change " << r.max_yaw_change << " is not in (0, pi]; ";
  if (r.max_hypotheses < 1 || r.max_hypotheses > 1000000)
    why << "registration.max_hypotheses " << r.max_hypotheses << " is not in [1, 1e6]; ";
  const auto& a = p.association;
  for (const auto& [name, v] : {std::pair<const char*, float>{"sigma_position", a.sigma_position},
                                {"sigma_centroid", a.sigma_centroid},
                                {"sigma_radius", a.sigma_radius},
                                {"sigma_axis", a.sigma_axis},
                                {"gate", a.gate}})
    if (!(v > 0.f && std::isfinite(v)))
      why << "association." << name << " " << v << " must be > 0; ";
  if (!(p.fragment_margin >= 0.f && std::isfinite(p.fragment_margin)))
    why << "fragment_margin " << p.fragment_margin << " must be >= 0; ";
  for (const auto& [name, v] :
       {std::pair<const char*, float>{"measurement_centroid", p.measurement_centroid},
        {"measurement_extent", p.measurement_extent},
        {"huber_k", p.huber_k},
        {"confidence_limit", p.confidence_limit}})
    if (!(v > 0.f && std::isfinite(v)))
      why << name << " " << v << " must be > 0; ";
  for (const auto& [name, v] :
       {std::pair<const char*, float>{"process_position", p.process_position}})
    if (!(v >= 0.f && std::isfinite(v)))
      why << name << " " << v << " must be >= 0; ";
  if (!(p.shrink_weight > 0.f && p.shrink_weight <= 1.f))
    why << "shrink_weight " << p.shrink_weight << " is not in (0, 1]; ";
  if (!in(p.min_probability, 0, 1))
    why << "min_probability " << p.min_probability << " is not in [0, 1]; ";
  if (!(p.reference_quality > 0.f && std::isfinite(p.reference_quality)))
    why << "reference_quality " << p.reference_quality << " must be > 0; ";
  if (!in(p.history, 1, 1000))
    why << "history " << p.history << " is not in [1, 1000]; ";
  if (!(p.axis_agreement > 0.f && p.axis_agreement <= 1.5708f))
    why << "axis_agreement " << p.axis_agreement << " is not in (0, pi/2]; ";
  if (!in(p.decision_probability, 0.5, 0.99))
    why << "decision_probability " << p.decision_probability << " is not in [0.5, 0.99]; ";
  std::string s = why.str();
  if (s.size() >= 2)
    s.resize(s.size() - 2);
  return s;
}

std::string
toString(TrackStatus s)
{
  switch (s) {
  case TrackStatus::Seen:
    return "seen";
  case TrackStatus::Missed:
    return "missed";
  case TrackStatus::Occluded:
    return "occluded";
  case TrackStatus::Merged:
    return "merged";
  case TrackStatus::SeenThrough:
    return "seen_through";
  case TrackStatus::OutOfView:
    return "out_of_view";
  case TrackStatus::NotUpdated:
    return "not_updated";
  }
  return "unknown";
}

std::string
toString(TrackAssignment::Role r)
{
  switch (r) {
  case TrackAssignment::Role::Ignored:
    return "ignored";
  case TrackAssignment::Role::Matched:
    return "matched";
  case TrackAssignment::Role::Started:
    return "started";
  case TrackAssignment::Role::Fragment:
    return "fragment";
  }
  return "unknown";
}

CylinderModel
CylinderTrack::worldCylinder() const
{
  CylinderModel m;
  m.axis = axis;
  m.radius = radius;
  m.base = centre + lo * axis;
  m.top = centre + hi * axis;
  m.point_on_axis = m.base;
  m.height = hi - lo;
  return m;
}

int
tableIndex(const std::vector<SupportPlane>& supports, const std::vector<float>& table)
{
  if (table.size() != 4)
    return -1;
  const Eigen::Vector4f t(table[0], table[1], table[2], table[3]);
  int best = -1;
  float best_d = 1e-3f;
  for (std::size_t k = 0; k < supports.size(); ++k) {
    const float d = (supports[k].plane - t).norm();
    if (d < best_d) {
      best_d = d;
      best = static_cast<int>(k);
    }
  }
  return best;
}

void
CylinderTracker::setParameters(const CylinderTrackerParameters& params)
{
  const std::string why = validate(params);
  if (!why.empty())
    throw std::invalid_argument("facyl::CylinderTracker::setParameters: " + why);
  params_ = params;
}

const CylinderTrack*
CylinderTracker::findTrack(int id) const
{
  for (const auto& t : tracks_)
    if (t.id == id)
      return &t;
  return nullptr;
}

bool
CylinderTracker::isCylinder(const CylinderTrack& t) const
{
  return t.confirmed && t.has_cylinder && t.decided_cylinder;
}

CylinderModel
CylinderTracker::cylinderInFrame(const CylinderTrack& t) const
{
  const Eigen::Affine3f to_frame = getWorldToFrame();
  CylinderModel m = t.worldCylinder();
  m.base = to_frame * m.base;
  m.top = to_frame * m.top;
  m.point_on_axis = m.base;
  m.axis = (to_frame.linear() * m.axis).normalized();
  const Eigen::Vector3f up = world_on_support_ ? Eigen::Vector3f(to_frame.linear().col(2))
                                               : Eigen::Vector3f(-sensor_pose_.linear().col(1));
  orientCylinder(m, up, sensor_pose_.translation());
  return m;
}

void
CylinderTracker::skipFrame()
{
  TrackerFrameInfo info;
  info.frame = info_.frame + 1;
  info.scene = info_.scene;
  info.skipped = true;
  info_ = info;
  assignments_.clear();
  for (auto& t : tracks_) {
    t.status = TrackStatus::NotUpdated;
    t.object = -1;
    t.merged_into = -1;
  }
}

void
CylinderTracker::reset()
{
  tracks_.clear();
  assignments_.clear();
  has_pose_ = false;
  has_velocity_ = velocity_in_plane_ = false;
  world_on_support_ = false;
  prior_held_ = false;
  prior_unseen_ = prior_challenged_ = 0;
  plane_angle_innovations_.clear();
  plane_offset_innovations_.clear();
  seen_extents_.clear();
  frame_to_world_ = Eigen::Affine3f::Identity();
}

void
CylinderTracker::endTracks()
{
  tracks_.clear();
}

void
CylinderTracker::predict()
{
  const float qp = square(params_.process_position);
  for (auto& t : tracks_) {
    ++t.age;
    t.var_centroid += qp;
    t.var_extent += qp;
    t.status = TrackStatus::NotUpdated;
    t.object = -1;
    t.merged_into = -1;
  }
}

bool
CylinderTracker::update(const std::vector<SupportPlane>& supports, int table,
                        const std::vector<RecognizedObject>& objects, const TrackerView& view,
                        const SupportPriorResult& prior)
{
  ++info_.frame;
  TrackerFrameInfo info;
  info.frame = info_.frame;
  info.scene = info_.scene;
  assignments_.assign(objects.size(), TrackAssignment{});
  if (table < -1 || table >= static_cast<int>(supports.size())) {
    PCL_ERROR("[facyl::%s::update] table index %d is not -1 or an index into the %zu supports; "
              "the frame is skipped, the tracks are kept\n",
              getClassName().c_str(), table, supports.size());
    --info_.frame;
    skipFrame();
    assignments_.assign(objects.size(), TrackAssignment{});
    return false;
  }
  predict();
  sensor_pose_ = view.sensor_pose;
  locateFrame(supports, table, objects, view, prior, info);

  std::vector<TrackObservation> obs(objects.size());
  for (std::size_t i = 0; i < objects.size(); ++i)
    obs[i] = observe(objects[i], frame_to_world_, params_.decision_probability);
  const std::vector<int> match = associate(obs, tracks_, params_.association);
  const std::vector<char> matched =
    correctMatched(objects, obs, match, info.anchored ? 1.f : 0.25f);
  startOrAttach(obs, match, matched);
  updateUnseen(view, objects, obs, matched, info.anchored);
  joinAndEndTracks();
  info_ = info;
  return true;
}

Eigen::Affine3f
CylinderTracker::predictedPose() const
{
  // The camera keeps its motion between two frames (constant velocity) when the last two
  // frames were anchored one after the other; else it stays where it was.
  if (!has_velocity_)
    return frame_to_world_;
  // The last motion in the world; after a frame anchored on the prior's plane itself
  // (SupportPriorResult::predicted) only its motion along the plane: a tilt or a height it
  // cannot have measured would go on frame after frame.
  const Eigen::Affine3f motion = frame_to_world_ * previous_frame_to_world_.inverse();
  return (velocity_in_plane_ ? inPlaneComponent(motion).asAffine() : motion) * frame_to_world_;
}

SupportPrior
CylinderTracker::expectedPlane(const Eigen::Affine3f& cloud_to_world) const
{
  SupportPrior prior;
  const Eigen::Affine3f world_to_cloud = cloud_to_world.inverse();
  Eigen::Vector3f normal = (world_to_cloud.linear() * Eigen::Vector3f::UnitZ()).normalized();
  const Eigen::Vector3f origin = world_to_cloud * Eigen::Vector3f::Zero();
  if (normal.dot(sensor_pose_.translation() - origin) < 0.f) // towards the sensor
    normal = -normal;
  prior.plane = Eigen::Vector4f(normal.x(), normal.y(), normal.z(), -normal.dot(origin));
  // Where the plane was seen last, on it.
  const Eigen::Vector3f seen = world_to_cloud * anchor_centre_;
  prior.centre = seen - normal * (normal.dot(seen) + prior.plane[3]);
  prior.max_angle = predictionTolerance(plane_angle_innovations_, params_.max_plane_angle);
  prior.max_offset = predictionTolerance(plane_offset_innovations_, params_.max_plane_offset);
  // What the last frames saw of it: the corners of the hull of their regions' hulls.
  std::vector<Eigen::Vector2f> corners;
  for (const auto& e : seen_extents_)
    corners.insert(corners.end(), e.begin(), e.end());
  for (const auto& c : convexHull2D(std::move(corners)))
    prior.extent.push_back(world_to_cloud * Eigen::Vector3f(c.x(), c.y(), 0.f));
  return prior;
}

void
CylinderTracker::recordExtent(const SupportPlane& anchor, const Eigen::Affine3f& cloud_to_world)
{
  const Eigen::Affine3f to_world = cloud_to_world * anchor.frame;
  std::vector<Eigen::Vector2f> hull;
  for (const auto& v : anchor.polygon)
    hull.push_back((to_world * Eigen::Vector3f(v.x(), v.y(), 0.f)).head<2>());
  seen_extents_.push_back(std::move(hull));
  if (seen_extents_.size() > static_cast<std::size_t>(params_.history))
    seen_extents_.erase(seen_extents_.begin(), seen_extents_.end() - params_.history);
}

SupportPrior
CylinderTracker::supportPrior() const
{
  if (!has_pose_ || !world_on_support_ || !prior_held_)
    return SupportPrior{};
  return expectedPlane(predictedPose());
}

void
CylinderTracker::recordPlaneInnovation(const SupportPrior& expected, const Eigen::Vector4f& plane)
{
  // What consistentWithPrior tests: the angle between the normals, the measured plane's height
  // at the expected centre.
  const float cos_angle = std::min(1.f, std::abs(expected.plane.head<3>().dot(plane.head<3>())));
  plane_angle_innovations_.push_back(std::acos(cos_angle));
  plane_offset_innovations_.push_back(plane.head<3>().dot(expected.centre) + plane[3]);
  for (auto* v : {&plane_angle_innovations_, &plane_offset_innovations_})
    if (v->size() > static_cast<std::size_t>(params_.history))
      v->erase(v->begin(), v->end() - params_.history);
}

void
CylinderTracker::keepTracksPlane(const std::vector<SupportPlane>& supports,
                                 const SupportPriorResult& prior, AnchorChoice& choice,
                                 TrackerFrameInfo& info)
{
  info.prior_held = prior_held_;
  info.prior_given = prior.given;
  info.prior_challenged = prior.challenged;
  info.prior_predicted = prior.predicted;
  if (!prior_held_ || supports.empty()) // nothing to keep, or a frame that cannot tell
    return;
  prior_unseen_ = choice.plane_jump ? prior_unseen_ + 1 : 0;
  prior_challenged_ = prior.challenged ? prior_challenged_ + 1 : 0;
  info.prior_unseen_frames = prior_unseen_;
  info.prior_challenged_frames = prior_challenged_;
  if (prior_challenged_ >= params_.support_switch_frames) {
    // The frame alone would have chosen another family of supports, frame after frame: the
    // next frame chooses alone.
    prior_held_ = false;
    prior_challenged_ = 0;
  }
  if (!choice.plane_jump)
    return;
  if (prior_unseen_ < params_.support_switch_frames)
    choice = AnchorChoice{}; // another plane for a frame or a few: the pose is predicted
  else
    prior_unseen_ = 0; // the tracks' plane is out of view: the frame's own anchors, as ever
}

void
CylinderTracker::locateFrame(const std::vector<SupportPlane>& supports, int table,
                             const std::vector<RecognizedObject>& objects, const TrackerView& view,
                             const SupportPriorResult& prior, TrackerFrameInfo& info)
{
  const bool continuing = has_pose_ && world_on_support_;
  const Eigen::Affine3f predicted = predictedPose();
  const Eigen::Affine3f last_pose = frame_to_world_;
  const bool last_anchored = info_.anchored && !info_.skipped;
  // A support continues the tracks' plane when it is the support prior's plane (one test for
  // both).
  const SupportPrior expected = continuing ? expectedPlane(predicted) : SupportPrior{};
  AnchorChoice choice =
    chooseAnchor(supports, table, objects, expected.valid() ? &expected : nullptr);
  const bool was_held = prior_held_;
  keepTracksPlane(supports, prior, choice, info);
  // An anchor that is the prior's plane moved to the few points near it (a top without depth,
  // SupportPriorResult::predicted) tells neither the plane's innovation nor the camera's motion
  // off the plane.
  const bool predicted_anchor =
    prior.predicted && choice.anchor >= 0 && choice.anchor == prior.support;
  if (expected.valid() && choice.anchor >= 0 && !choice.plane_jump && !predicted_anchor)
    recordPlaneInnovation(expected, supports[static_cast<std::size_t>(choice.anchor)].plane);

  Eigen::Affine3f pose = has_pose_ ? predicted : Eigen::Affine3f::Identity();
  bool new_scene = false;
  if (choice.anchor >= 0) {
    const Eigen::Affine3f plane_to_cloud = supports[static_cast<std::size_t>(choice.anchor)].frame;
    const Eigen::Affine3f cloud_to_plane = plane_to_cloud.inverse();
    if (!continuing) {
      if (has_pose_) { // tracks of frames without a support: into the support's plane
        const Eigen::Affine3f old_to_new = cloud_to_plane * frame_to_world_.inverse();
        for (auto& t : tracks_)
          transformTrack(t, old_to_new);
      }
      pose = cloud_to_plane;
      world_on_support_ = true;
    }
    else
      new_scene = registerFrame(objects, view, plane_to_cloud, cloud_to_plane, predicted, last_pose,
                                choice.plane_jump, !predicted_anchor, pose, info);
    info.anchored = true;
  }
  else if (!has_pose_)
    world_on_support_ = false; // the world is this cloud's frame until a support is seen
  if (choice.anchor >= 0) {
    // The world's plane is the anchor's from now on: another plane, or the same one started
    // anew, forgets the extent seen.
    if (!continuing || new_scene || choice.plane_jump)
      seen_extents_.clear();
    recordExtent(supports[static_cast<std::size_t>(choice.anchor)], pose);
    anchor_centre_ = pose * supports[static_cast<std::size_t>(choice.anchor)].frame.translation();
    // Held from the first anchored frame on; after a release, from the frame after the next.
    prior_held_ = prior_held_ || !was_held;
  }
  // (After a plane jump the last pose is in the old plane's world.)
  has_velocity_ = has_pose_ && info.anchored && last_anchored && !new_scene && !choice.plane_jump;
  velocity_in_plane_ = predicted_anchor;
  previous_frame_to_world_ = last_pose;
  frame_to_world_ = pose;
  has_pose_ = true;
  info.anchor = choice.anchor;
  info.new_scene = new_scene;
  info.scene = info_.scene;
}

bool
CylinderTracker::registerFrame(const std::vector<RecognizedObject>& objects,
                               const TrackerView& view, const Eigen::Affine3f& plane_to_cloud,
                               const Eigen::Affine3f& cloud_to_plane,
                               const Eigen::Affine3f& predicted, const Eigen::Affine3f& last_pose,
                               bool plane_jump, bool may_be_new, Eigen::Affine3f& pose,
                               TrackerFrameInfo& info)
{
  std::vector<TrackObservation> local(objects.size());
  for (std::size_t i = 0; i < objects.size(); ++i)
    local[i] = observe(objects[i], cloud_to_plane, params_.decision_probability);
  // On a jump, the old world (as the predicted pose puts it) into the new plane's frame.
  const Eigen::Affine3f onto_new = cloud_to_plane * predicted.inverse();
  // Another support of the room (parallel to the tracks' plane as predicted) becomes the
  // world's plane: the tracks move into its frame (their heights were over the old plane) and
  // are registered from there. A plane that is not parallel leaves them where they were: only
  // a registration by chance keeps the scene.
  const bool moved = plane_jump && parallelPlanes(onto_new.linear(), params_.max_plane_angle);
  if (moved)
    for (auto& t : tracks_)
      transformTrack(t, onto_new);
  const Eigen::Affine3f to_plane_world = moved ? onto_new : Eigen::Affine3f::Identity();
  const Eigen::Affine3f to_world = to_plane_world * predicted, last = to_plane_world * last_pose;
  const PlanarRigid prior = inPlaneComponent(to_world * plane_to_cloud);
  const PlanarRigid still = inPlaneComponent(last * plane_to_cloud);
  // Across a plane jump only the tracks of the old plane tell whether the scene goes on: those
  // started in the frames without it (their pose predicted) would match their own objects.
  const auto started_since = [&](const CylinderTrack& t) {
    return t.age <= static_cast<std::size_t>(std::max(0, info.prior_unseen_frames));
  };
  std::vector<CylinderTrack> before;
  if (plane_jump)
    for (const auto& t : tracks_)
      if (!started_since(t))
        before.push_back(t);
  const PlanarRegistration reg =
    registerObservations(local, plane_jump ? before : tracks_, prior, params_.registration,
                         has_velocity_ ? &still : nullptr);
  pose = reg.transform.asAffine() * cloud_to_plane;
  info.registration = reg.transform;
  info.registered = reg.matched_objects;

  // A new scene? The confirmed tracks expected in view against those matched.
  std::size_t confirmed = 0, expected = 0, seen = 0;
  for (const auto& o : local)
    seen += o.valid;
  const Eigen::Affine3f world_to_cloud = pose.inverse();
  for (const auto& t : tracks_) {
    if (!t.confirmed)
      continue;
    ++confirmed;
    int inside = 0;
    const TrackStatus s =
      viewStatus(t, world_to_cloud, TrackerView{view.camera, view.sensor_pose, {}}, {}, inside);
    expected += s != TrackStatus::OutOfView;
  }
  if (!may_be_new ||
      !isNewScene(confirmed, expected, seen, reg.matched_objects, plane_jump, params_.min_overlap))
    return false;
  // A new scene: the tracks of the old one end; those started in the frames without its plane
  // are of the new one, and move into its frame where the predicted pose put them.
  std::vector<CylinderTrack> young;
  if (plane_jump)
    for (auto& t : tracks_)
      if (started_since(t)) {
        if (!moved)
          transformTrack(t, onto_new);
        young.push_back(std::move(t));
      }
  endTracks();
  tracks_ = std::move(young);
  ++info_.scene;
  pose = cloud_to_plane;
  return true;
}

std::vector<char>
CylinderTracker::correctMatched(const std::vector<RecognizedObject>& objects,
                                const std::vector<TrackObservation>& obs,
                                const std::vector<int>& match, float weight)
{
  std::vector<char> matched_track(tracks_.size(), 0);
  for (std::size_t i = 0; i < obs.size(); ++i) {
    if (!obs[i].valid) {
      if (objects[i].cluster.centroid.size() == 3 && !objects[i].cluster.centroid.allFinite())
        PCL_WARN("[facyl::%s::update] object %zu has no finite centroid: ignored\n",
                 getClassName().c_str(), i);
      continue;
    }
    if (match[i] < 0)
      continue;
    auto& t = tracks_[static_cast<std::size_t>(match[i])];
    correctTrack(t, obs[i], weight, params_);
    t.object = static_cast<int>(i);
    matched_track[static_cast<std::size_t>(match[i])] = 1;
    assignments_[i].role = TrackAssignment::Role::Matched;
    assignments_[i].track_id = t.id;
  }
  return matched_track;
}

void
CylinderTracker::startOrAttach(const std::vector<TrackObservation>& obs,
                               const std::vector<int>& match,
                               const std::vector<char>& matched_track)
{
  for (std::size_t i = 0; i < obs.size(); ++i) {
    if (!obs[i].valid || match[i] >= 0)
      continue;
    int fragment_of = -1;
    float best_gain = 0.f;
    for (std::size_t j = 0; j < matched_track.size(); ++j) {
      if (!matched_track[j])
        continue;
      const auto& t = tracks_[j];
      const float gain = fragmentGain(obs[i], t, obs[static_cast<std::size_t>(t.object)],
                                      params_.fragment_margin, params_.association.sigma_centroid);
      if (gain > best_gain) {
        best_gain = gain;
        fragment_of = static_cast<int>(j);
      }
    }
    if (fragment_of >= 0) {
      assignments_[i].role = TrackAssignment::Role::Fragment;
      assignments_[i].track_id = tracks_[static_cast<std::size_t>(fragment_of)].id;
      continue;
    }
    tracks_.push_back(newTrack(obs[i], next_id_++, static_cast<int>(i), params_));
    assignments_[i].role = TrackAssignment::Role::Started;
    assignments_[i].track_id = tracks_.back().id;
  }
}

void
CylinderTracker::updateUnseen(const TrackerView& view, const std::vector<RecognizedObject>& objects,
                              const std::vector<TrackObservation>& obs,
                              const std::vector<char>& matched_track, bool anchored)
{
  const Eigen::Affine3f world_to_cloud = getWorldToFrame();
  for (std::size_t j = 0; j < matched_track.size(); ++j) {
    if (matched_track[j])
      continue;
    auto& t = tracks_[j];
    if (!anchored) {
      // The frame cannot tell where it is: confirmed tracks' misses do not count. A tentative
      // track must be seen again, anchored or not (else a stream without a support would pile
      // up every frame's objects as tracks).
      t.status = TrackStatus::NotUpdated;
      if (!t.confirmed)
        ++t.misses;
      continue;
    }
    int inside = -1;
    t.status = viewStatus(t, world_to_cloud, view, objects, inside);
    if (!t.confirmed) { // a tentative track must be seen again, wherever it is
      ++t.misses;
      continue;
    }
    switch (t.status) {
    case TrackStatus::OutOfView:
      ++t.out_of_view;
      break;
    case TrackStatus::Occluded:
      ++t.occluded;
      break;
    case TrackStatus::Merged: {
      auto& a = assignments_[static_cast<std::size_t>(inside)];
      if (a.role == TrackAssignment::Role::Started && t.seen_through == 0) {
        takeBack(t, inside, obs[static_cast<std::size_t>(inside)]);
        break;
      }
      ++t.occluded;
      for (std::size_t q = 0; q < matched_track.size(); ++q)
        if (matched_track[q] && tracks_[q].object == inside)
          t.merged_into = tracks_[q].id;
      a.merged.push_back(t.id);
      break;
    }
    case TrackStatus::SeenThrough:
      t.misses += params_.see_through_misses;
      ++t.seen_through;
      break;
    default:
      t.misses += 1;
      break;
    }
  }
}

void
CylinderTracker::takeBack(CylinderTrack& t, int object, const TrackObservation& o)
{
  // The object at its place started a new track: it is this one, seen with a fit too different
  // to match (the new track goes; the geometry is not updated from it).
  auto& a = assignments_[static_cast<std::size_t>(object)];
  for (auto& other : tracks_)
    if (other.id == a.track_id)
      other.misses = params_.max_tentative_misses + 1;
  filterPoint(t.centroid, t.var_centroid, o.geometry.centroid, square(params_.measurement_centroid),
              params_.huber_k);
  recordEvidence(t, o.p, t.hits + 1, params_);
  ++t.hits;
  t.misses = t.occluded = t.out_of_view = t.seen_through = 0;
  t.status = TrackStatus::Seen;
  t.object = object;
  a.role = TrackAssignment::Role::Matched;
  a.track_id = t.id;
}

void
CylinderTracker::joinAndEndTracks()
{
  // Two tracks of one object (a new one started while the old one was merged into another
  // segment or its fit changed): the younger one goes into the older one, whose id stays.
  for (std::size_t j = 0; j < tracks_.size(); ++j)
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      auto& older = tracks_[i];
      auto& younger = tracks_[j];
      if (i == j || !areOneObject(older, younger, params_.association))
        continue;
      absorbTrack(older, younger, params_.history, params_.confidence_limit);
      decide(older, false, params_);
      for (auto& a_k : assignments_) {
        if (a_k.track_id == younger.id)
          a_k.track_id = older.id;
        for (auto& id : a_k.merged)
          if (id == younger.id)
            id = older.id;
      }
    }
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const CylinderTrack& t) { return trackEnded(t, params_); }),
                tracks_.end());
  std::sort(tracks_.begin(), tracks_.end(),
            [](const CylinderTrack& a, const CylinderTrack& b) { return a.id < b.id; });
}

} // namespace facyl

FACYL_INSTANTIATE_trackerViewOf(pcl::PointXYZ)
FACYL_INSTANTIATE_trackerViewOf(pcl::PointXYZRGB)
FACYL_INSTANTIATE_trackerViewOf(pcl::PointXYZRGBA)
