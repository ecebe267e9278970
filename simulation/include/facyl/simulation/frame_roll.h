/*
 * facyl: fast cylinder detection for PCL.
 * A camera rolled about its optical axis: the frame it would have taken.
 */
#pragma once

#include <pcl/point_cloud.h>

#include <cstddef>
#include <stdexcept>
#include <utility>

namespace facyl {

/** \brief The organized frame \a cloud as a camera rolled by \a quarter_turns x 90 degrees
 * clockwise about its optical axis would have taken it (a wrist camera, a sensor mounted on
 * its side or upside down): the image grid turned and the points expressed in the rolled
 * camera's frame (x right, y down, z forward), together, so that each pixel still sees its
 * point. One quarter turn: pixel (u, v) of a W x H frame goes to (H - 1 - v, u) of the H x W
 * result, a point (x, y, z) to (-y, x, z). \a quarter_turns is taken modulo 4 (negative: anti-
 * clockwise). The sensor pose is kept.
 * \throws std::invalid_argument when \a cloud is not organized. */
/** \brief Where pixel \a index of a \a width x \a height frame goes when the camera rolls
 * by \a quarter_turns x 90 degrees clockwise (see rollFrame): its index in the rolled frame. */
inline std::size_t
rolledIndex(std::size_t index, int width, int height, int quarter_turns)
{
  const int k = ((quarter_turns % 4) + 4) % 4;
  int u = static_cast<int>(index % static_cast<std::size_t>(width));
  int v = static_cast<int>(index / static_cast<std::size_t>(width));
  int w = width, h = height;
  for (int t = 0; t < k; ++t) { // one clockwise quarter turn: (u, v) -> (h - 1 - v, u)
    const int nu = h - 1 - v;
    v = u;
    u = nu;
    std::swap(w, h);
  }
  return static_cast<std::size_t>(v) * static_cast<std::size_t>(w) + static_cast<std::size_t>(u);
}

/** \brief The organized frame \a cloud as a camera rolled by \a quarter_turns x 90 degrees
 * clockwise about its optical axis would have taken it (a wrist camera, a sensor mounted on
 * its side or upside down): the image grid turned and the points expressed in the rolled
 * camera's frame (x right, y down, z forward), together, so that each pixel still sees its
 * point. One quarter turn: pixel (u, v) of a W x H frame goes to (H - 1 - v, u) of the H x W
 * result (rolledIndex), a point (x, y, z) to (-y, x, z). \a quarter_turns is taken modulo 4
 * (negative: anti-clockwise). The sensor pose is kept.
 * \throws std::invalid_argument when \a cloud is not organized. */
template <typename PointT>
pcl::PointCloud<PointT>
rollFrame(const pcl::PointCloud<PointT>& cloud, int quarter_turns)
{
  if (!cloud.isOrganized())
    throw std::invalid_argument("facyl::rollFrame: the cloud is not organized");
  const int k = ((quarter_turns % 4) + 4) % 4;
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height);
  pcl::PointCloud<PointT> out;
  out.header = cloud.header;
  out.is_dense = cloud.is_dense;
  out.sensor_origin_ = cloud.sensor_origin_;
  out.sensor_orientation_ = cloud.sensor_orientation_;
  out.width = static_cast<std::uint32_t>(k % 2 ? h : w);
  out.height = static_cast<std::uint32_t>(k % 2 ? w : h);
  out.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    PointT p = cloud[i];
    for (int t = 0; t < k; ++t) { // (x, y) -> (-y, x) per quarter turn
      const float x = p.x;
      p.x = -p.y;
      p.y = x;
    }
    out[rolledIndex(i, w, h, k)] = p;
  }
  return out;
}

} // namespace facyl
