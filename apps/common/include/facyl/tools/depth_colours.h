/*
 * facyl: colours by depth for clouds without colour, for the tools that draw clouds
 * (facyl_detect --overlay, facyl_viewer). Many grabbers write x y z only; PCL reads such a file
 * into PointXYZRGBA as black points, which show nothing on a black image or a dark background.
 *
 * The map is Moreland's cool-warm diverging map (K. Moreland, "Diverging Color Maps for
 * Scientific Visualization", ISVC 2009; matplotlib's "coolwarm", sampled at 17 points, linear
 * between): near warm red, through light grey in the middle, far cool blue. Its lightness runs
 * in order on each side, and it holds none of the green, yellow and pure red the tools draw
 * their results in. The colours span the 2nd to the 98th percentile of the cloud's depths (a
 * few stray points do not flatten the rest); depth is the distance along the sensor's optical
 * axis, in the sensor pose the recognizer uses (facyl::plausibleSensorPose).
 */
#pragma once

#include <facyl/segmentation/tabletop_segmentation.h>

#include <pcl/common/point_tests.h>
#include <pcl/point_cloud.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace facyl_cli {

using Rgb8 = std::array<std::uint8_t, 3>;

/** The depth colour at \a t: 0 the near end of the range (warm red), 0.5 the middle (light
 * grey), 1 the far end (cool blue); clamped to [0, 1], NaN gives the middle. */
inline Rgb8
depthColour(float t)
{
  // matplotlib's coolwarm at 0, 1/16, ..., 1 (cool to warm), 8 bits.
  static constexpr std::array<Rgb8, 17> kCoolWarm{{{59, 76, 192},
                                                   {78, 104, 216},
                                                   {98, 130, 234},
                                                   {119, 154, 247},
                                                   {141, 176, 254},
                                                   {163, 194, 254},
                                                   {185, 208, 249},
                                                   {204, 217, 237},
                                                   {221, 220, 220},
                                                   {236, 211, 197},
                                                   {245, 196, 172},
                                                   {247, 176, 147},
                                                   {244, 152, 122},
                                                   {235, 125, 98},
                                                   {221, 95, 75},
                                                   {202, 59, 55},
                                                   {180, 4, 38}}};
  const float x = std::isnan(t) ? 8.f : 16.f * (1.f - std::clamp(t, 0.f, 1.f));
  const int k = std::min(15, static_cast<int>(x));
  const float w = x - static_cast<float>(k);
  Rgb8 c;
  for (std::size_t i = 0; i < 3; ++i)
    c[i] =
      static_cast<std::uint8_t>(std::lround((1.f - w) * kCoolWarm[k][i] + w * kCoolWarm[k + 1][i]));
  return c;
}

/** The range the colours span: the 2nd and the 98th percentile of the finite \a depths (of an
 * even sample of at most about 20000); (NaN, NaN) when none is finite. */
inline std::pair<float, float>
depthRange(const std::vector<float>& depths)
{
  const std::size_t step = std::max<std::size_t>(1, depths.size() / 20000);
  std::vector<float> sample;
  for (std::size_t i = 0; i < depths.size(); i += step)
    if (std::isfinite(depths[i]))
      sample.push_back(depths[i]);
  if (sample.empty())
    return {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN()};
  const auto at = [&sample](double q) {
    const auto k = static_cast<std::size_t>(q * static_cast<double>(sample.size() - 1) + 0.5);
    std::nth_element(sample.begin(), sample.begin() + static_cast<std::ptrdiff_t>(k), sample.end());
    return sample[k];
  };
  const float lo = at(0.02);
  return {lo, at(0.98)};
}

/** True when some finite point of \a cloud has a colour other than black. A file without
 * colour fields reads as all black (and so does one whose colour is all zero). */
template <typename PointT>
bool
hasColour(const pcl::PointCloud<PointT>& cloud)
{
  return std::any_of(cloud.begin(), cloud.end(), [](const PointT& p) {
    return pcl::isFinite(p) && (p.r != 0 || p.g != 0 || p.b != 0);
  });
}

/** Each point's depth: along the optical axis of \a cloud's sensor (plausibleSensorPose); NaN
 * for a point that is not finite. */
template <typename PointT>
std::vector<float>
sensorDepths(const pcl::PointCloud<PointT>& cloud)
{
  const Eigen::Affine3f to_sensor = facyl::plausibleSensorPose(cloud).inverse();
  const Eigen::RowVector3f axis = to_sensor.linear().row(2);
  const float offset = to_sensor.translation().z();
  std::vector<float> depths(cloud.size(), std::numeric_limits<float>::quiet_NaN());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (pcl::isFinite(cloud[i]))
      depths[i] = axis * cloud[i].getVector3fMap() + offset;
  return depths;
}

/** Colours every point of \a cloud by its depth (depthColour over depthRange, the middle when
 * all lie at one depth; opaque); points that are not finite become black (an image's pixels
 * without depth). */
template <typename PointT>
void
colourByDepth(pcl::PointCloud<PointT>& cloud)
{
  const std::vector<float> depths = sensorDepths(cloud);
  const auto [lo, hi] = depthRange(depths);
  const float span = hi - lo;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Rgb8 c = std::isfinite(depths[i])
                     ? depthColour(span > 0.f ? (depths[i] - lo) / span : 0.5f)
                     : Rgb8{0, 0, 0};
    cloud[i].r = c[0], cloud[i].g = c[1], cloud[i].b = c[2], cloud[i].a = 255;
  }
}

} // namespace facyl_cli
