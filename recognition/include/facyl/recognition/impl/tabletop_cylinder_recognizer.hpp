/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/common/point_tests.h>
#include <pcl/type_traits.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace facyl {

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

  std::vector<TabletopCluster> clusters;
  segmentation_.setParameters(params_.segmentation);
  segmentation_.setInputCloud(input_);
  segmentation_.setIndices(indices_); // nullptr: the whole cloud
  segmentation_.setCamera(camera_);
  const bool segmented = segmentation_.segment(clusters);
  const auto t1 = Clock::now();
  timing_.segmentation = ms(t0, t1);
  if (!segmented) {
    timing_.total = ms(t0, Clock::now());
    return false;
  }

  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  NormalCurvatureEstimation<pcl::PointXYZ, NormalCurvature> cues_estimation;
  cues_estimation.setKSearch(params_.neighbours);
  cues_estimation.setViewPoint(viewpoint.x(), viewpoint.y(), viewpoint.z());
  // The configured prior, then (when its fit is not accepted) "upright" and "lying" in the
  // table frame: tabletop objects stand or lie, and a strong prior keeps a domed lid or a flat
  // face from pulling the axis.
  // Optionally a last try allows any normal sign: the inside of an open container can make a
  // cluster of its own (so can the inside of a bowl).
  const bool any_sign = params_.retry_upright_lying && params_.hough.outward_normals &&
                        params_.retry_any_normal_sign;
  std::vector<HoughCylinderEstimation<pcl::PointXYZ, NormalCurvature>> estimators(
    params_.retry_upright_lying ? (any_sign ? 4 : 3) : 1);
  const OrientationPrior priors[4] = {params_.prior, OrientationPrior::VerticalStrong,
                                      OrientationPrior::Horizontal, params_.prior};
  for (std::size_t e = 0; e < estimators.size(); ++e) {
    auto& hough = estimators[e];
    HoughCylinderParameters hp = params_.hough;
    if (e == 3)
      hp.outward_normals = false;
    hough.setParameters(hp);
    hough.setOrientationMixture(GaussianMixture::fromPrior(priors[e]));
    hough.setReferenceFrame(segmentation_.getTableFrame().linear());
    hough.setNumberOfOrientations(params_.orientations);
    hough.setSeed(params_.seed);
  }

  for (auto& cluster : clusters) {
    RecognizedObject object;
    object.cluster = std::move(cluster);
    auto tc = Clock::now();
    if (classifier_) {
      object.p_cylinder = classifier_->cylinderProbability(makeView(object.cluster));
      const auto tc1 = Clock::now();
      timing_.classification += ms(tc, tc1);
      tc = tc1;
      if (std::isfinite(object.p_cylinder) && object.p_cylinder < params_.min_probability) {
        objects.push_back(std::move(object));
        continue;
      }
    }
    const pcl::Indices subset = evenSubsample(object.cluster.indices.indices, params_.max_fit_points);
    pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
    points->reserve(subset.size());
    for (const auto i : subset) {
      const auto& p = (*input_)[i];
      points->push_back(pcl::PointXYZ(p.x, p.y, p.z));
    }
    pcl::PointCloud<NormalCurvature>::Ptr cues(new pcl::PointCloud<NormalCurvature>);
    cues_estimation.setInputCloud(points);
    cues_estimation.compute(*cues);
    // Points with a normal, as columns (the estimator's inliers skip the rest).
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(points->size()));
    Eigen::Matrix3Xf nrm(3, static_cast<Eigen::Index>(points->size()));
    pcl::Indices column_of(points->size(), -1);
    Eigen::Index n = 0;
    for (std::size_t k = 0; k < points->size(); ++k) {
      const auto& c = (*cues)[k];
      if (!pcl::isFinite((*points)[k]) || !std::isfinite(c.normal_x))
        continue;
      pts.col(n) = (*points)[k].getVector3fMap();
      nrm.col(n) = Eigen::Vector3f(c.normal_x, c.normal_y, c.normal_z);
      column_of[k] = static_cast<pcl::index_t>(n++);
    }
    struct Fit {
      bool fitted{false};
      CylinderModel model; // inliers index `points`
      float inlier_ratio{0.f}, surface_ratio{0.f};
      float curvature_ratio{std::numeric_limits<float>::quiet_NaN()};
      float score{-1.f};
      bool accepted{false};
    };
    const auto fit_with = [&](HoughCylinderEstimation<pcl::PointXYZ, NormalCurvature>& hough) {
      Fit f;
      hough.setInputCloud(points);
      hough.setInputNormals(cues);
      std::vector<CylinderModel> models;
      if (!hough.segment(models) || models.empty())
        return f;
      f.fitted = true;
      f.model = std::move(models.front());
      f.inlier_ratio = f.model.inlier_ratio;
      CylinderModel in_columns = f.model;
      for (auto& i : in_columns.inliers)
        i = column_of[static_cast<std::size_t>(i)];
      const std::size_t caps =
        countCapPoints(in_columns, pts.leftCols(n), nrm.leftCols(n),
                       2.f * f.model.distance_threshold, params_.hough.normal_angle_threshold);
      const std::size_t inner =
        params_.hough.outward_normals
          ? countInnerWallPoints(in_columns, pts.leftCols(n), nrm.leftCols(n),
                                 params_.hough.normal_angle_threshold, 0.8f)
          : 0;
      f.surface_ratio =
        std::min(1.f, f.inlier_ratio + static_cast<float>(caps + inner) /
                                         static_cast<float>(points->size()));
      std::vector<float> k_max, k_min;
      for (const auto i : f.model.inliers) {
        const auto& c = (*cues)[static_cast<std::size_t>(i)];
        if (std::isfinite(c.pc1) && std::isfinite(c.pc2))
          k_max.push_back(std::abs(c.pc1)), k_min.push_back(std::abs(c.pc2));
      }
      if (!k_max.empty()) {
        const auto mid = k_max.size() / 2;
        std::nth_element(k_max.begin(), k_max.begin() + mid, k_max.end());
        std::nth_element(k_min.begin(), k_min.begin() + mid, k_min.end());
        f.curvature_ratio = k_max[mid] > 0.f ? k_min[mid] / k_max[mid] : 1.f;
      }
      f.score = params_.score == TabletopRecognizerParameters::Score::SurfaceRatio
                  ? f.surface_ratio
                  : f.inlier_ratio;
      f.accepted = f.score >= params_.min_inlier_ratio &&
                   !(f.curvature_ratio > params_.max_curvature_ratio) &&
                   f.model.angular_coverage >= params_.min_angular_coverage;
      return f;
    };
    Fit best = fit_with(estimators[0]);
    for (std::size_t e = 1; e < estimators.size() && !best.accepted; ++e) {
      Fit f = fit_with(estimators[e]);
      if (f.fitted && (f.accepted || f.score > best.score))
        best = std::move(f);
    }
    if (best.fitted) {
      object.fitted = true;
      object.cylinder = std::move(best.model);
      for (auto& i : object.cylinder.inliers)
        i = subset[static_cast<std::size_t>(i)];
      object.inlier_ratio = best.inlier_ratio;
      object.surface_ratio = best.surface_ratio;
      object.curvature_ratio = best.curvature_ratio;
      object.is_cylinder = best.accepted;
    }
    timing_.fitting += ms(tc, Clock::now());
    objects.push_back(std::move(object));
  }
  timing_.total = ms(t0, Clock::now());
  return true;
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
