/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/local_geometry.h>
#include <facyl/features/point_cues.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>
#include <pcl/point_traits.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>

namespace facyl {

template <typename PointT, typename PointNT>
void
HoughCylinderEstimation<PointT, PointNT>::setUpDirection(const Eigen::Vector3f& up)
{
  if (!(up.norm() > 0.f) || !up.allFinite()) {
    up_ = Eigen::Vector3f::Zero();
    setReferenceFrame(Eigen::Matrix3f::Identity());
    return;
  }
  up_ = up.normalized();
  setReferenceFrame(frameAboutUp(up));
}

template <typename PointT, typename PointNT>
const std::vector<OrientationAccumulator>&
HoughCylinderEstimation<PointT, PointNT>::accumulators()
{
  if (!user_accumulators_.empty())
    return user_accumulators_;
  if (drawn_.empty()) {
    const GaussianMixture mixture = getOrientationMixture();
    for (std::size_t k = 0; k < params_.accumulators; ++k)
      drawn_.push_back(
        OrientationAccumulator::sample(mixture, params_.orientations, params_.seed + k, frame_));
  }
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
HoughCylinderEstimation<PointT, PointNT>::fail(HoughFailure reason, const std::string& message,
                                               Level level)
{
  failure_ = reason;
  failure_message_ = message;
  const std::string name = getClassName();
  if (level == Level::Error)
    PCL_ERROR("[facyl::%s::segment] %s.\n", name.c_str(), message.c_str());
  else if (level == Level::Warn)
    PCL_WARN("[facyl::%s::segment] %s.\n", name.c_str(), message.c_str());
  else
    PCL_DEBUG("[facyl::%s::segment] %s.\n", name.c_str(), message.c_str());
  return false;
}

namespace detail {
/** printf into a std::string (messages of HoughCylinderEstimation). */
template <typename... Args>
std::string
houghFormat(const char* format, Args... args)
{
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, format, args...);
  return buffer;
}
} // namespace detail

template <typename PointT, typename PointNT>
bool
HoughCylinderEstimation<PointT, PointNT>::explainNoCylinder(const CylinderCues& cues,
                                                            std::size_t total_points)
{
  using detail::houghFormat;
  const Level level = diagnose_failures_ ? Level::Warn : Level::Debug;
  const std::size_t n = static_cast<std::size_t>(cues.points.cols());
  const std::size_t min_inliers = minimumInliers(params_, n);
  if (n < min_inliers)
    return fail(HoughFailure::TooFewPoints,
                houghFormat("too few points: %zu usable of %zu, and a cylinder needs %zu points "
                            "on its side and end caps (setMinInliers)",
                            n, total_points, min_inliers),
                level);
  const bool limited = params_.radius_min > 0.f || std::isfinite(params_.radius_max);
  if (limited && diagnose_failures_) {
    // The same search without radius limits: a cylinder outside them is worth saying.
    HoughCylinderParameters open = params_;
    open.radius_min = 0.f;
    open.radius_max = std::numeric_limits<float>::infinity();
    open.max_cylinders = 1;
    std::vector<CylinderModel> found;
    try {
      found = fitCylinders(cues, accumulators(), open, total_points);
    }
    catch (const std::exception&) {
      found.clear();
    }
    if (!found.empty() &&
        (found.front().radius < params_.radius_min || found.front().radius > params_.radius_max))
      return fail(HoughFailure::RadiusLimits,
                  houghFormat("the radius limits [%g, %g] exclude every candidate: without them "
                              "the best cylinder has radius %g (%zu inliers)",
                              params_.radius_min, params_.radius_max, found.front().radius,
                              found.front().inliers.size()),
                  level);
  }
  return fail(HoughFailure::NoCylinder,
              houghFormat("no cylinder found among %zu points (%zu usable; a cylinder needs %zu "
                          "points on its side and end caps, setMinInliers)",
                          total_points, n, min_inliers),
              level);
}

template <typename PointT, typename PointNT>
bool
HoughCylinderEstimation<PointT, PointNT>::checkInput()
{
  using detail::houghFormat;
  if (!this->input_)
    return fail(HoughFailure::NoInputCloud, "no input cloud: call setInputCloud first");
  if (this->input_->empty())
    return fail(HoughFailure::EmptyCloud, "the input cloud is empty");
  if (!normals_)
    return fail(HoughFailure::NoNormals,
                "no normals: call setInputNormals (e.g. with the output of "
                "facyl::NormalCurvatureEstimation or pcl::NormalEstimation)");
  if (normals_->size() != this->input_->size())
    return fail(HoughFailure::SizeMismatch,
                houghFormat("%zu normals for %zu points: give one normal per point",
                            normals_->size(), this->input_->size()));
  if (curvatures_ && curvatures_->size() != this->input_->size())
    return fail(HoughFailure::SizeMismatch,
                houghFormat("%zu curvatures for %zu points: give one per point",
                            curvatures_->size(), this->input_->size()));
  const std::string why = validate(params_);
  if (!why.empty())
    return fail(HoughFailure::InvalidParameters, why);
  if (user_accumulators_.empty()) {
    std::string bad;
    if (!getOrientationMixture().isValid(&bad))
      return fail(HoughFailure::InvalidParameters, "invalid orientation prior: " + bad);
    if (!frame_.allFinite() || std::abs(frame_.determinant()) < 1e-6f)
      return fail(HoughFailure::InvalidParameters, "the reference frame is singular or not finite");
  }
  else if (std::any_of(user_accumulators_.begin(), user_accumulators_.end(),
                       [](const OrientationAccumulator& a) { return a.size() == 0; })) {
    return fail(HoughFailure::InvalidParameters,
                "an accumulator given with setAccumulators is empty");
  }
  if (curvaturesToEstimate() && !estimate_curvatures_)
    return fail(HoughFailure::NoCurvatures,
                "SoftCurvature voting needs principal curvatures and their estimation is off "
                "(setEstimateCurvatures(false)): use facyl::NormalCurvature normals, call "
                "setInputCurvatures, turn the estimation on, or choose another voting mode");
  return true;
}

template <typename PointT, typename PointNT>
bool
HoughCylinderEstimation<PointT, PointNT>::gatherCues(CylinderCues& cues,
                                                     std::vector<pcl::index_t>& column_to_index)
{
  using detail::houghFormat;
  if (!this->initCompute())
    return fail(HoughFailure::InvalidIndices, "invalid input or indices");
  const auto& indices = *this->indices_;
  const auto& cloud = *this->input_;
  const auto& normals = *normals_;
  column_to_index.clear();
  column_to_index.reserve(indices.size());
  const auto n_max = static_cast<Eigen::Index>(indices.size());
  cues.points.resize(3, n_max);
  cues.normals.resize(3, n_max);
  const bool given_curvature =
    params_.voting_mode == VotingMode::SoftCurvature && !curvaturesToEstimate();
  if (given_curvature) {
    cues.curvature_directions.resize(3, n_max);
    cues.weights.resize(n_max);
  }
  Eigen::Index n = 0;
  for (const auto idx : indices) {
    if (idx < 0 || static_cast<std::size_t>(idx) >= cloud.size()) {
      this->deinitCompute();
      return fail(HoughFailure::InvalidIndices,
                  houghFormat("index %d is outside the cloud (%zu points)", static_cast<int>(idx),
                              cloud.size()));
    }
    const auto& p = cloud[idx];
    const auto& q = normals[idx];
    const Eigen::Vector3f normal(q.normal_x, q.normal_y, q.normal_z);
    const float len = normal.norm();
    if (!pcl::isFinite(p) || !std::isfinite(len) || len < 1e-3f)
      continue;
    cues.points.col(n) = p.getVector3fMap();
    cues.normals.col(n) = normal / len;
    if (given_curvature) {
      Eigen::Vector3f c{Eigen::Vector3f::Zero()};
      float k_max = 0.f, k_min = 0.f;
      if (curvatures_) {
        const auto& pc = (*curvatures_)[idx];
        c = Eigen::Vector3f(pc.principal_curvature_x, pc.principal_curvature_y,
                            pc.principal_curvature_z);
        k_max = pc.pc1;
        k_min = pc.pc2;
      }
      else if constexpr (kNormalsCarryCurvature) {
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
  if (n == 0)
    return fail(
      HoughFailure::NoFinitePoints,
      houghFormat("none of the %zu points has a finite position and normal", indices.size()));
  cues.points.conservativeResize(3, n);
  cues.normals.conservativeResize(3, n);
  if (given_curvature) {
    cues.curvature_directions.conservativeResize(3, n);
    cues.weights.conservativeResize(n);
  }
  return true;
}

namespace detail {
/** Curvatures of \a cues at facyl's own scale (kDefaultNeighbours, 16: normals of the 16
 * nearest points, then the spread of those normals), whatever scale the given normals
 * have: normals smoothed over k = 50 neighbours bend c_max on a small cylinder. The given
 * normals stay the normals of the vote and of the inlier test. Columns without a usable
 * neighbourhood vote without curvature (weight 0). */
inline void
estimateOwnCurvatures(CylinderCues& cues)
{
  const Eigen::Index n = cues.points.cols();
  const PointCues own = estimatePointCues(cues.points, std::numeric_limits<float>::max(),
                                          kDefaultNeighbours, cues.normals);
  cues.curvature_directions.setZero(3, n);
  cues.weights.setZero(n);
  for (Eigen::Index s = 0; s < n; ++s) {
    if (own.curvature_directions.col(s).allFinite()) {
      cues.curvature_directions.col(s) = own.curvature_directions.col(s);
      cues.weights(s) = own.weights(s);
    }
  }
}
} // namespace detail

template <typename PointT, typename PointNT>
bool
HoughCylinderEstimation<PointT, PointNT>::segment(std::vector<CylinderModel>& cylinders)
{
  cylinders.clear();
  failure_ = HoughFailure::None;
  failure_message_.clear();
  curvatures_estimated_ = false;
  if (!checkInput())
    return false;
  CylinderCues cues;
  std::vector<pcl::index_t> column_to_index;
  if (!gatherCues(cues, column_to_index))
    return false;
  const std::size_t total_points = this->indices_->size();
  try {
    if (curvaturesToEstimate()) {
      detail::estimateOwnCurvatures(cues);
      curvatures_estimated_ = true;
    }
    cylinders = fitCylinders(cues, accumulators(), params_, total_points);
  }
  catch (const std::exception& e) {
    cylinders.clear();
    return fail(HoughFailure::InternalError, e.what());
  }
  const Eigen::Vector3f viewpoint = this->input_->sensor_origin_.template head<3>();
  for (auto& c : cylinders) {
    for (auto& i : c.inliers)
      i = column_to_index[static_cast<std::size_t>(i)];
    std::sort(c.inliers.begin(), c.inliers.end());
    if (up_.norm() > 0.f)
      orientCylinder(c, up_, viewpoint);
  }
  if (cylinders.empty())
    return explainNoCylinder(cues, total_points);
  return true;
}

} // namespace facyl

#define FACYL_INSTANTIATE_HoughCylinderEstimation(T, NT)                                           \
  template class facyl::HoughCylinderEstimation<T, NT>;
