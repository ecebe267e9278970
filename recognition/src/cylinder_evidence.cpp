/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/recognition/cylinder_evidence.h>

#include <facyl/features/setting_problem.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace facyl {

std::string
validate(const CylinderDecision& d, std::string* rule)
{
  if (rule)
    rule->clear();
  const auto in = [](float v, bool open_below) {
    return (open_below ? v > 0.f : v >= 0.f) && v <= 1.f;
  };
  if (!in(d.min_score, false))
    return settingProblem("min_score", d.min_score, "is not in [0, 1]", rule);
  if (!in(d.max_curvature_ratio, true))
    return settingProblem("max_curvature_ratio", d.max_curvature_ratio, "is not in (0, 1]", rule);
  if (!in(d.min_angular_coverage, false))
    return settingProblem("min_angular_coverage", d.min_angular_coverage, "is not in [0, 1]", rule);
  if (!in(d.min_probability, false))
    return settingProblem("min_probability", d.min_probability, "is not in [0, 1]", rule);
  if (!in(d.max_arc_gap, false))
    return settingProblem("max_arc_gap", d.max_arc_gap, "is not in [0, 1]", rule);
  if (!in(d.max_taper, true))
    return settingProblem("max_taper", d.max_taper, "is not in (0, 1]", rule);
  return {};
}

bool
passesGates(const CylinderEvidence& e, const CylinderDecision& d)
{
  return e.fitted && e.score(d) >= d.min_score && !(e.curvature_ratio > d.max_curvature_ratio) &&
         e.angular_coverage >= d.min_angular_coverage && !(e.arc_gap > d.max_arc_gap) &&
         !(e.taper > d.max_taper);
}

std::array<float, kEvidenceFeatures>
evidenceFeatures(float p_network, const CylinderEvidence& e)
{
  const auto known = [](float v, float fallback) { return std::isfinite(v) ? v : fallback; };
  float logit = 0.f;
  if (std::isfinite(p_network)) {
    const float p = std::clamp(p_network, 1e-4f, 1.f - 1e-4f);
    logit = std::log(p / (1.f - p));
  }
  const ShapeEvidence& s = e.shape;
  std::array<float, kEvidenceFeatures> f{};
  f[0] = 1.f;
  f[kEvidenceFeatures - 1] = logit;
  if (e.from_lid) {
    const std::size_t l = kLidFeaturesBegin;
    f[l] = 1.f;
    f[l + 1] = known(e.surface_ratio, 0.f);
    f[l + 2] = known(e.angular_coverage, 0.f);
    f[l + 3] = known(e.seen_through, 0.f);
    f[l + 4] = known(s.outside_share, 0.f);
    return f;
  }
  const std::array<float, kLidFeaturesBegin - 1> side = {
    known(e.surface_ratio, 0.f),
    known(e.inlier_ratio, 0.f),
    known(e.curvature_ratio, 1.f),
    known(e.angular_coverage, 0.f),
    std::clamp(known(e.taper, 0.f), 0.f, 1.f),
    known(e.arc_gap, 0.f),
    std::clamp(known(s.normal_agreement, 4.f), 0.f, 4.f),
    known(s.normal_concentration, 1.f),
    std::clamp(known(s.profile_range, 0.f), 0.f, 1.f),
    std::clamp(known(s.axis_bend, 0.f), 0.f, 1.f),
    known(s.inner_share, 0.f),
    known(s.outside_share, 0.f),
    known(s.inner_share, 0.f) * std::clamp(1.f - known(s.aspect, 1.f), 0.f, 1.f)};
  std::copy(side.begin(), side.end(), f.begin() + 1);
  return f;
}

float
evidenceProbability(const std::array<float, kEvidenceFeatures>& w, float p_network,
                    const CylinderEvidence& e)
{
  const auto f = evidenceFeatures(p_network, e);
  double z = 0.0;
  for (std::size_t i = 0; i < kEvidenceFeatures; ++i)
    z += static_cast<double>(w[i]) * f[i];
  return static_cast<float>(1.0 / (1.0 + std::exp(-z)));
}

float
geometricProbability(const CylinderEvidence& e, const CylinderDecision& d)
{
  return e.fitted
           ? evidenceProbability(d.geometry_weights, std::numeric_limits<float>::quiet_NaN(), e)
           : 0.f;
}

bool
acceptGeometry(const CylinderEvidence& e, const CylinderDecision& d)
{
  return passesGates(e, d) && geometricProbability(e, d) >= d.min_probability;
}

bool
acceptCylinder(const CylinderEvidence& e, const CylinderDecision& d)
{
  if (!passesGates(e, d))
    return false;
  const float p = std::isfinite(e.p_cylinder) ? e.p_cylinder : geometricProbability(e, d);
  return p >= d.min_probability;
}

float
curvatureRatio(const pcl::PointCloud<NormalCurvature>& cues, const pcl::Indices& inliers)
{
  std::vector<float> k_max, k_min;
  for (const auto i : inliers) {
    if (i < 0 || static_cast<std::size_t>(i) >= cues.size())
      continue;
    const auto& c = cues[static_cast<std::size_t>(i)];
    if (std::isfinite(c.pc1) && std::isfinite(c.pc2))
      k_max.push_back(std::abs(c.pc1)), k_min.push_back(std::abs(c.pc2));
  }
  if (k_max.empty())
    return std::numeric_limits<float>::quiet_NaN();
  const auto mid = static_cast<std::ptrdiff_t>(k_max.size() / 2);
  std::nth_element(k_max.begin(), k_max.begin() + mid, k_max.end());
  std::nth_element(k_min.begin(), k_min.begin() + mid, k_min.end());
  return k_max[mid] > 0.f ? k_min[mid] / k_max[mid] : 1.f;
}

namespace {
/** Position of \a p in the model's frame: coordinate along the unit axis from the base, and
 * the radial vector. */
struct AxialPosition {
  float t;
  Eigen::Vector3f radial;
};
AxialPosition
axial(const CylinderModel& m, const Eigen::Vector3f& p)
{
  const Eigen::Vector3f a = m.axis.normalized();
  const Eigen::Vector3f d = p - m.base;
  const float t = d.dot(a);
  return {t, d - t * a};
}
float
length(const CylinderModel& m)
{
  return (m.top - m.base).dot(m.axis.normalized());
}
/** Half-thickness of the slab around base and top where caps are looked for: lids sit a
 * little below a can's rim, and the ends are estimated from the lateral inliers. */
float
capSlab(const CylinderModel& m, float distance)
{
  return std::max(distance, 0.1f * m.radius);
}

/** Counts the columns of \a points not in model.inliers (ascending) for which test(i) holds. */
template <typename Test>
std::size_t
countOutliers(const CylinderModel& model, const Eigen::Matrix3Xf& points, Test test)
{
  std::size_t count = 0, next = 0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    while (next < model.inliers.size() && model.inliers[next] < i)
      ++next;
    if (next < model.inliers.size() && model.inliers[next] == i)
      continue;
    count += test(i);
  }
  return count;
}
} // namespace

bool
onCap(const CylinderModel& model, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
      float distance, float cos_max)
{
  const AxialPosition x = axial(model, p);
  const float h = length(model);
  const float slab = capSlab(model, distance);
  const bool on_plane = std::abs(x.t) <= slab || std::abs(x.t - h) <= slab;
  return on_plane && x.radial.norm() <= model.radius + distance &&
         std::abs(n.dot(model.axis.normalized())) >= cos_max;
}

bool
onInnerWall(const CylinderModel& model, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
            float cos_max, float inner_ratio)
{
  const AxialPosition x = axial(model, p);
  const float rho = x.radial.norm();
  if (x.t < 0.f || x.t > length(model) || rho > model.radius || rho < inner_ratio * model.radius ||
      !(rho > 0.f))
    return false;
  return -n.dot(x.radial) >= cos_max * rho; // the normal points at the axis
}

std::size_t
countCapPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
               const Eigen::Matrix3Xf& normals, float distance, float max_angle)
{
  const float cos_max = std::cos(max_angle);
  return countOutliers(model, points, [&](Eigen::Index i) {
    return onCap(model, points.col(i), normals.col(i), distance, cos_max);
  });
}

std::size_t
countInnerWallPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                     const Eigen::Matrix3Xf& normals, float max_angle, float inner_ratio)
{
  const float cos_max = std::cos(max_angle);
  return countOutliers(model, points, [&](Eigen::Index i) {
    return onInnerWall(model, points.col(i), normals.col(i), cos_max, inner_ratio);
  });
}

std::vector<Explained>
explainedPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                const Eigen::Matrix3Xf& normals, const ExplainSettings& s)
{
  const bool with_normals = normals.cols() == points.cols();
  const float cos_max = std::cos(s.max_angle), h = length(model), d = s.distance;
  const Eigen::Vector3f a = model.axis.normalized();
  std::vector<Explained> out(static_cast<std::size_t>(points.cols()), Explained::No);
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const AxialPosition x = axial(model, points.col(i));
    const float rho = x.radial.norm();
    const bool normal_known = with_normals && normals.col(i).allFinite();
    const Eigen::Vector3f n =
      normal_known ? Eigen::Vector3f(normals.col(i)) : Eigen::Vector3f::Zero();
    bool lateral = std::abs(rho - model.radius) <= d && x.t >= -s.axial_margin &&
                   x.t <= h + s.axial_margin && rho > 0.f;
    if (lateral && normal_known) {
      const float along = n.dot(x.radial);
      lateral = (s.outward ? along : std::abs(along)) >= cos_max * rho;
    }
    auto& e = out[static_cast<std::size_t>(i)];
    if (lateral) {
      e = Explained::Lateral;
      continue;
    }
    const float slab = capSlab(model, 2.f * d);
    const bool on_plane = std::abs(x.t) <= slab || std::abs(x.t - h) <= slab;
    if (on_plane && rho <= model.radius + 2.f * d &&
        (!normal_known || std::abs(n.dot(a)) >= cos_max))
      e = Explained::Cap;
    else if (s.inner_wall && x.t >= 0.f && x.t <= h && rho <= model.radius &&
             rho >= s.inner_ratio * model.radius &&
             (!normal_known || -n.dot(x.radial) >= cos_max * rho))
      e = Explained::InnerWall;
  }
  return out;
}

std::vector<int>
pointOwners(const std::vector<std::vector<Explained>>& explained, std::size_t min_points,
            std::vector<bool>& kept)
{
  const std::size_t n = explained.empty() ? 0 : explained.front().size();
  for (const auto& e : explained)
    if (e.size() != n)
      throw std::invalid_argument("facyl::pointOwners: the cylinders' lists have " +
                                  std::to_string(e.size()) + " and " + std::to_string(n) +
                                  " entries; one per point each");
  std::vector<int> owner(n, -1);
  kept.assign(explained.size(), false);
  for (std::size_t c = 0; c < explained.size(); ++c) {
    std::vector<std::size_t> mine;
    for (std::size_t k = 0; k < n; ++k)
      if (owner[k] < 0 && explained[c][k] != Explained::No)
        mine.push_back(k);
    if (mine.empty() || mine.size() < min_points)
      continue;
    kept[c] = true;
    for (std::size_t k : mine)
      owner[k] = static_cast<int>(c);
  }
  return owner;
}

float
taperAlongAxis(const CylinderModel& model, const Eigen::Matrix3Xf& points,
               const Eigen::Matrix3Xf& normals, const std::vector<std::uint8_t>& alive)
{
  const Eigen::Vector3f a = model.axis.normalized();
  std::vector<float> t, rho;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if (!alive.empty() && !alive[static_cast<std::size_t>(i)])
      continue;
    const AxialPosition x = axial(model, points.col(i));
    const float r = x.radial.norm();
    if (r < 0.5f * model.radius || r > 1.5f * model.radius ||
        std::abs(normals.col(i).dot(a)) > 0.7071f)
      continue;
    t.push_back(x.t);
    rho.push_back(r);
  }
  double spread = 0.0; // sum of squared axial deviations of the last fit's points
  const auto fit = [&](const std::vector<std::uint8_t>& use, float& slope, float& offset) {
    double n = 0, st = 0, sr = 0, stt = 0, str = 0;
    for (std::size_t k = 0; k < t.size(); ++k)
      if (use[k]) {
        n += 1, st += t[k], sr += rho[k], stt += double(t[k]) * t[k], str += double(t[k]) * rho[k];
      }
    const double var = stt - st * st / std::max(n, 1.0);
    if (n < 20 || !(var > 1e-10 * n))
      return false;
    slope = static_cast<float>((str - st * sr / n) / var);
    offset = static_cast<float>((sr - slope * st) / n);
    spread = var;
    return true;
  };
  std::vector<std::uint8_t> use(t.size(), 1);
  float slope = 0.f, offset = 0.f;
  if (!fit(use, slope, offset))
    return std::numeric_limits<float>::quiet_NaN();
  // Once more without the outliers (handles, neighbours): residuals beyond 3 robust sigmas.
  std::vector<float> residual(t.size());
  for (std::size_t k = 0; k < t.size(); ++k)
    residual[k] = std::abs(rho[k] - (offset + slope * t[k]));
  std::vector<float> sorted = residual;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2),
                   sorted.end());
  const float cut = 3.f * 1.4826f * sorted[sorted.size() / 2] + 1e-6f;
  for (std::size_t k = 0; k < t.size(); ++k)
    use[k] = residual[k] <= cut;
  if (!fit(use, slope, offset))
    return std::numeric_limits<float>::quiet_NaN();
  // The slope's lower 2-sigma bound: over a short visible band (a tuna can's side) the slope
  // is uncertain, and only a taper the data show counts. Standard error of a least-squares
  // slope: residual sigma / sqrt(sum of squared axial deviations).
  double sse = 0.0, used = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (use[k]) {
      const double r = rho[k] - (offset + slope * t[k]);
      sse += r * r;
      used += 1.0;
    }
  const double se = std::sqrt(sse / std::max(used - 2.0, 1.0) / spread);
  return std::max(0.f, std::abs(slope) - static_cast<float>(2.0 * se));
}

float
convexJunctionShare(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                    const std::vector<Eigen::Index>& part, const std::vector<Eigen::Index>& rest,
                    float distance, float tolerance)
{
  const float d2 = distance * distance;
  std::size_t pairs = 0, convex = 0;
  for (const Eigen::Index a : part)
    for (const Eigen::Index b : rest) {
      const Eigen::Vector3f d = points.col(a) - points.col(b);
      const float n2 = d.squaredNorm();
      if (n2 > d2 || !(n2 > 0.f))
        continue;
      ++pairs;
      convex += (normals.col(a) - normals.col(b)).dot(d) >= tolerance * std::sqrt(n2);
    }
  return pairs ? static_cast<float>(convex) / static_cast<float>(pairs)
               : std::numeric_limits<float>::quiet_NaN();
}

std::size_t
circleSector(float x, float y, int sectors)
{
  const float a = std::atan2(y, x) + static_cast<float>(M_PI); // [0, 2 pi]
  return static_cast<std::size_t>(
    std::min(sectors - 1,
             static_cast<int>(a / (2.f * static_cast<float>(M_PI)) * static_cast<float>(sectors))));
}

float
arcGap(const CylinderModel& model, const Eigen::Matrix3Xf& points)
{
  constexpr int sectors = 36;
  const Eigen::Vector3f a = model.axis.normalized();
  const Eigen::Vector3f e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  int count[sectors] = {0};
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f d = points.col(i) - model.base;
    ++count[circleSector(d.dot(e1), d.dot(e2), sectors)];
  }
  int occupied = 0;
  for (const int c : count)
    occupied += c >= 2;
  if (occupied < 2)
    return 0.f;
  // Empty runs around the circle; the longest one is outside the span, the next is the gap.
  // The walk starts on an occupied sector, so that no run is cut in two where the circle's
  // numbering wraps.
  std::vector<int> runs;
  int start = 0;
  while (count[start] < 2)
    ++start; // occupied >= 2
  for (int k = 1, run = 0; k <= sectors; ++k) {
    const bool empty = k < sectors && count[(start + k) % sectors] < 2;
    if (empty)
      ++run;
    else if (run > 0) {
      runs.push_back(run);
      run = 0;
    }
  }
  if (runs.size() < 2)
    return 0.f;
  std::sort(runs.begin(), runs.end(), std::greater<int>());
  return static_cast<float>(runs[1]) / sectors;
}

CylinderEvidence
localEvidence(const CylinderModel& model, const Eigen::Matrix3Xf& points,
              const Eigen::Matrix3Xf& normals, const std::vector<std::uint8_t>& alive,
              const ExplainSettings& settings, float radial_margin, float axial_margin,
              float margin, std::vector<Explained>* explained, const Eigen::VectorXf& scatter)
{
  const std::vector<Explained> why = explainedPoints(model, points, normals, settings);
  const float reach =
    model.radius + std::max(radial_margin * model.radius, margin) + 2.f * settings.distance;
  const float beyond = std::max(axial_margin * model.radius, margin), h = length(model);
  std::size_t region = 0, lateral = 0, any = 0;
  std::vector<Eigen::Index> on_surface;
  std::vector<std::uint8_t> in_region(static_cast<std::size_t>(points.cols()), 0);
  const bool with_normals = normals.cols() == points.cols();
  const Eigen::Vector3f a = model.axis.normalized();
  const float cos_max = std::cos(settings.max_angle);
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!alive.empty() && !alive[k])
      continue;
    const AxialPosition x = axial(model, points.col(i));
    const bool inside = x.radial.norm() <= reach && x.t >= -beyond && x.t <= h + beyond;
    if (!inside && why[k] == Explained::No)
      continue;
    // A plane across the axis (the box a can stands on, a lid wider than the can) says nothing
    // against a cylinder; a sphere's or a cone's surface beyond the band does.
    if (why[k] == Explained::No && with_normals && std::abs(normals.col(i).dot(a)) >= cos_max)
      continue;
    ++region;
    in_region[k] = 1;
    if (why[k] == Explained::Lateral) {
      ++lateral;
      on_surface.push_back(i);
    }
    any += why[k] != Explained::No;
  }
  CylinderEvidence e;
  e.fitted = true;
  e.angular_coverage = model.angular_coverage;
  if (region > 0) {
    e.inlier_ratio = static_cast<float>(lateral) / static_cast<float>(region);
    e.surface_ratio = static_cast<float>(any) / static_cast<float>(region);
  }
  e.arc_gap = arcGap(model, points(Eigen::all, on_surface));
  if (normals.cols() == points.cols()) {
    e.taper = taperAlongAxis(model, points, normals, alive);
    e.shape = shapeEvidence(model, points, normals, scatter, in_region, settings.distance);
  }
  if (explained)
    *explained = why;
  return e;
}

float
shareInside(const CylinderModel& model, const Eigen::Matrix3Xf& points, float radial_factor,
            float axial_margin)
{
  if (points.cols() == 0 || !(model.radius > 0.f))
    return 0.f;
  const Eigen::Vector3f a = model.axis.normalized();
  const float h = (model.top - model.base).dot(a);
  const float reach = radial_factor * model.radius;
  std::size_t inside = 0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f d = points.col(i) - model.base;
    const float t = d.dot(a);
    inside += (d - t * a).norm() <= reach && t >= -axial_margin && t <= h + axial_margin;
  }
  return static_cast<float>(inside) / static_cast<float>(points.cols());
}

} // namespace facyl
