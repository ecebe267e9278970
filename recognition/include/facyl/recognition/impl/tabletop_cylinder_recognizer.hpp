/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/recognition/tabletop_cylinder_recognizer.h>

#include <pcl/common/point_tests.h>
#include <pcl/type_traits.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace facyl {

template <typename PointT>
struct TabletopCylinderRecognizer<PointT>::FitInput {
  pcl::Indices subset;                          ///< the cluster's points that are fitted
  pcl::PointCloud<pcl::PointXYZ>::Ptr points;   ///< the subset's coordinates
  pcl::PointCloud<NormalCurvature>::Ptr cues;   ///< their normals and curvatures
  Eigen::Matrix3Xf columns;                     ///< points with a normal, as columns
  Eigen::Matrix3Xf normals;                     ///< their normals
  pcl::Indices column_of;                       ///< subset position -> column, -1 without
};

template <typename PointT>
struct TabletopCylinderRecognizer<PointT>::Fit {
  CylinderModel model; ///< inliers index FitInput::points
  CylinderEvidence evidence;
  bool accepted{false};
};

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::configure()
{
  cues_estimation_.setKSearch(params_.neighbours);
  // The configured prior, then (when its fit is not accepted) "upright" and "lying" in the
  // table frame: tabletop objects stand or lie, and a strong prior keeps a domed lid or a flat
  // face from pulling the axis. Optionally a last try allows any normal sign: the inside of
  // an open container can make a cluster of its own (so can the inside of a bowl).
  const bool any_sign = params_.retry_upright_lying && params_.hough.outward_normals &&
                        params_.retry_any_normal_sign;
  estimators_.assign(params_.retry_upright_lying ? (any_sign ? 4 : 3) : 1, {});
  const OrientationPrior priors[4] = {params_.prior, OrientationPrior::VerticalStrong,
                                      OrientationPrior::Horizontal, params_.prior};
  for (std::size_t e = 0; e < estimators_.size(); ++e) {
    HoughCylinderParameters hp = params_.hough;
    if (e == 3)
      hp.outward_normals = false;
    estimators_[e].setParameters(hp);
    estimators_[e].setOrientationMixture(GaussianMixture::fromPrior(priors[e]));
    estimators_[e].setNumberOfOrientations(params_.orientations);
    estimators_[e].setSeed(params_.seed);
  }
  configured_ = true;
}

template <typename PointT>
bool
TabletopCylinderRecognizer<PointT>::recognize(std::vector<RecognizedObject>& objects)
{
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  objects.clear();
  timing_ = RecognitionTiming{};
  const auto t0 = Clock::now();
  const std::string why = validate(params_);
  if (!why.empty()) {
    PCL_ERROR("[facyl::TabletopCylinderRecognizer::recognize] Invalid parameters: %s.\n",
              why.c_str());
    return false;
  }
  if (!input_ || input_->empty()) {
    PCL_ERROR("[facyl::TabletopCylinderRecognizer::recognize] No input cloud, or an empty one.\n");
    return false;
  }
  if (!configured_)
    configure();

  std::vector<TabletopCluster> clusters;
  segmentation_.setParameters(params_.segmentation);
  segmentation_.setInputCloud(input_);
  segmentation_.setIndices(indices_); // nullptr: the whole cloud
  segmentation_.setCamera(camera_);
  const bool segmented = segmentation_.segment(clusters);
  timing_.segmentation = ms(t0, Clock::now());
  if (!segmented) {
    timing_.total = ms(t0, Clock::now());
    return false;
  }
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  cues_estimation_.setViewPoint(viewpoint.x(), viewpoint.y(), viewpoint.z());
  for (auto& hough : estimators_)
    hough.setReferenceFrame(segmentation_.getTableFrame().linear());
  for (auto& cluster : clusters)
    objects.push_back(recognizeCluster(std::move(cluster)));
  timing_.total = ms(t0, Clock::now());
  return true;
}

template <typename PointT>
RecognizedObject
TabletopCylinderRecognizer<PointT>::recognizeCluster(TabletopCluster cluster)
{
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  RecognizedObject object;
  object.cluster = std::move(cluster);
  auto t = Clock::now();
  if (classifier_) {
    object.evidence.p_cylinder = classifier_->cylinderProbability(makeView(object.cluster));
    const auto t1 = Clock::now();
    timing_.classification += ms(t, t1);
    t = t1;
    if (object.evidence.p_cylinder < params_.decision.min_probability)
      return object; // rejected before fitting
  }
  const FitInput input = prepareFit(object.cluster);
  Fit best = fitWithRetries(input);
  if (best.evidence.fitted) {
    best.evidence.p_cylinder = object.evidence.p_cylinder;
    object.evidence = best.evidence;
    object.cylinder = std::move(best.model);
    for (auto& i : object.cylinder.inliers)
      i = input.subset[static_cast<std::size_t>(i)];
    object.is_cylinder = acceptCylinder(object.evidence, params_.decision);
  }
  timing_.fitting += ms(t, Clock::now());
  return object;
}

template <typename PointT>
typename TabletopCylinderRecognizer<PointT>::FitInput
TabletopCylinderRecognizer<PointT>::prepareFit(const TabletopCluster& cluster)
{
  FitInput in;
  in.subset = evenSubsample(cluster.indices.indices, params_.max_fit_points);
  in.points.reset(new pcl::PointCloud<pcl::PointXYZ>);
  in.points->reserve(in.subset.size());
  for (const auto i : in.subset) {
    const auto& p = (*input_)[i];
    in.points->push_back(pcl::PointXYZ(p.x, p.y, p.z));
  }
  in.cues.reset(new pcl::PointCloud<NormalCurvature>);
  cues_estimation_.setInputCloud(in.points);
  cues_estimation_.compute(*in.cues);
  // Points with a normal, as columns (the estimator's inliers skip the rest).
  const auto n = static_cast<Eigen::Index>(in.points->size());
  in.columns.resize(3, n);
  in.normals.resize(3, n);
  in.column_of.assign(in.points->size(), -1);
  Eigen::Index m = 0;
  for (std::size_t k = 0; k < in.points->size(); ++k) {
    const auto& c = (*in.cues)[k];
    if (!pcl::isFinite((*in.points)[k]) || !std::isfinite(c.normal_x))
      continue;
    in.columns.col(m) = (*in.points)[k].getVector3fMap();
    in.normals.col(m) = Eigen::Vector3f(c.normal_x, c.normal_y, c.normal_z);
    in.column_of[k] = static_cast<pcl::index_t>(m++);
  }
  in.columns.conservativeResize(3, m);
  in.normals.conservativeResize(3, m);
  return in;
}

template <typename PointT>
typename TabletopCylinderRecognizer<PointT>::Fit
TabletopCylinderRecognizer<PointT>::fitOnce(const FitInput& input, std::size_t estimator)
{
  Fit f;
  auto& hough = estimators_[estimator];
  hough.setInputCloud(input.points);
  hough.setInputNormals(input.cues);
  std::vector<CylinderModel> models;
  if (!hough.segment(models) || models.empty())
    return f;
  f.model = std::move(models.front());
  CylinderEvidence& e = f.evidence;
  e.fitted = true;
  e.inlier_ratio = f.model.inlier_ratio;
  e.angular_coverage = f.model.angular_coverage;
  e.curvature_ratio = curvatureRatio(*input.cues, f.model.inliers);
  // The surface ratio: lateral inliers, plus the points on the caps and on the inner wall.
  CylinderModel in_columns = f.model;
  for (auto& i : in_columns.inliers)
    i = input.column_of[static_cast<std::size_t>(i)];
  const std::size_t caps =
    countCapPoints(in_columns, input.columns, input.normals, 2.f * f.model.distance_threshold,
                   params_.hough.normal_angle_threshold);
  const std::size_t inner = params_.hough.outward_normals
                              ? countInnerWallPoints(in_columns, input.columns, input.normals,
                                                     params_.hough.normal_angle_threshold, 0.8f)
                              : 0;
  e.surface_ratio = std::min(1.f, e.inlier_ratio + static_cast<float>(caps + inner) /
                                                     static_cast<float>(input.points->size()));
  f.accepted = acceptCylinder(e, params_.decision);
  return f;
}

template <typename PointT>
typename TabletopCylinderRecognizer<PointT>::Fit
TabletopCylinderRecognizer<PointT>::fitWithRetries(const FitInput& input)
{
  Fit best = fitOnce(input, 0);
  for (std::size_t e = 1; e < estimators_.size() && !best.accepted; ++e) {
    Fit f = fitOnce(input, e);
    if (f.evidence.fitted &&
        (f.accepted || f.evidence.score(params_.decision) > best.evidence.score(params_.decision) ||
         !best.evidence.fitted))
      best = std::move(f);
  }
  return best;
}

template <typename PointT>
ObjectView
TabletopCylinderRecognizer<PointT>::makeView(const TabletopCluster& cluster) const
{
  ObjectView view;
  view.box = cluster.box;
  const auto& idx = cluster.indices.indices;
  view.points.resize(3, static_cast<Eigen::Index>(idx.size()));
  for (std::size_t k = 0; k < idx.size(); ++k)
    view.points.col(static_cast<Eigen::Index>(k)) = (*input_)[idx[k]].getVector3fMap();
  if constexpr (pcl::traits::has_color_v<PointT>) {
    const PixelBox& b = cluster.box;
    if (b[0] < 0)
      return view;
    RgbImage& crop = view.crop;
    crop.width = b[2] - b[0] + 1;
    crop.height = b[3] - b[1] + 1;
    crop.data.assign(static_cast<std::size_t>(crop.width) * crop.height * 3, 0);
    if (input_->isOrganized()) {
      for (int v = b[1]; v <= b[3]; ++v)
        for (int u = b[0]; u <= b[2]; ++u) {
          const auto& p = input_->at(u, v);
          std::uint8_t* px =
            &crop.data[3 * (static_cast<std::size_t>(v - b[1]) * crop.width + (u - b[0]))];
          px[0] = p.r;
          px[1] = p.g;
          px[2] = p.b;
        }
    } else {
      for (const auto i : idx) {
        const auto& p = (*input_)[i];
        if (!(p.z > 0.f))
          continue;
        const Eigen::Vector2f px = camera_.project(p.getVector3fMap());
        const int u = static_cast<int>(std::lround(px.x())) - b[0];
        const int v = static_cast<int>(std::lround(px.y())) - b[1];
        if (u < 0 || v < 0 || u >= crop.width || v >= crop.height)
          continue;
        std::uint8_t* q = &crop.data[3 * (static_cast<std::size_t>(v) * crop.width + u)];
        q[0] = p.r;
        q[1] = p.g;
        q[2] = p.b;
      }
    }
  }
  return view;
}

} // namespace facyl
