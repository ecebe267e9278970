/*
 * facyl: fast cylinder detection for PCL.
 * findSectionStep: two stacked sections against one smooth section of a fitted cylinder's side.
 */
#include <facyl/recognition/cylinder_stack.h>

#include "median.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace facyl {

namespace {

/** A side point: its position t along the axis and (x, y) across it, relative to the axis;
 * its normal. */
struct SidePoint {
  double t, x, y;
  Eigen::Vector3f normal;
};

/** A circle across the axis; ok false when the fit failed. */
struct Circle {
  Eigen::Vector2d centre{Eigen::Vector2d::Zero()};
  double radius{0.0};
  bool ok{false};
};

/** Kasa's algebraic circle from the sums of f f^T and f s over points (f = (x, y, 1),
 * s = x^2 + y^2): s = a x + b y + c, centre (a, b) / 2, radius^2 = c + |centre|^2. */
Circle
kasaCircle(const Eigen::Matrix3d& ff, const Eigen::Vector3d& fs)
{
  Circle c;
  if (!(ff(2, 2) >= 3.0))
    return c;
  const Eigen::Vector3d beta = ff.ldlt().solve(fs);
  if (!beta.allFinite())
    return c;
  c.centre = 0.5 * beta.head<2>();
  const double r2 = beta[2] + c.centre.squaredNorm();
  c.ok = r2 > 0.0;
  c.radius = c.ok ? std::sqrt(r2) : 0.0;
  return c;
}

Eigen::Vector3d
circleFeatures(const SidePoint& p)
{
  return Eigen::Vector3d(p.x, p.y, 1.0);
}

double
circleResidual(const Circle& c, const SidePoint& p)
{
  return std::abs((Eigen::Vector2d(p.x, p.y) - c.centre).norm() - c.radius);
}

/** The circle of the points [begin, end) whose \a use is set. */
Circle
fitCircle(const std::vector<SidePoint>& pts, std::size_t begin, std::size_t end,
          const std::vector<std::uint8_t>& use)
{
  Eigen::Matrix3d ff = Eigen::Matrix3d::Zero();
  Eigen::Vector3d fs = Eigen::Vector3d::Zero();
  for (std::size_t k = begin; k < end; ++k)
    if (use[k]) {
      const Eigen::Vector3d f = circleFeatures(pts[k]);
      ff += f * f.transpose();
      fs += f * (pts[k].x * pts[k].x + pts[k].y * pts[k].y);
    }
  return kasaCircle(ff, fs);
}

/** The smooth section: s = f . beta with f = (x, y, 1, t x, t y, t, t^2); centre
 * (beta0 + beta3 t, beta1 + beta4 t) / 2, radius^2 = beta2 + beta5 t + beta6 t^2 + |centre|^2. */
struct SmoothSection {
  Eigen::Matrix<double, 7, 1> beta{Eigen::Matrix<double, 7, 1>::Zero()};
  bool ok{false};
  double residual(const SidePoint& p) const
  {
    const Eigen::Vector2d c =
      0.5 * Eigen::Vector2d(beta[0] + beta[3] * p.t, beta[1] + beta[4] * p.t);
    const double r2 = beta[2] + beta[5] * p.t + beta[6] * p.t * p.t + c.squaredNorm();
    if (!(r2 > 0.0))
      return std::numeric_limits<double>::infinity();
    return std::abs((Eigen::Vector2d(p.x, p.y) - c).norm() - std::sqrt(r2));
  }
};

SmoothSection
fitSmooth(const std::vector<SidePoint>& pts, const std::vector<std::uint8_t>& use)
{
  using Vector7d = Eigen::Matrix<double, 7, 1>;
  Eigen::Matrix<double, 7, 7> ff = Eigen::Matrix<double, 7, 7>::Zero();
  Vector7d fs = Vector7d::Zero();
  std::size_t n = 0;
  for (std::size_t k = 0; k < pts.size(); ++k)
    if (use[k]) {
      const SidePoint& p = pts[k];
      Vector7d f;
      f << p.x, p.y, 1.0, p.t * p.x, p.t * p.y, p.t, p.t * p.t;
      ff += f * f.transpose();
      fs += f * (p.x * p.x + p.y * p.y);
      ++n;
    }
  SmoothSection s;
  if (n < 7)
    return s;
  s.beta = ff.ldlt().solve(fs);
  s.ok = s.beta.allFinite();
  return s;
}

/** 1.4826 x the median of \a r (a robust sigma); \a r is reordered. */
double
robustSigma(std::vector<double>& r)
{
  if (r.empty())
    return std::numeric_limits<double>::infinity();
  const auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
  std::nth_element(r.begin(), mid, r.end());
  return 1.4826 * *mid;
}

/** The residuals of \a residual(k) over the points, a robust sigma of them, and \a use cleared
 * where they exceed 3 of it. */
template <typename Residual>
double
trimOutliers(std::size_t n, Residual residual, std::vector<std::uint8_t>& use)
{
  std::vector<double> r(n);
  for (std::size_t k = 0; k < n; ++k)
    r[k] = residual(k);
  std::vector<double> sorted = r;
  const double sigma = robustSigma(sorted);
  for (std::size_t k = 0; k < n; ++k)
    use[k] = r[k] <= 3.0 * sigma;
  return sigma;
}

/** The robust sigma of \a residual(k) over the points. */
template <typename Residual>
double
sigmaOf(std::size_t n, Residual residual)
{
  std::vector<double> r(n);
  for (std::size_t k = 0; k < n; ++k)
    r[k] = residual(k);
  return robustSigma(r);
}

/** The side points of findSectionStep around \a model, sorted along the axis; false when
 * the model or the normals do not fit. */
bool
sidePointsOf(const CylinderModel& model, const Eigen::Matrix3Xf& points,
             const Eigen::Matrix3Xf& normals, std::vector<SidePoint>& pts)
{
  const Eigen::Vector3f a = model.axis.normalized();
  if (!(model.radius > 0.f) || !a.allFinite() || normals.cols() != points.cols())
    return false;
  const Eigen::Vector3f e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  pts.clear();
  pts.reserve(static_cast<std::size_t>(points.cols()));
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f d = points.col(i) - model.base;
    const float t = d.dot(a);
    const Eigen::Vector3f radial = d - t * a;
    const float rho = radial.norm();
    if (!std::isfinite(rho) || rho < 0.5f * model.radius || rho > 1.5f * model.radius ||
        !(std::abs(normals.col(i).dot(a)) <= 0.7071f))
      continue;
    pts.push_back({t, radial.dot(e1), radial.dot(e2), normals.col(i)});
  }
  std::sort(pts.begin(), pts.end(),
            [](const SidePoint& p, const SidePoint& q) { return p.t < q.t; });
  return true;
}

/** Circles (Kasa) through the sorted side points before a split and from it, from prefix
 * sums of the fit's normal equations. */
class SectionCircles {
public:
  explicit SectionCircles(const std::vector<SidePoint>& pts)
      : ff_(pts.size() + 1, Eigen::Matrix3d::Zero())
      , fs_(pts.size() + 1, Eigen::Vector3d::Zero())
  {
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const Eigen::Vector3d f = circleFeatures(pts[k]);
      ff_[k + 1] = ff_[k] + f * f.transpose();
      fs_[k + 1] = fs_[k] + f * (pts[k].x * pts[k].x + pts[k].y * pts[k].y);
    }
  }
  Circle below(std::size_t k) const
  {
    return kasaCircle(ff_[k], fs_[k]);
  }
  Circle above(std::size_t k) const
  {
    const std::size_t n = ff_.size() - 1;
    return kasaCircle(ff_[n] - ff_[k], fs_[n] - fs_[k]);
  }

private:
  std::vector<Eigen::Matrix3d> ff_;
  std::vector<Eigen::Vector3d> fs_;
};

/** The heights tried between two sections: kSplits splits of \a n sorted side points, evenly
 * between \a min_side and n - min_side; the j-th. */
constexpr int kSplits = 33;
std::size_t
splitAt(int j, std::size_t n, std::size_t min_side)
{
  return min_side +
         (n - 2 * min_side) * static_cast<std::size_t>(j) / static_cast<std::size_t>(kSplits - 1);
}

/** The side points around \a model (sidePointsOf, in \a pts) and the least number of them a
 * section holds (min_side_points, and min_side_share of them); 0 when there are too few for
 * two sections. */
std::size_t
sectionablePoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                  const Eigen::Matrix3Xf& normals, const SectionStepSettings& s,
                  std::vector<SidePoint>& pts)
{
  if (!sidePointsOf(model, points, normals, pts)) {
    pts.clear();
    return 0;
  }
  const std::size_t n = pts.size();
  const std::size_t min_side = std::max<std::size_t>(
    s.min_side_points,
    static_cast<std::size_t>(std::ceil(s.min_side_share * static_cast<float>(n))));
  if (n < 2 * std::max<std::size_t>(s.min_side_points, 1) || 2 * min_side > n)
    return 0;
  return min_side;
}

/** Share of the normals of \a pts[begin, end) within \a max_angle of one of two directions
 * (each the normal with the most others within that angle; the second among those the first
 * leaves): most of a box's faces seen, little of a curved surface. */
float
twoFacesShare(const std::vector<SidePoint>& pts, std::size_t begin, std::size_t end,
              float max_angle)
{
  const float cos_max = std::cos(max_angle);
  std::vector<std::uint8_t> taken(end - begin, 0);
  std::size_t on_faces = 0;
  for (int face = 0; face < 2; ++face) {
    std::size_t best = 0, best_count = 0;
    const std::size_t stride = std::max<std::size_t>(1, (end - begin) / 64);
    for (std::size_t c = begin; c < end; c += stride) {
      if (taken[c - begin] || !pts[c].normal.allFinite())
        continue;
      std::size_t count = 0;
      for (std::size_t i = begin; i < end; ++i)
        count += !taken[i - begin] && pts[i].normal.dot(pts[c].normal) >= cos_max;
      if (count > best_count)
        best = c, best_count = count;
    }
    if (best_count == 0)
      break;
    for (std::size_t i = begin; i < end; ++i)
      if (!taken[i - begin] && pts[i].normal.dot(pts[best].normal) >= cos_max)
        taken[i - begin] = 1;
    on_faces += best_count;
  }
  return end > begin ? static_cast<float>(on_faces) / static_cast<float>(end - begin) : 0.f;
}

} // namespace

SectionStep
findSectionStep(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                const Eigen::Matrix3Xf& normals, const SectionStepSettings& s)
{
  SectionStep out;
  std::vector<SidePoint> pts;
  const std::size_t min_side = sectionablePoints(model, points, normals, s, pts);
  out.side_points = pts.size();
  if (min_side == 0)
    return out;
  const std::size_t n = pts.size();

  // One smooth section, fitted twice (the second time without the outliers).
  std::vector<std::uint8_t> use(n, 1);
  SmoothSection smooth = fitSmooth(pts, use);
  if (!smooth.ok)
    return out;
  trimOutliers(
    n, [&](std::size_t k) { return smooth.residual(pts[k]); }, use);
  smooth = fitSmooth(pts, use);
  if (!smooth.ok)
    return out;
  out.sigma_smooth =
    static_cast<float>(sigmaOf(n, [&](std::size_t k) { return smooth.residual(pts[k]); }));

  // Two sections: the split (between sorted points) whose circles leave the smallest median
  // residual; the sums of each side come from prefix sums.
  const SectionCircles circles(pts);
  double best = std::numeric_limits<double>::infinity();
  std::size_t split = 0;
  std::vector<double> residuals; // one buffer for every split
  residuals.reserve(n);
  for (int j = 0; j < kSplits; ++j) {
    const std::size_t k = splitAt(j, n, min_side);
    const Circle below = circles.below(k), above = circles.above(k);
    if (!below.ok || !above.ok)
      continue;
    residuals.clear();
    for (std::size_t i = 0; i < n; ++i)
      residuals.push_back(circleResidual(i < k ? below : above, pts[i]));
    const double sigma = robustSigma(residuals);
    if (sigma < best) {
      best = sigma;
      split = k;
    }
  }
  if (split == 0)
    return out;
  // Each section once more without its outliers.
  Circle below = circles.below(split);
  Circle above = circles.above(split);
  trimOutliers(
    n, [&](std::size_t i) { return circleResidual(i < split ? below : above, pts[i]); }, use);
  below = fitCircle(pts, 0, split, use);
  above = fitCircle(pts, split, n, use);
  if (!below.ok || !above.ok)
    return out;
  const auto step_residual = [&](std::size_t i) {
    return circleResidual(i < split ? below : above, pts[i]);
  };
  const double sigma_step = sigmaOf(n, step_residual);
  out.sigma_step = static_cast<float>(sigma_step);

  out.height = static_cast<float>(0.5 * (pts[split - 1].t + pts[split].t));
  out.radius_below = static_cast<float>(below.radius);
  out.radius_above = static_cast<float>(above.radius);
  out.centre_shift = static_cast<float>((below.centre - above.centre).norm());
  // How far apart the sections are where they are seen: each section's points from the other
  // section's circle (signed, median; over a short arc a circle's radius and centre trade off,
  // so the circles' own difference says little).
  const auto apart = [&](std::size_t begin, std::size_t end, const Circle& other) {
    std::vector<double> d;
    for (std::size_t i = begin; i < end; ++i)
      if (use[i])
        d.push_back((Eigen::Vector2d(pts[i].x, pts[i].y) - other.centre).norm() - other.radius);
    if (d.empty())
      return 0.0;
    const auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
    std::nth_element(d.begin(), mid, d.end());
    return std::abs(*mid);
  };
  const double gap = std::max(apart(0, split, above), apart(split, n, below));
  out.gap = static_cast<float>(gap);
  out.found =
    out.sigma_smooth >= s.min_improvement * out.sigma_step && gap >= s.min_step_sigmas * sigma_step;
  return out;
}

SectionEnd
findSectionEnd(const CylinderModel& model, const Eigen::Matrix3Xf& points,
               const Eigen::Matrix3Xf& normals, const SectionStepSettings& s)
{
  SectionEnd out;
  std::vector<SidePoint> pts;
  const std::size_t min_side = sectionablePoints(model, points, normals, s, pts);
  out.side_points = pts.size();
  if (min_side == 0)
    return out;
  const std::size_t n = pts.size();
  const SectionCircles circles(pts);
  // The split whose sections differ most in how well a circle fits them.
  double best = 0.0;
  std::size_t split = 0;
  const double extent = pts.back().t - pts.front().t;
  std::vector<double> residuals; // one buffer for every split's sections
  residuals.reserve(n);
  for (int j = 0; j < kSplits; ++j) {
    const std::size_t k = splitAt(j, n, min_side);
    // Each section spans min_side_share of the extent, too (not a rim's crowded pixels).
    if (pts[k - 1].t - pts.front().t < s.min_side_share * extent ||
        pts.back().t - pts[k].t < s.min_side_share * extent)
      continue;
    const Circle below = circles.below(k), above = circles.above(k);
    if (!below.ok || !above.ok)
      continue;
    const auto sigma = [&](const Circle& c, std::size_t begin, std::size_t end) {
      residuals.clear();
      for (std::size_t i = begin; i < end; ++i)
        residuals.push_back(circleResidual(c, pts[i]));
      return robustSigma(residuals);
    };
    const double sb = sigma(below, 0, k), sa = sigma(above, k, n);
    if (!(sb > 0.0) || !(sa > 0.0))
      continue;
    const double ratio = std::max(sa / sb, sb / sa);
    if (ratio > best) {
      best = ratio;
      split = k;
      out.circle_below = sb < sa;
      out.sigma_circle = static_cast<float>(std::min(sa, sb));
      out.sigma_other = static_cast<float>(std::max(sa, sb));
    }
  }
  if (split == 0 || best < s.min_end_ratio)
    return out;
  // The circle's section ends where most points stop lying on its circle (within 3 of its
  // sigmas): the split with the best ratio may fall short of that or beyond it.
  const Circle circle = out.circle_below ? circles.below(split) : circles.above(split);
  std::size_t chunk = std::max<std::size_t>(1, (n - 2 * min_side) / (kSplits - 1));
  const auto onCircle = [&](std::size_t begin, std::size_t end) {
    std::size_t on = 0;
    for (std::size_t i = begin; i < end; ++i)
      on += circleResidual(circle, pts[i]) <= 3.0 * out.sigma_circle;
    return 2 * on >= end - begin;
  };
  // In chunks of the splits' spacing, then finer: back while the circle's last chunk is off
  // it, on while the next is on it.
  for (; chunk > 0; chunk /= 4)
    if (out.circle_below) {
      while (split >= min_side + chunk && !onCircle(split - chunk, split))
        split -= chunk;
      while (split + chunk <= n - min_side && onCircle(split, split + chunk))
        split += chunk;
    }
    else {
      while (split + chunk <= n - min_side && !onCircle(split, split + chunk))
        split += chunk;
      while (split >= min_side + chunk && onCircle(split - chunk, split))
        split -= chunk;
    }
  // The circle's section ends at its last point (the other's first lies beyond a gap: a box's
  // faces wider than the circle are no side points).
  out.height = static_cast<float>(out.circle_below ? pts[split - 1].t : pts[split].t);
  // The other section is a box's faces: its normals on two directions.
  out.faces_share = out.circle_below ? twoFacesShare(pts, split, n, s.max_face_angle)
                                     : twoFacesShare(pts, 0, split, s.max_face_angle);
  // ... and an object's height: at least the circle's radius (a band at an end, where the
  // support's and the object's pixels mix, is none).
  const double other =
    out.circle_below ? pts.back().t - pts[split].t : pts[split - 1].t - pts.front().t;
  out.found = out.faces_share >= s.min_faces_share && other >= static_cast<double>(model.radius);
  return out;
}

InteriorLid
interiorLid(const CylinderModel& model, const Eigen::Matrix3Xf& points,
            const Eigen::Matrix3Xf& normals, float max_angle, float band,
            const SectionStepSettings& settings)
{
  InteriorLid lid;
  if (normals.cols() != points.cols() || !(model.radius > 0.f) || !(model.height > 0.f))
    return lid;
  const Eigen::Vector3f a = model.axis.normalized();
  const float cos_max = std::cos(max_angle), margin = settings.min_side_share * model.height;
  std::vector<float> t;
  float facing = 0.f;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f w = points.col(i) - model.base;
    const float ti = w.dot(a);
    const float along = normals.col(i).dot(a);
    if (ti < margin || ti > model.height - margin || !std::isfinite(along) ||
        std::abs(along) < cos_max || (w - ti * a).norm() > model.radius + band)
      continue;
    t.push_back(ti);
    facing += along;
  }
  if (t.size() < settings.min_side_points)
    return lid;
  const float level = detail::medianOf(t);
  std::vector<float> dev(t.size());
  for (std::size_t k = 0; k < t.size(); ++k)
    dev[k] = std::abs(t[k] - level);
  if (detail::medianOf(dev) <= band) {
    lid.height = level;
    lid.facing = facing >= 0.f ? 1 : -1;
  }
  return lid;
}

} // namespace facyl
