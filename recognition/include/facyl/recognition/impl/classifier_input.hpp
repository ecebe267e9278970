/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/recognition/classifier_input.h>

#include <pcl/common/point_tests.h>
#include <pcl/point_traits.h>

#include <cmath>

namespace facyl {

template <typename PointT>
ObjectView
objectView(const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices,
           const PinholeCamera& camera)
{
  ObjectView view;
  const auto n = static_cast<Eigen::Index>(indices.size());
  view.points.resize(3, n);
  view.pixels.setConstant(2, n, -1);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto i = indices[static_cast<std::size_t>(k)];
    const auto& p = cloud[static_cast<std::size_t>(i)];
    view.points.col(k) = p.getVector3fMap();
    if (cloud.isOrganized()) {
      view.pixels(0, k) = static_cast<int>(i % static_cast<pcl::index_t>(cloud.width));
      view.pixels(1, k) = static_cast<int>(i / static_cast<pcl::index_t>(cloud.width));
    }
    else if (camera.valid() && pcl::isFinite(p) && p.z > 0.f) {
      const Eigen::Vector2f px = camera.project(p.getVector3fMap());
      if (px.allFinite() && px.x() > -0.5f && px.y() > -0.5f &&
          px.x() < static_cast<float>(camera.width) - 0.5f &&
          px.y() < static_cast<float>(camera.height) - 0.5f) {
        view.pixels(0, k) = static_cast<int>(std::lround(px.x()));
        view.pixels(1, k) = static_cast<int>(std::lround(px.y()));
      }
    }
  }
  viewBoxAndCrop(view, cloud, indices);
  return view;
}

template <typename PointT>
void
viewBoxAndCrop(ObjectView& view, const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices)
{
  const auto n = static_cast<Eigen::Index>(indices.size());
  view.box = {-1, -1, -1, -1};
  view.crop = RgbImage{};
  if (view.pixels.cols() != n)
    return;
  for (Eigen::Index k = 0; k < n; ++k) {
    const int u = view.pixels(0, k), v = view.pixels(1, k);
    if (u < 0)
      continue;
    auto& b = view.box;
    if (b[0] < 0)
      b = {u, v, u, v};
    b = {std::min(b[0], u), std::min(b[1], v), std::max(b[2], u), std::max(b[3], v)};
  }
  if constexpr (pcl::traits::has_color_v<PointT>) {
    const PixelBox& b = view.box;
    if (b[0] < 0)
      return;
    RgbImage& crop = view.crop;
    crop.width = b[2] - b[0] + 1;
    crop.height = b[3] - b[1] + 1;
    crop.data.assign(static_cast<std::size_t>(crop.width) * crop.height * 3, 0);
    const auto put = [&](int u, int v, const PointT& p) {
      std::uint8_t* px =
        &crop.data[3 * (static_cast<std::size_t>(v - b[1]) * crop.width + (u - b[0]))];
      px[0] = p.r;
      px[1] = p.g;
      px[2] = p.b;
    };
    if (cloud.isOrganized()) {
      for (int v = b[1]; v <= b[3]; ++v)
        for (int u = b[0]; u <= b[2]; ++u)
          put(u, v, cloud.at(u, v));
    }
    else {
      for (Eigen::Index k = 0; k < n; ++k)
        if (view.pixels(0, k) >= 0)
          put(view.pixels(0, k), view.pixels(1, k), cloud[indices[static_cast<std::size_t>(k)]]);
    }
  }
}

} // namespace facyl
