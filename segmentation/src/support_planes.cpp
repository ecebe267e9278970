/*
 * facyl: fast cylinder detection for PCL.
 * Support planes: bands measured from the data, plane regions, families, height profiles.
 */
#include <facyl/segmentation/support_planes.h>
#include <facyl/segmentation/tabletop_geometry.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace facyl {

// ---------------------------------------------------------------- bands

float
DepthBand::sigma(float range) const
{
  if (ranges.empty() || sigmas.size() != ranges.size())
    return fixed / std::max(factor, 1e-6f);
  if (!(range > ranges.front()))
    return sigmas.front();
  if (range >= ranges.back()) {
    const float t = range / std::max(ranges.back(), 1e-6f);
    return sigmas.back() * t * t;
  }
  const auto it = std::upper_bound(ranges.begin(), ranges.end(), range);
  const std::size_t hi = static_cast<std::size_t>(it - ranges.begin()), lo = hi - 1;
  const float span = ranges[hi] - ranges[lo];
  const float t = span > 0.f ? (range - ranges[lo]) / span : 1.f;
  return sigmas[lo] + t * (sigmas[hi] - sigmas[lo]);
}

float
halfWidthFloor(const DepthBand& band)
{
  if (band.fixed > 0.f)
    return band.fixed;
  if (band.ranges.empty() || band.sigmas.size() != band.ranges.size())
    return 0.f;
  // sigma() never goes below its smallest sample: it interpolates between samples and grows
  // beyond the last. The margin covers the rounding of the interpolation.
  const float least = *std::min_element(band.sigmas.begin(), band.sigmas.end());
  return least > 0.f ? band.factor * least * (1.f - 1e-5f) : 0.f;
}

DepthBand
fixedBand(float half_width)
{
  DepthBand b;
  b.fixed = half_width;
  return b;
}

std::vector<float>
tabulateHalfWidths(const DepthBand& band)
{
  std::vector<float> half(kHalfWidthBins);
  for (std::size_t b = 0; b < kHalfWidthBins; ++b)
    half[b] = band.halfWidth((static_cast<float>(b) + 0.5f) * kHalfWidthBin);
  return half;
}

DepthBand
estimateDepthBand(const std::vector<float>& ranges, const std::vector<float>& residuals,
                  float factor, float min_sigma)
{
  // At most kMaxBandSamples pairs, evenly: 8 bins of 500 measure a scale within a few percent.
  constexpr std::size_t kMaxBandSamples = 4000;
  const std::size_t n = std::min(ranges.size(), residuals.size());
  const std::size_t stride = std::max<std::size_t>(1, n / kMaxBandSamples);
  std::vector<std::pair<float, float>> pairs; // (range, |residual|)
  pairs.reserve(n / stride + 1);
  for (std::size_t i = 0; i < n; i += stride)
    if (std::isfinite(ranges[i]) && std::isfinite(residuals[i]))
      pairs.emplace_back(ranges[i], std::abs(residuals[i]));
  if (pairs.empty()) {
    DepthBand b = fixedBand(factor * min_sigma);
    b.factor = factor;
    return b;
  }
  const std::size_t bins = std::clamp<std::size_t>(pairs.size() / 150, 1, 8);
  // The bins of equal counts by range: each bin holds the pairs a sort would put there (pairs
  // that compare equal are equal), in some order, which its medians do not see.
  for (std::size_t b = 1; b < bins; ++b)
    std::nth_element(pairs.begin() + static_cast<std::ptrdiff_t>((b - 1) * pairs.size() / bins),
                     pairs.begin() + static_cast<std::ptrdiff_t>(b * pairs.size() / bins),
                     pairs.end());
  DepthBand band;
  band.factor = factor;
  std::vector<float> r, a;
  for (std::size_t b = 0; b < bins; ++b) {
    const std::size_t first = b * pairs.size() / bins, last = (b + 1) * pairs.size() / bins;
    r.clear();
    a.clear();
    for (std::size_t k = first; k < last; ++k)
      r.push_back(pairs[k].first), a.push_back(pairs[k].second);
    const auto mid = [](std::vector<float>& v) {
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
      return v[v.size() / 2];
    };
    const float range = mid(r);
    const float sigma = std::max(min_sigma, 1.4826f * mid(a));
    if (!band.ranges.empty() && range <= band.ranges.back()) { // equal ranges: one bin
      band.sigmas.back() = std::max(band.sigmas.back(), sigma);
      continue;
    }
    band.ranges.push_back(range);
    band.sigmas.push_back(band.sigmas.empty() ? sigma : std::max(sigma, band.sigmas.back()));
  }
  return band;
}

// ---------------------------------------------------------------- plane regions

bool
fitWeightedPlane(const Eigen::Matrix3Xf& points, const Eigen::VectorXf& weights,
                 const Eigen::Vector3f& viewpoint, Eigen::Vector4f& plane)
{
  if (points.cols() < 3 || weights.size() != points.cols())
    return false;
  const double total = weights.cast<double>().sum();
  if (!(total > 0.0))
    return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < points.cols(); ++i)
    mean += static_cast<double>(weights[i]) * points.col(i).cast<double>();
  mean /= total;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d d = points.col(i).cast<double>() - mean;
    cov += static_cast<double>(weights[i]) * d * d.transpose();
  }
  cov /= total;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d values = eig.eigenvalues();
  if (!(values[1] > 1e-12) || !(values[1] > 4.0 * values[0]))
    return false;
  const Eigen::Vector3f n = eig.eigenvectors().col(0).cast<float>();
  plane = orientPlane(Eigen::Vector4f(n.x(), n.y(), n.z(), -n.dot(mean.cast<float>())), viewpoint);
  return plane.allFinite();
}

namespace {

/** Cells of a region as their indices, ascending (the order of a pass over every cell). */
using Members = std::vector<std::uint32_t>;

/** The plane of the cells \a member, weighted by 1 / sigma(range)^2 (\a band; nullptr: 1). */
bool
fitMembers(const PlaneRegionCells& g, const Members& member, const DepthBand* band,
           Eigen::Vector4f& plane)
{
  const auto n = static_cast<Eigen::Index>(member.size());
  Eigen::Matrix3Xf pts(3, n);
  Eigen::VectorXf w(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const std::uint32_t i = member[static_cast<std::size_t>(k)];
    pts.col(k) = g.cells.col(static_cast<Eigen::Index>(i));
    const float s = band ? band->sigma(g.range[i]) : 1.f;
    w[k] = 1.f / std::max(s * s, 1e-12f);
  }
  return fitWeightedPlane(pts, w, g.viewpoint, plane);
}

/** The band of \a plane measured on the samples (or cells) of the members. */
DepthBand
measureBand(const PlaneRegionCells& g, const Members& member, const Eigen::Vector4f& plane,
            const PlaneRegionSettings& s)
{
  if (s.fixed_band > 0.f) {
    DepthBand b = fixedBand(s.fixed_band);
    b.factor = s.band_factor;
    return b;
  }
  // Every k-th member: estimateDepthBand uses at most 4000 anyway.
  const std::size_t stride = std::max<std::size_t>(1, member.size() / 4000);
  std::vector<float> ranges, residuals;
  ranges.reserve(member.size() / stride + 1);
  residuals.reserve(member.size() / stride + 1);
  for (std::size_t k = 0; k < member.size(); k += stride) {
    const auto c = static_cast<Eigen::Index>(member[k]);
    const Eigen::Vector3f p = g.samples.col(c).allFinite() ? Eigen::Vector3f(g.samples.col(c))
                                                           : Eigen::Vector3f(g.cells.col(c));
    ranges.push_back((p - g.viewpoint).norm());
    residuals.push_back(plane.head<3>().dot(p) + plane[3]);
  }
  return estimateDepthBand(ranges, residuals, s.band_factor, s.min_sigma);
}

/** 3 x the median angle between the members' normals and the plane's, at least min_angle. */
float
normalTolerance(const PlaneRegionCells& g, const Members& member, const Eigen::Vector3f& n,
                const PlaneRegionSettings& s)
{
  // On every k-th member (at most about 2000).
  const std::size_t stride = std::max<std::size_t>(1, member.size() / 2000);
  std::vector<float> angles;
  for (std::size_t k = 0; k < member.size(); k += stride) {
    const float c = std::abs(n.dot(g.normals.col(static_cast<Eigen::Index>(member[k]))));
    angles.push_back(std::acos(std::min(1.f, c)));
  }
  if (angles.empty())
    return s.min_angle;
  std::nth_element(angles.begin(), angles.begin() + static_cast<std::ptrdiff_t>(angles.size() / 2),
                   angles.end());
  return std::max(3.f * angles[angles.size() / 2], s.min_angle);
}

/** \a band with each bin's sigma at most \a factor x \a limit's at its range. */
DepthBand
limitBand(DepthBand band, const DepthBand& limit, float factor)
{
  if (band.fixed > 0.f)
    return band;
  for (std::size_t b = 0; b < band.ranges.size(); ++b)
    band.sigmas[b] = std::min(band.sigmas[b], factor * limit.sigma(band.ranges[b]));
  for (std::size_t b = 1; b < band.sigmas.size(); ++b)
    band.sigmas[b] = std::max(band.sigmas[b], band.sigmas[b - 1]);
  return band;
}

} // namespace

PlaneRegionCells::PlaneRegionCells(const Eigen::Matrix3Xf& cells_, const Eigen::Matrix3Xf& normals_,
                                   const Eigen::Matrix3Xf& samples_,
                                   const Eigen::Vector3f& viewpoint_)
    : cells(cells_)
    , normals(normals_)
    , samples(samples_)
    , viewpoint(viewpoint_)
{
  if (!valid())
    return;
  const auto n = static_cast<std::size_t>(cells.cols());
  range.assign(n, 0.f);
  usable.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<Eigen::Index>(i);
    if (cells.col(c).allFinite() && normals.col(c).allFinite()) {
      usable.push_back(static_cast<std::uint32_t>(i));
      range[i] = (Eigen::Vector3f(cells.col(c)) - viewpoint).norm();
    }
  }
}

bool
refinePlaneRegion(const Eigen::Matrix3Xf& cells, const Eigen::Matrix3Xf& normals,
                  const Eigen::Matrix3Xf& samples, const std::vector<std::uint8_t>& seed,
                  const Eigen::Vector3f& viewpoint, const PlaneRegionSettings& s,
                  PlaneRegion& region, const std::vector<std::uint8_t>* excluded)
{
  return refinePlaneRegion(PlaneRegionCells(cells, normals, samples, viewpoint), seed, s, region,
                           excluded);
}

bool
refinePlaneRegion(const PlaneRegionCells& g, const std::vector<std::uint8_t>& seed,
                  const PlaneRegionSettings& s, PlaneRegion& region,
                  const std::vector<std::uint8_t>* excluded)
{
  const std::size_t n = static_cast<std::size_t>(g.cells.cols());
  if (!g.valid() || seed.size() != n || (excluded && excluded->size() != n))
    return false;
  // The cells that may be members in this call.
  Members usable;
  usable.reserve(g.usable.size());
  for (const std::uint32_t i : g.usable)
    if (!(excluded && (*excluded)[i]))
      usable.push_back(i);
  Members member;
  for (std::size_t i = 0; i < n; ++i)
    if (seed[i] && g.cells.col(static_cast<Eigen::Index>(i)).allFinite())
      member.push_back(static_cast<std::uint32_t>(i));
  Eigen::Vector4f plane;
  if (!fitMembers(g, member, nullptr, plane))
    return false;
  // The seed's own band and normal spread bound the growth: a band re-measured on a grown
  // region may widen (a table's bias shows over its whole extent) to twice the seed's at
  // most, so that a region never runs away into a neighbouring surface.
  const DepthBand seed_band = measureBand(g, member, plane, s);
  const float tolerance = normalTolerance(g, member, plane.head<3>(), s);
  if (!(tolerance <= s.max_angle))
    return false; // normals that spread this much are not a plane's (a dome, a cylinder's top)
  const float cos_max = std::cos(tolerance);
  // The usable cells on the plane within \a band (every other one: \a every_other). A cell
  // within the band's narrowest half-width (halfWidthFloor) is in it at any range.
  const auto members = [&](const DepthBand& band, bool every_other) {
    const float floor = halfWidthFloor(band);
    Members out;
    for (const std::uint32_t i : usable) {
      if (every_other && i % 2 != 0)
        continue;
      const auto c = static_cast<Eigen::Index>(i);
      if (std::abs(g.normals.col(c).dot(plane.head<3>())) < cos_max)
        continue;
      const float distance = std::abs(plane.head<3>().dot(g.cells.col(c)) + plane[3]);
      if (distance <= floor || distance <= band.halfWidth(g.range[i]))
        out.push_back(i);
    }
    return out;
  };
  // The plane from every other cell (plenty for 4 parameters) within twice the seed's band
  // (the widest a grown region's band may become), the members and the band from all of
  // them.
  DepthBand wide = seed_band;
  for (auto& sigma : wide.sigmas)
    sigma *= 2.f;
  if (wide.fixed > 0.f)
    wide.fixed = seed_band.fixed; // a given band is not widened
  for (int it = 0; it < std::max(1, s.iterations); ++it) {
    Members next = members(wide, true);
    const bool same = next == member;
    member.swap(next);
    Eigen::Vector4f refit;
    if (!fitMembers(g, member, &seed_band, refit))
      return false;
    plane = refit;
    if (same)
      break;
  }
  member = members(wide, false);
  const DepthBand band = limitBand(measureBand(g, member, plane, s), seed_band, 2.f);
  region.plane = plane;
  region.band = band;
  region.max_angle = tolerance;
  member = members(band, false);
  region.member.assign(n, 0);
  for (const std::uint32_t i : member)
    region.member[i] = 1;
  region.members = member.size();
  return region.members >= 3;
}

// ---------------------------------------------------------------- families and heights

std::vector<std::vector<std::size_t>>
groupCoplanar(const std::vector<Eigen::Vector4f>& planes, const std::vector<std::size_t>& order,
              float angle, float distance)
{
  std::vector<std::vector<std::size_t>> groups;
  const float cos_max = std::cos(angle);
  for (const std::size_t i : order) {
    bool joined = false;
    for (auto& g : groups) {
      const Eigen::Vector4f& lead = planes[g.front()];
      if (lead.head<3>().dot(planes[i].head<3>()) >= cos_max &&
          std::abs(lead[3] - planes[i][3]) <= distance) {
        g.push_back(i);
        joined = true;
        break;
      }
    }
    if (!joined)
      groups.push_back({i});
  }
  return groups;
}

namespace {

/** HeightProfile with the band's lower end per point given by \a lower(i). */
template <typename Lower>
HeightProfile
profileOf(const Eigen::Matrix3Xf& points, const Eigen::Vector4f& plane, Lower lower,
          float max_height)
{
  HeightProfile h;
  if (points.cols() == 0)
    return h;
  std::vector<float> heights(static_cast<std::size_t>(points.cols()));
  std::size_t in_band = 0;
  const Eigen::Vector3f n = plane.head<3>();
  const Eigen::Vector3f e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  Eigen::AlignedBox2f box;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const float z = n.dot(points.col(i)) + plane[3];
    heights[static_cast<std::size_t>(i)] = z;
    in_band += z >= lower(i) && z <= max_height;
    box.extend(Eigen::Vector2f(e1.dot(points.col(i)), e2.dot(points.col(i))));
  }
  h.extent = box.diagonal().norm();
  const auto at = [&heights](double q) {
    const auto k = static_cast<std::size_t>(q * static_cast<double>(heights.size() - 1));
    std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(k),
                     heights.end());
    return heights[k];
  };
  h.base = at(0.02);
  h.top = at(0.98);
  h.in_band = static_cast<float>(in_band) / static_cast<float>(heights.size());
  return h;
}

} // namespace

HeightProfile
heightProfile(const Eigen::Matrix3Xf& points, const Eigen::Vector4f& plane, float min_height,
              float max_height)
{
  return profileOf(
    points, plane, [min_height](Eigen::Index) { return min_height; }, max_height);
}

HeightProfile
heightProfile(const Eigen::Matrix3Xf& points, const Eigen::Vector4f& plane, const DepthBand& band,
              const Eigen::Vector3f& viewpoint, float min_height, float max_height)
{
  return profileOf(
    points, plane,
    [&](Eigen::Index i) {
      return std::max(min_height, band.halfWidth((points.col(i) - viewpoint).norm()));
    },
    max_height);
}

} // namespace facyl
