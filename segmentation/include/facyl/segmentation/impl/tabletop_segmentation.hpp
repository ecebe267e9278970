/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/polygon.h>
#include <facyl/segmentation/support_planes.h>
#include <facyl/segmentation/tabletop_segmentation.h>

#include <pcl/common/transforms.h>

#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/random_sample.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/euclidean_cluster_comparator.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace facyl {

template <typename PointT>
void
TabletopSegmentation<PointT>::reset()
{
  supports_.clear();
  extents_.clear();
  table_ = 0;
  table_found_ = false;
  focal_ = 0.f;
  image_down_.setZero();
  table_coefficients_.values.clear();
  hull_->clear();
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::segment(std::vector<TabletopCluster>& clusters)
{
  clusters.clear();
  reset();
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
  const Eigen::Affine3f pose = plausibleSensorPose(*input_);
  const std::size_t far = countFarPoints(*input_);
  if (far > 0)
    PCL_WARN("[facyl::TabletopSegmentation::segment] %zu points have a coordinate beyond +-%g "
             "and are ignored (treated as missing).\n",
             far, static_cast<double>(kMaxCoordinate));
  bool found = false;
  if (isIdentityPose(pose) && far == 0)
    found = segmentInSensorFrame(clusters);
  else {
    // The search works in the sensor's frame (depth along the line of sight, pixels seen
    // from the origin): the cloud is moved there, the results back to the cloud's frame.
    const PointCloudConstPtr given = input_;
    const Eigen::Vector3f given_up = up_;
    input_ = sensorFrameCopy(*given, pose);
    up_ = pose.linear().transpose() * up_;
    found = segmentInSensorFrame(clusters);
    input_ = given;
    up_ = given_up;
    if (found)
      transformResults(pose, clusters);
  }
  this->deinitCompute();
  return found;
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
  pcl::transformPointCloud(*hull_, *hull_, pose);
  image_down_ = pose.linear() * image_down_;
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::segmentInSensorFrame(std::vector<TabletopCluster>& clusters)
{
  std::vector<Candidate> candidates;
  if (searchedAsImage())
    findPlanesOrganized(candidates);
  else
    findPlanesUnorganized(candidates);
  keepSupportCandidates(candidates);
  if (candidates.empty()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] No plane with at least %zu points "
              "found%s.\n",
              params_.min_plane_points,
              up_.isZero() ? "" : " within max_support_tilt of the up direction");
    reset();
    return false;
  }
  pcl::Indices band;
  classifyPoints(candidates, band);
  if (supports_.empty()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] No plane of at least %g m^2 found.\n",
              params_.min_support_area);
    reset();
    return false;
  }
  std::vector<pcl::Indices> groups;
  if (searchedAsImage())
    clusterOrganized(band, groups);
  else
    clusterUnorganized(band, groups);
  chooseSupports(groups, clusters);
  // Largest first, like pcl::EuclideanClusterExtraction.
  std::stable_sort(clusters.begin(), clusters.end(), [](const auto& a, const auto& b) {
    return a.indices.indices.size() > b.indices.indices.size();
  });
  return true;
}

template <typename PointT>
int
TabletopSegmentation<PointT>::planeStep() const
{
  if (params_.plane_step > 0)
    return params_.plane_step;
  return std::clamp(static_cast<int>(std::lround(input_->width / 160.0)), 1, 16);
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::searchedAsImage() const
{
  // The image path needs a plane grid of at least 16 x 16 cells (its normals use a window of
  // several cells); narrower organized clouds (a LiDAR's few rings, a strip) are point sets.
  const auto cells = static_cast<std::uint32_t>(16 * planeStep());
  return input_->isOrganized() && input_->width >= cells && input_->height >= cells;
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::findPlanesOrganized(std::vector<Candidate>& candidates)
{
  const int step = planeStep();
  const int w = static_cast<int>(input_->width), h = static_cast<int>(input_->height);
  std::vector<std::uint8_t> allowed; // only when indices were given
  if (!fake_indices_) {
    allowed.assign(input_->size(), 0);
    for (const auto i : *indices_)
      allowed[i] = 1;
  }
  // A grid of every step-th pixel; each cell is the mean of the pixels of its block that have
  // depth near the first one's: real sensors lose several percent of their pixels (a single
  // pixel per cell would spread NaN normals) and active stereo is noisy (the mean of up to
  // step^2 pixels is less so); the depth test keeps objects' edges sharp.
  pcl::PointCloud<pcl::PointXYZ>::Ptr small(new pcl::PointCloud<pcl::PointXYZ>);
  small->width = static_cast<std::uint32_t>((w + step - 1) / step);
  small->height = static_cast<std::uint32_t>((h + step - 1) / step);
  small->is_dense = false;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  small->points.assign(static_cast<std::size_t>(small->width) * small->height,
                       pcl::PointXYZ(nan, nan, nan));
  std::vector<pcl::index_t> source(small->size(), -1);
  for (int v0 = 0, k = 0; v0 < h; v0 += step)
    for (int u0 = 0; u0 < w; u0 += step, ++k) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      float first = 0.f;
      int n = 0;
      for (int dv = 0; dv < step && v0 + dv < h; ++dv)
        for (int du = 0; du < step && u0 + du < w; ++du) {
          const std::size_t idx = static_cast<std::size_t>(v0 + dv) * w + u0 + du;
          const auto& p = (*input_)[idx];
          if (!(fake_indices_ || allowed[idx]) || !pcl::isFinite(p))
            continue;
          if (n == 0) {
            first = p.z;
            source[k] = static_cast<pcl::index_t>(idx);
          }
          else if (std::abs(p.z - first) > 0.02f * std::abs(first))
            continue;
          sum += p.getVector3fMap();
          ++n;
        }
      if (n > 0)
        (*small)[k].getVector3fMap() = sum / static_cast<float>(n);
    }
  focal_ = camera_.valid() ? camera_.fx : estimateFocalLength(*small) * static_cast<float>(step);
  image_down_ = imageDownDirection(*small, input_->sensor_origin_.head(3));
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setNormalEstimationMethod(ne.AVERAGE_3D_GRADIENT);
  // Neighbouring cells may differ in depth by 8 % at VGA's spacing (4 pixels), in proportion
  // to their angular spacing at other resolutions.
  ne.setMaxDepthChangeFactor(0.02f * static_cast<float>(step) * 640.f / static_cast<float>(w));
  ne.setNormalSmoothingSize(std::max(4.f, 16.f / static_cast<float>(step)));
  ne.setInputCloud(small);
  ne.compute(*normals);

  pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label> mps;
  const std::size_t cell = static_cast<std::size_t>(step * step);
  mps.setMinInliers(static_cast<unsigned>(std::max<std::size_t>(10, params_.min_plane_points / cell / 4)));
  mps.setAngularThreshold(params_.plane_angle);
  mps.setDistanceThreshold(params_.plane_distance);
  mps.setInputNormals(normals);
  mps.setInputCloud(small);
  std::vector<pcl::ModelCoefficients> coefficients;
  std::vector<pcl::PointIndices> inliers;
  mps.segment(coefficients, inliers);
  // Regions on one plane are one candidate (objects cut a table into several regions).
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  std::vector<Eigen::Vector4f> planes;
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < inliers.size(); ++i) {
    const auto& c = coefficients[i].values;
    planes.push_back(c.size() == 4 ? orientPlane(Eigen::Vector4f(c[0], c[1], c[2], c[3]), viewpoint)
                                   : Eigen::Vector4f::Zero());
    if (c.size() == 4 && planes.back().allFinite())
      order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return inliers[a].indices.size() > inliers[b].indices.size();
  });
  for (const auto& group :
       groupCoplanar(planes, order, params_.plane_angle, params_.plane_distance)) {
    Candidate c;
    c.plane = planes[group.front()];
    for (const std::size_t r : group)
      for (const auto k : inliers[r].indices)
        if (source[static_cast<std::size_t>(k)] >= 0)
          c.points.push_back(source[static_cast<std::size_t>(k)]);
    c.support = c.points.size() * cell;
    PCL_DEBUG("[facyl::TabletopSegmentation] region group: normal (%.3f %.3f %.3f) d %.3f, %zu "
              "points\n", c.plane[0], c.plane[1], c.plane[2], c.plane[3], c.support);
    if (c.support >= params_.min_plane_points)
      candidates.push_back(std::move(c));
  }
  return !candidates.empty();
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::findPlanesUnorganized(std::vector<Candidate>& candidates)
{
  // Plane search on a uniform random sample of the points, with normals: like the pixels of an
  // organized frame, the sample follows the sensor's density, so the table outweighs a larger
  // but farther floor (a voxel grid would weigh surfaces by their area).
  pcl::IndicesPtr finite(new pcl::Indices);
  for (const auto i : *indices_)
    if (pcl::isFinite((*input_)[i]))
      finite->push_back(i);
  pcl::RandomSample<PointT> sample;
  sample.setInputCloud(input_);
  sample.setIndices(finite);
  sample.setSample(static_cast<unsigned>(std::min<std::size_t>(params_.plane_samples, finite->size())));
  sample.setSeed(1);
  pcl::Indices sampled;
  sample.filter(sampled);
  if (sampled.size() < 10)
    return false;
  typename PointCloud::Ptr coarse(new PointCloud);
  pcl::copyPointCloud(*input_, sampled, *coarse);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  typename pcl::search::KdTree<PointT>::Ptr tree(new pcl::search::KdTree<PointT>);
  pcl::NormalEstimation<PointT, pcl::Normal> ne;
  ne.setInputCloud(coarse);
  ne.setSearchMethod(tree);
  ne.setKSearch(12);
  ne.compute(*normals);
  // Planes one after another, each on what the previous ones left: RANSAC on positions
  // (cheap), then the inliers whose normal agrees with the plane's.
  pcl::SACSegmentation<PointT> sac;
  sac.setOptimizeCoefficients(true);
  sac.setModelType(pcl::SACMODEL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setDistanceThreshold(params_.plane_distance);
  sac.setMaxIterations(200);
  sac.setInputCloud(coarse);
  const double scale = static_cast<double>(finite->size()) / static_cast<double>(sampled.size());
  const float cos_normal = std::cos(0.3f);
  pcl::IndicesPtr remaining(new pcl::Indices(sampled.size()));
  std::iota(remaining->begin(), remaining->end(), 0);
  for (std::size_t k = 0; k < params_.max_planes && remaining->size() >= 10; ++k) {
    sac.setIndices(remaining);
    pcl::PointIndices inliers;
    pcl::ModelCoefficients coefficients;
    sac.segment(inliers, coefficients);
    if (coefficients.values.size() != 4)
      break;
    const auto& c = coefficients.values;
    Candidate cand;
    cand.plane = orientPlane(Eigen::Vector4f(c[0], c[1], c[2], c[3]), input_->sensor_origin_.head(3));
    std::vector<std::uint8_t> taken(sampled.size(), 0);
    for (const auto i : inliers.indices) {
      taken[static_cast<std::size_t>(i)] = 1;
      const auto& n = (*normals)[static_cast<std::size_t>(i)];
      if (std::abs(Eigen::Vector3f(n.normal_x, n.normal_y, n.normal_z).dot(cand.plane.template head<3>())) >= cos_normal)
        cand.points.push_back(sampled[static_cast<std::size_t>(i)]);
    }
    cand.support = static_cast<std::size_t>(static_cast<double>(cand.points.size()) * scale);
    if (cand.support < params_.min_plane_points)
      break;
    candidates.push_back(std::move(cand));
    pcl::IndicesPtr left(new pcl::Indices);
    for (const auto i : *remaining)
      if (!taken[static_cast<std::size_t>(i)])
        left->push_back(i);
    remaining = left;
  }
  return !candidates.empty();
}

template <typename PointT>
void
TabletopSegmentation<PointT>::keepSupportCandidates(std::vector<Candidate>& candidates) const
{
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  // A support spans a plane (collinear points, e.g. one image row of a far surface, do not)
  // that does not pass by the sensor (it would be seen edge-on).
  std::vector<Candidate> planar;
  for (auto& c : candidates) {
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(c.points.size()));
    for (std::size_t k = 0; k < c.points.size(); ++k)
      pts.col(static_cast<Eigen::Index>(k)) = (*input_)[c.points[k]].getVector3fMap();
    Eigen::Vector4f refined;
    if (!fitPlane(pts, viewpoint, refined) ||
        refined.template head<3>().dot(viewpoint) + refined[3] < 0.05f)
      continue;
    c.plane = refined;
    planar.push_back(std::move(c));
  }
  candidates.swap(planar);
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.support > b.support; });
  // A region lying on a larger candidate (a part of the same table seen through a sensor's
  // slight bend) is a part of it, not another support.
  std::vector<Candidate> distinct;
  for (auto& c : candidates) {
    const bool part = std::any_of(distinct.begin(), distinct.end(), [&](const Candidate& big) {
      if (big.plane.template head<3>().dot(c.plane.template head<3>()) < std::cos(0.2f))
        return false;
      std::vector<float> h;
      for (const auto i : c.points)
        h.push_back(std::abs(big.plane.template head<3>().dot((*input_)[i].getVector3fMap()) +
                             big.plane[3]));
      std::nth_element(h.begin(), h.begin() + static_cast<std::ptrdiff_t>(h.size() / 2), h.end());
      return h[h.size() / 2] < 2.f * params_.plane_distance;
    });
    if (!part)
      distinct.push_back(std::move(c));
  }
  candidates.swap(distinct);
  if (!up_.isZero()) {
    const Eigen::Vector3f up = up_.normalized();
    const float cos_max = std::cos(params_.max_support_tilt);
    candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                    [&](const Candidate& c) {
                                      return c.plane.template head<3>().dot(up) < cos_max;
                                    }),
                     candidates.end());
  }
  if (params_.support == TabletopSegmentationParameters::Support::LargestPlane) {
    if (candidates.size() > 1)
      candidates.resize(1);
    return;
  }
  if (candidates.size() > params_.max_planes)
    candidates.resize(params_.max_planes);
}

template <typename PointT>
void
TabletopSegmentation<PointT>::classifyPoints(const std::vector<Candidate>& candidates,
                                             pcl::Indices& band)
{
  // One pass: each candidate's points, and the points above some candidate (in its object
  // band) with the candidates they lie on and above.
  const std::size_t n = candidates.size(); // <= 8
  std::vector<SupportPlane> all(n);
  struct Above {
    pcl::index_t index;
    std::uint8_t on, above;
  };
  std::vector<Above> above_band;
  for (std::size_t s = 0; s < n; ++s)
    all[s].inliers.indices.reserve(candidates[s].support + candidates[s].support / 2);
  for (const auto i : *indices_) {
    const auto& p = (*input_)[i];
    if (!pcl::isFinite(p))
      continue;
    std::uint8_t on = 0, above = 0;
    for (std::size_t s = 0; s < n; ++s) {
      const Eigen::Vector4f& q = candidates[s].plane;
      const float h = q.template head<3>().dot(p.getVector3fMap()) + q[3];
      if (std::abs(h) < params_.plane_distance) {
        on |= static_cast<std::uint8_t>(1u << s);
        all[s].inliers.indices.push_back(i);
      }
      else if (h >= params_.min_height && h <= params_.max_height)
        above |= static_cast<std::uint8_t>(1u << s);
    }
    if (above)
      above_band.push_back({i, on, above});
  }
  // Supports: the planes of one family of parallel planes (a table, the floor under it, a
  // shelf) that are large (a smaller plane is an object's face: its points stay objects).
  const bool largest = params_.support == TabletopSegmentationParameters::Support::LargestPlane;
  const std::vector<std::size_t> family = largest ? std::vector<std::size_t>{0}
                                                  : supportFamily(candidates, all);
  std::uint8_t kept = 0;
  for (const std::size_t s : family) {
    SupportPlane& support = all[s];
    support.plane = candidates[s].plane;
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (const auto i : candidates[s].points)
      centre += (*input_)[i].getVector3fMap();
    support.frame =
      planeFrame(candidates[s].plane, centre / static_cast<float>(candidates[s].points.size()));
    support.inliers.header = input_->header;
    support.polygon = supportHull(support, &candidates[s]);
    // A plane inside the object band of a larger parallel one (a shelf, a box top) is judged
    // by the region found on it: its infinite plane slices through the objects around it.
    bool elevated = false;
    for (const std::size_t t : family) {
      const float height = candidates[t].plane[3] - candidates[s].plane[3];
      elevated = elevated || (t != s && candidates[t].support > candidates[s].support &&
                              height >= params_.min_height && height <= params_.max_height);
    }
    // Its own region must be sizeable too: a small region's infinite plane can cross a
    // table.
    const float region = regionArea(candidates[s], support.frame);
    const float area = elevated ? region : polygonArea(support.polygon);
    PCL_DEBUG("[facyl::TabletopSegmentation] family plane %zu: normal (%.3f %.3f %.3f) d %.3f, "
              "%zu inliers, hull %.3f m^2, region %.3f m^2%s\n",
              s, support.plane[0], support.plane[1], support.plane[2], support.plane[3],
              support.inliers.indices.size(), polygonArea(support.polygon), region,
              elevated ? ", elevated" : "");
    if (support.polygon.size() >= 3 &&
        (largest || (area >= params_.min_support_area &&
                     region >= 0.25f * params_.min_support_area)))
      kept |= static_cast<std::uint8_t>(1u << s);
  }
  for (const std::size_t s : family)
    if (kept & (1u << s)) {
      extents_.push_back(supportHull(all[s], nullptr));
      supports_.push_back(std::move(all[s]));
    }
  for (const Above& a : above_band)
    if ((a.above & kept) && !(a.on & kept))
      band.push_back(a.index);
}

template <typename PointT>
std::vector<std::size_t>
TabletopSegmentation<PointT>::supportFamily(const std::vector<Candidate>& candidates,
                                            const std::vector<SupportPlane>& all) const
{
  // Families of parallel candidates.
  std::vector<Eigen::Vector4f> normals;
  std::vector<std::size_t> order;
  for (std::size_t s = 0; s < candidates.size(); ++s) {
    normals.push_back(Eigen::Vector4f(candidates[s].plane[0], candidates[s].plane[1],
                                      candidates[s].plane[2], 0.f));
    order.push_back(s); // largest first
  }
  // Supports are level: a table, the floor under it and a shelf are parallel within degrees.
  const auto families =
    groupCoplanar(normals, order, 0.1f, std::numeric_limits<float>::infinity());
  // With an up direction every candidate is horizontal already. Without one, the camera is
  // taken to be upright: supports face the top of the image (their normal points against the
  // image's down direction, measured on organized clouds); walls and ceilings do not. When no
  // family does (a camera looking straight down, or rolled; unorganized clouds), any may. Then
  // the family with most points wins.
  const auto faces_up = [&](const std::vector<std::size_t>& f) {
    return !up_.isZero() ||
           candidates[f.front()].plane.template head<3>().dot(image_down_) <= -0.1f;
  };
  const bool any_faces_up = std::any_of(families.begin(), families.end(), faces_up);
  std::size_t best = 0, best_points = 0;
  for (std::size_t f = 0; f < families.size(); ++f) {
    if (any_faces_up && !faces_up(families[f]))
      continue;
    std::size_t points = 0;
    for (const std::size_t s : families[f])
      points += all[s].inliers.indices.size();
    if (points > best_points)
      best = f, best_points = points;
  }
  return families.empty() ? std::vector<std::size_t>{} : families[best];
}

template <typename PointT>
float
TabletopSegmentation<PointT>::regionArea(const Candidate& c, const Eigen::Affine3f& frame) const
{
  const Eigen::Affine3f to_plane = frame.inverse();
  std::vector<Eigen::Vector2f> flat;
  for (const auto i : c.points)
    flat.push_back((to_plane * (*input_)[i].getVector3fMap()).template head<2>());
  return polygonArea(convexHull2D(std::move(flat)));
}

template <typename PointT>
std::vector<Eigen::Vector2f>
TabletopSegmentation<PointT>::supportHull(const SupportPlane& s, const Candidate* c) const
{
  const Eigen::Affine3f to_plane = s.frame.inverse();
  const auto& idx = s.inliers.indices;
  const auto flat = [&](pcl::index_t i) {
    return Eigen::Vector2f((to_plane * (*input_)[i].getVector3fMap()).template head<2>());
  };
  std::vector<Eigen::Vector2f> points;
  if (!searchedAsImage()) {
    const std::size_t stride = std::max<std::size_t>(1, idx.size() / params_.plane_samples);
    for (std::size_t k = 0; k < idx.size(); k += stride)
      points.push_back(flat(idx[k]));
    return convexHull2D(std::move(points));
  }
  if (c)
    for (const auto i : c->points)
      points.push_back(flat(i));
  // The region found on the plane, grown by the plane's points within 5 cm of it: the region
  // may miss a table's near edge, where a real sensor's depth bends, but the infinite plane's
  // points also hold the lines where it cuts walls and other objects. The image of a plane is
  // a projective map of it, which keeps convex hulls: only the first and the last point of each
  // image row can be a vertex.
  const std::vector<Eigen::Vector2f> region = convexHull2D(points); // none: every point
  constexpr float grow = 0.05f;
  const auto near_region = [&](const Eigen::Vector2f& p) {
    if (!c || region.size() < 3 || pointInPolygon(p, region))
      return true;
    for (std::size_t e = 0; e < region.size(); ++e) {
      const Eigen::Vector2f a = region[e], b = region[(e + 1) % region.size()];
      const float t = std::clamp((p - a).dot(b - a) / std::max((b - a).squaredNorm(), 1e-12f), 0.f, 1.f);
      if ((a + t * (b - a) - p).squaredNorm() <= grow * grow)
        return true;
    }
    return false;
  };
  const auto w = static_cast<pcl::index_t>(input_->width);
  const auto add = [&](pcl::index_t i) {
    const Eigen::Vector2f p = flat(i);
    if (near_region(p))
      points.push_back(p);
  };
  // Each image row: its first and last point near the region.
  std::size_t k = 0;
  while (k < idx.size()) {
    const pcl::index_t row_end = (idx[k] / w + 1) * w;
    std::size_t end = k;
    while (end < idx.size() && idx[end] < row_end)
      ++end;
    for (std::size_t j = k; j < end; ++j)
      if (near_region(flat(idx[j]))) {
        add(idx[j]);
        break;
      }
    for (std::size_t j = end; j-- > k;)
      if (near_region(flat(idx[j]))) {
        add(idx[j]);
        break;
      }
    k = end;
  }
  return convexHull2D(std::move(points));
}

template <typename PointT>
typename TabletopSegmentation<PointT>::Placement
TabletopSegmentation<PointT>::place(const Eigen::Matrix3Xf& pts,
                                    const std::vector<std::size_t>& family) const
{
  const auto& p = params_;
  Placement out;
  std::vector<HeightProfile> profiles(supports_.size());
  std::vector<float> over(supports_.size(), 0.f);
  for (const std::size_t s : family) {
    profiles[s] = heightProfile(pts, supports_[s].plane, p.min_height, p.max_height);
    const Eigen::Affine3f to_plane = supports_[s].frame.inverse();
    std::size_t in_hull = 0;
    for (Eigen::Index k = 0; k < pts.cols(); ++k)
      in_hull += pointInPolygon((to_plane * Eigen::Vector3f(pts.col(k))).template head<2>(),
                                supports_[s].polygon);
    over[s] = static_cast<float>(in_hull) / static_cast<float>(pts.cols());
    // The nearest support under the cluster: most of it in its band and over its hull (the
    // prism test of pcl::ExtractPolygonalPrismData, per cluster).
    if (profiles[s].in_band < 0.5f || over[s] < p.min_hull_share)
      continue;
    if (out.support < 0 || profiles[s].base < profiles[static_cast<std::size_t>(out.support)].base)
      out.support = static_cast<int>(s);
  }
  if (out.support < 0)
    return out;
  // Under a higher support (its legs, or what stands under it) is furniture, not an object
  // on the lower one. "Under" takes every point of the higher plane: seen at a grazing angle, a
  // table's region may miss its edges.
  for (const std::size_t s : family) {
    if (static_cast<int>(s) == out.support || !(profiles[s].top < 0.f))
      continue;
    const Eigen::Affine3f to_plane = supports_[s].frame.inverse();
    std::size_t under = 0;
    for (Eigen::Index k = 0; k < pts.cols(); ++k)
      under += pointInPolygon((to_plane * Eigen::Vector3f(pts.col(k))).template head<2>(),
                              extents_[s]);
    if (2 * under >= static_cast<std::size_t>(pts.cols())) {
      out.support = -1;
      return out;
    }
  }
  out.standing =
    standsOn(profiles[static_cast<std::size_t>(out.support)], p.contact_height, p.max_height, 0.02f);
  return out;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::chooseSupports(std::vector<pcl::Indices>& groups,
                                             std::vector<TabletopCluster>& clusters)
{
  const auto& p = params_;
  // The clusters' points (at most 400 of each, evenly: enough for the height and hull tests).
  std::vector<std::size_t> kept;
  std::vector<Eigen::Matrix3Xf> points;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].size() < p.min_cluster_size || groups[g].size() > p.max_cluster_size)
      continue;
    const std::size_t stride = std::max<std::size_t>(1, groups[g].size() / 400);
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>((groups[g].size() + stride - 1) / stride));
    for (std::size_t k = 0, c = 0; k < groups[g].size(); k += stride, ++c)
      pts.col(static_cast<Eigen::Index>(c)) = (*input_)[groups[g][k]].getVector3fMap();
    kept.push_back(g);
    points.push_back(std::move(pts));
  }
  std::vector<std::size_t> family(supports_.size());
  std::iota(family.begin(), family.end(), 0);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const Placement pl = place(points[k], family);
    if (pl.support < 0)
      continue;
    SupportPlane& support = supports_[static_cast<std::size_t>(pl.support)];
    ++support.objects;
    if (pl.standing)
      support.standing_points += groups[kept[k]].size();
    clusters.push_back(makeCluster(std::move(groups[kept[k]]), pl.support));
  }
  // The table: the most object points standing on it; else the largest support.
  table_ = family.front();
  for (const std::size_t s : family)
    if (supports_[s].standing_points > supports_[table_].standing_points ||
        (supports_[s].standing_points == supports_[table_].standing_points &&
         supports_[s].inliers.indices.size() > supports_[table_].inliers.indices.size()))
      table_ = s;
  table_found_ = supports_[table_].standing_points > 0;
  // Keep the supports that hold objects, and the table.
  std::vector<int> new_index(supports_.size(), -1);
  std::vector<SupportPlane> used;
  for (std::size_t s = 0; s < supports_.size(); ++s)
    if (supports_[s].objects > 0 || s == table_) {
      new_index[s] = static_cast<int>(used.size());
      used.push_back(std::move(supports_[s]));
    }
  table_ = static_cast<std::size_t>(new_index[table_]);
  supports_ = std::move(used);
  extents_.clear();
  for (auto& c : clusters)
    c.support = new_index[static_cast<std::size_t>(c.support)];
  const SupportPlane& table = supports_[table_];
  table_coefficients_.header = input_->header;
  table_coefficients_.values = {table.plane[0], table.plane[1], table.plane[2], table.plane[3]};
  hull_->clear();
  for (const auto& v : table.polygon) {
    PointT q;
    q.getVector3fMap() = table.frame * Eigen::Vector3f(v.x(), v.y(), 0.f);
    hull_->push_back(q);
  }
}

template <typename PointT>
TabletopCluster
TabletopSegmentation<PointT>::makeCluster(pcl::Indices indices, int support) const
{
  std::sort(indices.begin(), indices.end());
  TabletopCluster c;
  c.indices.header = input_->header;
  c.indices.indices = std::move(indices);
  c.support = support;
  Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(c.indices.indices.size()));
  for (std::size_t k = 0; k < c.indices.indices.size(); ++k)
    pts.col(static_cast<Eigen::Index>(k)) = (*input_)[c.indices.indices[k]].getVector3fMap();
  c.centroid = pts.rowwise().mean();
  c.box = input_->isOrganized() ? pixelBox(c.indices.indices, input_->width)
                                : projectedBox(pts, camera_);
  return c;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::clusterOrganized(const pcl::Indices& objects,
                                               std::vector<pcl::Indices>& out) const
{
  // A sparse copy with only the object points finite: the components then never visit the
  // rest of the image. (Buffers kept between calls: fresh VGA-sized allocations cost more in
  // page faults than the work done on them.)
  if (!masked_)
    masked_.reset(new pcl::PointCloud<pcl::PointXYZ>);
  const auto& masked = masked_;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  masked->points.assign(input_->size(), pcl::PointXYZ(nan, nan, nan));
  masked->width = input_->width;
  masked->height = input_->height;
  masked->is_dense = false;
  for (const auto i : objects)
    (*masked)[i].getVector3fMap() = (*input_)[i].getVector3fMap();
  if (params_.clustering == TabletopSegmentationParameters::Clustering::EdgeAware &&
      focal_ > 0.f) {
    has_depth_.resize(input_->size());
    for (std::size_t i = 0; i < input_->size(); ++i)
      has_depth_[i] = pcl::isFinite((*input_)[i]);
    out = segmentObjectsOrganized(*masked, has_depth_, focal_, input_->sensor_origin_.head(3),
                                  params_.objects);
    return;
  }
  pcl::EuclideanClusterComparator<pcl::PointXYZ, pcl::Label>::Ptr comparator(
    new pcl::EuclideanClusterComparator<pcl::PointXYZ, pcl::Label>);
  comparator->setInputCloud(masked);
  comparator->setDistanceThreshold(params_.cluster_tolerance, false);
  pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> components(comparator);
  components.setInputCloud(masked);
  labels_.clear(); // PCL's segment() resizes without resetting: start empty (capacity stays)
  std::vector<pcl::PointIndices> groups;
  components.segment(labels_, groups);
  out.clear();
  for (auto& g : groups)
    out.push_back(std::move(g.indices));
}

template <typename PointT>
void
TabletopSegmentation<PointT>::clusterUnorganized(const pcl::Indices& objects,
                                                 std::vector<pcl::Indices>& out) const
{
  out.clear();
  if (objects.empty())
    return;
  if (params_.clustering == TabletopSegmentationParameters::Clustering::EdgeAware) {
    segmentProjected(objects, out);
    return;
  }
  // Euclidean clusters of one representative per voxel of a quarter of the tolerance (any two
  // points of neighbouring voxels are closer than the tolerance), then every point joins its
  // voxel's cluster: on dense sensor clouds the radius searches then return few neighbours.
  const float leaf = 0.25f * params_.cluster_tolerance;
  std::unordered_map<std::uint64_t, std::size_t> voxel_of_key;
  pcl::IndicesPtr representatives(new pcl::Indices);
  std::vector<std::size_t> voxel(objects.size());
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const Eigen::Vector3f p = (*input_)[objects[k]].getVector3fMap() / leaf;
    const auto cell = [](float v) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v)) + (1 << 20)) &
             0x1fffffULL;
    };
    const std::uint64_t key = cell(p.x()) | (cell(p.y()) << 21) | (cell(p.z()) << 42);
    const auto it = voxel_of_key.emplace(key, representatives->size());
    if (it.second)
      representatives->push_back(objects[k]);
    voxel[k] = it.first->second;
  }
  typename pcl::search::KdTree<PointT>::Ptr tree(new pcl::search::KdTree<PointT>);
  tree->setInputCloud(input_, representatives);
  pcl::EuclideanClusterExtraction<PointT> ec;
  ec.setClusterTolerance(params_.cluster_tolerance);
  ec.setMinClusterSize(1);
  ec.setMaxClusterSize(std::numeric_limits<pcl::uindex_t>::max());
  ec.setSearchMethod(tree);
  ec.setInputCloud(input_);
  ec.setIndices(representatives);
  std::vector<pcl::PointIndices> groups;
  ec.extract(groups);
  std::unordered_map<pcl::index_t, std::size_t> group_of;
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (const auto i : groups[g].indices)
      group_of[i] = g;
  out.assign(groups.size(), pcl::Indices{});
  for (std::size_t k = 0; k < objects.size(); ++k)
    out[group_of.at((*representatives)[voxel[k]])].push_back(objects[k]);
}

template <typename PointT>
void
TabletopSegmentation<PointT>::segmentProjected(const pcl::Indices& objects,
                                               std::vector<pcl::Indices>& out) const
{
  // The camera: the one given, else a pinhole at the sensor origin looking at the objects
  // with a VGA sensor's angular resolution.
  const Eigen::Vector3f origin = input_->sensor_origin_.head(3);
  Eigen::Matrix3f to_camera = Eigen::Matrix3f::Identity(); // cloud to camera rotation
  PinholeCamera camera = camera_;
  if (!camera.valid()) {
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (const auto i : objects)
      mean += (*input_)[i].getVector3fMap() - origin;
    const Eigen::Vector3f z = mean.normalized();
    const Eigen::Vector3f x = z.unitOrthogonal(), y = z.cross(x);
    to_camera.row(0) = x;
    to_camera.row(1) = y;
    to_camera.row(2) = z;
    camera = PinholeCamera{525.f, 525.f, 0.f, 0.f, 0, 0};
    Eigen::AlignedBox2f box;
    for (const auto i : objects) {
      const Eigen::Vector3f c = to_camera * ((*input_)[i].getVector3fMap() - origin);
      if (c.z() > 0.f)
        box.extend(Eigen::Vector2f(c.x() / c.z(), c.y() / c.z()));
    }
    if (box.isEmpty())
      return;
    // At most 1280 x 960 pixels: a wider view gets a coarser grid.
    const float f = std::min({525.f, 1279.f / std::max(box.sizes().x(), 1e-6f),
                              959.f / std::max(box.sizes().y(), 1e-6f)});
    camera.fx = camera.fy = f;
    camera.cx = -f * box.min().x();
    camera.cy = -f * box.min().y();
    camera.width = static_cast<int>(std::ceil(f * box.sizes().x())) + 1;
    camera.height = static_cast<int>(std::ceil(f * box.sizes().y())) + 1;
  }
  const auto pixel_of = [&](const Eigen::Vector3f& p) -> long {
    const Eigen::Vector3f c = to_camera * (p - origin);
    if (!(c.z() > 0.f))
      return -1;
    const long u = std::lround(camera.fx * c.x() / c.z() + camera.cx);
    const long v = std::lround(camera.fy * c.y() / c.z() + camera.cy);
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height)
      return -1;
    return v * camera.width + u;
  };
  // A depth image of the nearest object point per pixel, and which pixels see any surface.
  const std::size_t n = static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  pcl::PointCloud<pcl::PointXYZ> image;
  image.width = static_cast<std::uint32_t>(camera.width);
  image.height = static_cast<std::uint32_t>(camera.height);
  image.points.assign(n, pcl::PointXYZ(nan, nan, nan));
  std::vector<float> range(n, std::numeric_limits<float>::infinity());
  std::vector<std::uint8_t> has_depth(n, 0);
  for (const auto i : *indices_) {
    const auto& p = (*input_)[i];
    if (!pcl::isFinite(p))
      continue;
    const long k = pixel_of(p.getVector3fMap());
    if (k >= 0)
      has_depth[static_cast<std::size_t>(k)] = 1;
  }
  std::vector<long> pixel(objects.size(), -1);
  for (std::size_t j = 0; j < objects.size(); ++j) {
    const Eigen::Vector3f p = (*input_)[objects[j]].getVector3fMap();
    const long k = pixel_of(p);
    pixel[j] = k;
    if (k < 0)
      continue;
    const float r = (p - origin).norm();
    if (r < range[static_cast<std::size_t>(k)]) {
      range[static_cast<std::size_t>(k)] = r;
      image[static_cast<std::size_t>(k)].getVector3fMap() = p;
    }
  }
  const std::vector<pcl::Indices> segments =
    segmentObjectsOrganized(image, has_depth, camera.fx, origin, params_.objects);
  // Every object point takes the segment of its pixel.
  std::vector<int> segment_of(n, -1);
  for (std::size_t s = 0; s < segments.size(); ++s)
    for (const auto k : segments[s])
      segment_of[static_cast<std::size_t>(k)] = static_cast<int>(s);
  out.assign(segments.size(), pcl::Indices{});
  for (std::size_t j = 0; j < objects.size(); ++j)
    if (pixel[j] >= 0 && segment_of[static_cast<std::size_t>(pixel[j])] >= 0)
      out[static_cast<std::size_t>(segment_of[static_cast<std::size_t>(pixel[j])])].push_back(objects[j]);
}

} // namespace facyl
