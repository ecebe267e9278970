/*
 * facyl: shared helpers of the tests.
 */
#pragma once

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/sample_consensus_alt/cylinder_model.h>
#include <facyl/simulation/cylinder_simulation.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace facyl_test {

/** A file of the real data folder (FACYL_REAL_DATA_DIR), or "" when it is absent. */
inline std::string
realFile(const std::string& name)
{
  const std::filesystem::path p = std::filesystem::path(FACYL_REAL_DATA_DIR) / name;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

inline pcl::PointCloud<facyl::NormalCurvature>::Ptr
estimateCues(const pcl::PointCloud<pcl::PointNormal>::ConstPtr& cloud, int k = 16)
{
  pcl::PointCloud<facyl::NormalCurvature>::Ptr cues(new pcl::PointCloud<facyl::NormalCurvature>);
  facyl::NormalCurvatureEstimation<pcl::PointNormal> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(k);
  ne.compute(*cues);
  return cues;
}

inline float
degrees(float radians)
{
  return radians * 180.f / static_cast<float>(M_PI);
}

inline float
quantile(std::vector<float> v, double q)
{
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

/** Distance between the axis lines of two cylinders, measured at \a at (the true base). */
inline float
axisOffset(const facyl::CylinderModel& m, const Eigen::Vector3f& at)
{
  return facyl::distanceToLine(at, m.point_on_axis, m.axis);
}

} // namespace facyl_test
