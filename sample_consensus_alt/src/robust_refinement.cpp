/*
 * facyl: fast cylinder detection for PCL.
 * Robust point-based refinement: the cylinder that the points themselves support, whatever
 * the normals say (they are the first cue to go at high noise).
 */
#include "fitting_detail.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace facyl {

using detail::medianOf;

namespace {

/** The window of the scale estimate: wide enough that truncation does not bias it (the MAD of
 * a Gaussian cut at 4.685 sigma is that of the whole). */
constexpr float kScaleWindow = 4.685f;

/** Surface distances e = |P(x - p)| - r of \a points to the cylinder (p, a, r). */
void
surfaceDistances(const Eigen::Matrix3Xf& points, const Eigen::Vector3f& p, const Eigen::Vector3f& a,
                 float r, Eigen::ArrayXf& e)
{
  e.resize(points.cols());
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f w = points.col(i) - p;
    e(i) = (w - w.dot(a) * a).norm() - r;
  }
}

/** 1.4826 MAD of the distances within \a window of the surface; \a fallback if none is. */
float
robustScale(const Eigen::ArrayXf& e, float window, float fallback)
{
  std::vector<float> near;
  near.reserve(static_cast<std::size_t>(e.size()));
  for (Eigen::Index i = 0; i < e.size(); ++i)
    if (std::abs(e(i)) < window)
      near.push_back(std::abs(e(i)));
  return near.size() < 5 ? fallback : 1.4826f * medianOf(near);
}

/** One reweighted Gauss-Newton step on \a points (Tukey weights at \a cutoff; with
 * \a normals, only the points that pass \a gate): updates (p, a, r). One pass over the points
 * accumulates the normal equations (no per-point temporaries); the 5 x 5 system in double.
 * \return the sum of the weights, or -1 if the system is degenerate. */
double
reweightedStep(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
               const NormalGate& gate, Eigen::Vector3d& p, Eigen::Vector3d& a, double& r,
               double cutoff, double& step)
{
  const Eigen::Vector3f af = a.cast<float>(), pf = p.cast<float>();
  const Eigen::Vector3f u = af.unitOrthogonal(), v = af.cross(u);
  const bool gated = normals.cols() == points.cols();
  const float cos_normal = std::cos(gate.max_angle);
  const float rf = static_cast<float>(r);
  const float inv_cutoff2 = static_cast<float>(1.0 / (cutoff * cutoff));
  // Jacobian of e in (p_u, p_v, a_u, a_v, r): -(du, dv, along du, along dv, 1); the sums of
  // w j j^T and w j e (upper triangle), accumulated in double.
  Eigen::Matrix<double, 5, 5> jtj = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> jte = Eigen::Matrix<double, 5, 1>::Zero();
  double support = 0.0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f w = points.col(i) - pf;
    const float wu = u.dot(w), wv = v.dot(w);
    const float rho = std::sqrt(wu * wu + wv * wv);
    if (!(rho > 0.f))
      continue;
    const float e = rho - rf;
    const float t = e * e * inv_cutoff2;
    if (!(t < 1.f))
      continue;
    if (gated) {
      const float agree = normals.col(i).dot(u) * wu + normals.col(i).dot(v) * wv;
      if ((gate.outward ? agree : std::abs(agree)) < cos_normal * rho)
        continue;
    }
    const double weight = static_cast<double>((1.f - t) * (1.f - t));
    const float along = af.dot(w);
    const float du = wu / rho, dv = wv / rho;
    const double j[5] = {du, dv, along * du, along * dv, 1.0};
    for (int row = 0; row < 5; ++row) {
      const double wj = weight * j[row];
      for (int col = row; col < 5; ++col)
        jtj(row, col) += wj * j[col];
      jte(row) += wj * static_cast<double>(e);
    }
    support += weight;
  }
  if (support < 5.0)
    return -1.0;
  const Eigen::Matrix<double, 5, 5> full = jtj.selfadjointView<Eigen::Upper>();
  const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> ldlt(full);
  // e(x + delta) ~ e - j^T delta: the step solves (J^T W J) delta = J^T W e.
  const Eigen::Matrix<double, 5, 1> delta = ldlt.solve(jte);
  if (ldlt.info() != Eigen::Success || !delta.allFinite() ||
      !(ldlt.vectorD().minCoeff() > 1e-12 * ldlt.vectorD().maxCoeff()))
    return -1.0;
  const Eigen::Vector3d ud = u.cast<double>(), vd = v.cast<double>();
  p += delta(0) * ud + delta(1) * vd;
  a = (a + delta(2) * ud + delta(3) * vd).normalized();
  r += delta(4);
  // The step in radii (position, radius) and radians (tilt).
  step =
    std::max({std::abs(delta(0)), std::abs(delta(1)), std::abs(delta(4))}) / std::max(r, 1e-12) +
    std::max(std::abs(delta(2)), std::abs(delta(3)));
  return support;
}

} // namespace

bool
refineCylinderRobust(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                     const NormalGate& gate, RobustCylinder& c, int iterations)
{
  const Eigen::Index n = points.cols();
  if (n < 5 || !(c.radius > 0.f) || !c.axis.allFinite() || !c.point_on_axis.allFinite() ||
      !(c.cutoff > 0.f))
    return false;
  Eigen::Vector3d a = c.axis.cast<double>().normalized();
  Eigen::Vector3d p = c.point_on_axis.cast<double>();
  double r = c.radius;
  Eigen::ArrayXf e;
  surfaceDistances(points, p.cast<float>(), a.cast<float>(), static_cast<float>(r), e);
  const float floor = 1e-5f * c.radius;
  float scale = c.scale > 0.f ? c.scale : robustScale(e, c.radius, 0.1f * c.radius);
  scale = std::max(scale, floor);
  // The points the refinement can reach: the window only closes, so points three windows
  // away would need the model to move further than any step of a converging fit.
  std::vector<Eigen::Index> reach;
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::abs(e(i)) < 3.f * c.cutoff * scale)
      reach.push_back(i);
  if (reach.size() < 5)
    return false;
  const Eigen::Matrix3Xf pts = points(Eigen::all, reach);
  const Eigen::Matrix3Xf nrm =
    normals.cols() == n ? Eigen::Matrix3Xf(normals(Eigen::all, reach)) : Eigen::Matrix3Xf();
  // Keep the point on the axis next to the supporting points (conditioning of the tilt).
  {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double count = 0.0;
    for (Eigen::Index i = 0; i < n; ++i)
      if (std::abs(e(i)) < c.cutoff * scale) {
        sum += points.col(i).cast<double>();
        count += 1.0;
      }
    if (count > 0.0)
      p += (sum / count - p).dot(a) * a;
  }
  double support = 0.0;
  for (int it = 0; it < iterations; ++it) {
    double step = 0.0;
    const double s = reweightedStep(pts, nrm, gate, p, a, r, c.cutoff * scale, step);
    if (s < 0.0 || !(r > 0.0))
      return false;
    support = s;
    surfaceDistances(pts, p.cast<float>(), a.cast<float>(), static_cast<float>(r), e);
    // The scale only shrinks: a start far from the surface widens the first window, and the
    // window then closes on the points that the converging model explains.
    const float next = std::clamp(robustScale(e, kScaleWindow * scale, scale), floor, scale);
    // Settled: a step below 1e-4 (radii or radians: 0.006 deg) and a scale that holds.
    const bool settled = step < 1e-4 && next > 0.98f * scale;
    scale = next;
    if (settled)
      break;
  }
  if (!(r > 0.0) || !a.allFinite() || !p.allFinite())
    return false;
  c.point_on_axis = p.cast<float>();
  c.axis = a.cast<float>();
  c.radius = static_cast<float>(r);
  c.scale = scale;
  c.support = static_cast<float>(support);
  return true;
}

float
unbiasedRadius(float radius, float scale)
{
  if (!(radius > 0.f) || !std::isfinite(radius))
    throw std::invalid_argument("facyl::unbiasedRadius: the radius must be positive and finite");
  if (!(scale > 0.f) || !std::isfinite(scale))
    return radius;
  return std::max(radius - scale * scale / (2.f * radius), 0.5f * radius);
}

float
pointSupport(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
             const NormalGate& gate, const RobustCylinder& c, float scale)
{
  const Eigen::Index n = points.cols();
  if (n == 0 || !(scale > 0.f))
    return 0.f;
  const Eigen::Vector3f a = c.axis.normalized();
  const Eigen::Matrix3Xf w = points.colwise() - c.point_on_axis;
  const Eigen::Matrix3Xf d = w - a * (a.transpose() * w);
  const Eigen::ArrayXf rho = d.colwise().norm().transpose().array();
  const Eigen::ArrayXf t = ((rho - c.radius) / (c.cutoff * scale)).square();
  Eigen::ArrayXf weight = (t < 1.f).select((1.f - t).square(), 0.f);
  if (normals.cols() == n) {
    const Eigen::ArrayXf along = (normals.array() * d.array()).colwise().sum().transpose();
    const Eigen::ArrayXf agree = gate.outward ? along : along.abs();
    weight = (agree >= std::cos(gate.max_angle) * rho && rho > 0.f).select(weight, 0.f);
  }
  return weight.sum();
}

float
normalDeviation(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                const RobustCylinder& c, float window)
{
  // The median angle is the angle of the median cosine (acos is monotonic).
  const Eigen::Vector3f a = c.axis.normalized();
  std::vector<float> cosines;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f w = points.col(i) - c.point_on_axis;
    const Eigen::Vector3f d = w - w.dot(a) * a;
    const float rho = d.norm();
    if (!(rho > 0.f) || !(std::abs(rho - c.radius) < window))
      continue;
    cosines.push_back(std::min(1.f, std::abs(normals.col(i).dot(d)) / rho));
  }
  return cosines.size() < 5 ? 0.f : std::acos(medianOf(cosines));
}

} // namespace facyl
