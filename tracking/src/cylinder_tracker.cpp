/*
 * facyl: fast cylinder detection for PCL.
 * CylinderTracker, and explicit instantiations of trackerViewOf for the common point types.
 */
#include <facyl/tracking/impl/cylinder_tracker.hpp>

#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace facyl {

namespace {

float
square(float v)
{
  return v * v;
}

/** Cosine of the largest tilt of an "upright" cylinder's axis from the support's normal. */
constexpr float kUprightCos = 0.88f; // 28 degrees

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
  return t.confirmed && t.has_cylinder && t.pCylinder() >= params_.min_probability;
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

struct CylinderTracker::Observation {
  bool valid{false};
  AssociationGeometry geometry;                                                ///< world
  Eigen::Vector3f base{Eigen::Vector3f::Zero()}, top{Eigen::Vector3f::Zero()}; ///< world
  float p{0.5f};      ///< evidence that it is a cylinder
  float quality{1.f}; ///< points x angular coverage of the fit (cylinders)
  int support{-1};
  std::size_t points{0};
};

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
  has_velocity_ = false;
  world_on_support_ = false;
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

namespace {

/** Turns a track's axis up (world z, the support's normal); lying ones keep theirs. */
void
axisUp(CylinderTrack& t)
{
  if (t.axis.z() < 0.f) {
    t.axis = -t.axis;
    const float lo = t.lo;
    t.lo = -t.hi;
    t.hi = -lo;
  }
}

void
transformTrack(CylinderTrack& t, const Eigen::Affine3f& m)
{
  t.centroid = m * t.centroid;
  t.centre = m * t.centre;
  t.axis = (m.linear() * t.axis).normalized();
  axisUp(t);
}

} // namespace

void
CylinderTracker::startTrack(const Observation& o, int object)
{
  CylinderTrack t;
  t.id = next_id_++;
  t.age = 1;
  t.hits = 1;
  t.status = TrackStatus::Seen;
  t.object = object;
  t.support = o.support;
  t.centroid = o.geometry.centroid;
  t.var_centroid = square(params_.measurement_centroid);
  t.log_odds = updateLogOdds(0.f, o.p, params_.confidence_limit);
  if (o.geometry.cylinder) {
    t.has_cylinder = true;
    t.cylinder_hits = 1;
    t.centre = o.geometry.centre;
    t.axis = o.geometry.axis;
    t.radius = o.geometry.radius;
    t.lo = -0.5f * o.geometry.height;
    t.hi = 0.5f * o.geometry.height;
    t.var_extent = square(params_.measurement_extent);
    t.fits.assign(1, CylinderTrack::Fit{t.axis, t.centre, t.radius, o.quality * o.quality});
    axisUp(t);
  }
  t.confirmed = t.hits >= static_cast<std::size_t>(params_.confirm_hits);
  tracks_.push_back(t);
}

void
CylinderTracker::correct(CylinderTrack& t, const Observation& o, float weight)
{
  const float k = params_.huber_k;
  filterPoint(t.centroid, t.var_centroid, o.geometry.centroid,
              square(params_.measurement_centroid) / weight, k);
  if (o.geometry.cylinder) {
    const auto& g = o.geometry;
    if (!t.has_cylinder) {
      t.has_cylinder = true;
      t.centre = g.centre;
      t.axis = g.axis;
      t.radius = g.radius;
      t.lo = -0.5f * g.height;
      t.hi = 0.5f * g.height;
      t.var_extent = square(params_.measurement_extent);
      t.fits.assign(1,
                    CylinderTrack::Fit{t.axis, t.centre, t.radius, o.quality * o.quality * weight});
    }
    else {
      // Observations count by what the frame saw of the object (reference_quality).
      const float scale =
        std::clamp(params_.reference_quality / std::max(o.quality, 1e-3f), 0.25f, 4.f) / weight;
      // The history: the axis most fits agree with, the line and radius they give.
      t.fits.push_back(
        CylinderTrack::Fit{g.axis, g.centre, g.radius, o.quality * o.quality * weight});
      if (t.fits.size() > static_cast<std::size_t>(params_.history))
        t.fits.erase(t.fits.begin(), t.fits.end() - params_.history);
      std::vector<Eigen::Vector3f> axes;
      std::vector<float> weights;
      for (const auto& f : t.fits) {
        axes.push_back(f.axis);
        weights.push_back(f.weight);
      }
      std::vector<char> agree;
      const Eigen::Vector3f axis = consensusAxis(axes, weights, params_.axis_agreement, &agree);
      if (axis.dot(t.axis) < 0.f) { // keep the extent's sense
        const float lo = t.lo;
        t.lo = -t.hi;
        t.hi = -lo;
      }
      t.axis = axis.dot(t.axis) < 0.f ? Eigen::Vector3f(-axis) : axis;
      // The line: where the agreeing fits' axes pass the plane across the axis at the centre,
      // a weighted median in each direction of that plane, twice.
      const Eigen::Vector3f e1 = t.axis.unitOrthogonal(), e2 = t.axis.cross(e1);
      for (int pass = 0; pass < 2; ++pass) {
        std::vector<float> u, v, w;
        for (std::size_t i = 0; i < t.fits.size(); ++i) {
          if (!agree[i])
            continue;
          const auto& f = t.fits[i];
          const Eigen::Vector3f a = f.axis.dot(t.axis) < 0.f ? Eigen::Vector3f(-f.axis) : f.axis;
          const Eigen::Vector3f q = f.centre + a * (t.centre - f.centre).dot(a) - t.centre;
          u.push_back(q.dot(e1));
          v.push_back(q.dot(e2));
          w.push_back(f.weight);
        }
        const float du = weightedMedian(u, w), dv = weightedMedian(v, w);
        if (std::isfinite(du) && std::isfinite(dv))
          t.centre += du * e1 + dv * e2;
      }
      std::vector<float> radii, radius_weights;
      for (std::size_t i = 0; i < t.fits.size(); ++i)
        if (agree[i]) {
          radii.push_back(t.fits[i].radius);
          radius_weights.push_back(t.fits[i].weight);
        }
      const float r = weightedMedian(radii, radius_weights);
      if (std::isfinite(r))
        t.radius = r;
      const float sb = (o.base - t.centre).dot(t.axis), st = (o.top - t.centre).dot(t.axis);
      filterExtent(t.lo, t.hi, t.var_extent, std::min(sb, st), std::max(sb, st),
                   square(params_.measurement_extent) * scale, params_.shrink_weight);
      const float mid = 0.5f * (t.lo + t.hi);
      t.centre += mid * t.axis;
      t.lo -= mid;
      t.hi -= mid;
    }
    axisUp(t);
    ++t.cylinder_hits;
  }
  t.log_odds = updateLogOdds(t.log_odds, o.p, params_.confidence_limit);
  t.support = o.support;
  ++t.hits;
  t.misses = 0;
  t.occluded = 0;
  t.out_of_view = 0;
  t.seen_through = 0;
  t.status = TrackStatus::Seen;
  if (t.hits >= static_cast<std::size_t>(params_.confirm_hits))
    t.confirmed = true;
}

TrackStatus
CylinderTracker::viewStatus(const CylinderTrack& t, const TrackerView& view,
                            const std::vector<RecognizedObject>& objects, int& inside) const
{
  inside = -1;
  const PinholeCamera& cam = view.camera;
  if (!cam.valid())
    return TrackStatus::Missed;
  const Eigen::Affine3f to_sensor = view.sensor_pose.inverse() * getWorldToFrame();
  const Eigen::Vector3f c = to_sensor * (t.has_cylinder ? t.centre : t.centroid);
  if (!(c.z() > 0.05f))
    return TrackStatus::OutOfView;
  const auto inImage = [&cam](const Eigen::Vector2f& uv) {
    return uv.x() >= 0.f && uv.y() >= 0.f && uv.x() <= cam.width - 1.f &&
           uv.y() <= cam.height - 1.f;
  };
  const Eigen::Vector2f uv = cam.project(c);
  if (!inImage(uv))
    return TrackStatus::OutOfView;
  if (!view.depth)
    return TrackStatus::Missed;

  // Probes: points of the object's surface facing the sensor, with their depth. A cylinder's
  // front at three heights (not at its base, where the support lies right behind it) and three
  // offsets across; another object's visible centroid and four points around it.
  struct Probe {
    Eigen::Vector3f p;
    float near_margin, far_margin;
  };
  std::vector<Probe> probes;
  const float tolerance = 0.025f + 0.005f * c.z() * c.z();
  if (t.has_cylinder) {
    const Eigen::Vector3f a = (to_sensor.linear() * t.axis).normalized();
    for (const float h : {0.3f, 0.55f, 0.8f}) {
      const Eigen::Vector3f q = to_sensor * (t.centre + t.axis * (t.lo + h * (t.hi - t.lo)));
      Eigen::Vector3f towards = q - a * q.dot(a); // from the sensor to the axis, across it
      if (!(towards.norm() > 1e-6f))
        continue;
      towards.normalize();
      const Eigen::Vector3f across = a.cross(towards);
      for (const float s : {-0.5f, 0.f, 0.5f})
        probes.push_back(
          {q + across * (s * t.radius) - towards * (t.radius * std::sqrt(1.f - s * s)), tolerance,
           tolerance});
    }
  }
  else {
    // The centroid of the visible points lies behind the visible surface, by up to the
    // object's depth: nearer surfaces count only well in front of it.
    const float d = 0.02f * c.z();
    for (const Eigen::Vector3f& o :
         {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(d, 0, 0), Eigen::Vector3f(-d, 0, 0),
          Eigen::Vector3f(0, d, 0), Eigen::Vector3f(0, -d, 0)})
      probes.push_back({c + o, tolerance + 0.08f, tolerance + 0.03f});
  }
  int finite = 0, nearer = 0, farther = 0;
  for (const auto& probe : probes) {
    if (!(probe.p.z() > 0.05f))
      continue;
    const Eigen::Vector2f q = cam.project(probe.p);
    if (!inImage(q))
      continue;
    const float d =
      view.depth(static_cast<int>(std::lround(q.x())), static_cast<int>(std::lround(q.y())));
    if (!std::isfinite(d))
      continue;
    ++finite;
    nearer += d < probe.p.z() - probe.near_margin;
    farther += d > probe.p.z() + probe.far_margin;
  }
  if (finite < 3)
    return TrackStatus::Missed;
  if (2 * nearer > finite)
    return TrackStatus::Occluded;
  if (2 * farther > finite)
    return TrackStatus::SeenThrough;
  // A surface at its depth: inside another object's segment (a merge), or nothing found there.
  const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const auto& b = objects[k].cluster.box;
    if (b[0] >= 0 && u >= b[0] && u <= b[2] && v >= b[1] && v <= b[3]) {
      inside = static_cast<int>(k);
      return TrackStatus::Merged;
    }
  }
  return TrackStatus::Missed;
}

bool
CylinderTracker::update(const std::vector<SupportPlane>& supports, int table,
                        const std::vector<RecognizedObject>& objects, const TrackerView& view)
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

  // ---- the anchor: the support that continues the tracks' plane, the table first
  std::vector<std::size_t> on(supports.size(), 0);
  for (const auto& o : objects)
    if (o.cluster.support >= 0 && o.cluster.support < static_cast<int>(supports.size()))
      ++on[static_cast<std::size_t>(o.cluster.support)];
  std::vector<int> preference;
  if (table >= 0)
    preference.push_back(table);
  std::vector<int> others;
  for (std::size_t k = 0; k < supports.size(); ++k)
    if (static_cast<int>(k) != table)
      others.push_back(static_cast<int>(k));
  std::stable_sort(others.begin(), others.end(), [&](int a, int b) {
    return on[static_cast<std::size_t>(a)] > on[static_cast<std::size_t>(b)];
  });
  preference.insert(preference.end(), others.begin(), others.end());
  preference.erase(
    std::remove_if(
      preference.begin(), preference.end(),
      [&](int k) { return !supports[static_cast<std::size_t>(k)].frame.matrix().allFinite(); }),
    preference.end());
  const bool continuing = has_pose_ && world_on_support_;
  // The camera keeps its motion between two frames (constant velocity) when the last two
  // frames were anchored one after the other; else it stays where it was.
  const Eigen::Affine3f predicted =
    has_velocity_
      ? Eigen::Affine3f(frame_to_world_ * (previous_frame_to_world_.inverse() * frame_to_world_))
      : frame_to_world_;
  const Eigen::Affine3f last_pose = frame_to_world_;
  const bool last_anchored = info_.anchored && !info_.skipped;
  const auto continues = [&](int k) {
    const Eigen::Affine3f m = predicted * supports[static_cast<std::size_t>(k)].frame;
    const float cos_angle = std::min(1.f, std::abs(m.linear().col(2).normalized().z()));
    return std::acos(cos_angle) <= params_.max_plane_angle &&
           std::abs(m.translation().z()) <= params_.max_plane_offset && m.linear().col(2).z() > 0.f;
  };
  int anchor = -1;
  bool plane_jump = false;
  for (const int k : preference)
    if (!continuing || continues(k)) {
      anchor = k;
      break;
    }
  if (anchor < 0 && !preference.empty()) {
    anchor = preference.front();
    plane_jump = true;
  }

  // ---- the frame's pose in the world
  const auto reference = [](const AssociationGeometry& g) {
    return g.cylinder ? g.centre : g.centroid;
  };
  const auto geometryOf = [](const CylinderTrack& t) {
    AssociationGeometry g;
    g.centroid = t.centroid;
    g.cylinder = t.has_cylinder;
    g.centre = t.centre;
    g.axis = t.axis;
    g.radius = t.radius;
    g.height = t.hi - t.lo;
    return g;
  };
  const auto observe = [&](const RecognizedObject& r, const Eigen::Affine3f& pose) {
    Observation o;
    o.valid = r.cluster.centroid.allFinite();
    o.support = r.cluster.support;
    o.points = r.cluster.indices.indices.size();
    o.geometry.centroid = pose * r.cluster.centroid;
    const auto& c = r.cylinder;
    if (r.is_cylinder && r.evidence.fitted && c.base.allFinite() && c.top.allFinite() &&
        c.axis.allFinite() && std::isfinite(c.radius) && c.radius > 0.f) {
      o.base = pose * c.base;
      o.top = pose * c.top;
      Eigen::Vector3f axis = o.top - o.base;
      if (axis.norm() < 1e-4f)
        axis = pose.linear() * c.axis;
      o.geometry.cylinder = true;
      o.geometry.axis = axis.normalized();
      o.geometry.centre = 0.5f * (o.base + o.top);
      o.geometry.radius = c.radius;
      o.geometry.height = (o.top - o.base).norm();
      o.quality = static_cast<float>(o.points) * std::max(0.05f, c.angular_coverage);
    }
    // The decision sets the side, the probability its strength.
    const float p = r.evidence.p_cylinder, side = params_.decision_probability;
    if (r.is_cylinder)
      o.p = std::isfinite(p) ? std::max(p, side) : side;
    else
      o.p = std::isfinite(p) ? std::min(p, 1.f - side) : 1.f - side;
    return o;
  };

  Eigen::Affine3f pose = has_pose_ ? predicted : Eigen::Affine3f::Identity();
  bool new_scene = false;
  if (anchor >= 0) {
    const Eigen::Affine3f plane_to_cloud = supports[static_cast<std::size_t>(anchor)].frame;
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
    else {
      const PlanarRigid prior = inPlaneComponent(predicted * plane_to_cloud);
      // Lying cylinders (axis within 30 degrees of the plane) are lines: their horizontal
      // direction fixes the yaw.
      const auto lyingAxis = [](const AssociationGeometry& g) -> Eigen::Vector2f {
        if (!g.cylinder || std::abs(g.axis.z()) > 0.5f)
          return Eigen::Vector2f::Zero();
        return g.axis.head<2>().normalized();
      };
      Eigen::Matrix2Xf from(2, static_cast<Eigen::Index>(objects.size()));
      Eigen::Matrix2Xf from_axes(2, from.cols());
      std::vector<Observation> local(objects.size());
      for (std::size_t i = 0; i < objects.size(); ++i) {
        local[i] = observe(objects[i], cloud_to_plane);
        from.col(static_cast<Eigen::Index>(i)) = reference(local[i].geometry).head<2>();
        from_axes.col(static_cast<Eigen::Index>(i)) = lyingAxis(local[i].geometry);
      }
      Eigen::Matrix2Xf to(2, static_cast<Eigen::Index>(tracks_.size()));
      Eigen::Matrix2Xf to_axes(2, to.cols());
      std::vector<AssociationGeometry> tg(tracks_.size());
      for (std::size_t j = 0; j < tracks_.size(); ++j) {
        tg[j] = geometryOf(tracks_[j]);
        to.col(static_cast<Eigen::Index>(j)) = reference(tg[j]).head<2>();
        to_axes.col(static_cast<Eigen::Index>(j)) = lyingAxis(tg[j]);
      }
      std::vector<RegistrationCandidate> candidates;
      for (std::size_t i = 0; i < objects.size(); ++i) {
        const auto& o = local[i].geometry;
        if (!local[i].valid)
          continue;
        for (std::size_t j = 0; j < tracks_.size(); ++j) {
          const auto& t = tg[j];
          const float trust = tracks_[j].confirmed ? 1.f : 0.5f;
          RegistrationCandidate c;
          c.object = static_cast<int>(i);
          c.track = static_cast<int>(j);
          if (o.cylinder && t.cylinder) {
            if (std::abs(o.radius - t.radius) > 0.01f + 0.2f * std::max(o.radius, t.radius) ||
                std::abs(o.centre.z() - t.centre.z()) > 0.04f + 0.25f * t.height)
              continue;
            const bool upright = std::abs(t.axis.z()) > kUprightCos;
            c.weight = trust;
            c.tolerance = upright || std::abs(t.axis.z()) < 0.5f ? 0.02f : 0.04f; // tilted: 4 cm
          }
          else {
            if (std::abs(reference(o).z() - reference(t).z()) > 0.06f)
              continue;
            c.weight = 0.4f * trust;
            c.tolerance = 0.05f;
          }
          candidates.push_back(c);
        }
      }
      PlanarRegistration reg =
        registerInPlane(from, to, candidates, prior, params_.registration, from_axes, to_axes);
      // The camera's velocity predicts a smooth path; when it jumped instead (back to where it
      // was: a looped recording, a dropped run of frames) and the prediction matched fewer than
      // half of the objects, the last frame's pose is tried as the prior too, and the one that
      // matches more objects is kept.
      std::size_t valid = 0;
      for (const auto& o : local)
        valid += o.valid;
      if (has_velocity_ && 2 * reg.matched_objects < valid) {
        const PlanarRegistration still =
          registerInPlane(from, to, candidates, inPlaneComponent(last_pose * plane_to_cloud),
                          params_.registration, from_axes, to_axes);
        if (still.matched_objects > reg.matched_objects)
          reg = still;
      }
      pose = reg.transform.asAffine() * cloud_to_plane;
      info.registration = reg.transform;
      info.registered = reg.matched_objects;

      // ---- a new scene?
      std::size_t confirmed = 0, expected = 0, seen = 0;
      for (const auto& o : local)
        seen += o.valid;
      frame_to_world_ = pose; // for the view test
      for (const auto& t : tracks_) {
        if (!t.confirmed)
          continue;
        ++confirmed;
        int inside = 0;
        const TrackStatus s =
          viewStatus(t, TrackerView{view.camera, view.sensor_pose, {}}, {}, inside);
        expected += s != TrackStatus::OutOfView;
      }
      expected = std::min(expected, seen);
      const bool no_overlap = params_.min_overlap > 0.f && expected >= 3 &&
                              static_cast<float>(reg.matched_objects) <
                                params_.min_overlap * static_cast<float>(expected);
      if (confirmed > 0 && ((plane_jump && reg.matched_objects < 2) || no_overlap)) {
        endTracks();
        new_scene = true;
        ++info_.scene;
        pose = cloud_to_plane;
      }
    }
    info.anchored = true;
  }
  else if (!has_pose_)
    world_on_support_ = false; // the world is this cloud's frame until a support is seen
  has_velocity_ = has_pose_ && info.anchored && last_anchored && !new_scene;
  previous_frame_to_world_ = last_pose;
  frame_to_world_ = pose;
  has_pose_ = true;
  info.anchor = anchor;
  info.new_scene = new_scene;
  info.scene = info_.scene;

  // ---- association
  std::vector<Observation> obs(objects.size());
  for (std::size_t i = 0; i < objects.size(); ++i)
    obs[i] = observe(objects[i], pose);
  const std::size_t n = obs.size(), m = tracks_.size();
  std::vector<AssociationGeometry> tg(m);
  for (std::size_t j = 0; j < m; ++j)
    tg[j] = geometryOf(tracks_[j]);
  const float inf = std::numeric_limits<float>::infinity();
  Eigen::MatrixXf cost(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(m));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      float c = obs[i].valid ? associationCost(tg[j], obs[i].geometry, params_.association) : inf;
      if (tracks_[j].seen_through > 0 && c > 0.25f * params_.association.gate)
        c = inf;
      cost(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = c;
    }
  std::vector<int> match = assignMinimumCost(cost, params_.association.gate);
  // A second chance, with twice the sigmas, for what is left on both sides: an object whose
  // fit changed much is still the one at the track's place.
  {
    std::vector<int> rows, cols;
    std::vector<char> taken(m, 0);
    for (std::size_t i = 0; i < n; ++i)
      if (match[i] >= 0)
        taken[static_cast<std::size_t>(match[i])] = 1;
    for (std::size_t i = 0; i < n; ++i)
      if (match[i] < 0 && obs[i].valid)
        rows.push_back(static_cast<int>(i));
    for (std::size_t j = 0; j < m; ++j)
      if (!taken[j] && tracks_[j].seen_through == 0)
        cols.push_back(static_cast<int>(j));
    if (!rows.empty() && !cols.empty()) {
      AssociationSettings loose = params_.association;
      loose.sigma_position *= 2.f;
      loose.sigma_centroid *= 2.f;
      loose.sigma_radius *= 2.f;
      loose.sigma_axis *= 2.f;
      Eigen::MatrixXf c2(static_cast<Eigen::Index>(rows.size()),
                         static_cast<Eigen::Index>(cols.size()));
      for (std::size_t a = 0; a < rows.size(); ++a)
        for (std::size_t b = 0; b < cols.size(); ++b)
          c2(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) =
            associationCost(tg[static_cast<std::size_t>(cols[b])],
                            obs[static_cast<std::size_t>(rows[a])].geometry, loose);
      const std::vector<int> second = assignMinimumCost(c2, params_.association.gate);
      for (std::size_t a = 0; a < rows.size(); ++a)
        if (second[a] >= 0)
          match[static_cast<std::size_t>(rows[a])] = cols[static_cast<std::size_t>(second[a])];
    }
  }

  const float weight = info.anchored ? 1.f : 0.25f;
  std::vector<char> matched_track(m, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!obs[i].valid) {
      if (objects[i].cluster.centroid.size() == 3 && !objects[i].cluster.centroid.allFinite())
        PCL_WARN("[facyl::%s::update] object %zu has no finite centroid: ignored\n",
                 getClassName().c_str(), i);
      continue;
    }
    if (match[i] < 0)
      continue;
    auto& t = tracks_[static_cast<std::size_t>(match[i])];
    correct(t, obs[i], weight);
    t.object = static_cast<int>(i);
    matched_track[static_cast<std::size_t>(match[i])] = 1;
    assignments_[i].role = TrackAssignment::Role::Matched;
    assignments_[i].track_id = t.id;
  }

  // ---- objects left: fragments of a matched object (a split), or new tracks
  for (std::size_t i = 0; i < n; ++i) {
    if (!obs[i].valid || match[i] >= 0)
      continue;
    const auto& o = obs[i];
    int fragment_of = -1;
    float best_gain = 0.f;
    for (std::size_t j = 0; j < m; ++j) {
      if (!matched_track[j])
        continue;
      const auto& t = tracks_[j];
      const auto& mo = obs[static_cast<std::size_t>(t.object)];
      float gain = 0.f;
      if (t.has_cylinder) { // within the tracked cylinder and its margin
        const Eigen::Vector3f d = o.geometry.centroid - t.centre;
        const float along = d.dot(t.axis);
        const float across = (d - along * t.axis).norm();
        if (across <= t.radius + params_.fragment_margin &&
            along >= t.lo - params_.fragment_margin && along <= t.hi + params_.fragment_margin)
          gain = 1.f;
      }
      if (gain == 0.f) { // the two pieces together are nearer the track than its match alone
        const float wi = static_cast<float>(o.points), wj = static_cast<float>(mo.points);
        if (wi + wj > 0.f) {
          const Eigen::Vector3f merged =
            (wi * o.geometry.centroid + wj * mo.geometry.centroid) / (wi + wj);
          const float before = (mo.geometry.centroid - t.centroid).norm();
          const float after = (merged - t.centroid).norm();
          if (after + 0.005f < before &&
              (o.geometry.centroid - t.centroid).norm() <= 3.f * params_.association.sigma_centroid)
            gain = (before - after) / std::max(before, 1e-3f);
        }
      }
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
    startTrack(o, static_cast<int>(i));
    assignments_[i].role = TrackAssignment::Role::Started;
    assignments_[i].track_id = tracks_.back().id;
  }

  // ---- tracks not seen
  for (std::size_t j = 0; j < m; ++j) {
    if (matched_track[j])
      continue;
    auto& t = tracks_[j];
    if (!info.anchored) {
      // The frame cannot tell where it is: confirmed tracks' misses do not count. A tentative
      // track must be seen again, anchored or not (else a stream without a support would pile
      // up every frame's objects as tracks).
      t.status = TrackStatus::NotUpdated;
      if (!t.confirmed)
        ++t.misses;
      continue;
    }
    int inside = -1;
    t.status = viewStatus(t, view, objects, inside);
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
        // The object at its place started a new track: it is this one, seen with a fit too
        // different to match (the new track goes; the geometry is not updated from it).
        for (auto& other : tracks_)
          if (other.id == a.track_id)
            other.misses = params_.max_tentative_misses + 1;
        const auto& o = obs[static_cast<std::size_t>(inside)];
        filterPoint(t.centroid, t.var_centroid, o.geometry.centroid,
                    square(params_.measurement_centroid), params_.huber_k);
        t.log_odds = updateLogOdds(t.log_odds, o.p, params_.confidence_limit);
        ++t.hits;
        t.misses = t.occluded = t.out_of_view = t.seen_through = 0;
        t.status = TrackStatus::Seen;
        t.object = inside;
        a.role = TrackAssignment::Role::Matched;
        a.track_id = t.id;
        break;
      }
      ++t.occluded;
      for (std::size_t q = 0; q < m; ++q)
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
  // Two tracks of one object (a new one started while the old one was merged into another
  // segment or its fit changed): when they agree within one sigma (associationCost < 1) the
  // younger one goes into the older one, whose id stays.
  for (std::size_t j = 0; j < tracks_.size(); ++j)
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      auto& older = tracks_[i];
      auto& younger = tracks_[j];
      if (i == j || older.id >= younger.id || younger.misses > 1000 || older.misses > 1000 ||
          !younger.confirmed ||
          (older.status == TrackStatus::Seen && younger.status == TrackStatus::Seen))
        continue;
      const AssociationGeometry a = geometryOf(older), b = geometryOf(younger);
      if (associationCost(a, b, params_.association) >= 1.f)
        continue;
      if (younger.status == TrackStatus::Seen) { // the older one takes the frame's object
        older.status = TrackStatus::Seen;
        older.object = younger.object;
        older.misses = older.occluded = older.out_of_view = older.seen_through = 0;
        older.merged_into = -1;
        older.centroid = younger.centroid;
        if (younger.has_cylinder) {
          older.has_cylinder = true;
          older.fits.insert(older.fits.end(), younger.fits.begin(), younger.fits.end());
          if (older.fits.size() > static_cast<std::size_t>(params_.history))
            older.fits.erase(older.fits.begin(), older.fits.end() - params_.history);
          older.centre = younger.centre;
          older.axis = younger.axis;
          older.radius = younger.radius;
          older.lo = younger.lo;
          older.hi = younger.hi;
        }
      }
      older.hits += younger.hits;
      older.cylinder_hits += younger.cylinder_hits;
      older.log_odds = std::clamp(older.log_odds + younger.log_odds, -params_.confidence_limit,
                                  params_.confidence_limit);
      for (auto& a_k : assignments_) {
        if (a_k.track_id == younger.id)
          a_k.track_id = older.id;
        for (auto& id : a_k.merged)
          if (id == younger.id)
            id = older.id;
      }
      younger.misses = std::numeric_limits<int>::max() / 2; // ended below
      younger.confirmed = false;
    }
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const CylinderTrack& t) {
                                 if (!t.confirmed)
                                   return t.misses > params_.max_tentative_misses;
                                 return t.misses > params_.max_misses ||
                                        t.occluded > params_.max_occluded ||
                                        t.out_of_view > params_.max_out_of_view;
                               }),
                tracks_.end());
  std::sort(tracks_.begin(), tracks_.end(),
            [](const CylinderTrack& a, const CylinderTrack& b) { return a.id < b.id; });
  info_ = info;
  return true;
}

} // namespace facyl

FACYL_INSTANTIATE_trackerViewOf(pcl::PointXYZ)
FACYL_INSTANTIATE_trackerViewOf(pcl::PointXYZRGB)
FACYL_INSTANTIATE_trackerViewOf(pcl::PointXYZRGBA)
