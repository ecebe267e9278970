/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/sample_consensus_alt/cylinder_fitting.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <sstream>

namespace facyl {

// ---------------------------------------------------------------------------------------
// CylinderModel

void
CylinderModel::toCoefficients(pcl::ModelCoefficients& coefficients) const
{
  coefficients.values = {point_on_axis.x(), point_on_axis.y(), point_on_axis.z(),
                         axis.x(),          axis.y(),          axis.z(),
                         radius};
}

float
CylinderModel::signedDistance(const Eigen::Vector3f& p) const
{
  return distanceToLine(p, point_on_axis, axis) - radius;
}

float
axisAngle(const Eigen::Vector3f& a, const Eigen::Vector3f& b)
{
  // atan2 of |cross| and |dot| keeps precision at small angles, where acos(dot) rounds to 0.
  const Eigen::Vector3f u = a.normalized(), v = b.normalized();
  return std::atan2(u.cross(v).norm(), std::abs(u.dot(v)));
}

float
distanceToLine(const Eigen::Vector3f& p, const Eigen::Vector3f& point, const Eigen::Vector3f& axis)
{
  const Eigen::Vector3f w = p - point;
  return (w - w.dot(axis) * axis).norm();
}

// ---------------------------------------------------------------------------------------
// Voting

bool
parseVotingMode(const std::string& name, VotingMode& mode)
{
  for (const auto m : {VotingMode::Rabbani, VotingMode::SoftNormal, VotingMode::SoftCurvature})
    if (name == toString(m)) {
      mode = m;
      return true;
    }
  return false;
}

std::string
toString(VotingMode mode)
{
  switch (mode) {
  case VotingMode::Rabbani:
    return "rabbani";
  case VotingMode::SoftNormal:
    return "soft-normal";
  case VotingMode::SoftCurvature:
    return "soft-curvature";
  }
  return "unknown";
}

void
VotingCues::resize(Eigen::Index n)
{
  for (auto* a : {&nx, &ny, &nz, &cx, &cy, &cz, &weight})
    a->resize(n);
}

namespace {
/** The vote of every point for one cell, summed: the hot loop (N_d x N evaluations). Plain
 * loops over arrays so that the compiler vectorises them, cloned for AVX2+FMA where the CPU
 * has it (the default build targets baseline x86-64). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FACYL_VOTE_CLONES __attribute__((target_clones("avx2,fma", "default")))
#else
#define FACYL_VOTE_CLONES
#endif

FACYL_VOTE_CLONES float
softVotes(float dx, float dy, float dz, const float* nx, const float* ny, const float* nz,
          const float* cx, const float* cy, const float* cz, const float* w, Eigen::Index n,
          int p, bool curvature)
{
  float acc = 0.f;
  if (curvature && p == 1) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float dn = std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      const float dc = std::abs(dx * cx[s] + dy * cy[s] + dz * cz[s]);
      acc += w[s] * (1.f - dn) * (1.f - dc);
    }
  }
  else if (curvature && p == 2) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float dn = std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      const float dc = std::abs(dx * cx[s] + dy * cy[s] + dz * cz[s]);
      const float b = (1.f - dn) * (1.f - dc);
      acc += w[s] * b * b;
    }
  }
  else if (curvature) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float dn = std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      const float dc = std::abs(dx * cx[s] + dy * cy[s] + dz * cz[s]);
      const float b = (1.f - dn) * (1.f - dc);
      float v = b;
      for (int k = 1; k < p; ++k)
        v *= b;
      acc += w[s] * v;
    }
  }
  else if (p == 1) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s)
      acc += w[s] * (1.f - std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]));
  }
  else if (p == 2) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float b = 1.f - std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      acc += w[s] * b * b;
    }
  }
  else {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float b = 1.f - std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      float v = b;
      for (int k = 1; k < p; ++k)
        v *= b;
      acc += w[s] * v;
    }
  }
  return acc;
}

FACYL_VOTE_CLONES float
hardVotes(float dx, float dy, float dz, const float* nx, const float* ny, const float* nz,
          Eigen::Index n, float threshold)
{
  float count = 0.f;
#pragma omp simd reduction(+ : count)
  for (Eigen::Index s = 0; s < n; ++s)
    count += std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]) < threshold ? 1.f : 0.f;
  return count;
}
} // namespace

void
castVotes(const Eigen::Matrix3Xf& directions, const VotingCues& cues, VotingMode mode,
          int kernel_exponent, float hard_threshold, Eigen::VectorXf& votes)
{
  const Eigen::Index n = cues.size();
  votes.setZero(directions.cols());
  if (n == 0)
    return;
  const int p = std::max(1, kernel_exponent);
  const bool curvature = mode == VotingMode::SoftCurvature;
  for (Eigen::Index i = 0; i < directions.cols(); ++i) {
    const float dx = directions(0, i), dy = directions(1, i), dz = directions(2, i);
    votes(i) = mode == VotingMode::Rabbani
                   ? hardVotes(dx, dy, dz, cues.nx.data(), cues.ny.data(), cues.nz.data(), n,
                               hard_threshold)
                   : softVotes(dx, dy, dz, cues.nx.data(), cues.ny.data(), cues.nz.data(),
                               cues.cx.data(), cues.cy.data(), cues.cz.data(),
                               cues.weight.data(), n, p, curvature);
  }
}

std::vector<Eigen::Index>
findPeaks(const Eigen::Matrix3Xf& directions, const Eigen::VectorXf& votes,
          std::size_t max_peaks, float min_separation)
{
  std::vector<Eigen::Index> order(static_cast<std::size_t>(votes.size()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](Eigen::Index a, Eigen::Index b) { return votes(a) > votes(b); });
  const float cos_sep = std::cos(min_separation);
  std::vector<Eigen::Index> peaks;
  for (const auto i : order) {
    if (peaks.size() >= max_peaks || !(votes(i) > 0.f))
      break;
    bool far = true;
    for (const auto j : peaks)
      if (std::abs(directions.col(i).dot(directions.col(j))) > cos_sep) {
        far = false;
        break;
      }
    if (far)
      peaks.push_back(i);
  }
  return peaks;
}

namespace {
float
medianOf(std::vector<float>& v)
{
  if (v.empty())
    return 0.f;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/** Two unit vectors completing \a a to a right-handed orthonormal frame. */
void
basisFor(const Eigen::Vector3f& a, Eigen::Vector3f& u, Eigen::Vector3f& v)
{
  u = a.unitOrthogonal();
  v = a.cross(u);
}

constexpr float kOneDegree = static_cast<float>(M_PI / 180.0);

/** sum_s w_s n_s n_s^T over the cues' normals. */
Eigen::Matrix3d
normalScatter(const VotingCues& cues, const Eigen::ArrayXf& w)
{
  Eigen::Matrix3d m;
  m(0, 0) = (w * cues.nx * cues.nx).sum();
  m(1, 1) = (w * cues.ny * cues.ny).sum();
  m(2, 2) = (w * cues.nz * cues.nz).sum();
  m(0, 1) = m(1, 0) = (w * cues.nx * cues.ny).sum();
  m(0, 2) = m(2, 0) = (w * cues.nx * cues.nz).sum();
  m(1, 2) = m(2, 1) = (w * cues.ny * cues.nz).sum();
  return m;
}
} // namespace

Eigen::Vector3f
refineAxis(const VotingCues& cues, const Eigen::Vector3f& initial, float initial_tolerance,
           int iterations)
{
  Eigen::Vector3f a = initial.normalized();
  float tolerance = std::min(initial_tolerance, static_cast<float>(M_PI / 2));
  const Eigen::Index n = cues.size();
  Eigen::ArrayXf omega(n);
  std::vector<float> residuals;
  residuals.reserve(static_cast<std::size_t>(n));
  for (int it = 0; it < iterations; ++it) {
    const float s = std::sin(tolerance);
    const Eigen::ArrayXf dn = a.x() * cues.nx + a.y() * cues.ny + a.z() * cues.nz;
    omega = (dn.abs() < s).select(cues.weight * (1.f - (dn / s).square()).square(), 0.f);
    const float total = omega.sum();
    if (!(total > 0.f))
      break;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(normalScatter(cues, omega));
    Eigen::Vector3f next = solver.eigenvectors().col(0).cast<float>().normalized();
    if (!next.allFinite())
      break;
    if (next.dot(a) < 0.f)
      next = -next;
    const float change = axisAngle(next, a);
    a = next;
    residuals.clear();
    for (Eigen::Index i = 0; i < n; ++i)
      if (omega(i) > 0.f)
        residuals.push_back(std::abs(dn(i)));
    const float sigma = 1.4826f * medianOf(residuals);
    const float next_tolerance =
        std::clamp(std::asin(std::min(1.f, 3.5f * sigma)), kOneDegree, tolerance);
    const bool settled = change < 1e-5f && next_tolerance == tolerance;
    tolerance = next_tolerance;
    if (settled)
      break;
  }
  return foldToHemisphere(a);
}

// ---------------------------------------------------------------------------------------
// Position and radius

bool
houghCircle(const Eigen::Matrix2Xf& points, const Eigen::Matrix2Xf& normals, float r_min,
            float r_max, int grid, Circle& circle)
{
  const Eigen::Index n = points.cols();
  if (n == 0 || grid < 2 || !(r_max > r_min) || !std::isfinite(r_max))
    return false;
  const Eigen::Vector2f lo = points.rowwise().minCoeff().array() - r_max;
  const Eigen::Vector2f hi = points.rowwise().maxCoeff().array() + r_max;
  const float cell = (hi - lo).maxCoeff() / static_cast<float>(grid);
  if (!(cell > 0.f))
    return false;
  std::vector<float> acc(static_cast<std::size_t>(grid * grid), 0.f);
  // Rays in grid units: from p +- r_min m to p +- r_max m, about a cell a step.
  const float inv_cell = 1.f / cell;
  const int steps = static_cast<int>(std::ceil((r_max - r_min) * inv_cell)) + 1;
  const float step = (r_max - r_min) * inv_cell / static_cast<float>(std::max(1, steps - 1));
  for (Eigen::Index i = 0; i < n; ++i) {
    const float px = (points(0, i) - lo.x()) * inv_cell, py = (points(1, i) - lo.y()) * inv_cell;
    const float mx = normals(0, i), my = normals(1, i);
    const float t0 = r_min * inv_cell;
    for (const float sign : {1.f, -1.f}) {
      float x = px + sign * t0 * mx, y = py + sign * t0 * my;
      const float dx = sign * step * mx, dy = sign * step * my;
      for (int k = 0; k < steps; ++k, x += dx, y += dy) {
        if (x < 0.f || y < 0.f)
          continue;
        const int ix = static_cast<int>(x), iy = static_cast<int>(y);
        if (ix < grid && iy < grid)
          acc[static_cast<std::size_t>(iy * grid + ix)] += 1.f;
      }
    }
  }
  // Peak of the 3x3 box-filtered accumulator (separable: rows, then columns), then the
  // vote-weighted centre of its 3x3 cells.
  std::vector<float> rows(acc.size(), 0.f);
  for (int y = 0; y < grid; ++y)
    for (int x = 1; x + 1 < grid; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * grid + x);
      rows[i] = acc[i - 1] + acc[i] + acc[i + 1];
    }
  float best = 0.f;
  int bx = -1, by = -1;
  for (int y = 1; y + 1 < grid; ++y)
    for (int x = 1; x + 1 < grid; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * grid + x);
      const float s = rows[i - static_cast<std::size_t>(grid)] + rows[i] +
                      rows[i + static_cast<std::size_t>(grid)];
      if (s > best) {
        best = s;
        bx = x;
        by = y;
      }
    }
  if (bx < 0)
    return false;
  Eigen::Vector2f centre = Eigen::Vector2f::Zero();
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const float w = acc[static_cast<std::size_t>((by + dy) * grid + bx + dx)];
      centre += w * (lo + Eigen::Vector2f(bx + dx + 0.5f, by + dy + 0.5f) * cell);
    }
  centre /= best;

  // Radius: the mode of the distances from the centre to the points whose normal line passes
  // near it (those that voted for it), on bins of one cell.
  std::vector<float> distances;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2f w = centre - points.col(i);
    const float off_line = std::abs(normals(0, i) * w.y() - normals(1, i) * w.x());
    const float d = w.norm();
    if (off_line < 1.5f * cell && d >= r_min && d <= r_max)
      distances.push_back(d);
  }
  if (distances.empty())
    return false;
  const int bins = static_cast<int>((r_max - r_min) / cell) + 1;
  std::vector<int> hist(static_cast<std::size_t>(bins) + 2, 0);
  for (const float d : distances)
    ++hist[static_cast<std::size_t>((d - r_min) / cell) + 1];
  int mode = 1, mode_count = -1;
  for (int b = 1; b <= bins; ++b) {
    const int c = hist[b - 1] + hist[b] + hist[b + 1];
    if (c > mode_count) {
      mode_count = c;
      mode = b;
    }
  }
  const float mode_lo = r_min + static_cast<float>(mode - 2) * cell;
  const float mode_hi = mode_lo + 3.f * cell;
  std::vector<float> near_mode;
  for (const float d : distances)
    if (d >= mode_lo && d <= mode_hi)
      near_mode.push_back(d);
  circle.center = centre;
  circle.radius = near_mode.empty() ? medianOf(distances) : medianOf(near_mode);
  return true;
}

bool
fitCircle(const Eigen::Matrix2Xf& points, float threshold, Circle& circle, int iterations)
{
  const Eigen::Index n = points.cols();
  Eigen::Vector2d c = circle.center.cast<double>();
  double r = circle.radius;
  double thr = threshold;
  std::vector<float> residuals;
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jte = Eigen::Vector3d::Zero();
    residuals.clear();
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector2d w = points.col(i).cast<double>() - c;
      const double d = w.norm();
      const double e = d - r;
      if (!(std::abs(e) < thr) || d <= 0.0)
        continue;
      const Eigen::Vector3d j(-w.x() / d, -w.y() / d, -1.0);
      jtj.noalias() += j * j.transpose();
      jte.noalias() += j * e;
      residuals.push_back(static_cast<float>(std::abs(e)));
    }
    if (residuals.size() < 3)
      return false;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(jtj);
    const Eigen::Vector3d delta = -ldlt.solve(jte);
    if (ldlt.info() != Eigen::Success || !delta.allFinite())
      return false;
    c += delta.head<2>();
    r += delta(2);
    const double sigma = 1.4826 * medianOf(residuals);
    thr = std::clamp(3.5 * sigma, 1e-6 + 1e-4 * std::abs(r), thr);
    if (delta.norm() < 1e-7 * (1.0 + std::abs(r)))
      break;
  }
  if (!(r > 0.0) || !c.allFinite())
    return false;
  circle.center = c.cast<float>();
  circle.radius = static_cast<float>(r);
  return true;
}

bool
refineCylinder(const Eigen::Matrix3Xf& points, Eigen::Vector3f& point_on_axis,
               Eigen::Vector3f& axis, float& radius, int iterations)
{
  const Eigen::Index n = points.cols();
  if (n < 5)
    return false;
  Eigen::Vector3d a = axis.cast<double>().normalized();
  // Keep the point on the axis next to the data: the Jacobian in the tilt is proportional to
  // the distance along the axis, and a far point makes the system badly conditioned.
  const Eigen::Vector3d centroid = points.cast<double>().rowwise().mean();
  Eigen::Vector3d p0 = point_on_axis.cast<double>();
  p0 += (centroid - p0).dot(a) * a;
  double r = radius;
  for (int it = 0; it < iterations; ++it) {
    const Eigen::Vector3d u = a.unitOrthogonal(), v = a.cross(u);
    Eigen::Matrix<double, 5, 5> jtj = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> jte = Eigen::Matrix<double, 5, 1>::Zero();
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d w = points.col(i).cast<double>() - p0;
      const double wa = w.dot(a);
      const Eigen::Vector3d d = w - wa * a;
      const double rho = d.norm();
      if (rho <= 0.0)
        continue;
      const Eigen::Vector3d dir = d / rho;
      const double du = dir.dot(u), dv = dir.dot(v);
      Eigen::Matrix<double, 5, 1> j;
      j << -du, -dv, -wa * du, -wa * dv, -1.0;
      jtj.noalias() += j * j.transpose();
      jte.noalias() += j * (rho - r);
    }
    const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> ldlt(jtj);
    const Eigen::Matrix<double, 5, 1> delta = -ldlt.solve(jte);
    if (ldlt.info() != Eigen::Success || !delta.allFinite() ||
        !(ldlt.vectorD().minCoeff() > 1e-12 * ldlt.vectorD().maxCoeff()))
      return false;
    p0 += delta(0) * u + delta(1) * v;
    a = (a + delta(2) * u + delta(3) * v).normalized();
    r += delta(4);
    if (delta.norm() < 1e-8 * (1.0 + std::abs(r)))
      break;
  }
  if (!(r > 0.0) || !a.allFinite() || !p0.allFinite())
    return false;
  point_on_axis = p0.cast<float>();
  axis = a.cast<float>();
  radius = static_cast<float>(r);
  return true;
}

float
normalRotationSlope(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                    const Eigen::Vector3f& point_on_axis, const Eigen::Vector3f& axis)
{
  const Eigen::Index n = points.cols();
  if (n < 3)
    return 1.f;
  const Eigen::Vector3f a = axis.normalized();
  const Eigen::Vector3f u = a.unitOrthogonal(), v = a.cross(u);
  std::vector<double> phi, eps;
  phi.reserve(static_cast<std::size_t>(n));
  eps.reserve(static_cast<std::size_t>(n));
  double sum_sin = 0.0, sum_cos = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3f w = points.col(i) - point_on_axis;
    const Eigen::Vector2d d(w.dot(u), w.dot(v));
    Eigen::Vector2d m(normals.col(i).dot(u), normals.col(i).dot(v));
    if (!(d.norm() > 0.0) || !(m.norm() > 0.0))
      continue;
    if (m.dot(d) < 0.0)
      m = -m;
    const double angle = std::atan2(d.y(), d.x());
    phi.push_back(angle);
    eps.push_back(std::atan2(d.x() * m.y() - d.y() * m.x(), d.dot(m)));
    sum_sin += std::sin(2.0 * angle); // angles modulo pi: opposite strips (two lids) pool
    sum_cos += std::cos(2.0 * angle);
  }
  if (phi.size() < 3)
    return 1.f;
  const double mean_phi = 0.5 * std::atan2(sum_sin, sum_cos);
  double var = 0.0, cov = 0.0, var_eps = 0.0, mean_eps = 0.0, mean_c = 0.0;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    phi[k] = std::remainder(phi[k] - mean_phi, M_PI);
    mean_c += phi[k];
    mean_eps += eps[k];
  }
  const double count = static_cast<double>(phi.size());
  mean_c /= count;
  mean_eps /= count;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    var += (phi[k] - mean_c) * (phi[k] - mean_c);
    cov += (phi[k] - mean_c) * (eps[k] - mean_eps);
    var_eps += (eps[k] - mean_eps) * (eps[k] - mean_eps);
  }
  var /= count;
  cov /= count;
  var_eps /= count;
  // A uniform arc of width W has variance W^2 / 12: past a quarter turn (modulo pi), no plane
  // strip fits.
  if (var > M_PI * M_PI / 48.0)
    return 1.f;
  if (!(var > 0.0))
    return 0.f;
  // The slope must be measured, not guessed: take its lower 2-sigma bound, so that an arc too
  // narrow for the normals' noise (a huge radius through a flat patch) scores 0.
  const double slope = 1.0 + cov / var;
  const double residual = std::max(0.0, var_eps - cov * cov / var);
  const double standard_error = std::sqrt(residual / (count * var));
  return static_cast<float>(std::clamp(slope - 2.0 * standard_error, 0.0, 1.0));
}

// ---------------------------------------------------------------------------------------
// The estimator

std::string
validate(const HoughCylinderParameters& p)
{
  std::ostringstream why;
  if (p.kernel_exponent < 1 || p.kernel_exponent > 16)
    why << "kernel exponent " << p.kernel_exponent << " is not in [1, 16]";
  else if (!(p.radius_min >= 0.f) || !std::isfinite(p.radius_min))
    why << "minimum radius " << p.radius_min << " is not a finite value >= 0";
  else if (!(p.radius_max > p.radius_min))
    why << "radius limits [" << p.radius_min << ", " << p.radius_max
        << "] are empty or inverted";
  else if (!(p.distance_threshold >= 0.f) || !std::isfinite(p.distance_threshold))
    why << "distance threshold " << p.distance_threshold << " is not a finite value >= 0";
  else if (!(p.normal_angle_threshold > 0.f) ||
           !(p.normal_angle_threshold <= static_cast<float>(M_PI / 2) + 1e-6f))
    why << "normal angle threshold " << p.normal_angle_threshold << " rad is not in (0, pi/2]";
  else if (p.orientation_candidates < 1)
    why << "at least one orientation candidate is needed";
  else if (p.max_cylinders < 1)
    why << "max cylinders must be at least 1";
  else if (p.circle_grid < 8 || p.circle_grid > 4096)
    why << "circle grid " << p.circle_grid << " is not in [8, 4096]";
  return why.str();
}

namespace {

/** Cues of the listed columns, as voting arrays. */
VotingCues
gatherVotingCues(const CylinderCues& cues, const std::vector<int>& columns, bool curvature)
{
  VotingCues v;
  v.resize(static_cast<Eigen::Index>(columns.size()));
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const int s = columns[k];
    v.nx(i) = cues.normals(0, s);
    v.ny(i) = cues.normals(1, s);
    v.nz(i) = cues.normals(2, s);
    if (curvature) {
      v.cx(i) = cues.curvature_directions(0, s);
      v.cy(i) = cues.curvature_directions(1, s);
      v.cz(i) = cues.curvature_directions(2, s);
      v.weight(i) = cues.weights(s);
    }
    else {
      v.cx(i) = v.cy(i) = v.cz(i) = 0.f;
      v.weight(i) = 1.f;
    }
  }
  return v;
}

/** Evenly strided subset of at most \a limit entries (all when limit is 0). */
std::vector<int>
subsample(const std::vector<int>& columns, std::size_t limit)
{
  if (limit == 0 || columns.size() <= limit)
    return columns;
  std::vector<int> out(limit);
  for (std::size_t k = 0; k < limit; ++k)
    out[k] = columns[k * columns.size() / limit];
  return out;
}

struct Candidate {
  Eigen::Vector3f point_on_axis;
  Eigen::Vector3f axis;
  float radius{0.f};
  float threshold{0.f};
  float radius_limit{std::numeric_limits<float>::infinity()}; ///< given or from the data
};

/** Robust noise estimate: 1.4826 MAD of the surface distances of the points near it. */
float
estimateThreshold(const CylinderCues& cues, const std::vector<int>& columns,
                  const Candidate& c)
{
  std::vector<float> residuals;
  residuals.reserve(columns.size());
  for (const int s : columns) {
    const float e = std::abs(distanceToLine(cues.points.col(s), c.point_on_axis, c.axis) - c.radius);
    if (e < 0.3f * c.radius)
      residuals.push_back(e);
  }
  const float sigma = 1.4826f * medianOf(residuals);
  return std::clamp(3.f * sigma, 1e-3f * c.radius, 0.1f * c.radius);
}

/** Inliers: near the surface, and with a normal close to the surface normal. */
std::vector<int>
selectInliers(const CylinderCues& cues, const std::vector<int>& columns, const Candidate& c,
              float cos_normal, bool outward)
{
  std::vector<int> inliers;
  for (const int s : columns) {
    const Eigen::Vector3f w = cues.points.col(s) - c.point_on_axis;
    const Eigen::Vector3f d = w - w.dot(c.axis) * c.axis;
    const float rho = d.norm();
    if (std::abs(rho - c.radius) >= c.threshold || !(rho > 0.f))
      continue;
    const float along = cues.normals.col(s).dot(d);
    if ((outward ? along : std::abs(along)) < cos_normal * rho)
      continue;
    inliers.push_back(s);
  }
  return inliers;
}

/** The points whose normal is within the normal angle threshold of orthogonal to \a axis:
 * those a cylinder about it can explain. */
std::vector<int>
supporters(const CylinderCues& cues, const std::vector<int>& active, const Eigen::Vector3f& axis,
           const HoughCylinderParameters& params)
{
  const float sin_n = std::sin(params.normal_angle_threshold);
  std::vector<int> support;
  for (const int s : active)
    if (std::abs(axis.dot(cues.normals.col(s))) < sin_n)
      support.push_back(s);
  return support;
}

/** Step 2 for one axis: circle Hough on the supporters, circle and cylinder least squares. */
std::optional<Candidate>
fitPosition(const CylinderCues& cues, const std::vector<int>& active, const Eigen::Vector3f& axis,
            const HoughCylinderParameters& params)
{
  Eigen::Vector3f u, v;
  basisFor(axis, u, v);
  const std::vector<int> support = supporters(cues, active, axis, params);
  if (support.size() < 5)
    return std::nullopt;

  // The supporters projected on the plane orthogonal to the axis, with their normals.
  Eigen::Matrix<float, 2, 3> project;
  project << u.transpose(), v.transpose();
  const Eigen::Matrix3Xf support_points = cues.points(Eigen::all, support);
  const Eigen::Matrix3Xf support_normals = cues.normals(Eigen::all, support);
  const Eigen::Matrix2Xf q = project * support_points;
  const Eigen::Matrix2Xf m = project * support_normals;
  const Eigen::RowVectorXf m_len = m.colwise().norm();
  const Eigen::Matrix2Xf qm = m.array().rowwise() / m_len.array();
  const float extent = (q.rowwise().maxCoeff() - q.rowwise().minCoeff()).norm();
  const float r_max = std::min(params.radius_max, 2.f * extent);
  if (!(r_max > params.radius_min))
    return std::nullopt;

  // Circle Hough voters: an even subset of the supporters whose normal is not along the axis.
  std::vector<Eigen::Index> voters;
  const auto n_support = static_cast<Eigen::Index>(support.size());
  const Eigen::Index n_voters = std::min<Eigen::Index>(n_support, 300);
  for (Eigen::Index k = 0; k < n_voters; ++k) {
    const Eigen::Index i = k * n_support / n_voters;
    if (m_len(i) > 0.3f)
      voters.push_back(i);
  }
  const Eigen::Matrix2Xf vq = q(Eigen::all, voters);
  const Eigen::Matrix2Xf vm = qm(Eigen::all, voters);
  Circle circle;
  if (!houghCircle(vq, vm, params.radius_min, r_max, params.circle_grid, circle))
    return std::nullopt;
  float cell = (extent + 2.f * r_max) / static_cast<float>(params.circle_grid);

  // The points that agree with a circle: near it, with a normal along its radius. Other
  // structure that shares the axis direction (a table under a lying can) drops out here.
  const float cos_n = std::cos(params.normal_angle_threshold);
  const auto agreeing = [&](const Eigen::Matrix2Xf& pts, const Eigen::Matrix2Xf& nrm,
                            const Circle& c, float band) {
    std::vector<Eigen::Index> keep;
    for (Eigen::Index i = 0; i < pts.cols(); ++i) {
      const Eigen::Vector2f w = pts.col(i) - c.center;
      const float d = w.norm();
      const float along = nrm.col(i).dot(w);
      if (std::abs(d - c.radius) < band &&
          (params.outward_normals ? along : std::abs(along)) >= cos_n * d)
        keep.push_back(i);
    }
    return keep;
  };
  // Coarse to fine: with a wide radius range the first grid's cells can exceed the radius;
  // vote again on the agreeing points over a range around the first estimate.
  if (cell > 0.1f * circle.radius) {
    const auto keep = agreeing(vq, vm, circle, std::max(0.5f * circle.radius, 2.f * cell));
    if (keep.size() >= 5) {
      const float lo = std::max(params.radius_min, 0.5f * circle.radius - cell);
      const float hi = std::min(r_max, 1.5f * circle.radius + cell);
      Circle fine;
      if (hi > lo && houghCircle(vq(Eigen::all, keep), vm(Eigen::all, keep), lo, hi,
                                 params.circle_grid, fine)) {
        Eigen::Matrix2Xf kept = vq(Eigen::all, keep);
        const float fine_extent = (kept.rowwise().maxCoeff() - kept.rowwise().minCoeff()).norm();
        circle = fine;
        cell = (fine_extent + 2.f * hi) / static_cast<float>(params.circle_grid);
      }
    }
  }
  const auto keep = agreeing(q, qm, circle, std::max(0.3f * circle.radius, 3.f * cell));
  if (keep.size() < 5 ||
      !fitCircle(q(Eigen::all, keep), std::max(0.3f * circle.radius, 3.f * cell), circle))
    return std::nullopt;
  if (circle.radius < params.radius_min || circle.radius > r_max)
    return std::nullopt;

  Candidate c;
  c.axis = axis;
  c.point_on_axis = circle.center.x() * u + circle.center.y() * v;
  c.radius = circle.radius;
  c.radius_limit = r_max;
  const bool auto_threshold = params.distance_threshold <= 0.f;
  c.threshold = auto_threshold ? estimateThreshold(cues, support, c) : params.distance_threshold;
  return c;
}

/** Least squares on all five parameters, alternating with the choice of inliers. */
Candidate
refineCandidate(const CylinderCues& cues, const std::vector<int>& active, Candidate c,
                const HoughCylinderParameters& params)
{
  const bool auto_threshold = params.distance_threshold <= 0.f;
  const std::vector<int> support = supporters(cues, active, c.axis, params);
  const float cos_normal = std::cos(params.normal_angle_threshold);
  for (int round = 0; round < 3; ++round) {
    const std::vector<int> inliers =
      selectInliers(cues, active, c, cos_normal, params.outward_normals);
    if (inliers.size() < 6)
      break;
    const Eigen::Matrix3Xf pts = cues.points(Eigen::all, inliers);
    Candidate next = c;
    if (!refineCylinder(pts, next.point_on_axis, next.axis, next.radius) ||
        next.radius < params.radius_min || next.radius > c.radius_limit)
      break;
    if (auto_threshold)
      next.threshold = estimateThreshold(cues, support, next);
    const bool settled = axisAngle(next.axis, c.axis) < 1e-5f &&
                         std::abs(next.radius - c.radius) < 1e-6f * c.radius;
    c = next;
    if (settled)
      break;
  }
  return c;
}

/** The finished model of a candidate: inliers, extent, quality figures. */
CylinderModel
describe(const CylinderCues& cues, const std::vector<int>& active, const Candidate& c,
         const HoughCylinderParameters& params)
{
  CylinderModel m;
  m.axis = c.axis;
  m.point_on_axis = c.point_on_axis;
  m.radius = c.radius;
  m.distance_threshold = c.threshold;
  const std::vector<int> inliers =
      selectInliers(cues, active, c, std::cos(params.normal_angle_threshold),
                    params.outward_normals);
  m.inliers.assign(inliers.begin(), inliers.end());
  describeInliers(cues.points(Eigen::all, inliers), m);
  return m;
}

} // namespace

void
describeInliers(const Eigen::Matrix3Xf& points, CylinderModel& m)
{
  m.axis = foldToHemisphere(m.axis.normalized());
  Eigen::Vector3f u, v;
  basisFor(m.axis, u, v);
  const Eigen::Vector3f origin = m.point_on_axis;
  float t_min = std::numeric_limits<float>::max(), t_max = -t_min;
  double sq = 0.0;
  std::vector<char> sectors(36, 0);
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f w = points.col(i) - origin;
    const float t = w.dot(m.axis);
    const Eigen::Vector3f d = w - t * m.axis;
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
    const double e = d.norm() - m.radius;
    sq += e * e;
    const float angle = std::atan2(d.dot(v), d.dot(u)) + static_cast<float>(M_PI);
    sectors[std::min<std::size_t>(35, static_cast<std::size_t>(angle / (2 * M_PI) * 36))] = 1;
  }
  if (points.cols() == 0)
    t_min = t_max = 0.f;
  m.base = origin + t_min * m.axis;
  m.top = origin + t_max * m.axis;
  m.point_on_axis = m.base;
  m.height = t_max - t_min;
  m.rms_error = points.cols() == 0 ? 0.f : static_cast<float>(std::sqrt(sq / points.cols()));
  m.angular_coverage =
      static_cast<float>(std::count(sectors.begin(), sectors.end(), 1)) / 36.f;
}

namespace {

std::optional<CylinderModel>
fitOne(const CylinderCues& cues, const std::vector<int>& active,
       const std::vector<OrientationAccumulator>& accumulators,
       const HoughCylinderParameters& params)
{
  const bool curvature = params.voting_mode == VotingMode::SoftCurvature;
  const std::vector<int> voters = subsample(active, params.max_voting_points);
  const VotingCues voting = gatherVotingCues(cues, voters, curvature);
  // The axis refinement needs fewer normals than the votes (the final least squares uses all
  // inliers anyway).
  const VotingCues refining = voters.size() > 400
                                  ? gatherVotingCues(cues, subsample(voters, 400), curvature)
                                  : voting;

  struct Seed {
    Eigen::Vector3f axis;
    float cell_radius;
  };
  std::vector<Seed> seeds;
  Eigen::VectorXf votes;
  bool normals_seed_tried = false;
  // A seed within the refinement's reach of a known one adds nothing but time.
  const auto addPeaks = [&](const OrientationAccumulator& acc, VotingMode mode,
                            std::size_t count) {
    const float cell = acc.cellRadius();
    const float separation = std::max(4.f * cell, 10.f * kOneDegree);
    castVotes(acc.directions(), voting, mode, params.kernel_exponent, std::sin(cell), votes);
    for (const auto i : findPeaks(acc.directions(), votes, count, separation)) {
      const Eigen::Vector3f d = acc.directions().col(i);
      const bool known = std::any_of(seeds.begin(), seeds.end(), [&](const Seed& s) {
        return axisAngle(s.axis, d) < (mode == params.voting_mode ? std::max(s.cell_radius, cell)
                                                                  : separation);
      });
      if (!known)
        seeds.push_back({d, cell});
    }
  };
  for (const auto& acc : accumulators)
    addPeaks(acc, params.voting_mode, params.orientation_candidates);

  // Candidates compete on their inliers. With curvature cues each inlier counts by its vote
  // for the candidate's axis (eq. 3): a plane strip that happens to fit a wide cylinder (a lid
  // seen along an axis in its plane) has random c_max and low weights, a real lateral surface
  // has c_max orthogonal to the axis and weights near 1.
  // Either way the score is scaled by normalRotationSlope: plane strips score ~0.
  const auto score = [&](const CylinderModel& m) {
    const double slope = normalRotationSlope(cues.points(Eigen::all, m.inliers),
                                             cues.normals(Eigen::all, m.inliers),
                                             m.point_on_axis, m.axis);
    if (!curvature)
      return slope * static_cast<double>(m.inliers.size());
    double sum = 0.0;
    for (const auto s : m.inliers) {
      const float dn = std::abs(m.axis.dot(cues.normals.col(s)));
      const float dc = std::abs(m.axis.dot(cues.curvature_directions.col(s)));
      sum += cues.weights(s) * (1.f - dn) * (1.f - dc);
    }
    return slope * sum;
  };
  // One more seed beyond the paper: the dominant direction of the planar points' normals.
  // Lids and the table under an upright object are planar and orthogonal to its axis, so
  // the points that spoil the votes (eq. 3 spreads theirs over a great circle) point at the
  // axis themselves. The seed only competes; the fit decides.
  if (curvature) {
    const Eigen::Matrix3d m = normalScatter(voting, 1.f - voting.weight);
    if (m.trace() > 0.0) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      solver.computeDirect(m);
      const Eigen::Vector3f d = foldToHemisphere(solver.eigenvectors().col(2).cast<float>());
      const float cell = accumulators.front().cellRadius();
      const float separation = std::max(4.f * cell, 10.f * kOneDegree);
      if (d.allFinite() && std::none_of(seeds.begin(), seeds.end(), [&](const Seed& s) {
            return axisAngle(s.axis, d) < separation;
          }))
        seeds.push_back({d, cell});
    }
  }

  std::optional<CylinderModel> best;
  Candidate best_candidate;
  double best_score = -1.0;
  std::vector<Eigen::Vector3f> tried;
  for (std::size_t k = 0;; ++k) {
    if (k == seeds.size()) {
      // Curvature directions fade into noise before normals do (a short or noisy cylinder).
      // Unless a convincing cylinder was found already (a quarter of the points, half the
      // circumference), the best normals-only peak joins the candidates; the fit decides.
      const bool convincing = best && best->angular_coverage >= 0.5f &&
                              4 * best->inliers.size() >= active.size();
      const std::size_t before = seeds.size();
      if (curvature && !convincing && !normals_seed_tried) {
        normals_seed_tried = true;
        addPeaks(accumulators.front(), VotingMode::SoftNormal, 1);
      }
      if (seeds.size() == before)
        break;
    }
    const Seed seed = seeds[k];
    Eigen::Vector3f axis = seed.axis;
    if (params.refine) {
      axis = refineAxis(refining, seed.axis, std::max(3.f * seed.cell_radius, 10.f * kOneDegree));
      if (std::any_of(tried.begin(), tried.end(),
                      [&](const Eigen::Vector3f& t) { return axisAngle(t, axis) < 0.5f * kOneDegree; }))
        continue;
      tried.push_back(axis);
    }
    const auto candidate = fitPosition(cues, active, axis, params);
    if (!candidate)
      continue;
    CylinderModel model = describe(cues, active, *candidate, params);
    const double s = score(model);
    if (!best || s > best_score || (s == best_score && model.rms_error < best->rms_error)) {
      best = std::move(model);
      best_score = s;
      best_candidate = *candidate;
    }
  }
  // Candidates compete after the circle fit; only the winner gets the least squares.
  if (best && params.refine)
    best = describe(cues, active, refineCandidate(cues, active, best_candidate, params), params);
  return best;
}

} // namespace

std::vector<CylinderModel>
fitCylinders(const CylinderCues& cues, const std::vector<OrientationAccumulator>& accumulators,
             const HoughCylinderParameters& params, std::size_t total_points)
{
  std::vector<CylinderModel> models;
  const Eigen::Index n = cues.points.cols();
  if (n == 0 || accumulators.empty())
    return models;
  const bool curvature = params.voting_mode == VotingMode::SoftCurvature &&
                         cues.weights.size() == n && cues.curvature_directions.cols() == n;
  HoughCylinderParameters p = params;
  if (params.voting_mode == VotingMode::SoftCurvature && !curvature)
    p.voting_mode = VotingMode::SoftNormal; // the caller checks; this is a last guard
  const std::size_t min_inliers =
      p.min_inliers > 0 ? p.min_inliers
                        : std::max<std::size_t>(10, static_cast<std::size_t>(0.05 * n));
  const double total_weight = curvature ? cues.weights.cast<double>().sum() : double(n);

  std::vector<char> alive(static_cast<std::size_t>(n), 1);
  for (std::size_t round = 0; round < p.max_cylinders; ++round) {
    std::vector<int> active;
    for (Eigen::Index s = 0; s < n; ++s)
      if (alive[static_cast<std::size_t>(s)])
        active.push_back(static_cast<int>(s));
    if (active.size() < min_inliers)
      break;
    auto model = fitOne(cues, active, accumulators, p);
    if (!model || model->inliers.size() < min_inliers)
      break;
    double w = 0.0;
    for (const auto s : model->inliers)
      w += curvature ? cues.weights(s) : 1.0;
    model->confidence = total_weight > 0.0 ? static_cast<float>(w / total_weight) : 0.f;
    model->inlier_ratio =
        static_cast<float>(model->inliers.size()) / static_cast<float>(std::max<std::size_t>(1, total_points));
    // Remove the inliers and whatever lies inside the finite cylinder (its lids).
    for (const auto s : model->inliers)
      alive[static_cast<std::size_t>(s)] = 0;
    const float reach = model->radius + model->distance_threshold;
    for (const int s : active) {
      const Eigen::Vector3f w3 = cues.points.col(s) - model->base;
      const float t = w3.dot(model->axis);
      if (t > -model->distance_threshold && t < model->height + model->distance_threshold &&
          (w3 - t * model->axis).norm() < reach)
        alive[static_cast<std::size_t>(s)] = 0;
    }
    models.push_back(std::move(*model));
  }
  return models;
}

} // namespace facyl
