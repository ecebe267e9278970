/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/tracking/cylinder_tracker.h>

#include <pcl/common/point_tests.h>

#include <algorithm>
#include <limits>

namespace facyl {

template <typename PointT>
TrackerView
trackerViewOf(const typename pcl::PointCloud<PointT>::ConstPtr& cloud, const PinholeCamera& camera)
{
  TrackerView view;
  view.camera = camera;
  if (!cloud || cloud->empty())
    return view;
  view.sensor_pose = plausibleSensorPose(*cloud);
  if (!cloud->isOrganized() || cloud->height < 2)
    return view;
  const Eigen::Affine3f to_sensor = view.sensor_pose.inverse();
  if (!view.camera.valid()) {
    const std::size_t step = std::max<std::size_t>(1, cloud->size() / 3000);
    Eigen::Matrix3Xf points(3, static_cast<Eigen::Index>(cloud->size() / step + 1));
    Eigen::Matrix2Xf pixels(2, points.cols());
    Eigen::Index n = 0;
    for (std::size_t i = 0; i < cloud->size(); i += step)
      if (pcl::isFinite((*cloud)[i])) {
        points.col(n) = to_sensor * (*cloud)[i].getVector3fMap();
        pixels.col(n++) = Eigen::Vector2f(static_cast<float>(i % cloud->width),
                                          static_cast<float>(i / cloud->width));
      }
    if (!estimatePinhole(points.leftCols(n), pixels.leftCols(n), static_cast<int>(cloud->width),
                         static_cast<int>(cloud->height), view.camera))
      view.camera = PinholeCamera{};
  }
  if (view.camera.width != static_cast<int>(cloud->width) ||
      view.camera.height != static_cast<int>(cloud->height))
    return view; // intrinsics of another image: no depth lookups
  view.depth = [cloud, to_sensor](int u, int v) {
    const auto& p = cloud->at(u, v);
    if (!pcl::isFinite(p))
      return std::numeric_limits<float>::quiet_NaN();
    return (to_sensor * p.getVector3fMap()).z();
  };
  return view;
}

} // namespace facyl
