/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/recognition/shape_evidence.h>

#include "median.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace facyl {

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kPi = static_cast<float>(M_PI);

using detail::medianOf;

/** A point in the cylinder's frame: along the axis from the base, its radial vector and
 * distance, and its normal's parts along the axis and across it. */
struct Local {
  float t{0.f}, rho{0.f}, along{0.f};
  Eigen::Vector3f radial{Eigen::Vector3f::Zero()}, across{Eigen::Vector3f::Zero()};
};

Local
local(const Eigen::Vector3f& a, const Eigen::Vector3f& base, const Eigen::Vector3f& p,
      const Eigen::Vector3f& n)
{
  Local l;
  const Eigen::Vector3f d = p - base;
  l.t = d.dot(a);
  l.radial = d - l.t * a;
  l.rho = l.radial.norm();
  l.along = n.dot(a);
  l.across = n - l.along * a;
  return l;
}
} // namespace

float
largestCircularWindowShare(std::vector<float> angles, float width)
{
  if (angles.empty())
    return 0.f;
  const float two_pi = 2.f * kPi;
  for (auto& x : angles)
    x = x - two_pi * std::floor(x / two_pi);
  std::sort(angles.begin(), angles.end());
  const std::size_t n = angles.size();
  std::size_t best = 0, end = 0;
  // Each angle starts a window; its end walks forward over the angles unrolled once more.
  const auto at = [&](std::size_t k) { return k < n ? angles[k] : angles[k - n] + two_pi; };
  for (std::size_t begin = 0; begin < n; ++begin) {
    end = std::max(end, begin);
    while (end < begin + n && at(end) <= angles[begin] + width)
      ++end;
    best = std::max(best, end - begin);
  }
  return static_cast<float>(best) / static_cast<float>(n);
}

ShapeEvidence
shapeEvidence(const CylinderModel& model, const Eigen::Matrix3Xf& points,
              const Eigen::Matrix3Xf& normals, const Eigen::VectorXf& scatter,
              const std::vector<std::uint8_t>& mask, float distance)
{
  ShapeEvidence e{kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
  const float r = model.radius;
  if (!(r > 0.f) || !(distance > 0.f) || normals.cols() != points.cols())
    return e;
  const Eigen::Vector3f a = model.axis.normalized();
  const Eigen::Vector3f e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  const float h = (model.top - model.base).dot(a);
  e.aspect = std::max(h, 0.f) / r;
  const float outside = r + std::max(2.f * distance, 0.1f * r);
  constexpr int kProfileSlices = 6, kBendSlices = 5;
  std::array<std::vector<float>, kProfileSlices> profile;
  std::array<Eigen::Vector3f, kBendSlices> centre_sum;
  std::array<int, kBendSlices> centre_count{};
  centre_sum.fill(Eigen::Vector3f::Zero());
  std::vector<float> deviation, azimuth, noise;
  const bool with_scatter = scatter.size() == points.cols();
  std::size_t used = 0, inner = 0, beyond = 0;
  const auto slice = [&](float t, int slices) {
    return std::clamp(static_cast<int>(std::floor(t / h * slices)), 0, slices - 1);
  };
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if (!mask.empty() && !mask[static_cast<std::size_t>(i)])
      continue;
    const Eigen::Vector3f n = normals.col(i);
    if (!n.allFinite() || !points.col(i).allFinite())
      continue;
    const Local l = local(a, model.base, points.col(i), n);
    ++used;
    beyond += l.rho > outside;
    const bool within = l.t >= 0.f && l.t <= h && h > 0.f;
    const float across = l.across.norm();
    if (!within || !(l.rho > 0.f) || !(across > 0.f))
      continue;
    const float cos_radial = l.across.dot(l.radial) / (across * l.rho);
    inner += l.rho < 0.85f * r && cos_radial < -0.5f && std::abs(l.along) < 0.8f;
    // The side: the profile from points between half and one and a half radii, normals
    // within 45 degrees of perpendicular to the axis (not the lids).
    if (l.rho > 0.5f * r && l.rho < 1.5f * r && std::abs(l.along) < 0.7071f)
      profile[static_cast<std::size_t>(slice(l.t, kProfileSlices))].push_back(l.rho);
    if (std::abs(l.rho - r) > distance || std::abs(l.along) > 0.866f)
      continue;
    // A side point: how its normal agrees with the radial line (either sign: the inside
    // of an open container faces the axis), where its normal points, where its slice's
    // centre is.
    deviation.push_back(std::acos(std::min(1.f, std::abs(cos_radial))));
    if (with_scatter && std::isfinite(scatter[i]))
      noise.push_back(scatter[i]);
    azimuth.push_back(std::atan2(l.across.dot(e2), l.across.dot(e1)));
    const int s = slice(l.t, kBendSlices);
    const float sign = cos_radial >= 0.f ? 1.f : -1.f;
    centre_sum[static_cast<std::size_t>(s)] += l.radial - sign * r * l.across / across;
    ++centre_count[static_cast<std::size_t>(s)];
  }
  if (used > 0) {
    e.inner_share = static_cast<float>(inner) / static_cast<float>(used);
    e.outside_share = static_cast<float>(beyond) / static_cast<float>(used);
  }
  if (deviation.size() >= 10) {
    if (noise.size() >= 10) // a floor far below any sensor's noise: a noiseless surface
      e.normal_agreement = medianOf(deviation) / std::max(std::sqrt(medianOf(noise)), 1e-3f);
    e.normal_concentration = largestCircularWindowShare(azimuth, 20.f * kPi / 180.f);
  }
  // The middle slices: a can's rims and a bottle's neck are narrower than its side, but
  // only at its ends; a bowl's, a sphere's and a cone's radius changes all along.
  std::vector<float> radii;
  for (std::size_t k = 1; k + 1 < profile.size(); ++k)
    if (profile[k].size() >= 8)
      radii.push_back(medianOf(profile[k]));
  if (radii.size() >= 3) {
    const auto [lo, hi] = std::minmax_element(radii.begin(), radii.end());
    e.profile_range = (*hi - *lo) / r;
  }
  std::vector<Eigen::Vector3f> centres;
  for (int s = 0; s < kBendSlices; ++s)
    if (centre_count[static_cast<std::size_t>(s)] >= 8)
      centres.push_back(centre_sum[static_cast<std::size_t>(s)] /
                        static_cast<float>(centre_count[static_cast<std::size_t>(s)]));
  if (centres.size() >= 3) {
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (const auto& c : centres)
      mean += c;
    mean /= static_cast<float>(centres.size());
    float far = 0.f;
    for (const auto& c : centres)
      far = std::max(far, (c - mean).norm());
    e.axis_bend = far / r;
  }
  return e;
}

} // namespace facyl
