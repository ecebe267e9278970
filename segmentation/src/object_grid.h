/*
 * facyl: fast cylinder detection for PCL.
 * The valid pixels of an organized cloud as the edge-aware object segmentation walks them
 * (object_segmentation.cpp, object_joins.cpp); internal to the library.
 */
#pragma once

#include <facyl/segmentation/object_segmentation.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace facyl {
namespace edge_aware {

/** x, y and z finite. */
inline bool
finite(const pcl::PointXYZ& p)
{
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

/** The valid pixels of an organized cloud, numbered compactly (in image order), with their
 * ranges and the connection test between neighbours. */
class Grid {
public:
  /** The finite pixels of \a cloud: \a finite (ascending) when given, else all of them. */
  Grid(const pcl::PointCloud<pcl::PointXYZ>& cloud, float focal, const Eigen::Vector3f& viewpoint,
       const ObjectSegmentationParameters& p, const DepthBand* noise = nullptr,
       const pcl::Indices* finite_pixels = nullptr)
      : Grid(static_cast<int>(cloud.width), static_cast<int>(cloud.height), focal, viewpoint, p,
             noise, finite_pixels ? finite_pixels->size() : countFinite(cloud), finite_pixels)
  {
    if (finite_pixels) {
      for (const auto idx : *finite_pixels) {
        const auto i = static_cast<std::size_t>(idx);
        if (finite(cloud[i]))
          add(i, static_cast<int>(i % static_cast<std::size_t>(w_)),
              static_cast<int>(i / static_cast<std::size_t>(w_)), cloud[i].getVector3fMap());
      }
      return;
    }
    // Row by row: the pixel's column and row without a division per pixel.
    for (int v = 0, i = 0; v < h_; ++v)
      for (int u = 0; u < w_; ++u, ++i)
        if (finite(cloud[static_cast<std::size_t>(i)]))
          add(static_cast<std::size_t>(i), u, v,
              cloud[static_cast<std::size_t>(i)].getVector3fMap());
  }
  /** The finite columns of \a points, at the pixels \a pixels (ascending) of a \a width x
   * \a height image. */
  Grid(const Eigen::Matrix3Xf& points, const pcl::Indices& pixels, int width, int height,
       float focal, const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p,
       const DepthBand* noise)
      : Grid(width, height, focal, viewpoint, p, noise, pixels.size(), &pixels)
  {
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      const auto i = static_cast<std::size_t>(pixels[k]);
      const auto c = static_cast<Eigen::Index>(k);
      if (points.col(c).allFinite())
        add(i, static_cast<int>(i % static_cast<std::size_t>(w_)),
            static_cast<int>(i / static_cast<std::size_t>(w_)), points.col(c));
    }
  }
  int width() const
  {
    return w_;
  }
  int height() const
  {
    return h_;
  }
  /** Valid pixels. */
  std::size_t size() const
  {
    return pixel_.size();
  }
  std::size_t pixel(int c) const
  {
    return pixel_[static_cast<std::size_t>(c)];
  }
  /** Compact number of pixel (u, v), or -1 (outside the image, or not valid). */
  int at(int u, int v) const
  {
    // One unsigned comparison per coordinate: negative ones wrap beyond the size.
    if (static_cast<unsigned>(u) >= static_cast<unsigned>(w_) ||
        static_cast<unsigned>(v - v0_) >= static_cast<unsigned>(rows_))
      return -1;
    return slot_[static_cast<std::size_t>(v - v0_) * static_cast<std::size_t>(w_) +
                 static_cast<std::size_t>(u)];
  }
  /** at() of the five pixels centred on the valid pixel (\a u, \a v) along a column
   * (\a vertical) or a row: one bounds test per pixel, no multiplication. */
  void across(int u, int v, bool vertical, int (&out)[5]) const
  {
    const std::ptrdiff_t step = vertical ? w_ : 1;
    const int along = vertical ? v - v0_ : u, size = vertical ? rows_ : w_;
    const int* centre = slot_.data() +
                        static_cast<std::ptrdiff_t>(v - v0_) * static_cast<std::ptrdiff_t>(w_) +
                        static_cast<std::ptrdiff_t>(u);
    for (int d = -2; d <= 2; ++d)
      out[d + 2] =
        static_cast<unsigned>(along + d) < static_cast<unsigned>(size) ? centre[d * step] : -1;
  }
  const Eigen::Vector3f& point(int c) const
  {
    return xyz_[static_cast<std::size_t>(c)];
  }
  float range(int c) const
  {
    return range_[static_cast<std::size_t>(c)];
  }
  /** Neighbours a and b are on one surface: no depth discontinuity. */
  bool linked(int a, int b) const
  {
    const float g2 =
      std::min(gap2_[static_cast<std::size_t>(a)], gap2_[static_cast<std::size_t>(b)]);
    return (point(a) - point(b)).squaredNorm() < g2;
  }
  /** Calls f(b) for each valid 4-neighbour b of a, and g() for each other neighbour. */
  template <typename F, typename G> void forNeighbours(int a, F f, G g) const
  {
    const int u = u_[static_cast<std::size_t>(a)], v = v_[static_cast<std::size_t>(a)];
    for (const int b : {at(u + 1, v), at(u - 1, v), at(u, v + 1), at(u, v - 1)}) {
      if (b >= 0)
        f(b);
      else
        g();
    }
  }
  /** Image position of valid pixel c. */
  void position(int c, int& u, int& v) const
  {
    u = u_[static_cast<std::size_t>(c)];
    v = v_[static_cast<std::size_t>(c)];
  }

private:
  /** An empty grid of a \a width x \a height image, with room for \a valid pixels; given
   * its \a pixels (ascending), its slots span only their rows. */
  Grid(int width, int height, float focal, const Eigen::Vector3f& viewpoint,
       const ObjectSegmentationParameters& p, const DepthBand* noise, std::size_t valid,
       const pcl::Indices* pixels)
      : w_(width)
      , h_(height)
      , v0_(pixels && !pixels->empty() && width > 0 ? pixels->front() / width : 0)
      , rows_(pixels && width > 0 ? (pixels->empty() ? 0 : pixels->back() / width - v0_ + 1)
                                  : height)
      , slot_(static_cast<std::size_t>(width) * static_cast<std::size_t>(rows_), -1)
      , focal_(focal)
      , viewpoint_(viewpoint)
      , p_(p)
  {
    if (noise)
      noise_half_ = tabulateHalfWidths(*noise);
    pixel_.reserve(valid);
    xyz_.reserve(valid);
    u_.reserve(valid);
    v_.reserve(valid);
    range_.reserve(valid);
    gap2_.reserve(valid);
  }
  static std::size_t countFinite(const pcl::PointCloud<pcl::PointXYZ>& cloud)
  {
    std::size_t valid = 0;
    for (const auto& q : cloud)
      valid += finite(q);
    return valid;
  }
  /** Pixel \a i at (\a u, \a v) with the point \a q. */
  void add(std::size_t i, int u, int v, const Eigen::Vector3f& q)
  {
    slot_[i - static_cast<std::size_t>(v0_) * static_cast<std::size_t>(w_)] =
      static_cast<int>(pixel_.size());
    pixel_.push_back(i);
    xyz_.push_back(q);
    u_.push_back(u);
    v_.push_back(v);
    const float r = (q - viewpoint_).norm();
    range_.push_back(r);
    const float gap = connectionGap(p_, r, focal_, noise_half_);
    gap2_.push_back(gap * gap);
  }
  int w_, h_;
  int v0_, rows_; ///< the rows that slot_ spans: [v0_, v0_ + rows_)
  std::vector<int> slot_;
  float focal_;
  Eigen::Vector3f viewpoint_;
  ObjectSegmentationParameters p_;
  std::vector<float> noise_half_;
  std::vector<std::size_t> pixel_;
  std::vector<Eigen::Vector3f> xyz_; ///< per valid pixel: its point
  std::vector<int> u_, v_;
  std::vector<float> range_, gap2_;
};

} // namespace edge_aware
} // namespace facyl
