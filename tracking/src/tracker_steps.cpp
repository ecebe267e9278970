/*
 * facyl: fast cylinder detection for PCL.
 * The steps of CylinderTracker::update (see tracker_steps.h).
 */
#include <facyl/tracking/tracker_steps.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facyl {

namespace {

float
square(float v)
{
  return v * v;
}

/** Cosine of the largest tilt of an "upright" cylinder's axis from the support's normal. */
constexpr float kUprightCos = 0.88f; // 28 degrees

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

/** The point registration and the tracks' places compare: a cylinder's centre, else the
 * centroid. */
Eigen::Vector3f
reference(const AssociationGeometry& g)
{
  return g.cylinder ? g.centre : g.centroid;
}

/** Lying cylinders (axis within 30 degrees of the plane) are lines: their horizontal direction
 * fixes the yaw. Zero for anything else. */
Eigen::Vector2f
lyingAxis(const AssociationGeometry& g)
{
  if (!g.cylinder || std::abs(g.axis.z()) > 0.5f)
    return Eigen::Vector2f::Zero();
  return g.axis.head<2>().normalized();
}

} // namespace

// --------------------------------------------------------------------------- anchoring

AnchorChoice
chooseAnchor(const std::vector<SupportPlane>& supports, int table,
             const std::vector<RecognizedObject>& objects, const SupportPrior* tracks_plane)
{
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
  AnchorChoice choice;
  for (const int k : preference)
    if (!tracks_plane ||
        consistentWithPrior(*tracks_plane, supports[static_cast<std::size_t>(k)].plane)) {
      choice.anchor = k;
      break;
    }
  if (choice.anchor < 0 && !preference.empty()) {
    choice.anchor = preference.front();
    choice.plane_jump = true;
  }
  return choice;
}

std::vector<RegistrationCandidate>
registrationCandidates(const std::vector<TrackObservation>& objects,
                       const std::vector<CylinderTrack>& tracks)
{
  std::vector<AssociationGeometry> tg(tracks.size());
  for (std::size_t j = 0; j < tracks.size(); ++j)
    tg[j] = associationGeometry(tracks[j]);
  std::vector<RegistrationCandidate> candidates;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const auto& o = objects[i].geometry;
    if (!objects[i].valid)
      continue;
    for (std::size_t j = 0; j < tracks.size(); ++j) {
      const auto& t = tg[j];
      const float trust = tracks[j].confirmed ? 1.f : 0.5f;
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
  return candidates;
}

PlanarRegistration
registerObservations(const std::vector<TrackObservation>& objects,
                     const std::vector<CylinderTrack>& tracks, const PlanarRigid& prior,
                     const RegistrationSettings& settings, const PlanarRigid* fallback)
{
  Eigen::Matrix2Xf from(2, static_cast<Eigen::Index>(objects.size()));
  Eigen::Matrix2Xf from_axes(2, from.cols());
  for (std::size_t i = 0; i < objects.size(); ++i) {
    from.col(static_cast<Eigen::Index>(i)) = reference(objects[i].geometry).head<2>();
    from_axes.col(static_cast<Eigen::Index>(i)) = lyingAxis(objects[i].geometry);
  }
  Eigen::Matrix2Xf to(2, static_cast<Eigen::Index>(tracks.size()));
  Eigen::Matrix2Xf to_axes(2, to.cols());
  for (std::size_t j = 0; j < tracks.size(); ++j) {
    const AssociationGeometry g = associationGeometry(tracks[j]);
    to.col(static_cast<Eigen::Index>(j)) = reference(g).head<2>();
    to_axes.col(static_cast<Eigen::Index>(j)) = lyingAxis(g);
  }
  const std::vector<RegistrationCandidate> candidates = registrationCandidates(objects, tracks);
  PlanarRegistration reg =
    registerInPlane(from, to, candidates, prior, settings, from_axes, to_axes);
  std::size_t valid = 0;
  for (const auto& o : objects)
    valid += o.valid;
  if (fallback && 2 * reg.matched_objects < valid) {
    const PlanarRegistration still =
      registerInPlane(from, to, candidates, *fallback, settings, from_axes, to_axes);
    if (still.matched_objects > reg.matched_objects)
      reg = still;
  }
  return reg;
}

bool
isNewScene(std::size_t confirmed, std::size_t expected_in_view, std::size_t seen,
           std::size_t matched, bool plane_jump, float min_overlap)
{
  const std::size_t expected = std::min(expected_in_view, seen);
  const bool no_overlap = min_overlap > 0.f && expected >= 3 &&
                          static_cast<float>(matched) < min_overlap * static_cast<float>(expected);
  return confirmed > 0 && ((plane_jump && matched < 2) || no_overlap);
}

// ------------------------------------------------------------------------ observations

TrackObservation
observe(const RecognizedObject& r, const Eigen::Affine3f& pose, float decision_probability)
{
  TrackObservation o;
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
  const float p = r.evidence.p_cylinder, side = decision_probability;
  if (r.is_cylinder)
    o.p = std::isfinite(p) ? std::max(p, side) : side;
  else
    o.p = std::isfinite(p) ? std::min(p, 1.f - side) : 1.f - side;
  return o;
}

AssociationGeometry
associationGeometry(const CylinderTrack& t)
{
  AssociationGeometry g;
  g.centroid = t.centroid;
  g.cylinder = t.has_cylinder;
  g.centre = t.centre;
  g.axis = t.axis;
  g.radius = t.radius;
  g.height = t.hi - t.lo;
  return g;
}

void
transformTrack(CylinderTrack& t, const Eigen::Affine3f& m)
{
  t.centroid = m * t.centroid;
  t.centre = m * t.centre;
  t.axis = (m.linear() * t.axis).normalized();
  for (auto& f : t.fits) { // the history too: later estimates are made from it
    f.centre = m * f.centre;
    f.axis = (m.linear() * f.axis).normalized();
  }
  axisUp(t);
}

// ------------------------------------------------------------------------- association

std::vector<int>
associate(const std::vector<TrackObservation>& obs, const std::vector<CylinderTrack>& tracks,
          const AssociationSettings& settings)
{
  const std::size_t n = obs.size(), m = tracks.size();
  std::vector<AssociationGeometry> tg(m);
  for (std::size_t j = 0; j < m; ++j)
    tg[j] = associationGeometry(tracks[j]);
  const float inf = std::numeric_limits<float>::infinity();
  Eigen::MatrixXf cost(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(m));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      float c = obs[i].valid ? associationCost(tg[j], obs[i].geometry, settings) : inf;
      if (tracks[j].seen_through > 0 && c > 0.25f * settings.gate)
        c = inf;
      cost(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = c;
    }
  std::vector<int> match = assignMinimumCost(cost, settings.gate);
  // The second chance, for what is left on both sides.
  std::vector<int> rows, cols;
  std::vector<char> taken(m, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (match[i] >= 0)
      taken[static_cast<std::size_t>(match[i])] = 1;
  for (std::size_t i = 0; i < n; ++i)
    if (match[i] < 0 && obs[i].valid)
      rows.push_back(static_cast<int>(i));
  for (std::size_t j = 0; j < m; ++j)
    if (!taken[j] && tracks[j].seen_through == 0)
      cols.push_back(static_cast<int>(j));
  if (rows.empty() || cols.empty())
    return match;
  AssociationSettings loose = settings;
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
  const std::vector<int> second = assignMinimumCost(c2, settings.gate);
  for (std::size_t a = 0; a < rows.size(); ++a)
    if (second[a] >= 0)
      match[static_cast<std::size_t>(rows[a])] = cols[static_cast<std::size_t>(second[a])];
  return match;
}

// -------------------------------------------------------------------------- filtering

CylinderTrack
newTrack(const TrackObservation& o, int id, int object, const CylinderTrackerParameters& params)
{
  CylinderTrack t;
  t.id = id;
  t.age = 1;
  t.hits = 1;
  t.status = TrackStatus::Seen;
  t.object = object;
  t.support = o.support;
  t.centroid = o.geometry.centroid;
  t.var_centroid = square(params.measurement_centroid);
  recordEvidence(t, o.p, 1, params);
  if (o.geometry.cylinder) {
    t.has_cylinder = true;
    t.cylinder_hits = 1;
    t.centre = o.geometry.centre;
    t.axis = o.geometry.axis;
    t.radius = o.geometry.radius;
    t.lo = -0.5f * o.geometry.height;
    t.hi = 0.5f * o.geometry.height;
    t.var_extent = square(params.measurement_extent);
    t.fits.assign(1, CylinderTrack::Fit{t.axis, t.centre, t.radius, o.quality * o.quality});
    axisUp(t);
  }
  t.confirmed = t.hits >= static_cast<std::size_t>(params.confirm_hits);
  return t;
}

void
cylinderFromHistory(CylinderTrack& t, float axis_agreement)
{
  std::vector<Eigen::Vector3f> axes;
  std::vector<float> weights;
  for (const auto& f : t.fits) {
    axes.push_back(f.axis);
    weights.push_back(f.weight);
  }
  std::vector<char> agree;
  const Eigen::Vector3f axis = consensusAxis(axes, weights, axis_agreement, &agree);
  if (axis.dot(t.axis) < 0.f) { // keep the extent's sense
    const float lo = t.lo;
    t.lo = -t.hi;
    t.hi = -lo;
  }
  t.axis = axis.dot(t.axis) < 0.f ? Eigen::Vector3f(-axis) : axis;
  // The line: where the agreeing fits' axes pass the plane across the axis at the centre, a
  // weighted median in each direction of that plane, twice.
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
}

void
decide(CylinderTrack& t, bool first, const CylinderTrackerParameters& params)
{
  // The threshold's log-odds unclamped: min_probability 0 (every track) and 1 (none) keep
  // their meaning.
  const float p = params.min_probability;
  const float threshold = p <= 0.f   ? -std::numeric_limits<float>::infinity()
                          : p >= 1.f ? std::numeric_limits<float>::infinity()
                                     : std::log(p / (1.f - p));
  const float margin = first ? 0.f : decisionMargin(t.evidence_var, params.confidence_limit);
  t.decided_cylinder =
    decideWithHysteresis(first ? false : t.decided_cylinder, t.log_odds, threshold, margin);
}

void
recordEvidence(CylinderTrack& t, float p, std::size_t n, const CylinderTrackerParameters& params)
{
  t.log_odds = updateLogOdds(t.log_odds, p, params.confidence_limit);
  updateEvidenceSpread(t.evidence_mean, t.evidence_var, n, logOdds(p), params.history);
  decide(t, n <= 1, params);
}

void
correctTrack(CylinderTrack& t, const TrackObservation& o, float weight,
             const CylinderTrackerParameters& params)
{
  const float k = params.huber_k;
  filterPoint(t.centroid, t.var_centroid, o.geometry.centroid,
              square(params.measurement_centroid) / weight, k);
  if (o.geometry.cylinder) {
    const auto& g = o.geometry;
    if (!t.has_cylinder) {
      t.has_cylinder = true;
      t.centre = g.centre;
      t.axis = g.axis;
      t.radius = g.radius;
      t.lo = -0.5f * g.height;
      t.hi = 0.5f * g.height;
      t.var_extent = square(params.measurement_extent);
      t.fits.assign(1,
                    CylinderTrack::Fit{t.axis, t.centre, t.radius, o.quality * o.quality * weight});
    }
    else {
      // Observations count by what the frame saw of the object (reference_quality).
      const float scale =
        std::clamp(params.reference_quality / std::max(o.quality, 1e-3f), 0.25f, 4.f) / weight;
      t.fits.push_back(
        CylinderTrack::Fit{g.axis, g.centre, g.radius, o.quality * o.quality * weight});
      if (t.fits.size() > static_cast<std::size_t>(params.history))
        t.fits.erase(t.fits.begin(), t.fits.end() - params.history);
      cylinderFromHistory(t, params.axis_agreement);
      const float sb = (o.base - t.centre).dot(t.axis), st = (o.top - t.centre).dot(t.axis);
      filterExtent(t.lo, t.hi, t.var_extent, std::min(sb, st), std::max(sb, st),
                   square(params.measurement_extent) * scale, params.shrink_weight);
      const float mid = 0.5f * (t.lo + t.hi);
      t.centre += mid * t.axis;
      t.lo -= mid;
      t.hi -= mid;
    }
    axisUp(t);
    ++t.cylinder_hits;
  }
  recordEvidence(t, o.p, t.hits + 1, params);
  t.support = o.support;
  ++t.hits;
  t.misses = 0;
  t.occluded = 0;
  t.out_of_view = 0;
  t.seen_through = 0;
  t.status = TrackStatus::Seen;
  if (t.hits >= static_cast<std::size_t>(params.confirm_hits))
    t.confirmed = true;
}

// -------------------------------------------------------------- objects left, tracks not seen

float
fragmentGain(const TrackObservation& o, const CylinderTrack& t, const TrackObservation& mo,
             float margin, float sigma_centroid)
{
  if (t.has_cylinder) { // within the tracked cylinder and its margin
    const Eigen::Vector3f d = o.geometry.centroid - t.centre;
    const float along = d.dot(t.axis);
    const float across = (d - along * t.axis).norm();
    if (across <= t.radius + margin && along >= t.lo - margin && along <= t.hi + margin)
      return 1.f;
  }
  // The two pieces together are nearer the track than its match alone.
  const float wi = static_cast<float>(o.points), wj = static_cast<float>(mo.points);
  if (!(wi + wj > 0.f))
    return 0.f;
  const Eigen::Vector3f merged = (wi * o.geometry.centroid + wj * mo.geometry.centroid) / (wi + wj);
  const float before = (mo.geometry.centroid - t.centroid).norm();
  const float after = (merged - t.centroid).norm();
  if (after + 0.005f < before && (o.geometry.centroid - t.centroid).norm() <= 3.f * sigma_centroid)
    return (before - after) / std::max(before, 1e-3f);
  return 0.f;
}

TrackStatus
viewStatus(const CylinderTrack& t, const Eigen::Affine3f& world_to_cloud, const TrackerView& view,
           const std::vector<RecognizedObject>& objects, int& inside)
{
  inside = -1;
  const PinholeCamera& cam = view.camera;
  if (!cam.valid())
    return TrackStatus::Missed;
  const Eigen::Affine3f to_sensor = view.sensor_pose.inverse() * world_to_cloud;
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

  // Probes: points of the object's surface facing the sensor, with their depth.
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

namespace {

/** Whether the centre of \a a's cylinder lies inside \b's: within its radius of its axis and
 * within its extent along it. */
bool
centreInside(const CylinderTrack& a, const CylinderTrack& b)
{
  const Eigen::Vector3f d = a.centre - b.centre;
  const float along = d.dot(b.axis);
  return along >= b.lo && along <= b.hi && (d - along * b.axis).norm() < b.radius;
}

} // namespace

bool
areOneObject(const CylinderTrack& older, const CylinderTrack& younger,
             const AssociationSettings& settings)
{
  if (older.id >= younger.id || younger.misses > 1000 || older.misses > 1000 ||
      !younger.confirmed ||
      (older.status == TrackStatus::Seen && younger.status == TrackStatus::Seen))
    return false;
  // Two solid cylinders each holding the other's centre are one object, whatever their axes
  // (one track's fits off by a tilt).
  if (older.has_cylinder && younger.has_cylinder && centreInside(older, younger) &&
      centreInside(younger, older))
    return true;
  return associationCost(associationGeometry(older), associationGeometry(younger), settings) < 1.f;
}

void
absorbTrack(CylinderTrack& older, CylinderTrack& younger, int history, float confidence_limit)
{
  if (younger.status == TrackStatus::Seen) { // the older one takes the frame's object
    older.status = TrackStatus::Seen;
    older.object = younger.object;
    older.misses = older.occluded = older.out_of_view = older.seen_through = 0;
    older.merged_into = -1;
    older.centroid = younger.centroid;
    if (younger.has_cylinder) {
      older.has_cylinder = true;
      older.fits.insert(older.fits.end(), younger.fits.begin(), younger.fits.end());
      if (older.fits.size() > static_cast<std::size_t>(history))
        older.fits.erase(older.fits.begin(), older.fits.end() - history);
      older.centre = younger.centre;
      older.axis = younger.axis;
      older.radius = younger.radius;
      older.lo = younger.lo;
      older.hi = younger.hi;
    }
  }
  older.hits += younger.hits;
  older.cylinder_hits += younger.cylinder_hits;
  older.log_odds =
    std::clamp(older.log_odds + younger.log_odds, -confidence_limit, confidence_limit);
  younger.misses = std::numeric_limits<int>::max() / 2; // ended
  younger.confirmed = false;
}

bool
trackEnded(const CylinderTrack& t, const CylinderTrackerParameters& params)
{
  if (!t.confirmed)
    return t.misses > params.max_tentative_misses;
  return t.misses > params.max_misses || t.occluded > params.max_occluded ||
         t.out_of_view > params.max_out_of_view;
}

} // namespace facyl
