/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/segmentation/segment_tabletop.h>
#include <facyl/segmentation/tabletop_segmentation.h>

#include <pcl/common/point_tests.h>
#include <pcl/common/transforms.h>

#include <chrono>
#include <cstddef>

namespace facyl {

template <typename PointT>
void
TabletopSegmentation<PointT>::reset()
{
  supports_.clear();
  table_ = 0;
  table_found_ = false;
  focal_ = 0.f;
  table_coefficients_.values.clear();
  hull_.clear();
  prior_result_ = SupportPriorResult{};
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::run(std::vector<TabletopCluster>& clusters, bool check_pose)
{
  clusters.clear();
  reset();
  timing_ = SegmentationTiming{};
  const auto t0 = std::chrono::steady_clock::now();
  const std::string why = validate(params_);
  if (!why.empty()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] Invalid parameters: %s.\n", why.c_str());
    return false;
  }
  if (!input_ || input_->empty()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] No input cloud, or an empty one.\n");
    return false;
  }
  if (!up_.allFinite()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The up direction is not finite.\n");
    return false;
  }
  if (camera_.valid() && !cameraUsable(camera_)) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The camera given with setCamera (%g, %g, "
              "%g, %g, %d x %d pixels) is not usable: finite intrinsics and at most 8192 x 8192 "
              "pixels.\n",
              camera_.fx, camera_.fy, camera_.cx, camera_.cy, camera_.width, camera_.height);
    return false;
  }
  if (!this->initCompute()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] Invalid input or indices.\n");
    return false;
  }
  std::size_t finite = 0;
  for (auto it = indices_->begin(); it != indices_->end() && finite < 3; ++it)
    finite += pcl::isFinite((*input_)[*it]);
  if (finite < 3) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The cloud has fewer than 3 finite points.\n");
    this->deinitCompute();
    return false;
  }
  if (!spansPlane(*input_, *indices_)) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The finite points lie on one line (or at "
              "one point): they hold no plane.\n");
    this->deinitCompute();
    return false;
  }
  const Eigen::Affine3f pose =
    check_pose ? plausibleSensorPose(*input_) : Eigen::Affine3f(Eigen::Affine3f::Identity());
  const std::size_t far = check_pose ? countFarPoints(*input_) : 0;
  if (far > 0)
    PCL_WARN("[facyl::TabletopSegmentation::segment] %zu points have a coordinate beyond +-%g "
             "and are ignored (treated as missing).\n",
             far, static_cast<double>(kMaxCoordinate));
  // PCL's list of every index is not read when no indices were given.
  const pcl::Indices* given = fake_indices_ ? nullptr : indices_.get();
  const SupportPrior* prior = prior_.valid() ? &prior_ : nullptr;
  if (isIdentityPose(pose) && far == 0)
    adopt(
      segmentTabletop(pointFrame(*input_, given, xyz_), camera_, up_, params_, workspace_, prior),
      clusters);
  else {
    // The search works in the sensor's frame (depth along the line of sight, pixels seen
    // from the origin): on a copy of the cloud moved there, the results then moved back to
    // the cloud's frame.
    const auto local = sensorFrameCopy(*input_, pose);
    const SupportPrior local_prior = prior_.transformed(pose.inverse());
    adopt(segmentTabletop(pointFrame(*local, given, xyz_), camera_, pose.linear().transpose() * up_,
                          params_, workspace_, prior ? &local_prior : nullptr),
          clusters);
    transformResults(pose, clusters);
  }
  this->deinitCompute();
  timing_.total =
    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::adopt(TabletopSegments segments,
                                    std::vector<TabletopCluster>& clusters)
{
  supports_ = std::move(segments.supports);
  table_ = segments.table;
  table_found_ = segments.table_found;
  focal_ = segments.focal;
  timing_ = segments.timing;
  prior_result_ = segments.prior;
  clusters = std::move(segments.clusters);
  if (supports_.empty())
    return;
  const SupportPlane& table = supports_[table_];
  table_coefficients_.header = input_->header;
  table_coefficients_.values = {table.plane[0], table.plane[1], table.plane[2], table.plane[3]};
  hull_.clear();
  for (const auto& v : table.polygon) {
    PointT q;
    q.getVector3fMap() = table.frame * Eigen::Vector3f(v.x(), v.y(), 0.f);
    hull_.push_back(q);
  }
}

template <typename PointT>
void
TabletopSegmentation<PointT>::transformResults(const Eigen::Affine3f& pose,
                                               std::vector<TabletopCluster>& clusters)
{
  for (auto& c : clusters)
    c.centroid = pose * c.centroid;
  for (auto& s : supports_) {
    s.plane = transformPlane(s.plane, pose);
    s.frame = pose * s.frame;
  }
  auto& t = table_coefficients_.values;
  if (t.size() == 4) {
    const Eigen::Vector4f moved = transformPlane(Eigen::Vector4f(t[0], t[1], t[2], t[3]), pose);
    t = {moved[0], moved[1], moved[2], moved[3]};
  }
  pcl::transformPointCloud(hull_, hull_, pose);
}

} // namespace facyl
