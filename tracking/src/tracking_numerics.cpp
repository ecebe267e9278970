/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/tracking/tracking_numerics.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace facyl {

namespace {

constexpr float kPi = 3.14159265358979f;

/** \a a in (-pi, pi]. */
float
wrapAngle(float a)
{
  a = std::fmod(a + kPi, 2.f * kPi);
  if (a <= 0.f)
    a += 2.f * kPi;
  return a - kPi;
}

} // namespace

Eigen::Affine3f
PlanarRigid::asAffine() const
{
  Eigen::Affine3f m = Eigen::Affine3f::Identity();
  m.linear() = Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  m.translation() = Eigen::Vector3f(t.x(), t.y(), 0.f);
  return m;
}

PlanarRigid
inPlaneComponent(const Eigen::Affine3f& m)
{
  PlanarRigid p;
  Eigen::Vector3f x = m.linear().col(0);
  if (Eigen::Vector2f(x.x(), x.y()).norm() < 1e-3f) // x along z: use y, turned back
    x = -m.linear().col(1).cross(Eigen::Vector3f::UnitZ()).cross(Eigen::Vector3f::UnitZ());
  p.yaw = std::atan2(x.y(), x.x());
  p.t = m.translation().head<2>();
  return p;
}

PlanarRigid
fitPlanarRigid(const Eigen::Matrix2Xf& from, const Eigen::Matrix2Xf& to,
               const Eigen::VectorXf& weights, float fallback_yaw)
{
  PlanarRigid r;
  r.yaw = fallback_yaw;
  const Eigen::Index n = std::min(from.cols(), to.cols());
  double total = 0.0;
  Eigen::Vector2d mf = Eigen::Vector2d::Zero(), mt = Eigen::Vector2d::Zero();
  int positive = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w = weights.size() > i ? std::max(0.f, weights(i)) : 0.0;
    if (!(w > 0.0))
      continue;
    ++positive;
    total += w;
    mf += w * from.col(i).cast<double>();
    mt += w * to.col(i).cast<double>();
  }
  if (positive == 0)
    return r; // nothing to fit: the fallback rotation, no translation
  mf /= total;
  mt /= total;
  // Umeyama: the rotation maximising sum w <R a_i, b_i> over centred points; in 2-D its angle
  // is atan2(sum w (a x b), sum w (a . b)).
  double cross = 0.0, dot = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w = weights.size() > i ? std::max(0.f, weights(i)) : 0.0;
    if (!(w > 0.0))
      continue;
    const Eigen::Vector2d a = from.col(i).cast<double>() - mf;
    const Eigen::Vector2d b = to.col(i).cast<double>() - mt;
    cross += w * (a.x() * b.y() - a.y() * b.x());
    dot += w * a.dot(b);
  }
  if (positive >= 2 && std::hypot(cross, dot) > 1e-9 * total)
    r.yaw = static_cast<float>(std::atan2(cross, dot));
  const double c = std::cos(r.yaw), s = std::sin(r.yaw);
  r.t = (mt - Eigen::Vector2d(c * mf.x() - s * mf.y(), s * mf.x() + c * mf.y())).cast<float>();
  return r;
}

namespace {

/** Half-length (m) of the segment that stands for a lying cylinder's axis in the fits: its
 * angle then weighs like a position error at 30 cm. A lying cylinder's axis is fitted to a
 * tenth of a degree, an upright one's position to about 2 mm: a direction is worth a point
 * pair more than a metre apart; 30 cm keeps a wrong one (a box's edge fitted) from pulling. */
constexpr float kAxisArm = 0.3f;

/** The landmarks of a registration: points, and for lying cylinders their axis directions. */
struct Landmarks {
  const Eigen::Matrix2Xf& objects;
  const Eigen::Matrix2Xf& tracks;
  const Eigen::Matrix2Xf& object_axes; ///< empty, or unit / zero columns
  const Eigen::Matrix2Xf& track_axes;

  /** Both ends of candidate \a k have an axis: they agree along a line. */
  bool isLine(const RegistrationCandidate& k) const
  {
    return object_axes.cols() > k.object && track_axes.cols() > k.track &&
           object_axes.col(k.object).squaredNorm() > 0.5f &&
           track_axes.col(k.track).squaredNorm() > 0.5f;
  }
  /** Residual of \a k under \a t: the distance of the points, or for a line the distance
   * across the track's axis and the angle between the axes (times kAxisArm). */
  float residual(const RegistrationCandidate& k, const PlanarRigid& t) const
  {
    const Eigen::Vector2f d = t.apply(objects.col(k.object)) - tracks.col(k.track);
    if (!isLine(k))
      return d.norm();
    const Eigen::Vector2f a = track_axes.col(k.track);
    const Eigen::Vector2f across = d - a * d.dot(a);
    const float c = std::cos(t.yaw), s = std::sin(t.yaw);
    const Eigen::Vector2f o = object_axes.col(k.object);
    const Eigen::Vector2f turned(c * o.x() - s * o.y(), s * o.x() + c * o.y());
    const float sine = std::abs(turned.x() * a.y() - turned.y() * a.x());
    return std::sqrt(across.squaredNorm() + kAxisArm * kAxisArm * sine * sine);
  }
  /** The point pairs \a k gives a Procrustes fit at \a t, with weight \a w: the points, or for
   * a line a segment along each axis, the track's centred where the object's lies across it. */
  void pairs(const RegistrationCandidate& k, const PlanarRigid& t, float w,
             std::vector<Eigen::Vector2f>& from, std::vector<Eigen::Vector2f>& to,
             std::vector<float>& weights) const
  {
    const Eigen::Vector2f o = objects.col(k.object);
    if (!isLine(k)) {
      from.push_back(o);
      to.push_back(tracks.col(k.track));
      weights.push_back(w);
      return;
    }
    const Eigen::Vector2f p = t.apply(o);
    Eigen::Vector2f a = track_axes.col(k.track);
    const float c = std::cos(t.yaw), s = std::sin(t.yaw);
    const Eigen::Vector2f ao = object_axes.col(k.object);
    if (Eigen::Vector2f(c * ao.x() - s * ao.y(), s * ao.x() + c * ao.y()).dot(a) < 0.f)
      a = -a;
    const Eigen::Vector2f foot = tracks.col(k.track) + a * (p - tracks.col(k.track)).dot(a);
    for (const float side : {-1.f, 1.f}) {
      from.push_back(o + side * kAxisArm * ao);
      to.push_back(foot + side * kAxisArm * a);
      weights.push_back(0.5f * w);
    }
  }
};

PlanarRigid
fitPairs(const std::vector<Eigen::Vector2f>& from, const std::vector<Eigen::Vector2f>& to,
         const std::vector<float>& weights, float fallback_yaw)
{
  Eigen::Matrix2Xf f(2, static_cast<Eigen::Index>(from.size())), t(2, f.cols());
  Eigen::VectorXf w(f.cols());
  for (std::size_t i = 0; i < from.size(); ++i) {
    f.col(static_cast<Eigen::Index>(i)) = from[i];
    t.col(static_cast<Eigen::Index>(i)) = to[i];
    w(static_cast<Eigen::Index>(i)) = weights[i];
  }
  return fitPlanarRigid(f, t, w, fallback_yaw);
}

/** Residuals of the candidates under \a t, greedy one-to-one: the best agreeing candidates
 * first, each object and track once. \return the score; \a inliers the chosen candidates. */
float
scoreUnique(const Landmarks& l, const std::vector<RegistrationCandidate>& candidates,
            const PlanarRigid& t, std::vector<int>* inliers, std::size_t* matched_objects)
{
  std::vector<std::pair<float, int>> agree;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const auto& k = candidates[c];
    const float r = l.residual(k, t);
    if (r < k.tolerance)
      agree.emplace_back(k.weight * (1.f - (r * r) / (k.tolerance * k.tolerance)),
                         static_cast<int>(c));
  }
  std::sort(agree.begin(), agree.end(), [](const auto& a, const auto& b) {
    return a.first > b.first || (a.first == b.first && a.second < b.second);
  });
  std::vector<int> used_objects, used_tracks;
  float score = 0.f;
  if (inliers)
    inliers->clear();
  for (const auto& [value, c] : agree) {
    const auto& k = candidates[static_cast<std::size_t>(c)];
    if (std::find(used_objects.begin(), used_objects.end(), k.object) != used_objects.end() ||
        std::find(used_tracks.begin(), used_tracks.end(), k.track) != used_tracks.end())
      continue;
    used_objects.push_back(k.object);
    used_tracks.push_back(k.track);
    score += value;
    if (inliers)
      inliers->push_back(c);
  }
  if (matched_objects)
    *matched_objects = used_objects.size();
  return score;
}

/** The fast score of the hypothesis search: each object's best agreeing candidate (a track
 * may count twice; the unique score decides between the best hypotheses). */
float
scoreFast(const Landmarks& l, const std::vector<RegistrationCandidate>& candidates,
          const PlanarRigid& t, std::vector<float>& best_of_object)
{
  std::fill(best_of_object.begin(), best_of_object.end(), 0.f);
  for (const auto& k : candidates) {
    const float r = l.residual(k, t);
    if (r < k.tolerance) {
      float& b = best_of_object[static_cast<std::size_t>(k.object)];
      b = std::max(b, k.weight * (1.f - (r * r) / (k.tolerance * k.tolerance)));
    }
  }
  return std::accumulate(best_of_object.begin(), best_of_object.end(), 0.f);
}

/** \a best refined by weighted Procrustes on its unique inliers, twice. */
PlanarRegistration
refine(const Landmarks& l, const std::vector<RegistrationCandidate>& near,
       const std::vector<RegistrationCandidate>& candidates, const PlanarRigid& best,
       const PlanarRigid& prior, const RegistrationSettings& settings, bool best_is_prior)
{
  PlanarRegistration out;
  PlanarRigid t = best;
  std::vector<int> inliers;
  std::size_t matched = 0;
  float score = scoreUnique(l, near, t, &inliers, &matched);
  for (int iteration = 0; iteration < 2 && !inliers.empty(); ++iteration) {
    std::vector<Eigen::Vector2f> from, to;
    std::vector<float> w;
    for (const int c : inliers) {
      const auto& k = near[static_cast<std::size_t>(c)];
      l.pairs(k, t, k.weight / (k.tolerance * k.tolerance), from, to, w);
    }
    const PlanarRigid refined = fitPairs(from, to, w, t.yaw);
    if (std::abs(wrapAngle(refined.yaw - prior.yaw)) > settings.max_yaw_change ||
        (refined.t - prior.t).norm() > 2.f * settings.search_radius)
      break;
    std::vector<int> refined_inliers;
    std::size_t refined_matched = 0;
    const float refined_score = scoreUnique(l, near, refined, &refined_inliers, &refined_matched);
    if (refined_score + 1e-6f < score && refined_matched <= matched)
      break;
    t = refined;
    inliers = std::move(refined_inliers);
    matched = refined_matched;
    score = refined_score;
  }
  out.transform = t;
  out.score = score;
  out.matched_objects = matched;
  out.from_prior = best_is_prior;
  // Inliers as indices into the caller's candidates.
  for (const int c : inliers) {
    const auto& k = near[static_cast<std::size_t>(c)];
    for (std::size_t j = 0; j < candidates.size(); ++j)
      if (candidates[j].object == k.object && candidates[j].track == k.track) {
        out.inliers.push_back(static_cast<int>(j));
        break;
      }
  }
  return out;
}

} // namespace

PlanarRegistration
registerInPlane(const Eigen::Matrix2Xf& objects, const Eigen::Matrix2Xf& tracks,
                const std::vector<RegistrationCandidate>& candidates, const PlanarRigid& prior,
                const RegistrationSettings& settings, const Eigen::Matrix2Xf& object_axes,
                const Eigen::Matrix2Xf& track_axes)
{
  PlanarRegistration out;
  out.transform = prior;
  const Landmarks l{objects, tracks, object_axes, track_axes};
  // Candidates that the prior can reach, strongest first.
  std::vector<RegistrationCandidate> near;
  for (const auto& k : candidates)
    if (k.object >= 0 && k.object < objects.cols() && k.track >= 0 && k.track < tracks.cols() &&
        k.weight > 0.f && k.tolerance > 0.f &&
        (prior.apply(objects.col(k.object)) - tracks.col(k.track)).norm() <= settings.search_radius)
      near.push_back(k);
  if (near.empty())
    return out;
  std::stable_sort(near.begin(), near.end(),
                   [](const auto& a, const auto& b) { return a.weight > b.weight; });
  const auto reachable = [&](const PlanarRigid& h) {
    return std::abs(wrapAngle(h.yaw - prior.yaw)) <= settings.max_yaw_change &&
           (h.t - prior.t).norm() <= 2.f * settings.search_radius;
  };

  // From the prior first: each object's closest candidate, reweighted (Huber on the residual)
  // within a shrinking radius, four times (ICP-like; a stream's prior is close). Accepted when
  // at least half of the objects with candidates, and two, agree: the search below is for
  // jumps and costs O(c^2 (n + m)).
  {
    PlanarRigid local = prior;
    float radius = 0.5f * settings.search_radius;
    std::vector<int> closest(static_cast<std::size_t>(objects.cols()));
    std::vector<float> residual(static_cast<std::size_t>(objects.cols()));
    for (int iteration = 0; iteration < 4; ++iteration) {
      std::fill(closest.begin(), closest.end(), -1);
      std::fill(residual.begin(), residual.end(), radius);
      for (std::size_t c = 0; c < near.size(); ++c) {
        const float r = l.residual(near[c], local);
        if (r < residual[static_cast<std::size_t>(near[c].object)]) {
          residual[static_cast<std::size_t>(near[c].object)] = r;
          closest[static_cast<std::size_t>(near[c].object)] = static_cast<int>(c);
        }
      }
      std::vector<Eigen::Vector2f> from, to;
      std::vector<float> w;
      for (std::size_t i = 0; i < closest.size(); ++i)
        if (closest[i] >= 0) {
          const auto& k = near[static_cast<std::size_t>(closest[i])];
          l.pairs(k, local,
                  k.weight / (k.tolerance * k.tolerance) *
                    huberWeight(residual[i], k.tolerance, 1.f),
                  from, to, w);
        }
      if (from.empty())
        break;
      const PlanarRigid next = fitPairs(from, to, w, local.yaw);
      if (!reachable(next))
        break;
      local = next;
      radius = std::max(0.5f * radius, 0.05f);
    }
    std::vector<char> has(static_cast<std::size_t>(objects.cols()), 0);
    for (const auto& k : near)
      has[static_cast<std::size_t>(k.object)] = 1;
    const auto with_candidates = static_cast<std::size_t>(std::count(has.begin(), has.end(), 1));
    std::size_t agreeing = 0;
    scoreUnique(l, near, local, nullptr, &agreeing);
    if (agreeing >= 2 && 2 * agreeing >= with_candidates)
      return refine(l, near, candidates, local, prior, settings, false);
  }

  // A slight preference for hypotheses near the prior breaks ties (one landmark, several
  // tracks of its kind in reach).
  const auto deviation = [&](const PlanarRigid& h) {
    return 0.05f * (std::abs(wrapAngle(h.yaw - prior.yaw)) / settings.max_yaw_change +
                    (h.t - prior.t).norm() / settings.search_radius);
  };
  std::vector<float> best_of_object(static_cast<std::size_t>(objects.cols()), 0.f);
  PlanarRigid best = prior;
  float best_score = scoreFast(l, near, prior, best_of_object);
  bool best_is_prior = true;
  const auto consider = [&](const PlanarRigid& h) {
    if (!reachable(h))
      return;
    const float score = scoreFast(l, near, h, best_of_object) - deviation(h);
    if (score > best_score) {
      best_score = score;
      best = h;
      best_is_prior = false;
    }
  };
  std::size_t hypotheses = 0;
  const float c0 = std::cos(prior.yaw), s0 = std::sin(prior.yaw);
  for (const auto& k : near) { // one landmark: translation with the prior's yaw
    const Eigen::Vector2f o = objects.col(k.object);
    PlanarRigid h;
    h.yaw = prior.yaw;
    h.t = tracks.col(k.track) - Eigen::Vector2f(c0 * o.x() - s0 * o.y(), s0 * o.x() + c0 * o.y());
    consider(h);
    ++hypotheses;
  }
  for (std::size_t a = 0; a < near.size() && hypotheses < settings.max_hypotheses; ++a)
    for (std::size_t b = a + 1; b < near.size() && hypotheses < settings.max_hypotheses; ++b) {
      const auto& ka = near[a];
      const auto& kb = near[b];
      if (ka.object == kb.object || ka.track == kb.track)
        continue;
      const Eigen::Vector2f od = objects.col(kb.object) - objects.col(ka.object);
      const Eigen::Vector2f td = tracks.col(kb.track) - tracks.col(ka.track);
      const float lo = od.norm(), lt = td.norm();
      if (std::abs(lo - lt) > settings.pair_tolerance || lo < 0.03f)
        continue; // not a rigid pair, or too short to give a direction
      PlanarRigid h;
      h.yaw = wrapAngle(std::atan2(td.y(), td.x()) - std::atan2(od.y(), od.x()));
      const float c = std::cos(h.yaw), s = std::sin(h.yaw);
      const Eigen::Vector2f om = 0.5f * (objects.col(ka.object) + objects.col(kb.object));
      const Eigen::Vector2f tm = 0.5f * (tracks.col(ka.track) + tracks.col(kb.track));
      h.t = tm - Eigen::Vector2f(c * om.x() - s * om.y(), s * om.x() + c * om.y());
      consider(h);
      ++hypotheses;
    }
  return refine(l, near, candidates, best, prior, settings, best_is_prior);
}

float
associationCost(const AssociationGeometry& t, const AssociationGeometry& o,
                const AssociationSettings& s)
{
  const float centroid2 = (o.centroid - t.centroid).squaredNorm();
  if (!(t.cylinder && o.cylinder))
    return centroid2 / (s.sigma_centroid * s.sigma_centroid);
  const Eigen::Vector3f a = t.axis.normalized();
  const Eigen::Vector3f d = o.centre - t.centre;
  const float along = d.dot(a);
  const float excess = std::max(0.f, std::abs(along) - 0.5f * t.height);
  const float position2 = (d - along * a).squaredNorm() + excess * excess;
  const float sr = s.sigma_radius + 0.1f * std::max(t.radius, o.radius);
  const float dr = o.radius - t.radius;
  const float angle = std::acos(std::min(1.f, std::abs(a.dot(o.axis.normalized()))));
  return position2 / (s.sigma_position * s.sigma_position) + (dr * dr) / (sr * sr) +
         (angle * angle) / (s.sigma_axis * s.sigma_axis) +
         centroid2 / (4.f * s.sigma_centroid * s.sigma_centroid);
}

std::vector<int>
assignMinimumCost(const Eigen::MatrixXf& cost, float gate)
{
  const auto rows = static_cast<int>(cost.rows()), cols = static_cast<int>(cost.cols());
  std::vector<int> assignment(static_cast<std::size_t>(rows), -1);
  if (rows == 0 || cols == 0)
    return assignment;
  // Kuhn-Munkres with potentials on an n x m matrix, n <= m (transposed when needed). Pairs
  // beyond the gate cost `big`, more than any sum of admissible costs, so the optimum first
  // maximises the admissible pairs, then minimises their cost; they are dropped afterwards.
  const bool transposed = rows > cols;
  const int n = transposed ? cols : rows, m = transposed ? rows : cols;
  const double big = (static_cast<double>(std::max(gate, 1.f)) + 1.0) * (n + 1) * 4.0;
  const auto at = [&](int i, int j) -> double { // i < n, j < m
    const float c = transposed ? cost(j, i) : cost(i, j);
    return std::isfinite(c) && c <= gate ? static_cast<double>(c) : big;
  };
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(static_cast<std::size_t>(n + 1), 0.0),
    v(static_cast<std::size_t>(m + 1), 0.0);
  std::vector<int> p(static_cast<std::size_t>(m + 1), 0), way(static_cast<std::size_t>(m + 1), 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(static_cast<std::size_t>(m + 1), inf);
    std::vector<char> used(static_cast<std::size_t>(m + 1), 0);
    do {
      used[static_cast<std::size_t>(j0)] = 1;
      const int i0 = p[static_cast<std::size_t>(j0)];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j)
        if (!used[static_cast<std::size_t>(j)]) {
          const double cur =
            at(i0 - 1, j - 1) - u[static_cast<std::size_t>(i0)] - v[static_cast<std::size_t>(j)];
          if (cur < minv[static_cast<std::size_t>(j)]) {
            minv[static_cast<std::size_t>(j)] = cur;
            way[static_cast<std::size_t>(j)] = j0;
          }
          if (minv[static_cast<std::size_t>(j)] < delta) {
            delta = minv[static_cast<std::size_t>(j)];
            j1 = j;
          }
        }
      for (int j = 0; j <= m; ++j)
        if (used[static_cast<std::size_t>(j)]) {
          u[static_cast<std::size_t>(p[static_cast<std::size_t>(j)])] += delta;
          v[static_cast<std::size_t>(j)] -= delta;
        }
        else
          minv[static_cast<std::size_t>(j)] -= delta;
      j0 = j1;
    } while (p[static_cast<std::size_t>(j0)] != 0);
    do {
      const int j1 = way[static_cast<std::size_t>(j0)];
      p[static_cast<std::size_t>(j0)] = p[static_cast<std::size_t>(j1)];
      j0 = j1;
    } while (j0);
  }
  for (int j = 1; j <= m; ++j) {
    const int i = p[static_cast<std::size_t>(j)];
    if (i == 0 || at(i - 1, j - 1) >= big)
      continue;
    if (transposed)
      assignment[static_cast<std::size_t>(j - 1)] = i - 1;
    else
      assignment[static_cast<std::size_t>(i - 1)] = j - 1;
  }
  return assignment;
}

float
huberWeight(float r, float sigma, float k)
{
  const float a = std::abs(r);
  if (!(sigma > 0.f) || a <= k * sigma)
    return 1.f;
  return k * sigma / a;
}

void
filterScalar(float& x, float& var, float z, float var_z, float huber_k)
{
  if (!std::isfinite(z))
    return;
  const float innovation = z - x;
  const float w = huberWeight(innovation, std::sqrt(var + var_z), huber_k);
  const float gain = var / (var + var_z / w);
  x += gain * innovation;
  var *= 1.f - gain;
}

void
filterPoint(Eigen::Vector3f& x, float& var, const Eigen::Vector3f& z, float var_z, float huber_k)
{
  if (!z.allFinite())
    return;
  const Eigen::Vector3f innovation = z - x;
  // |innovation| of an isotropic 3-D error has three times the per-axis variance.
  const float w = huberWeight(innovation.norm(), std::sqrt(3.f * (var + var_z)), huber_k);
  const float gain = var / (var + var_z / w);
  x += gain * innovation;
  var *= 1.f - gain;
}

void
filterAxis(Eigen::Vector3f& a, float& var, Eigen::Vector3f z, float var_z, float huber_k)
{
  if (!z.allFinite() || !(z.norm() > 0.f))
    return;
  z.normalize();
  if (z.dot(a) < 0.f)
    z = -z;
  const Eigen::Vector3f turn = a.cross(z);
  const float angle = std::atan2(turn.norm(), a.dot(z));
  const float w = huberWeight(angle, std::sqrt(var + var_z), huber_k);
  const float gain = var / (var + var_z / w);
  if (turn.norm() > 1e-7f)
    a = (Eigen::AngleAxisf(gain * angle, turn.normalized()) * a).normalized();
  var *= 1.f - gain;
}

void
filterExtent(float& lo, float& hi, float& var, float z_lo, float z_hi, float var_z,
             float shrink_weight)
{
  if (!std::isfinite(z_lo) || !std::isfinite(z_hi))
    return;
  if (z_lo > z_hi)
    std::swap(z_lo, z_hi);
  const float w_lo = z_lo < lo ? 1.f : shrink_weight;
  const float w_hi = z_hi > hi ? 1.f : shrink_weight;
  const float g_lo = var / (var + var_z / w_lo);
  const float g_hi = var / (var + var_z / w_hi);
  lo += g_lo * (z_lo - lo);
  hi += g_hi * (z_hi - hi);
  if (lo > hi)
    std::swap(lo, hi);
  var *= 1.f - 0.5f * (g_lo + g_hi);
}

float
median(std::vector<float> values)
{
  if (values.empty())
    return std::numeric_limits<float>::quiet_NaN();
  const std::size_t h = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(h), values.end());
  if (values.size() % 2)
    return values[h];
  const float upper = values[h];
  return 0.5f * (upper + *std::max_element(values.begin(),
                                           values.begin() + static_cast<std::ptrdiff_t>(h)));
}

float
weightedMedian(const std::vector<float>& values, const std::vector<float>& weights)
{
  std::vector<std::pair<float, float>> v;
  float total = 0.f;
  for (std::size_t i = 0; i < values.size() && i < weights.size(); ++i)
    if (weights[i] > 0.f && std::isfinite(values[i])) {
      v.emplace_back(values[i], weights[i]);
      total += weights[i];
    }
  if (v.empty())
    return std::numeric_limits<float>::quiet_NaN();
  std::sort(v.begin(), v.end());
  float cumulated = 0.f;
  for (const auto& [value, weight] : v) {
    cumulated += weight;
    if (cumulated >= 0.5f * total)
      return value;
  }
  return v.back().first;
}

Eigen::Vector3f
consensusAxis(const std::vector<Eigen::Vector3f>& axes, const std::vector<float>& weights,
              float inlier_angle, std::vector<char>* inliers)
{
  const std::size_t n = std::min(axes.size(), weights.size());
  if (inliers)
    inliers->assign(axes.size(), 0);
  if (n == 0)
    return Eigen::Vector3f::Zero();
  const float cos_limit = std::cos(inlier_angle);
  std::size_t best = 0;
  float best_support = -1.f;
  for (std::size_t i = 0; i < n; ++i) {
    float support = 0.f;
    for (std::size_t j = 0; j < n; ++j)
      if (std::abs(axes[i].dot(axes[j])) >= cos_limit)
        support += std::max(0.f, weights[j]);
    if (support >= best_support) {
      best_support = support;
      best = i;
    }
  }
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  for (std::size_t j = 0; j < n; ++j) {
    const float d = axes[best].dot(axes[j]);
    if (std::abs(d) < cos_limit)
      continue;
    sum += std::max(0.f, weights[j]) * (d < 0.f ? -axes[j] : axes[j]);
    if (inliers)
      (*inliers)[j] = 1;
  }
  return sum.norm() > 0.f ? Eigen::Vector3f(sum.normalized()) : axes[best];
}

float
logOdds(float p)
{
  if (!std::isfinite(p))
    p = 0.5f;
  p = std::min(0.99f, std::max(0.01f, p));
  return std::log(p / (1.f - p));
}

float
updateLogOdds(float l, float p_observed, float limit)
{
  return std::min(limit, std::max(-limit, l + logOdds(p_observed)));
}

float
probability(float l)
{
  return 1.f / (1.f + std::exp(-l));
}

float
predictionTolerance(const std::vector<float>& innovations, float cap)
{
  double sum = static_cast<double>(cap) * cap / 9.0;
  for (const float x : innovations)
    sum += static_cast<double>(x) * x;
  const double rms = std::sqrt(sum / static_cast<double>(innovations.size() + 1));
  return std::min(cap, static_cast<float>(3.0 * rms));
}

void
updateEvidenceSpread(float& mean, float& var, std::size_t n, float evidence, int memory)
{
  if (n <= 1) {
    mean = evidence;
    var = 0.f;
    return;
  }
  const float w =
    std::max(1.f / static_cast<float>(n), 1.f / static_cast<float>(std::max(memory, 1)));
  const float d = evidence - mean;
  mean += w * d;
  var = (1.f - w) * (var + w * d * d);
}

float
decisionMargin(float evidence_var, float limit)
{
  return std::min(std::sqrt(std::max(evidence_var, 0.f)), 0.5f * limit);
}

bool
decideWithHysteresis(bool current, float l, float threshold, float margin)
{
  return current ? !(l < threshold - margin) : l >= threshold + margin;
}

} // namespace facyl
