/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/recognition/classifier_input.h>

#include <pcl/common/point_tests.h>
#include <pcl/point_traits.h>

#include <algorithm>
#include <cmath>

namespace facyl {

template <typename PointT>
ObjectView
objectView(const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices,
           const PinholeCamera& camera, bool with_crop)
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
  viewBoxAndCrop(view, cloud, indices, with_crop);
  return view;
}

template <typename PointT>
void
viewBoxAndCrop(ObjectView& view, const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices,
               bool with_crop)
{
  const auto n = static_cast<Eigen::Index>(indices.size());
  view.crop = RgbImage{};
  if (view.pixels.cols() != n) {
    view.box = {-1, -1, -1, -1};
    return;
  }
  viewBox(view);
  if (!with_crop)
    return;
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

template <typename PointT>
ObjectView
lookAtObjectView(const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices,
                 const Eigen::Vector3f& viewpoint, bool with_crop)
{
  ObjectView view;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  std::size_t finite = 0;
  for (const auto i : indices)
    if (pcl::isFinite(cloud[static_cast<std::size_t>(i)])) {
      centroid += cloud[static_cast<std::size_t>(i)].getVector3fMap();
      ++finite;
    }
  if (finite == 0 || !((centroid / static_cast<float>(finite) - viewpoint).norm() > 0.f))
    return view;
  // The camera: z towards the centroid, x along the cloud's x as far as possible.
  const Eigen::Vector3f z = (centroid / static_cast<float>(finite) - viewpoint).normalized();
  Eigen::Vector3f x = Eigen::Vector3f::UnitX() - z.x() * z;
  if (x.norm() < 0.3f)
    x = Eigen::Vector3f::UnitY() - z.y() * z;
  x.normalize();
  Eigen::Matrix3f to_camera;
  to_camera.row(0) = x;
  to_camera.row(1) = z.cross(x);
  to_camera.row(2) = z;
  const auto n = static_cast<Eigen::Index>(indices.size());
  view.points.resize(3, n);
  view.pixels.setConstant(2, n, -1);
  Eigen::AlignedBox2f tangent; // the points' x/z, y/z
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto& p = cloud[static_cast<std::size_t>(indices[static_cast<std::size_t>(k)])];
    view.points.col(k) = to_camera * (p.getVector3fMap() - viewpoint);
    const Eigen::Vector3f c = view.points.col(k);
    if (c.allFinite() && c.z() > 0.f)
      tangent.extend(Eigen::Vector2f(c.x() / c.z(), c.y() / c.z()));
  }
  if (tangent.isEmpty())
    return view;
  // About one point per pixel of the box: the silhouette is filled.
  const float area = std::max(tangent.sizes().prod(), 1e-12f);
  const float f = std::clamp(std::sqrt(static_cast<float>(finite) / area), 50.f, 2000.f);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Vector3f c = view.points.col(k);
    if (!c.allFinite() || !(c.z() > 0.f))
      continue;
    view.pixels(0, k) = static_cast<int>(std::lround(f * (c.x() / c.z() - tangent.min().x())));
    view.pixels(1, k) = static_cast<int>(std::lround(f * (c.y() / c.z() - tangent.min().y())));
  }
  viewBoxAndCrop(view, cloud, indices, with_crop);
  return view;
}

} // namespace facyl
