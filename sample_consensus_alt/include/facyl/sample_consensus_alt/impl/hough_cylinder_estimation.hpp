/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/local_geometry.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>
#include <pcl/point_traits.h>

#include <algorithm>
#include <exception>

namespace facyl {

template <typename PointT, typename PointNT>
void
HoughCylinderEstimation<PointT, PointNT>::setUpDirection(const Eigen::Vector3f& up)
{
  const Eigen::Vector3f z = up.normalized();
  const Eigen::Vector3f x = z.unitOrthogonal();
  Eigen::Matrix3f frame;
  frame << x, z.cross(x), z;
  setReferenceFrame(frame);
}

template <typename PointT, typename PointNT>
const std::vector<OrientationAccumulator>&
HoughCylinderEstimation<PointT, PointNT>::accumulators()
{
  if (!user_accumulators_.empty())
    return user_accumulators_;
  if (drawn_.empty())
    for (std::size_t k = 0; k < num_accumulators_; ++k)
      drawn_.push_back(
          OrientationAccumulator::sample(mixture_, num_orientations_, seed_ + k, frame_));
  return drawn_;
}

template <typename PointT, typename PointNT>
bool
HoughCylinderEstimation<PointT, PointNT>::segment(pcl::PointIndices& inliers,
                                                  pcl::ModelCoefficients& coefficients)
{
  inliers.indices.clear();
  coefficients.values.clear();
  std::vector<CylinderModel> cylinders;
  if (!segment(cylinders))
    return false;
  inliers.header = coefficients.header = this->input_->header;
  inliers.indices = cylinders.front().inliers;
  cylinders.front().toCoefficients(coefficients);
  return true;
}

template <typename PointT, typename PointNT>
bool
HoughCylinderEstimation<PointT, PointNT>::segment(std::vector<CylinderModel>& cylinders)
{
  cylinders.clear();
  const char* name = "HoughCylinderEstimation";
  if (!this->input_) {
    PCL_ERROR("[facyl::%s::segment] no input cloud: call setInputCloud first.\n", name);
    return false;
  }
  if (this->input_->empty()) {
    PCL_ERROR("[facyl::%s::segment] the input cloud is empty.\n", name);
    return false;
  }
  if (!normals_) {
    PCL_ERROR("[facyl::%s::segment] no normals: call setInputNormals (e.g. with the output of "
              "facyl::NormalCurvatureEstimation).\n",
              name);
    return false;
  }
  if (normals_->size() != this->input_->size()) {
    PCL_ERROR("[facyl::%s::segment] %zu normals for %zu points: give one normal per point.\n",
              name, normals_->size(), this->input_->size());
    return false;
  }
  if (curvatures_ && curvatures_->size() != this->input_->size()) {
    PCL_ERROR("[facyl::%s::segment] %zu curvatures for %zu points: give one per point.\n", name,
              curvatures_->size(), this->input_->size());
    return false;
  }
  const std::string why = validate(params_);
  if (!why.empty()) {
    PCL_ERROR("[facyl::%s::segment] %s.\n", name, why.c_str());
    return false;
  }
  if (user_accumulators_.empty()) {
    std::string bad;
    if (num_orientations_ == 0 || num_accumulators_ == 0) {
      PCL_ERROR("[facyl::%s::segment] the orientation accumulator is empty (N_d = %zu, %zu "
                "accumulators).\n",
                name, num_orientations_, num_accumulators_);
      return false;
    }
    if (!mixture_.isValid(&bad)) {
      PCL_ERROR("[facyl::%s::segment] invalid orientation prior: %s.\n", name, bad.c_str());
      return false;
    }
    if (!frame_.allFinite() || std::abs(frame_.determinant()) < 1e-6f) {
      PCL_ERROR("[facyl::%s::segment] the reference frame is singular or not finite.\n", name);
      return false;
    }
  }
  else if (std::any_of(user_accumulators_.begin(), user_accumulators_.end(),
                       [](const OrientationAccumulator& a) { return a.size() == 0; })) {
    PCL_ERROR("[facyl::%s::segment] an accumulator given with setAccumulators is empty.\n",
              name);
    return false;
  }

  constexpr bool normals_carry_curvature =
      pcl::traits::has_field<PointNT, pcl::fields::pc1>::value &&
      pcl::traits::has_field<PointNT, pcl::fields::pc2>::value &&
      pcl::traits::has_field<PointNT, pcl::fields::principal_curvature_x>::value;
  const bool need_curvature = params_.voting_mode == VotingMode::SoftCurvature;
  if (need_curvature && !curvatures_ && !normals_carry_curvature) {
    PCL_ERROR("[facyl::%s::segment] SoftCurvature voting needs principal curvatures: use "
              "facyl::NormalCurvature normals, call setInputCurvatures, or choose another "
              "voting mode.\n",
              name);
    return false;
  }

  if (!this->initCompute()) {
    PCL_ERROR("[facyl::%s::segment] invalid input or indices.\n", name);
    return false;
  }
  const auto& indices = *this->indices_;
  const auto& cloud = *this->input_;
  const auto& normals = *normals_;

  // Gather the finite points with finite normals (and curvatures) into columns.
  CylinderCues cues;
  std::vector<pcl::index_t> column_to_index;
  column_to_index.reserve(indices.size());
  const auto n_max = static_cast<Eigen::Index>(indices.size());
  cues.points.resize(3, n_max);
  cues.normals.resize(3, n_max);
  if (need_curvature) {
    cues.curvature_directions.resize(3, n_max);
    cues.weights.resize(n_max);
  }
  Eigen::Index n = 0;
  for (const auto idx : indices) {
    if (idx < 0 || static_cast<std::size_t>(idx) >= cloud.size()) {
      PCL_ERROR("[facyl::%s::segment] index %d is outside the cloud (%zu points).\n", name,
                static_cast<int>(idx), cloud.size());
      this->deinitCompute();
      return false;
    }
    const auto& p = cloud[idx];
    const auto& q = normals[idx];
    const Eigen::Vector3f normal(q.normal_x, q.normal_y, q.normal_z);
    const float len = normal.norm();
    if (!pcl::isFinite(p) || !std::isfinite(len) || len < 1e-3f)
      continue;
    cues.points.col(n) = p.getVector3fMap();
    cues.normals.col(n) = normal / len;
    if (need_curvature) {
      Eigen::Vector3f c{Eigen::Vector3f::Zero()};
      float k_max = 0.f, k_min = 0.f;
      if (curvatures_) {
        const auto& pc = (*curvatures_)[idx];
        c = Eigen::Vector3f(pc.principal_curvature_x, pc.principal_curvature_y,
                            pc.principal_curvature_z);
        k_max = pc.pc1;
        k_min = pc.pc2;
      }
      else if constexpr (normals_carry_curvature) {
        c = Eigen::Vector3f(q.principal_curvature_x, q.principal_curvature_y,
                            q.principal_curvature_z);
        k_max = q.pc1;
        k_min = q.pc2;
      }
      const float c_len = c.norm();
      const bool ok = std::isfinite(c_len) && c_len > 1e-3f;
      cues.curvature_directions.col(n) = ok ? Eigen::Vector3f(c / c_len) : Eigen::Vector3f::Zero();
      cues.weights(n) = ok ? curvatureAnisotropy(k_max, k_min) : 0.f;
    }
    column_to_index.push_back(idx);
    ++n;
  }
  this->deinitCompute();
  if (n == 0) {
    PCL_ERROR("[facyl::%s::segment] none of the %zu points has a finite position and "
              "normal.\n",
              name, indices.size());
    return false;
  }
  cues.points.conservativeResize(3, n);
  cues.normals.conservativeResize(3, n);
  if (need_curvature) {
    cues.curvature_directions.conservativeResize(3, n);
    cues.weights.conservativeResize(n);
  }

  try {
    cylinders = fitCylinders(cues, accumulators(), params_, indices.size());
  }
  catch (const std::exception& e) {
    PCL_ERROR("[facyl::%s::segment] %s\n", name, e.what());
    cylinders.clear();
    return false;
  }
  for (auto& c : cylinders) {
    for (auto& i : c.inliers)
      i = column_to_index[static_cast<std::size_t>(i)];
    std::sort(c.inliers.begin(), c.inliers.end());
  }
  if (cylinders.empty()) {
    // A normal outcome (the points hold no cylinder), not something to act on.
    PCL_DEBUG("[facyl::%s::segment] no cylinder found among %zu points.\n", name,
              indices.size());
    return false;
  }
  return true;
}

} // namespace facyl

#define FACYL_INSTANTIATE_HoughCylinderEstimation(T, NT)                                    \
  template class facyl::HoughCylinderEstimation<T, NT>;
