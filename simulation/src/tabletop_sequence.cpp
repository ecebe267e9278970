/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/simulation/random.h>
#include <facyl/simulation/tabletop_sequence.h>
#include <facyl/tools/json_writer.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace facyl {

namespace {

constexpr float kTwoPi = 6.28318530718f;

/** Highest world z of \a o (the corners of its local bounding box). */
float
topOf(const SceneObject& o)
{
  Eigen::Vector3f lo, hi;
  switch (o.cls) {
  case SceneClass::Box:
    lo = Eigen::Vector3f(-0.5f * o.size.x(), -0.5f * o.size.y(), 0.f);
    hi = Eigen::Vector3f(0.5f * o.size.x(), 0.5f * o.size.y(), o.size.z());
    break;
  case SceneClass::Sphere:
    lo = Eigen::Vector3f(-o.radius, -o.radius, 0.f);
    hi = Eigen::Vector3f(o.radius, o.radius, 2.f * o.radius);
    break;
  case SceneClass::Bowl:
    lo = Eigen::Vector3f(-o.radius, -o.radius, 0.f);
    hi = Eigen::Vector3f(o.radius, o.radius, o.radius);
    break;
  default: // cylinders (a handle sticks out sideways only), cones
    lo = Eigen::Vector3f(-o.radius - (o.handle ? 0.03f : 0.f), -o.radius, 0.f);
    hi = Eigen::Vector3f(o.radius + (o.handle ? 0.03f : 0.f), o.radius, o.height);
  }
  float top = -1e9f;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3f corner(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(),
                                 k & 4 ? hi.z() : lo.z());
    top = std::max(top, (o.pose * corner).z());
  }
  return top;
}

/** The object to take away or put down: nothing stands on it or leans against it; a cylinder
 * when there is one. -1 when there is none. */
int
changeableObject(const TabletopScene& scene, Random& rng)
{
  std::vector<int> free, cylinders;
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    bool held = false;
    for (const auto& o : scene.objects) {
      if (o.support == static_cast<int>(k))
        held = true;
      if (o.leaning &&
          std::find(o.touches.begin(), o.touches.end(), static_cast<int>(k)) != o.touches.end())
        held = true;
    }
    if (held)
      continue;
    free.push_back(static_cast<int>(k));
    if (scene.objects[k].cls == SceneClass::Cylinder)
      cylinders.push_back(static_cast<int>(k));
  }
  const auto& pool = cylinders.empty() ? free : cylinders;
  if (pool.empty())
    return -1;
  return pool[static_cast<std::size_t>(rng.integer(0, static_cast<int>(pool.size()) - 1))];
}

} // namespace

std::string
toString(TabletopSequenceParameters::Change c)
{
  switch (c) {
  case TabletopSequenceParameters::Change::Remove:
    return "remove";
  case TabletopSequenceParameters::Change::Add:
    return "add";
  default:
    return "none";
  }
}

bool
parseSequenceChange(const std::string& name, TabletopSequenceParameters::Change& c)
{
  if (name == "none")
    c = TabletopSequenceParameters::Change::None;
  else if (name == "remove")
    c = TabletopSequenceParameters::Change::Remove;
  else if (name == "add")
    c = TabletopSequenceParameters::Change::Add;
  else
    return false;
  return true;
}

std::string
validate(const TabletopSequenceParameters& p)
{
  std::ostringstream why;
  if (p.frames < 2 || p.frames > 100000)
    why << "frames " << p.frames << " is not in [2, 100000]; ";
  if (!(p.orbit >= 0.f && p.orbit <= 6.3f))
    why << "orbit " << p.orbit << " is not in [0, 6.3] rad; ";
  if (!(p.elevation_swing >= 0.f && p.elevation_swing <= 0.6f))
    why << "elevation_swing " << p.elevation_swing << " is not in [0, 0.6] rad; ";
  if (!(p.distance_swing >= 0.f && p.distance_swing <= 0.5f))
    why << "distance_swing " << p.distance_swing << " is not in [0, 0.5]; ";
  if (p.change_frame != 0 && p.frames >= 2 && p.change_frame >= p.frames)
    why << "change_frame " << p.change_frame << " is not in [1, frames - 1]; ";
  std::string s = why.str();
  if (s.size() >= 2)
    s.resize(s.size() - 2);
  return s;
}

bool
TabletopSequence::present(std::size_t object, std::size_t frame) const
{
  if (static_cast<int>(object) != changed_object)
    return object < scene.objects.size();
  if (change == TabletopSequenceParameters::Change::Remove)
    return frame < change_frame;
  if (change == TabletopSequenceParameters::Change::Add)
    return frame >= change_frame;
  return true;
}

TabletopScene
TabletopSequence::sceneAt(std::size_t frame) const
{
  TabletopScene s = scene;
  s.camera_to_world = cameras.at(frame);
  if (changed_object < 0 || present(static_cast<std::size_t>(changed_object), frame))
    return s;
  const int gone = changed_object;
  s.objects.erase(s.objects.begin() + gone);
  for (auto& o : s.objects) {
    if (o.support > gone)
      --o.support;
    std::vector<int> touches;
    for (const int k : o.touches)
      if (k != gone)
        touches.push_back(k > gone ? k - 1 : k);
    o.touches = std::move(touches);
  }
  return s;
}

TabletopSequence
generateTabletopSequence(const TabletopSceneParameters& scene_params,
                         const TabletopSequenceParameters& params)
{
  const std::string why = validate(params);
  if (!why.empty())
    throw std::invalid_argument("facyl::generateTabletopSequence: " + why);
  TabletopSequence seq;
  seq.scene = generateTabletopScene(scene_params);
  // The path's own random stream: the scene's draws are untouched.
  Random rng(scene_params.seed ^ 0x5E0E4CE5A11D0F00ull);
  const float direction = rng.chance(0.5) ? 1.f : -1.f;
  const float phase_elevation = rng.uniform(0.f, kTwoPi);
  const float phase_distance = rng.uniform(0.f, kTwoPi);

  // The first camera as generateTabletopScene placed it: eye, the point looked at (on the
  // optical axis at the target's height, 5 cm above the table), distance, elevation, azimuth
  // and roll.
  const Eigen::Isometry3f& first = seq.scene.camera_to_world;
  const Eigen::Vector3f eye = first.translation();
  const Eigen::Vector3f forward = first.linear().col(2);
  float along = forward.z() < -1e-3f ? (0.05f - eye.z()) / forward.z() : 1.f;
  along = std::min(std::max(along, 0.3f), 5.f);
  const Eigen::Vector3f target = eye + along * forward;
  const Eigen::Vector3f offset = eye - target;
  const float distance = offset.norm();
  const float elevation = std::asin(std::min(1.f, std::max(-1.f, offset.z() / distance)));
  const float azimuth = std::atan2(offset.x(), -offset.y());
  const auto lookAt = [](const Eigen::Vector3f& from, const Eigen::Vector3f& to) {
    const Eigen::Vector3f f = (to - from).normalized();
    Eigen::Vector3f right = f.cross(Eigen::Vector3f::UnitZ());
    if (right.norm() < 1e-6f)
      right = Eigen::Vector3f::UnitX();
    right.normalize();
    Eigen::Matrix3f r;
    r.col(0) = right;
    r.col(1) = f.cross(right);
    r.col(2) = f;
    return r;
  };
  const Eigen::Matrix3f roll = lookAt(eye, target).transpose() * first.linear();
  float tallest = 0.f;
  for (const auto& o : seq.scene.objects)
    tallest = std::max(tallest, topOf(o));

  seq.cameras.reserve(params.frames);
  for (std::size_t k = 0; k < params.frames; ++k) {
    const float s = static_cast<float>(k) / static_cast<float>(params.frames - 1);
    const float az = azimuth + direction * params.orbit * s;
    const float el =
      std::min(1.45f, std::max(0.26f, elevation + params.elevation_swing *
                                                    (std::sin(kTwoPi * s + phase_elevation) -
                                                     std::sin(phase_elevation))));
    float d = distance * (1.f + params.distance_swing * (std::sin(kTwoPi * s + phase_distance) -
                                                         std::sin(phase_distance)));
    d = std::max(d, (tallest - target.z() + scene_params.sensor.min_range + 0.05f) / std::sin(el));
    const Eigen::Vector3f e =
      target +
      d * Eigen::Vector3f(std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el));
    Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
    pose.linear() = lookAt(e, target) * roll;
    pose.translation() = e;
    seq.cameras.push_back(pose);
  }
  seq.cameras.front() = first; // exactly the scene's camera

  seq.change = params.change;
  if (params.change != TabletopSequenceParameters::Change::None) {
    seq.change_frame = params.change_frame ? params.change_frame : params.frames / 2;
    seq.changed_object = changeableObject(seq.scene, rng);
    if (seq.changed_object < 0)
      seq.change = TabletopSequenceParameters::Change::None;
  }
  return seq;
}

RenderedScene
renderSequenceFrame(const TabletopSequence& sequence, std::size_t frame,
                    const CameraIntrinsics& camera, const DepthSensorModel& sensor,
                    std::uint64_t seed)
{
  if (frame >= sequence.cameras.size())
    throw std::out_of_range("facyl::renderSequenceFrame: frame " + std::to_string(frame) +
                            " of a path of " + std::to_string(sequence.cameras.size()));
  RenderedScene out = renderTabletopScene(sequence.sceneAt(frame), camera, sensor, seed);
  const int gone = sequence.changed_object;
  if (gone >= 0 && !sequence.present(static_cast<std::size_t>(gone), frame)) {
    // Back to the sequence's numbering: ids of the objects after the absent one move up.
    const auto first_after = static_cast<std::uint16_t>(2 + gone);
    for (auto& id : out.object_id)
      if (id >= first_after && id < kFirstSceneryId)
        ++id;
    out.visible_pixels.insert(out.visible_pixels.begin() + gone, 0);
  }
  out.scene = sequence.scene;
  out.scene.camera_to_world = sequence.cameras[frame];
  return out;
}

std::uint64_t
sequenceFrameSeed(std::uint64_t seed, std::size_t frame)
{
  return seed * 100003ull + frame;
}

std::string
sequenceJson(const TabletopSequence& sequence)
{
  using facyl_cli::Json;
  Json j{{"frames", sequence.cameras.size()}, {"change", toString(sequence.change)}};
  if (sequence.changed_object >= 0) {
    j["changed_object"] = sequence.changed_object + 2;
    j["change_frame"] = sequence.change_frame;
  }
  else
    j["changed_object"] = nullptr;
  Json objects = Json::array();
  for (std::size_t i = 0; i < sequence.scene.objects.size(); ++i) {
    const auto& o = sequence.scene.objects[i];
    objects.push_back(Json{{"id", i + 2}, {"class", toString(o.cls)}, {"kind", o.kind}});
  }
  j["objects"] = objects;
  Json cameras = Json::array();
  for (std::size_t k = 0; k < sequence.cameras.size(); ++k) {
    const Eigen::Matrix4f m = sequence.cameras[k].matrix();
    Json pose = Json::array();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        pose.push_back(static_cast<double>(m(r, c)));
    Json present = Json::array();
    for (std::size_t i = 0; i < sequence.scene.objects.size(); ++i)
      if (sequence.present(i, k))
        present.push_back(i + 2);
    cameras.push_back(Json{{"frame", k}, {"camera_to_world", pose}, {"present", present}});
  }
  j["cameras"] = cameras;
  return facyl_cli::dumpJsonWithDigits(j, 7); // a float's 7 significant digits
}

} // namespace facyl
