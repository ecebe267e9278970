/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/parallel.h>
#include <facyl/recognition/cylinder_lid.h>
#include <facyl/recognition/cylinder_parts.h>
#include <facyl/recognition/cylinder_stack.h>
#include <facyl/recognition/impl/classifier_input.hpp>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>

#include <pcl/common/transforms.h>

#include <pcl/common/point_tests.h>
#include <pcl/type_traits.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <unordered_set>

namespace facyl {

template <typename PointT> struct TabletopCylinderRecognizer<PointT>::FitInput {
  pcl::Indices subset;                        ///< the cluster's points that are fitted
  pcl::PointCloud<pcl::PointXYZ>::Ptr points; ///< the subset's coordinates
  pcl::PointCloud<NormalCurvature>::Ptr cues; ///< their normals and curvatures
  Eigen::Matrix3Xf columns;                   ///< points with a normal, as columns
  Eigen::Matrix3Xf normals;                   ///< their normals
  Eigen::VectorXf scatter;                    ///< their neighbours' normal scatter (k_max + k_min)
  pcl::Indices column_of;                     ///< subset position -> column, -1 without
  /// Organized: pixels per side of the lattice's cells (each subset pixel stands for its cell).
  int cell{1};
};

template <typename PointT> struct TabletopCylinderRecognizer<PointT>::Fit {
  CylinderModel model; ///< inliers index FitInput::points
  CylinderEvidence evidence;
  bool accepted{false};
  float explained_share{0.f}; ///< of the points fitted: lateral inliers, caps, inner wall
};

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::configure()
{
  const int threads = threadCount(params_.threads);
  fitters_.clear();
  for (int t = 0; t < threads; ++t)
    fitters_.push_back(makeFitter());
  configured_ = true;
}

template <typename PointT>
std::unique_ptr<typename TabletopCylinderRecognizer<PointT>::Fitter>
TabletopCylinderRecognizer<PointT>::makeFitter() const
{
  auto f = std::make_unique<Fitter>();
  f->cues.setKSearch(params_.neighbours);
  // The cues come from a lattice of pixels (prepareFit), their neighbours from its grid: a
  // window that holds the k nearest points wherever a cylinder's side is inclined by up to
  // kFitCueInclination to the line of sight (all but the outer 1 - sin 78 deg = 2% of its
  // width in the image), so that they are the nearest in space, as a k-d tree's would be.
  f->cues.setImageWindowRadius(imageWindowRadius(params_.neighbours, kFitCueInclination));
  // One thread for a cluster's cues while clusters are fitted in parallel; fitClusters gives
  // them the threads no cluster takes.
  f->cues.setNumberOfThreads(1);
  // The configured prior, then (when its fit is not accepted) "lying" in the table frame:
  // tabletop objects stand or lie, and a strong prior keeps a domed lid or a flat face from
  // pulling the axis. Optionally a try that allows any normal sign: the inside of an open
  // container can make a cluster of its own (so can the inside of a bowl). Standing is asked
  // last, with the axis held (below): a strongly vertical prior whose axis was refined
  // afterwards answered it worse (docs/tabletop.md, "no strongly vertical retry").
  const bool any_sign =
    params_.retry_upright_lying && params_.hough.outward_normals && params_.retry_any_normal_sign;
  auto& estimators = f->estimators;
  estimators.assign(params_.retry_upright_lying ? (any_sign ? 3 : 2) : 1, {});
  const OrientationPrior priors[3] = {params_.hough.prior, OrientationPrior::Horizontal,
                                      params_.hough.prior};
  for (std::size_t e = 0; e < estimators.size(); ++e) {
    HoughCylinderParameters hp = params_.hough;
    if (e == 2)
      hp.outward_normals = false;
    hp.prior = priors[e];
    estimators[e].setParameters(hp);
    estimators[e].setDiagnoseFailures(false); // a cluster without a cylinder is an answer
  }
  // Last, on objects with a support: the axis fixed along the support's normal, only position
  // and radius fitted. A short, wide tin seen from above shows mostly its lid and a thin band
  // of side, whose free fit may tilt; standing is what tabletop objects mostly do.
  if (params_.retry_upright_lying) {
    HoughCylinderParameters hp = params_.hough;
    hp.refine = false; // the axis stays the support's normal
    estimators.emplace_back();
    estimators.back().setParameters(hp);
    estimators.back().setDiagnoseFailures(false);
    f->upright = estimators.size() - 1;
  }
  else
    f->upright = estimators.size();
  return f;
}

template <typename PointT>
bool
TabletopCylinderRecognizer<PointT>::recognize(std::vector<RecognizedObject>& objects)
{
  objects.clear();
  timing_ = RecognitionTiming{};
  const auto t0 = std::chrono::steady_clock::now();
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
  const Eigen::Affine3f pose = plausibleSensorPose(*input_);
  const std::size_t far = countFarPoints(*input_);
  if (far > 0)
    PCL_WARN("[facyl::TabletopCylinderRecognizer::recognize] %zu points have a coordinate "
             "beyond +-%g and are ignored (treated as missing).\n",
             far, static_cast<double>(kMaxCoordinate));
  if (isIdentityPose(pose) && far == 0)
    return recognizeInSensorFrame(objects, t0);
  // Everything here works in the sensor's frame (pixels and depth seen from the origin, the
  // camera of setCamera): the cloud is moved there (points beyond kMaxCoordinate dropped), the
  // results back to the cloud's frame, so that the answer does not depend on the frame the
  // cloud is stored in.
  const PointCloudConstPtr given = input_;
  bool found = false;
  {
    // The input and up direction are the caller's again however the recognition ends (an
    // exception included).
    struct Restore {
      TabletopCylinderRecognizer& rec;
      const PointCloudConstPtr input;
      const Eigen::Vector3f up;
      const SupportPrior prior;
      ~Restore()
      {
        rec.input_ = input;
        rec.up_ = up;
        rec.prior_ = prior;
      }
    } restore{*this, given, up_, prior_};
    input_ = sensorFrameCopy(*given, pose);
    up_ = pose.linear().transpose() * up_;
    if (prior_.valid())
      prior_ = prior_.transformed(pose.inverse());
    found = recognizeInSensorFrame(objects, t0);
  }
  segmentation_.setInputCloud(given);
  std::vector<TabletopCluster> none;
  segmentation_.transformResults(pose, none);
  for (auto& o : objects) {
    o.cluster.centroid = pose * o.cluster.centroid;
    auto& m = o.cylinder;
    m.point_on_axis = pose * m.point_on_axis;
    m.base = pose * m.base;
    m.top = pose * m.top;
    m.axis = pose.linear() * m.axis;
  }
  return found;
}

template <typename PointT>
bool
TabletopCylinderRecognizer<PointT>::recognizeInSensorFrame(std::vector<RecognizedObject>& objects,
                                                           std::chrono::steady_clock::time_point t0)
{
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  std::vector<TabletopCluster> clusters;
  segmentation_.setParameters(params_.segmentation);
  segmentation_.setInputCloud(input_);
  if (segmentation_indices_ != indices_) {
    segmentation_.setIndices(indices_); // nullptr: the whole cloud
    segmentation_indices_ = indices_;
  }
  segmentation_.setCamera(camera_);
  segmentation_.setUpDirection(up_);
  segmentation_.setSupportPrior(prior_);
  segmentation_.setNumberOfThreads(static_cast<unsigned int>(fitters_.size()));
  // The cloud is in the sensor's frame, its far points gone (recognize() saw to it).
  const bool segmented = segmentation_.segmentInSensorFrame(clusters);
  timing_.segmentation = ms(t0, Clock::now());
  timing_.segmentation_steps = segmentation_.getTiming();
  if (!segmented) {
    timing_.total = ms(t0, Clock::now());
    return false;
  }
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  for (auto& f : fitters_)
    f->cues.setViewPoint(viewpoint.x(), viewpoint.y(), viewpoint.z());
  const std::vector<float> p_network = classifyClusters(clusters);
  std::vector<std::vector<RecognizedObject>> fitted = fitClusters(clusters, p_network);
  for (std::size_t k = 0; k < fitted.size(); ++k) {
    const std::size_t first = objects.size();
    for (auto& o : fitted[k])
      objects.push_back(std::move(o));
    if (classifier_)
      applyClassifier(objects, first, p_network[k]);
  }
  joinCylinderParts(objects);
  if (!classifier_) // the evidence model without a network
    for (auto& o : objects)
      if (o.evidence.fitted)
        o.evidence.p_cylinder = geometricProbability(o.evidence, params_.decision);
  for (auto& o : objects) // base nearest the support, axis away from it
    if (o.evidence.fitted) {
      const int s = o.cluster.support;
      const Eigen::Vector3f up =
        s >= 0 ? Eigen::Vector3f(
                   segmentation_.getSupports()[static_cast<std::size_t>(s)].frame.linear().col(2))
               : Eigen::Vector3f(0.f, -1.f, 0.f);
      orientCylinder(o.cylinder, up, viewpoint);
    }
  timing_.total = ms(t0, Clock::now());
  return true;
}

template <typename PointT>
std::vector<std::vector<RecognizedObject>>
TabletopCylinderRecognizer<PointT>::fitClusters(std::vector<TabletopCluster>& clusters,
                                                const std::vector<float>& p_network)
{
  std::vector<std::vector<RecognizedObject>> fitted(clusters.size());
  std::vector<std::size_t> order; // the clusters to fit
  for (std::size_t k = 0; k < clusters.size(); ++k) {
    if (classifier_ && p_network[k] < params_.reject_below) { // rejected before fitting
      RecognizedObject object;                                // (paper III-B)
      object.cluster = std::move(clusters[k]);
      fitted[k].push_back(std::move(object));
    }
    else
      order.push_back(k);
  }
  if (order.empty())
    return fitted;
  // One cluster at a time per thread, largest first (a long fit started last would keep the
  // others waiting); each thread uses its own fitter.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return clusters[a].indices.indices.size() > clusters[b].indices.indices.size();
  });
  // Threads the clusters leave idle run a cluster's retries at once.
  const int spare = std::max<int>(1, static_cast<int>(fitters_.size() / order.size()));
  for (auto& f : fitters_) {
    f->retry_threads = spare;
    f->cues.setNumberOfThreads(static_cast<unsigned int>(spare));
  }
  const auto t = std::chrono::steady_clock::now();
  parallelForWorkers(order.size(), static_cast<int>(fitters_.size()), 1,
                     [&](std::size_t begin, std::size_t end, int worker) {
                       Fitter& fitter = *fitters_[static_cast<std::size_t>(worker)];
                       for (std::size_t i = begin; i < end; ++i) {
                         const std::size_t k = order[i];
                         usePriorFrameOf(fitter, clusters[k].support);
                         recognizeCluster(fitter, std::move(clusters[k]), p_network[k], fitted[k]);
                       }
                     });
  timing_.fitting =
    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  return fitted;
}

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::usePriorFrameOf(Fitter& fitter, int support) const
{
  // The frame of the support the object stands on; without one, that of an upright camera
  // (z up: against the image's rows).
  Eigen::Matrix3f frame;
  if (support >= 0)
    frame = segmentation_.getSupports()[static_cast<std::size_t>(support)].frame.linear();
  else
    frame << 1.f, 0.f, 0.f, 0.f, 0.f, -1.f, 0.f, 1.f, 0.f; // columns x, y, z = -image y
  for (auto& hough : fitter.estimators)
    hough.setReferenceFrame(frame);
  fitter.with_support = support >= 0;
  fitter.up = frame.col(2);
  fitter.support_plane = support >= 0
                           ? segmentation_.getSupports()[static_cast<std::size_t>(support)].plane
                           : Eigen::Vector4f::Zero();
  if (fitter.upright < fitter.estimators.size())
    fitter.estimators[fitter.upright].setAccumulators(
      {OrientationAccumulator(Eigen::Matrix3Xf(frame.col(2)))});
}

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::joinCylinderParts(std::vector<RecognizedObject>& objects)
{
  // Parts of one object that the segmentation cut apart where its surface jumps or turns
  // inwards (cylinder_parts.h): an open container's inside seen through its opening (cut off
  // its outside at the near rim: the two, joined and judged again as one, are a bowl, no longer
  // like a can), a small fragment beside it (a mug's handle), an end set into its rim (a tin's
  // lid). Organized clouds only: the normals come from the pixel grid.
  constexpr float kAttachmentSize = 0.1f; // of the cylinder's object's points, at most
  if (!input_->isOrganized())
    return;
  std::vector<Eigen::Matrix3Xf> points(objects.size()), normals(objects.size());
  for (std::size_t k = 0; k < objects.size(); ++k)
    sampleWithNormals(objects[k].cluster.indices.indices, points[k], normals[k]);
  std::vector<int> host(objects.size(), -1);
  bool any = false;
  for (std::size_t a = 0; a < objects.size(); ++a) {
    const RecognizedObject& outer = objects[a];
    if (!outer.evidence.fitted || !acceptGeometry(outer.evidence, params_.decision))
      continue;
    const CylinderModel& c = outer.cylinder;
    const std::size_t size = outer.cluster.indices.indices.size();
    for (std::size_t b = 0; b < objects.size(); ++b) {
      if (b == a || host[b] >= 0 || host[a] >= 0 ||
          objects[b].cluster.support != outer.cluster.support)
        continue;
      // An end (smaller than the wall it closes) is a disc, whatever it looks like alone; an
      // object that is a cylinder on its own is no inside or attachment of another (a can
      // beside a tin that a wide cylinder was fitted to).
      const std::size_t part = objects[b].cluster.indices.indices.size();
      const bool small = static_cast<float>(part) <= kAttachmentSize * static_cast<float>(size);
      if ((part < size && isEndCap(c, points[b], normals[b])) ||
          (!objects[b].is_cylinder && (isContainerInside(c, points[b], normals[b]) ||
                                       (small && isAttachment(c, points[b]))))) {
        host[b] = static_cast<int>(a);
        any = true;
      }
    }
  }
  if (!any)
    return;
  // The joined object keeps the cylinder fitted to the outer wall and its evidence (the fit
  // already saw the wall); the classifier judges the whole.
  std::vector<RecognizedObject> kept, joined;
  for (std::size_t a = 0; a < objects.size(); ++a) {
    if (host[a] >= 0)
      continue;
    if (std::find(host.begin(), host.end(), static_cast<int>(a)) == host.end()) {
      kept.push_back(std::move(objects[a]));
      continue;
    }
    RecognizedObject o = std::move(objects[a]);
    TabletopCluster& c = o.cluster;
    std::size_t inside = 0; // points of the open container's inside joined to it
    for (std::size_t b = 0; b < objects.size(); ++b)
      if (host[b] == static_cast<int>(a)) {
        c.indices.indices.insert(c.indices.indices.end(),
                                 objects[b].cluster.indices.indices.begin(),
                                 objects[b].cluster.indices.indices.end());
        if (isContainerInside(o.cylinder, points[b], normals[b]))
          inside += objects[b].cluster.indices.indices.size();
      }
    // The evidence of the whole: its inside is what an open container shows (a bowl's is most
    // of it, a cup's less, a can has none).
    auto& shape = o.evidence.shape;
    const float inner = static_cast<float>(inside) / static_cast<float>(c.indices.indices.size());
    shape.inner_share =
      std::isfinite(shape.inner_share) ? std::max(shape.inner_share, inner) : inner;
    std::sort(c.indices.indices.begin(), c.indices.indices.end());
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(c.indices.indices.size()));
    for (std::size_t k = 0; k < c.indices.indices.size(); ++k)
      pts.col(static_cast<Eigen::Index>(k)) = (*input_)[c.indices.indices[k]].getVector3fMap();
    c.centroid = pts.rowwise().mean();
    c.box = input_->isOrganized() ? pixelBox(c.indices.indices, input_->width)
                                  : projectedBox(pts, camera_);
    joined.push_back(std::move(o));
  }
  PCL_DEBUG("[facyl::TabletopCylinderRecognizer] %zu cylinders joined with their insides, "
            "attachments or ends\n",
            joined.size());
  if (classifier_) {
    std::vector<TabletopCluster> views;
    for (const auto& o : joined)
      views.push_back(o.cluster);
    const std::vector<float> p = classifyClusters(views);
    for (std::size_t k = 0; k < joined.size(); ++k) {
      auto& e = joined[k].evidence;
      e.p_network = p[k];
      e.p_cylinder = classifier_->fuse(e.p_network, e, params_.decision);
    }
  }
  for (auto& o : joined)
    o.is_cylinder = acceptCylinder(o.evidence, params_.decision);
  objects = std::move(kept);
  for (auto& o : joined)
    objects.push_back(std::move(o));
}

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::sampleWithNormals(const pcl::Indices& indices,
                                                      Eigen::Matrix3Xf& points,
                                                      Eigen::Matrix3Xf& normals) const
{
  // About 200 of the points, each with the normal of the pixel grid (the cross product of its
  // neighbours 2 pixels away, towards the sensor; NaN at the image's border and where a
  // neighbour has no depth).
  const auto w = static_cast<int>(input_->width), h = static_cast<int>(input_->height);
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  const std::size_t stride = std::max<std::size_t>(1, indices.size() / 200);
  const auto n = static_cast<Eigen::Index>((indices.size() + stride - 1) / stride);
  points.resize(3, n);
  normals.setConstant(3, n, std::numeric_limits<float>::quiet_NaN());
  constexpr int s = 2;
  for (Eigen::Index j = 0; j < n; ++j) {
    const pcl::index_t i = indices[static_cast<std::size_t>(j) * stride];
    const int u = static_cast<int>(i % w), v = static_cast<int>(i / w);
    const Eigen::Vector3f p = (*input_)[i].getVector3fMap();
    points.col(j) = p;
    if (u < s || v < s || u + s >= w || v + s >= h)
      continue;
    const auto at = [&](int du, int dv) {
      return Eigen::Vector3f(
        (*input_)[static_cast<std::size_t>((v + dv) * w + u + du)].getVector3fMap());
    };
    const Eigen::Vector3f m = (at(s, 0) - at(-s, 0)).cross(at(0, s) - at(0, -s));
    if (m.allFinite() && m.norm() > 0.f)
      normals.col(j) = m.dot(viewpoint - p) >= 0.f ? Eigen::Vector3f(m.normalized())
                                                   : Eigen::Vector3f(-m.normalized());
  }
}

template <typename PointT>
ObjectView
TabletopCylinderRecognizer<PointT>::viewOf(const pcl::Indices& indices) const
{
  const bool with_crop = !classifier_ || classifier_->usesCrop();
  if (input_->isOrganized() || camera_.valid())
    return objectView(*input_, indices, camera_, with_crop);
  return lookAtObjectView(*input_, indices, input_->sensor_origin_.head(3), with_crop);
}

template <typename PointT>
std::vector<float>
TabletopCylinderRecognizer<PointT>::classifyClusters(const std::vector<TabletopCluster>& clusters)
{
  std::vector<float> p(clusters.size(), std::numeric_limits<float>::quiet_NaN());
  if (!classifier_ || clusters.empty())
    return p;
  const auto t = std::chrono::steady_clock::now();
  std::vector<ObjectView> views;
  views.reserve(clusters.size());
  for (const auto& c : clusters)
    views.push_back(viewOf(c.indices.indices));
  p = classifier_->cylinderProbabilities(views);
  timing_.classification +=
    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  return p;
}

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::applyClassifier(std::vector<RecognizedObject>& objects,
                                                    std::size_t first, float p_cluster)
{
  const auto t = std::chrono::steady_clock::now();
  // A cluster split into several objects: each fitted part is classified on its own view.
  const bool split = objects.size() - first > 1;
  std::vector<ObjectView> views;
  std::vector<std::size_t> which;
  for (std::size_t k = first; k < objects.size(); ++k) {
    auto& e = objects[k].evidence;
    e.p_network = p_cluster;
    if (split && e.fitted) {
      views.push_back(viewOf(objects[k].cluster.indices.indices));
      which.push_back(k);
    }
  }
  if (!views.empty()) {
    const std::vector<float> p = classifier_->cylinderProbabilities(views);
    for (std::size_t j = 0; j < which.size(); ++j)
      objects[which[j]].evidence.p_network = p[j];
  }
  for (std::size_t k = first; k < objects.size(); ++k) {
    auto& o = objects[k];
    auto& e = o.evidence;
    e.p_cylinder = e.fitted ? classifier_->fuse(e.p_network, e, params_.decision) : e.p_network;
    o.is_cylinder = acceptCylinder(e, params_.decision); // p now known
  }
  timing_.classification +=
    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::recognizeCluster(Fitter& fitter, TabletopCluster cluster,
                                                     float p_network,
                                                     std::vector<RecognizedObject>& objects) const
{
  recognizeStack(fitter, std::move(cluster), p_network, params_.max_stacked_objects,
                 params_.max_cylinders_per_cluster, objects);
}

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::recognizeStack(Fitter& fitter, TabletopCluster cluster,
                                                   float p_network, std::size_t stacked,
                                                   std::size_t cylinders,
                                                   std::vector<RecognizedObject>& objects) const
{
  RecognizedObject object;
  object.cluster = std::move(cluster);
  const FitInput input = prepareFit(fitter, object.cluster);
  Fit best = fitWithRetries(fitter, input, {});
  // An upright object seen from above: its lid, where the side's fit is not accepted and
  // explains less. A side fit standing counts the lid as its cap only where its extent reaches
  // it, and a thin band of side seen under a large lid ends short of it.
  bool lid = false;
  if (!best.accepted && fitter.with_support) {
    Fit f = fitLidOf(fitter, object.cluster, input);
    if (f.evidence.fitted && passesGates(f.evidence, params_.decision) &&
        (!best.evidence.fitted || f.explained_share > best.explained_share))
      best = std::move(f), lid = true;
  }
  if (best.evidence.fitted) {
    object.evidence = best.evidence;
    object.cylinder = best.model;
    for (auto& i : object.cylinder.inliers)
      i = input.subset[static_cast<std::size_t>(i)];
    object.is_cylinder = acceptCylinder(object.evidence, params_.decision);
    if (object.is_cylinder && !lid) // a lid's rim is a circle in a plane: no side to refine on
      refineOnAllPoints(object.cluster.indices.indices, input.cell, object.cylinder);
  }
  if (lid) { // no side to cut at a step or to search for other cylinders
    objects.push_back(std::move(object));
    return;
  }
  // Objects stacked on each other, one cylinder fitted across them: each on its own.
  if (stacked > 1 && splitStack(fitter, object, input, best, p_network, stacked, objects))
    return;
  // Cylinder-first recovery: a cluster the best fit does not explain, or that the classifier
  // does not see as a cylinder as a whole, may hold several objects (each part is then
  // classified on its own view).
  const bool doubted = classifier_ && p_network < params_.decision.min_probability;
  if (cylinders > 1 && best.evidence.fitted &&
      (!object.is_cylinder || doubted || best.explained_share < params_.min_explained_share)) {
    std::vector<Fit> parts = extractCylinders(fitter, input, std::move(best), cylinders);
    pcl::Indices rest;
    if (!parts.empty() && splitCluster(object, input, parts, objects, rest)) {
      // What no cylinder explains is an object of its own (a can beside the cup found first):
      // fitted as one, with the cylinders the cluster may still yield.
      if (!rest.empty())
        recognizeStack(fitter, partOf(object.cluster, std::move(rest)), p_network, stacked,
                       std::max<std::size_t>(1, cylinders - parts.size()), objects);
      return;
    }
  }
  objects.push_back(std::move(object));
}

template <typename PointT>
float
TabletopCylinderRecognizer<PointT>::stackCut(const FitInput& input, const Fit& fit) const
{
  const SectionStep step = findSectionStep(fit.model, input.columns, input.normals);
  PCL_DEBUG("[facyl::TabletopCylinderRecognizer] sections of r %.3f (%zu side points): sigma "
            "smooth %.4f, step %.4f at %.3f (r %.3f / %.3f, shift %.3f, gap %.4f): %s\n",
            fit.model.radius, step.side_points, step.sigma_smooth, step.sigma_step, step.height,
            step.radius_below, step.radius_above, step.centre_shift, step.gap,
            step.found ? "two" : "one");
  if (step.found)
    return step.height;
  // Else a lid inside the extent: the object below ends there (its lid goes with it).
  const float band = 2.f * fit.model.distance_threshold;
  const InteriorLid lid = interiorLid(fit.model, input.columns, input.normals,
                                      params_.hough.normal_angle_threshold, band);
  PCL_DEBUG("[facyl::TabletopCylinderRecognizer] lid inside the extent: %.3f of %.3f\n", lid.height,
            fit.model.height);
  if (std::isfinite(lid.height))
    return lid.height + static_cast<float>(lid.facing) * band; // the lid below the cut's side
  // Else, where the fit leaves much of the cluster unexplained, where the side stops being a
  // circle and shows a box's faces (a box standing on a tin hides its lid). What lies flat at
  // that height is the box's: its top, when the cylinder stands on it (the cylinder's own lid
  // there is hidden).
  if (fit.explained_share >= params_.min_explained_share)
    return std::numeric_limits<float>::quiet_NaN();
  const SectionEnd end = findSectionEnd(fit.model, input.columns, input.normals);
  PCL_DEBUG("[facyl::TabletopCylinderRecognizer] side's end: circle %s %.3f, sigma %.4f against "
            "%.4f, faces %.2f: %s\n",
            end.circle_below ? "below" : "above", end.height, end.sigma_circle, end.sigma_other,
            end.faces_share, end.found ? "found" : "none");
  if (!end.found)
    return std::numeric_limits<float>::quiet_NaN();
  return end.height + (end.circle_below ? -band : band);
}

template <typename PointT>
bool
TabletopCylinderRecognizer<PointT>::splitStack(Fitter& fitter, const RecognizedObject& whole,
                                               const FitInput& input, const Fit& fit,
                                               float p_network, std::size_t stacked,
                                               std::vector<RecognizedObject>& objects) const
{
  // The side of a cylinder (not a sphere's or a box's), seen around enough of it.
  const CylinderEvidence& e = fit.evidence;
  const CylinderDecision& d = params_.decision;
  if (!e.fitted || e.curvature_ratio > d.max_curvature_ratio ||
      e.angular_coverage < d.min_angular_coverage)
    return false;
  const float cut = stackCut(input, fit);
  if (!std::isfinite(cut))
    return false;
  const Eigen::Vector3f a = fit.model.axis.normalized();
  std::array<pcl::Indices, 2> part;
  for (const auto i : whole.cluster.indices.indices)
    part[a.dot((*input_)[i].getVector3fMap() - fit.model.base) >= cut ? 1 : 0].push_back(i);
  const std::size_t min_size = params_.segmentation.min_cluster_size;
  if (part[0].size() < min_size || part[1].size() < min_size)
    return false;
  std::vector<RecognizedObject> parts;
  for (auto& p : part)
    recognizeStack(fitter, partOf(whole.cluster, std::move(p)), p_network, stacked - 1,
                   params_.max_cylinders_per_cluster, parts);
  // Kept when a part is a cylinder (by the fit: the classifier judges each part's view later);
  // else the whole as fitted.
  if (std::none_of(parts.begin(), parts.end(),
                   [](const RecognizedObject& o) { return o.is_cylinder; }))
    return false;
  for (auto& o : parts)
    objects.push_back(std::move(o));
  return true;
}

template <typename PointT>
TabletopCluster
TabletopCylinderRecognizer<PointT>::partOf(const TabletopCluster& whole, pcl::Indices indices) const
{
  TabletopCluster c;
  c.indices.header = whole.indices.header;
  c.support = whole.support;
  Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(indices.size()));
  for (std::size_t k = 0; k < indices.size(); ++k)
    pts.col(static_cast<Eigen::Index>(k)) = (*input_)[indices[k]].getVector3fMap();
  c.centroid = indices.empty() ? Eigen::Vector3f::Zero() : Eigen::Vector3f(pts.rowwise().mean());
  c.box = input_->isOrganized() ? pixelBox(indices, input_->width) : projectedBox(pts, camera_);
  c.indices.indices = std::move(indices);
  return c;
}

template <typename PointT>
std::vector<typename TabletopCylinderRecognizer<PointT>::Fit>
TabletopCylinderRecognizer<PointT>::extractCylinders(Fitter& fitter, const FitInput& input, Fit fit,
                                                     std::size_t cylinders) const
{
  // Judged on the points around each cylinder; the margins make a sphere's or a cone's band
  // leave the rest of the sphere or cone in its region, and a box edge its faces.
  constexpr float radial_margin = 0.15f, axial_margin = 0.5f;
  const float margin = params_.recovery_margin;
  // Neighbours in the subsample: a few times its spacing.
  const float junction_distance = 0.02f;
  std::vector<Fit> parts;
  std::vector<std::uint8_t> alive(input.points->size(), 0);
  std::size_t left = 0;
  for (std::size_t k = 0; k < alive.size(); ++k)
    left += alive[k] = input.column_of[k] >= 0;
  const std::size_t min_part = std::max<std::size_t>(30, input.points->size() / 30);
  for (std::size_t round = 0; round < cylinders; ++round) {
    if (round > 0)
      fit = fitWithRetries(fitter, input, alive);
    if (!fit.evidence.fitted)
      break;
    std::vector<std::uint8_t> alive_columns(static_cast<std::size_t>(input.columns.cols()), 0);
    for (std::size_t k = 0; k < alive.size(); ++k)
      if (alive[k])
        alive_columns[static_cast<std::size_t>(input.column_of[k])] = 1;
    std::vector<Explained> why;
    const ExplainSettings settings = explainSettings(fit.model);
    CylinderEvidence e =
      localEvidence(fit.model, input.columns, input.normals, alive_columns, settings, radial_margin,
                    axial_margin, margin, &why, input.scatter);
    e.curvature_ratio = fit.evidence.curvature_ratio;
    std::vector<Eigen::Index> part, rest;
    for (std::size_t k = 0; k < alive.size(); ++k)
      if (alive[k])
        (why[static_cast<std::size_t>(input.column_of[k])] != Explained::No ? part : rest)
          .push_back(input.column_of[k]);
    PCL_DEBUG("[facyl::TabletopCylinderRecognizer] recovery round %zu: radius %.3f, %zu of %zu "
              "points, surface %.2f, p %.2f\n",
              round, fit.model.radius, part.size(), part.size() + rest.size(), e.surface_ratio,
              geometricProbability(e, params_.decision));
    if (!acceptCylinder(e, params_.decision) || part.size() < min_part) {
      PCL_DEBUG("[facyl::TabletopCylinderRecognizer] recovery round %zu: not taken (gates %s: "
                "coverage %.2f, arc gap %.2f, curvature %.2f, taper %.2f; %zu points, at least "
                "%zu)\n",
                round, passesGates(e, params_.decision) ? "pass" : "fail", e.angular_coverage,
                e.arc_gap, e.curvature_ratio, e.taper, part.size(), min_part);
      break;
    }
    // Objects that touch meet at a concave crease; a part of one object (a box's edge)
    // continues into the rest convexly or smoothly. What lies on the cylinder by its position
    // is not another object (a rim, whose normals the estimate bends between side and lid).
    const std::vector<Explained> where = explainedPoints(fit.model, input.columns, {}, settings);
    std::vector<Eigen::Index> beside;
    for (const Eigen::Index c : rest)
      if (where[static_cast<std::size_t>(c)] == Explained::No)
        beside.push_back(c);
    const float convex =
      convexJunctionShare(input.columns, input.normals, part, beside, junction_distance, 0.1f);
    PCL_DEBUG("[facyl::TabletopCylinderRecognizer] recovery round %zu: %zu points beside it, "
              "junction %.2f convex\n",
              round, beside.size(), convex);
    if (convex > 0.5f)
      break;
    for (std::size_t k = 0; k < alive.size(); ++k)
      if (alive[k] && why[static_cast<std::size_t>(input.column_of[k])] != Explained::No)
        alive[k] = 0;
    const std::size_t explained = part.size();
    left -= explained;
    fit.evidence = e;
    parts.push_back(std::move(fit));
    if (left < min_part)
      break;
  }
  return parts;
}

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::refineOnAllPoints(const pcl::Indices& cluster, int stride,
                                                      CylinderModel& model) const
{
  // The fit saw a pixel grid; the surface is located better with every pixel of the grid
  // cells of its inliers (whose normals were checked: a cup's inner wall, near the surface by
  // position alone, is left out) within the inlier distance of the surface.
  if (!input_->isOrganized() || stride <= 1 || model.inliers.size() < 20)
    return;
  const Eigen::Vector3f a = model.axis.normalized();
  const float d = model.distance_threshold;
  const int w = static_cast<int>(input_->width), h = static_cast<int>(input_->height);
  std::vector<Eigen::Vector3f> near;
  // The cluster's indices are ascending: membership by binary search.
  const auto member = [&cluster](pcl::index_t j) {
    return std::binary_search(cluster.begin(), cluster.end(), j);
  };
  for (const auto i : model.inliers) {
    const int u0 = static_cast<int>(i % w), v0 = static_cast<int>(i / w);
    for (int v = v0; v < std::min(h, v0 + stride); ++v)
      for (int u = u0; u < std::min(w, u0 + stride); ++u) {
        const auto j = static_cast<pcl::index_t>(v * w + u);
        if (!member(j))
          continue;
        const Eigen::Vector3f p = (*input_)[j].getVector3fMap();
        const float rho = distanceToLine(p, model.base, a);
        if (std::abs(rho - model.radius) <= d)
          near.push_back(p);
      }
  }
  if (near.size() < 20)
    return;
  Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(near.size()));
  for (std::size_t k = 0; k < near.size(); ++k)
    pts.col(static_cast<Eigen::Index>(k)) = near[k];
  Eigen::Vector3f point = model.base, axis = a;
  float radius = model.radius;
  if (!refineCylinder(pts, point, axis, radius) ||
      !(std::abs(radius - model.radius) < 0.1f * model.radius) || axisAngle(axis, a) > 0.05f)
    return; // a refinement that moves far is not trusted
  CylinderModel refined = model;
  refined.point_on_axis = point;
  refined.axis = axis.normalized();
  refined.radius = radius;
  describeInliers(pts, refined);
  refined.inliers = model.inliers;
  refined.inlier_ratio = model.inlier_ratio;
  refined.confidence = model.confidence;
  refined.angular_coverage = model.angular_coverage;
  refined.distance_threshold = model.distance_threshold;
  model = std::move(refined);
}

template <typename PointT>
ExplainSettings
TabletopCylinderRecognizer<PointT>::explainSettings(const CylinderModel& model) const
{
  ExplainSettings s;
  s.distance = std::max(model.distance_threshold, 1e-4f);
  s.max_angle = params_.hough.normal_angle_threshold;
  s.outward = params_.hough.outward_normals;
  s.inner_wall = params_.hough.outward_normals;
  s.axial_margin = 2.f * s.distance;
  return s;
}

template <typename PointT>
bool
TabletopCylinderRecognizer<PointT>::splitCluster(const RecognizedObject& whole,
                                                 const FitInput& input,
                                                 const std::vector<Fit>& parts,
                                                 std::vector<RecognizedObject>& objects,
                                                 pcl::Indices& rest) const
{
  // Every point of the cluster goes to the first cylinder that explains its position; one
  // that the cylinders before it leave too few points is not an object.
  const auto& idx = whole.cluster.indices.indices;
  Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(idx.size()));
  for (std::size_t k = 0; k < idx.size(); ++k)
    pts.col(static_cast<Eigen::Index>(k)) = (*input_)[idx[k]].getVector3fMap();
  std::vector<std::vector<Explained>> explained;
  for (const Fit& part : parts) {
    ExplainSettings s = explainSettings(part.model);
    s.distance *= 2.f; // by position alone: a little wider than the inliers' band
    explained.push_back(explainedPoints(part.model, pts, {}, s));
  }
  const auto& seg = segmentation_.getParameters();
  std::vector<bool> kept;
  std::vector<int> owner = pointOwners(explained, seg.min_cluster_size, kept);
  const auto first = std::find(kept.begin(), kept.end(), true);
  if (first == kept.end())
    return false;
  const auto of = [&](int part) {
    pcl::Indices mine;
    for (std::size_t k = 0; k < idx.size(); ++k)
      if (owner[k] == part)
        mine.push_back(idx[k]);
    return mine;
  };
  // What no cylinder explains is an object of its own when it is large (a box beside a
  // can); a small rest is the unexplained part of the cylinders found (a handle, a rim) and
  // stays with the first of them.
  const std::size_t unexplained =
    static_cast<std::size_t>(std::count(owner.begin(), owner.end(), -1));
  const bool rest_is_object =
    unexplained >= seg.min_cluster_size &&
    static_cast<float>(unexplained) >=
      (1.f - params_.min_explained_share) * static_cast<float>(idx.size());
  if (!rest_is_object)
    std::replace(owner.begin(), owner.end(), -1, static_cast<int>(first - kept.begin()));
  for (std::size_t p = 0; p < parts.size(); ++p) {
    if (!kept[p])
      continue;
    RecognizedObject o;
    o.cluster = partOf(whole.cluster, of(static_cast<int>(p)));
    o.evidence = parts[p].evidence;
    o.cylinder = parts[p].model;
    for (auto& i : o.cylinder.inliers)
      i = input.subset[static_cast<std::size_t>(i)];
    refineOnAllPoints(o.cluster.indices.indices, input.cell, o.cylinder);
    o.is_cylinder = true;
    objects.push_back(std::move(o));
  }
  rest = rest_is_object ? of(-1) : pcl::Indices();
  return true;
}

template <typename PointT>
void
TabletopCylinderRecognizer<PointT>::copySubset(FitInput& in) const
{
  in.points.reset(new pcl::PointCloud<pcl::PointXYZ>);
  in.points->reserve(in.subset.size());
  for (const auto i : in.subset) {
    const auto& p = (*input_)[i];
    in.points->push_back(pcl::PointXYZ(p.x, p.y, p.z));
  }
}

template <typename PointT>
typename TabletopCylinderRecognizer<PointT>::FitInput
TabletopCylinderRecognizer<PointT>::prepareFit(Fitter& fitter, const TabletopCluster& cluster) const
{
  FitInput in;
  in.cues.reset(new pcl::PointCloud<NormalCurvature>);
  // Organized clouds searched as images (their focal length known): a lattice of pixels
  // fit_point_angle apart, so that the neighbourhoods of the cues span the same angle at every
  // depth: depth noise grows with z^2, and the noise of a curvature with noise / size^2, so the
  // cues stay as reliable far away as near. A cluster of more than max_fit_points pixels gets a
  // wider lattice. Narrow organized clouds (a LiDAR's few rings) are point sets.
  if (input_->isOrganized() && segmentation_.getFocalLength() > 0.f) {
    const float spacing =
      std::max(1.f, std::round(params_.fit_point_angle * segmentation_.getFocalLength()));
    const PixelLattice lattice =
      pixelLattice(cluster.indices.indices, input_->width, spacing, params_.max_fit_points);
    in.subset = lattice.pixels;
    in.cell = static_cast<int>(std::lround(lattice.spacing));
    copySubset(in);
    // The lattice is an organized cloud of its own: the cues' neighbours come from its grid.
    fitter.cues.setInputCloud(latticeCloud(lattice, *in.points));
    fitter.cues.setIndices(
      pcl::IndicesPtr(new pcl::Indices(lattice.cell_of.begin(), lattice.cell_of.end())));
  }
  else {
    // Point sets: the same grid of directions from the sensor.
    const auto& idx = cluster.indices.indices;
    if (params_.fit_point_angle > 0.f) {
      Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(idx.size()));
      for (std::size_t k = 0; k < idx.size(); ++k)
        pts.col(static_cast<Eigen::Index>(k)) = (*input_)[idx[k]].getVector3fMap();
      in.subset =
        evenSubsample(angularGrid(idx, pts, params_.fit_point_angle), params_.max_fit_points);
    }
    else
      in.subset = evenSubsample(idx, params_.max_fit_points);
    copySubset(in);
    fitter.cues.setInputCloud(in.points);
    fitter.cues.setIndices(pcl::IndicesPtr());
  }
  fitter.cues.compute(*in.cues);
  // Points with a normal, as columns (the estimator's inliers skip the rest).
  const auto n = static_cast<Eigen::Index>(in.points->size());
  in.columns.resize(3, n);
  in.normals.resize(3, n);
  in.scatter.resize(n);
  in.column_of.assign(in.points->size(), -1);
  Eigen::Index m = 0;
  for (std::size_t k = 0; k < in.points->size(); ++k) {
    const auto& c = (*in.cues)[k];
    if (!pcl::isFinite((*in.points)[k]) || !std::isfinite(c.normal_x))
      continue;
    in.columns.col(m) = (*in.points)[k].getVector3fMap();
    in.normals.col(m) = Eigen::Vector3f(c.normal_x, c.normal_y, c.normal_z);
    in.scatter[m] = c.pc1 + c.pc2;
    in.column_of[k] = static_cast<pcl::index_t>(m++);
  }
  in.columns.conservativeResize(3, m);
  in.normals.conservativeResize(3, m);
  in.scatter.conservativeResize(m);
  return in;
}

template <typename PointT>
typename TabletopCylinderRecognizer<PointT>::Fit
TabletopCylinderRecognizer<PointT>::fitOnce(Fitter& fitter, const FitInput& input,
                                            const std::vector<std::uint8_t>& alive,
                                            std::size_t estimator) const
{
  Fit f;
  auto& hough = fitter.estimators[estimator];
  hough.setInputCloud(input.points);
  hough.setInputNormals(input.cues);
  pcl::IndicesPtr indices; // nullptr: every point
  std::size_t fitted_points = input.points->size();
  if (!alive.empty()) {
    indices.reset(new pcl::Indices);
    for (std::size_t k = 0; k < alive.size(); ++k)
      if (alive[k])
        indices->push_back(static_cast<pcl::index_t>(k));
    fitted_points = indices->size();
  }
  hough.setIndices(indices);
  std::vector<CylinderModel> models;
  if (!hough.segment(models) || models.empty())
    return f;
  f.model = std::move(models.front());
  CylinderEvidence& e = f.evidence;
  e.fitted = true;
  e.inlier_ratio = f.model.inlier_ratio;
  e.angular_coverage = f.model.angular_coverage;
  e.curvature_ratio = curvatureRatio(*input.cues, f.model.inliers);
  std::vector<std::uint8_t> alive_columns;
  if (!alive.empty()) {
    alive_columns.assign(static_cast<std::size_t>(input.columns.cols()), 0);
    for (std::size_t k = 0; k < alive.size(); ++k)
      if (alive[k] && input.column_of[k] >= 0)
        alive_columns[static_cast<std::size_t>(input.column_of[k])] = 1;
  }
  e.taper = taperAlongAxis(f.model, input.columns, input.normals, alive_columns);
  e.shape = shapeEvidence(f.model, input.columns, input.normals, input.scatter, alive_columns,
                          f.model.distance_threshold);
  // The surface ratio: lateral inliers, plus the points on the caps and on the inner wall.
  std::vector<std::uint8_t> counted(static_cast<std::size_t>(input.columns.cols()), 0);
  for (const auto i : f.model.inliers)
    counted[static_cast<std::size_t>(input.column_of[static_cast<std::size_t>(i)])] = 1;
  const float cos_max = std::cos(params_.hough.normal_angle_threshold);
  std::size_t caps = 0, inner = 0;
  for (std::size_t k = 0; k < input.column_of.size(); ++k) {
    const auto c = input.column_of[k];
    if (c < 0 || (!alive.empty() && !alive[k]) || counted[static_cast<std::size_t>(c)])
      continue;
    const Eigen::Vector3f p = input.columns.col(c), n = input.normals.col(c);
    if (onCap(f.model, p, n, 2.f * f.model.distance_threshold, cos_max))
      ++caps;
    else if (params_.hough.outward_normals && onInnerWall(f.model, p, n, cos_max, 0.8f))
      ++inner;
  }
  e.surface_ratio = std::min(1.f, e.inlier_ratio + static_cast<float>(caps + inner) /
                                                     static_cast<float>(fitted_points));
  f.explained_share = e.surface_ratio;
  f.accepted = acceptCylinder(e, params_.decision);
  PCL_DEBUG("[facyl::TabletopCylinderRecognizer] fit %zu of %zu points: radius %.3f, surface %.2f, "
            "p %.2f%s\n",
            estimator, fitted_points, f.model.radius, e.surface_ratio,
            geometricProbability(e, params_.decision), f.accepted ? ", accepted" : "");
  return f;
}

template <typename PointT>
Eigen::Matrix3Xf
TabletopCylinderRecognizer<PointT>::pointsAround(const PixelBox& box) const
{
  // The box grown by half its size each way, every other pixel.
  const int w = static_cast<int>(input_->width), h = static_cast<int>(input_->height);
  const int gu = (box[2] - box[0]) / 2 + 1, gv = (box[3] - box[1]) / 2 + 1;
  std::vector<Eigen::Vector3f> around;
  for (int v = std::max(0, box[1] - gv); v <= std::min(h - 1, box[3] + gv); v += 2)
    for (int u = std::max(0, box[0] - gu); u <= std::min(w - 1, box[2] + gu); u += 2) {
      const auto& p = (*input_)(static_cast<std::size_t>(u), static_cast<std::size_t>(v));
      if (pcl::isFinite(p))
        around.push_back(p.getVector3fMap());
    }
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(around.size()));
  for (std::size_t k = 0; k < around.size(); ++k)
    out.col(static_cast<Eigen::Index>(k)) = around[k];
  return out;
}

template <typename PointT>
typename TabletopCylinderRecognizer<PointT>::Fit
TabletopCylinderRecognizer<PointT>::fitLidOf(const Fitter& fitter, const TabletopCluster& cluster,
                                             const FitInput& input) const
{
  Fit f;
  if (!input_->isOrganized() || cluster.support < 0)
    return f;
  // The sensor's noise at the object's range: its support's band there (the same sensor saw
  // that plane): a lid is as flat, and a ray sees through it when it sees beyond that. A
  // support without a band (none measured): no flatness limit, the rim's band for depth.
  const float noise =
    segmentation_.getSupports()[static_cast<std::size_t>(cluster.support)].band.halfWidth(
      cluster.centroid.norm());
  const bool known = noise > 0.f && std::isfinite(noise);
  LidSettings s;
  if (known)
    s.max_band = noise;
  s.max_normal_angle = params_.hough.normal_angle_threshold;
  s.min_radius = params_.hough.radius_min;
  s.max_radius = params_.hough.radius_max;
  const auto& idx = cluster.indices.indices;
  Eigen::Matrix3Xf dense(3, static_cast<Eigen::Index>(idx.size()));
  for (std::size_t k = 0; k < idx.size(); ++k)
    dense.col(static_cast<Eigen::Index>(k)) = (*input_)[idx[k]].getVector3fMap();
  const LidFit lid =
    fitLid(input.columns, input.normals, fitter.support_plane, fitter.up, s, dense);
  if (!lid.found)
    return f;
  // A solid lid hides what lies behind it: the frame around the object must not see through
  // the disc.
  const Eigen::Matrix3Xf seen = pointsAround(cluster.box);
  const float through =
    seenThroughShare(seen, lid.model, lid.rim_band, known ? noise : lid.rim_band);
  // ... and is an object's top: not walled in all round (a container's floor).
  const float walled = walledShare(seen, lid.model, lid.rim_band);
  PCL_DEBUG("[facyl::TabletopCylinderRecognizer] lid of %zu points: radius %.3f, height %.3f, rim "
            "%.2f, seen through %.2f, walled %.2f\n",
            lid.lid_points, lid.model.radius, lid.model.height, lid.rim_coverage, through, walled);
  if (!(through <= kMaxSeenThrough) || walled > 0.5f)
    return f;
  f.model = lid.model;
  // The evidence as for a side's fit, the lid's rim seen as its coverage: what the cylinder
  // explains of the points (the lid as its cap, any side seen), what lies beyond it.
  CylinderEvidence& e = f.evidence;
  e.fitted = true;
  e.from_lid = true;
  e.seen_through = through;
  e.angular_coverage = lid.rim_coverage;
  const std::vector<Explained> why =
    explainedPoints(f.model, input.columns, input.normals, explainSettings(f.model));
  const auto n = static_cast<float>(std::max<std::size_t>(1, input.points->size()));
  e.inlier_ratio = static_cast<float>(std::count(why.begin(), why.end(), Explained::Lateral)) / n;
  e.surface_ratio =
    static_cast<float>(
      why.size() - static_cast<std::size_t>(std::count(why.begin(), why.end(), Explained::No))) /
    n;
  e.shape = shapeEvidence(f.model, input.columns, input.normals, input.scatter, {},
                          f.model.distance_threshold);
  e.shape.outside_share = lid.outside_share; // beyond the rim band: the lid's own measure
  f.explained_share = e.surface_ratio;
  // The columns' indices to the subset's (as the estimator's inliers).
  pcl::Indices to_subset(static_cast<std::size_t>(input.columns.cols()));
  for (std::size_t k = 0; k < input.column_of.size(); ++k)
    if (input.column_of[k] >= 0)
      to_subset[static_cast<std::size_t>(input.column_of[k])] = static_cast<pcl::index_t>(k);
  for (auto& i : f.model.inliers)
    i = to_subset[static_cast<std::size_t>(i)];
  f.model.inlier_ratio = e.inlier_ratio;
  f.accepted = acceptCylinder(e, params_.decision);
  PCL_DEBUG("[facyl::TabletopCylinderRecognizer] lid fit: surface %.2f, outside %.2f, p %.2f%s\n",
            e.surface_ratio, e.shape.outside_share, geometricProbability(e, params_.decision),
            f.accepted ? ", accepted" : "");
  return f;
}

/* The retry with the axis fixed along the support's normal (upright) looks where a fit within
 * one accumulator cell of that normal already is, and the lying prior (Horizontal) where one
 * within a cell of the support's plane is: the retry's axis would be that one again (its vote
 * cannot tell axes a cell apart). The other retry (any normal sign) asks another question and
 * always runs. */
template <typename PointT>
bool
TabletopCylinderRecognizer<PointT>::retryRepeats(const Fitter& fitter, std::size_t estimator,
                                                 const Fit& fit) const
{
  if (!fit.evidence.fitted || estimator >= fitter.estimators.size())
    return false;
  const auto& hough = fitter.estimators[estimator];
  const float cell = OrientationAccumulator::nominalCellRadius(hough.getParameters().orientations);
  const float along = std::abs(fit.model.axis.normalized().dot(fitter.up));
  const float from_up = std::acos(std::min(1.f, along)); // rad, in [0, pi/2]
  if (estimator == fitter.upright)
    return from_up < cell;
  if (hough.getParameters().prior == OrientationPrior::Horizontal)
    return 0.5f * static_cast<float>(M_PI) - from_up < cell;
  return false;
}

template <typename PointT>
typename TabletopCylinderRecognizer<PointT>::Fit
TabletopCylinderRecognizer<PointT>::fitWithRetries(Fitter& fitter, const FitInput& input,
                                                   const std::vector<std::uint8_t>& alive) const
{
  std::vector<std::size_t> retries;
  for (std::size_t e = 1; e < fitter.estimators.size(); ++e)
    if (e != fitter.upright || fitter.with_support)
      retries.push_back(e);
  // Each fit has an estimator of its own. With threads to spare, the first fit and the retries
  // run at once, started in order, and a fit not started yet is skipped once an earlier one is
  // accepted (its answer would not be looked at). Either way they are judged in order: the
  // answer of one fit after another.
  const bool at_once = fitter.retry_threads > 1;
  std::vector<Fit> fits(retries.size() + 1);
  if (at_once) {
    std::atomic<std::size_t> accepted{fits.size()}; // the earliest fit accepted so far
    parallelFor(fits.size(), fitter.retry_threads, 1, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        if (accepted.load() < i)
          continue;
        fits[i] = fitOnce(fitter, input, alive, i == 0 ? 0 : retries[i - 1]);
        for (std::size_t a = accepted.load(); fits[i].accepted && i < a;)
          if (accepted.compare_exchange_weak(a, i))
            break;
      }
    });
  }
  else
    fits[0] = fitOnce(fitter, input, alive, 0);
  Fit best = std::move(fits[0]);
  for (std::size_t i = 0; i < retries.size() && !best.accepted; ++i) {
    if (retryRepeats(fitter, retries[i], best))
      continue; // judged alike with threads to spare, so that results do not depend on them
    Fit f = at_once ? std::move(fits[i + 1]) : fitOnce(fitter, input, alive, retries[i]);
    // Of fits that are not accepted, the likelier cylinder (a fit that explains more of the
    // points by bending around them is not).
    if (f.evidence.fitted && (f.accepted || !best.evidence.fitted ||
                              geometricProbability(f.evidence, params_.decision) >
                                geometricProbability(best.evidence, params_.decision)))
      best = std::move(f);
  }
  return best;
}

} // namespace facyl
