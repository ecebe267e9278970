/*
 * facyl: fast cylinder detection for PCL.
 * The point-type-independent steps of TabletopSegmentation (see plane_search.h).
 */
#include <facyl/segmentation/plane_search.h>
#include <facyl/segmentation/support_planes.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/common/centroid.h>
#include <pcl/common/eigen.h>
#include <pcl/features/normal_3d.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/euclidean_cluster_comparator.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif

namespace facyl {

namespace {

/** One entry of the summed-area tables of averageGradientNormals: the sums of the horizontal
 * and vertical differences above and left of it, and how many of each were finite. */
struct GradientSums {
  double dx[3], dy[3];
  unsigned nx, ny;
};

/** PCL's depth-change map and its chamfer distance map (IntegralImageNormalEstimation::
 * computeFeature), over the flat buffer as PCL reads it. */
std::vector<float>
depthDistanceMap(const pcl::PointCloud<pcl::PointXYZ>& cloud, float max_depth_change_factor)
{
  const std::size_t w = cloud.width, h = cloud.height, n = w * h;
  std::vector<unsigned char> change(n, 255);
  for (std::size_t ri = 0; ri + 1 < h; ++ri)
    for (std::size_t ci = 0; ci + 1 < w; ++ci) {
      const std::size_t index = ri * w + ci;
      const float depth = cloud[index].z, right = cloud[index + 1].z, down = cloud[index + w].z;
      const float allowed = max_depth_change_factor * (std::abs(depth) + 1.0f) * 2.0f;
      if (std::fabs(depth - right) > allowed || !std::isfinite(depth) || !std::isfinite(right))
        change[index] = change[index + 1] = 0;
      if (std::fabs(depth - down) > allowed || !std::isfinite(depth) || !std::isfinite(down))
        change[index] = change[index + w] = 0;
    }
  std::vector<float> d(n);
  for (std::size_t i = 0; i < n; ++i)
    d[i] = change[i] == 0 ? 0.0f : static_cast<float>(w + h);
  for (std::size_t ri = 1; ri < h; ++ri) {
    float* previous = d.data() + (ri - 1) * w;
    float* current = previous + w;
    for (std::size_t ci = 1; ci < w; ++ci) {
      const float m = std::min(std::min(previous[ci - 1] + 1.4f, previous[ci] + 1.0f),
                               std::min(current[ci - 1] + 1.0f, previous[ci + 1] + 1.4f));
      if (m < current[ci])
        current[ci] = m;
    }
  }
  for (std::ptrdiff_t ri = static_cast<std::ptrdiff_t>(h) - 2; ri >= 0; --ri) {
    float* current = d.data() + static_cast<std::size_t>(ri) * w;
    float* next = current + w;
    for (std::ptrdiff_t ci = static_cast<std::ptrdiff_t>(w) - 2; ci >= 0; --ci) {
      // At ci = 0, next[-1] is the last of this row, and in the first pass previous[w] the
      // first of the next: PCL's passes run over the flat buffer.
      const float m = std::min(std::min(next[ci - 1] + 1.4f, next[ci] + 1.0f),
                               std::min(current[ci + 1] + 1.0f, next[ci + 1] + 1.4f));
      if (m < current[ci])
        current[ci] = m;
    }
  }
  return d;
}

/** PCL's summed-area tables (IntegralImage2D<float, 3>, first order) of the differences of
 * initAverage3DGradientMethod: for interior cells right minus left and down minus up, zero
 * (finite) elsewhere. (w + 1) x (h + 1) entries. */
std::vector<GradientSums>
gradientSums(const pcl::PointCloud<pcl::PointXYZ>& cloud)
{
  const std::size_t w = cloud.width, h = cloud.height, stride = w + 1;
  std::vector<GradientSums> table(stride * (h + 1)); // zeros: the first row and column stay so
  const auto add = [](double(&sum)[3], unsigned& count, const float(&e)[3]) {
    if (std::isfinite((e[0] + e[1]) + e[2])) {
      for (int k = 0; k < 3; ++k)
        sum[k] += static_cast<double>(e[k]);
      ++count;
    }
  };
  for (std::size_t r = 0; r < h; ++r) {
    const GradientSums* previous = table.data() + r * stride;
    GradientSums* current = table.data() + (r + 1) * stride;
    const bool row_inside = r >= 1 && r + 2 <= h;
    for (std::size_t c = 0; c < w; ++c) {
      GradientSums& e = current[c + 1];
      for (int k = 0; k < 3; ++k) {
        e.dx[k] = previous[c + 1].dx[k] + current[c].dx[k] - previous[c].dx[k];
        e.dy[k] = previous[c + 1].dy[k] + current[c].dy[k] - previous[c].dy[k];
      }
      e.nx = previous[c + 1].nx + current[c].nx - previous[c].nx;
      e.ny = previous[c + 1].ny + current[c].ny - previous[c].ny;
      float dx[3] = {0.f, 0.f, 0.f}, dy[3] = {0.f, 0.f, 0.f};
      if (row_inside && c >= 1 && c + 2 <= w) {
        const pcl::PointXYZ &left = cloud[r * w + c - 1], &right = cloud[r * w + c + 1];
        const pcl::PointXYZ &up = cloud[(r - 1) * w + c], &down = cloud[(r + 1) * w + c];
        dx[0] = right.x - left.x, dx[1] = right.y - left.y, dx[2] = right.z - left.z;
        dy[0] = down.x - up.x, dy[1] = down.y - up.y, dy[2] = down.z - up.z;
      }
      add(e.dx, e.nx, dx);
      add(e.dy, e.ny, dy);
    }
  }
  return table;
}

} // namespace

void
averageGradientNormals(const pcl::PointCloud<pcl::PointXYZ>& cloud, float max_depth_change_factor,
                       float smoothing_size, pcl::PointCloud<pcl::Normal>& normals)
{
  if (!(smoothing_size > 0.f) || !(smoothing_size < 1e6f))
    throw std::invalid_argument(
      "facyl::averageGradientNormals: the smoothing size must be positive and finite");
  if (!(max_depth_change_factor >= 0.f) || !std::isfinite(max_depth_change_factor))
    throw std::invalid_argument(
      "facyl::averageGradientNormals: the depth change factor must be finite and >= 0");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  normals.header = cloud.header;
  normals.sensor_origin_ = cloud.sensor_origin_;
  normals.sensor_orientation_ = cloud.sensor_orientation_;
  pcl::Normal bad;
  bad.normal_x = bad.normal_y = bad.normal_z = bad.curvature = nan;
  normals.points.assign(cloud.size(), bad);
  normals.width = cloud.width;
  normals.height = cloud.height;
  normals.is_dense = false;
  const std::size_t w = cloud.width, h = cloud.height;
  const auto border = static_cast<std::size_t>(static_cast<int>(smoothing_size));
  if (w < 2 * border + 1 || h < 2 * border + 1 || w < 3 || h < 3)
    return;
  const std::vector<float> distance = depthDistanceMap(cloud, max_depth_change_factor);
  const std::vector<GradientSums> table = gradientSums(cloud);
  const std::size_t stride = w + 1;
  const float vx = cloud.sensor_origin_.coeff(0), vy = cloud.sensor_origin_.coeff(1),
              vz = cloud.sensor_origin_.coeff(2);
  for (std::size_t ri = border; ri < h - border; ++ri)
    for (std::size_t ci = border; ci < w - border; ++ci) {
      const std::size_t index = ri * w + ci;
      if (!std::isfinite(cloud[index].z))
        continue;
      const float smoothing = std::min(distance[index], smoothing_size);
      if (!(smoothing > 2.0f))
        continue;
      const auto rect = static_cast<unsigned>(static_cast<int>(smoothing));
      const unsigned half = rect / 2;
      const std::size_t upper_left = (ri - half) * stride + (ci - half);
      const GradientSums& ul = table[upper_left];
      const GradientSums& ur = table[upper_left + rect];
      const GradientSums& ll = table[upper_left + rect * stride];
      const GradientSums& lr = table[upper_left + rect * stride + rect];
      const unsigned count_x = lr.nx + ul.nx - ur.nx - ll.nx;
      const unsigned count_y = lr.ny + ul.ny - ur.ny - ll.ny;
      if (count_x == 0 || count_y == 0)
        continue;
      Eigen::Vector3d gx, gy;
      for (int k = 0; k < 3; ++k) {
        gx[k] = lr.dx[k] + ul.dx[k] - ur.dx[k] - ll.dx[k];
        gy[k] = lr.dy[k] + ul.dy[k] - ur.dy[k] - ll.dy[k];
      }
      Eigen::Vector3d n = gy.cross(gx);
      const double length = n.squaredNorm();
      if (length == 0.0)
        continue;
      n /= std::sqrt(length);
      float nx = static_cast<float>(n[0]), ny = static_cast<float>(n[1]),
            nz = static_cast<float>(n[2]);
      pcl::flipNormalTowardsViewpoint(cloud[index], vx, vy, vz, nx, ny, nz);
      pcl::Normal& out = normals[index];
      out.normal_x = nx;
      out.normal_y = ny;
      out.normal_z = nz;
    }
}

void
finishPlaneGrid(BlockMeans& blocks, int image_width, PlaneGrid& grid)
{
  const int step = blocks.step;
  grid.step = step;
  grid.small.reset(new pcl::PointCloud<pcl::PointXYZ>);
  auto& small = *grid.small;
  small.width = static_cast<std::uint32_t>(blocks.cw);
  small.height = static_cast<std::uint32_t>(blocks.ch);
  small.is_dense = false;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  small.points.assign(blocks.cw * blocks.ch, pcl::PointXYZ(nan, nan, nan));
  for (std::size_t k = 0; k < small.size(); ++k)
    if (blocks.count[k] > 0)
      small[k].getVector3fMap() = blocks.sum[k] / static_cast<float>(blocks.count[k]);
  grid.source = std::move(blocks.source);
  const auto& source = grid.source;
  // Normals of the cells (integral images) and the cells as columns, with one raw pixel each
  // (for the bands).
  grid.normals.reset(new pcl::PointCloud<pcl::Normal>);
  // Neighbouring cells may differ in depth by 8 % at VGA's spacing (4 pixels), in proportion
  // to their angular spacing at other resolutions.
  averageGradientNormals(small,
                         0.02f * static_cast<float>(step) * 640.f / static_cast<float>(image_width),
                         std::max(4.f, 16.f / static_cast<float>(step)), *grid.normals);
  const auto n = static_cast<Eigen::Index>(small.size());
  grid.cells.resize(3, n);
  grid.cell_normals.resize(3, n);
  grid.samples.resize(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    grid.cells.col(k) = small[kk].getVector3fMap();
    grid.cell_normals.col(k) = (*grid.normals)[kk].getNormalVector3fMap();
    grid.samples.col(k) = source[kk] >= 0 ? blocks.first[kk] : Eigen::Vector3f::Constant(nan);
  }
  blocks.sum.clear();
  blocks.first.clear();
  blocks.count.clear();
}

std::vector<pcl::PointIndices>
planarRegions(const pcl::PointCloud<pcl::PointXYZ>& cloud,
              const pcl::PointCloud<pcl::Normal>& normals, unsigned min_inliers,
              double angular_threshold, double distance_threshold, double maximum_curvature)
{
  const std::size_t w = cloud.width, h = cloud.height, n = cloud.size();
  if (!cloud.isOrganized() || normals.size() != n || n == 0)
    return {};
  // pcl::PlaneCoefficientComparator as OrganizedMultiPlaneSegmentation sets it up: the
  // offsets of each cell's tangent plane, cos of the angle, a threshold that grows with z^2.
  std::vector<float> plane_d(n);
  for (std::size_t i = 0; i < n; ++i)
    plane_d[i] = cloud[i].getVector3fMap().dot(normals[i].getNormalVector3fMap());
  const float cos_angle = std::cos(static_cast<float>(angular_threshold));
  const auto distance = static_cast<float>(distance_threshold);
  const Eigen::Vector3f z_axis(0.0f, 0.0f, 1.0f);
  const auto same = [&](std::size_t a, std::size_t b) {
    float threshold = distance;
    const float z = cloud[a].getVector3fMap().dot(z_axis);
    threshold *= z * z;
    return std::fabs(plane_d[a] - plane_d[b]) < threshold &&
           normals[a].getNormalVector3fMap().dot(normals[b].getNormalVector3fMap()) > cos_angle;
  };
  // pcl::OrganizedConnectedComponentSegmentation: runs labelled in one pass, joined by roots.
  constexpr unsigned invalid = std::numeric_limits<unsigned>::max();
  std::vector<unsigned> label(n, invalid), runs;
  const auto root = [&](unsigned r) {
    while (runs[r] != r)
      r = runs[r];
    return r;
  };
  const auto fresh = [&](std::size_t i) {
    label[i] = static_cast<unsigned>(runs.size());
    runs.push_back(label[i]);
  };
  if (std::isfinite(cloud[0].x))
    fresh(0);
  for (std::size_t c = 1; c < w; ++c) {
    if (!std::isfinite(cloud[c].x))
      continue;
    if (same(c, c - 1))
      label[c] = label[c - 1];
    else
      fresh(c);
  }
  for (std::size_t r = 1; r < h; ++r) {
    const std::size_t row = r * w, previous = row - w;
    if (std::isfinite(cloud[row].x)) {
      if (same(row, previous))
        label[row] = label[previous];
      else
        fresh(row);
    }
    for (std::size_t c = 1; c < w; ++c) {
      const std::size_t i = row + c, up = previous + c;
      if (!std::isfinite(cloud[i].x))
        continue;
      if (same(i, i - 1))
        label[i] = label[i - 1];
      if (same(i, up)) {
        if (label[i] == invalid)
          label[i] = label[up];
        else if (label[up] != invalid) {
          const unsigned a = root(label[i]), b = root(label[up]);
          if (a < b)
            runs[b] = a;
          else
            runs[a] = b;
        }
      }
      if (label[i] == invalid)
        fresh(i);
    }
  }
  std::vector<unsigned> region(runs.size());
  std::size_t regions = 0;
  for (std::size_t k = 0; k < runs.size(); ++k)
    region[k] =
      runs[k] == k ? static_cast<unsigned>(regions++) : region[root(static_cast<unsigned>(k))];
  std::vector<pcl::PointIndices> members(regions);
  for (std::size_t i = 0; i < n; ++i)
    if (label[i] != invalid)
      members[region[label[i]]].indices.push_back(static_cast<pcl::index_t>(i));
  // The regions larger than min_inliers that are flat enough (PCL also orients their planes,
  // which does not decide which are kept).
  std::vector<pcl::PointIndices> out;
  Eigen::Vector4f centroid = Eigen::Vector4f::Zero();
  Eigen::Matrix3f covariance;
  for (auto& m : members) {
    if (static_cast<unsigned>(m.indices.size()) <= min_inliers)
      continue;
    pcl::computeMeanAndCovarianceMatrix(cloud, m.indices, covariance, centroid);
    float eigen_value;
    Eigen::Vector3f eigen_vector;
    pcl::eigen33(covariance, eigen_value, eigen_vector);
    const float trace = covariance.coeff(0) + covariance.coeff(4) + covariance.coeff(8);
    const float curvature = trace != 0 ? std::abs(eigen_value / trace) : 0.f;
    if (curvature < maximum_curvature)
      out.push_back(std::move(m));
  }
  return out;
}

std::vector<pcl::PointIndices>
planeSeeds(const PlaneGrid& grid, std::size_t min_plane_points, float plane_angle,
           float seed_distance)
{
  const std::size_t cell = static_cast<std::size_t>(grid.step * grid.step);
  const std::size_t min_cells = std::max<std::size_t>(10, min_plane_points / cell / 4);
  std::vector<pcl::PointIndices> inliers;
  float relax = 1.f;
  for (int attempt = 0; attempt < 3; ++attempt, relax *= 2.f) {
    inliers = planarRegions(*grid.small, *grid.normals, static_cast<unsigned>(min_cells),
                            std::min(0.5f, relax * plane_angle), relax * seed_distance,
                            relax * relax * 0.001);
    if (std::any_of(inliers.begin(), inliers.end(), [&](const pcl::PointIndices& r) {
          return r.indices.size() * cell >= min_plane_points;
        }))
      break;
  }
  std::sort(inliers.begin(), inliers.end(),
            [](const auto& a, const auto& b) { return a.indices.size() > b.indices.size(); });
  return inliers;
}

SampledPlaneCues
sampledPlaneCues(const pcl::PointCloud<pcl::PointXYZ>::Ptr& sample,
                 const Eigen::Vector3f& viewpoint, float plane_distance)
{
  SampledPlaneCues c;
  c.cloud = sample;
  pcl::PointCloud<pcl::Normal> normals;
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setInputCloud(sample);
  ne.setSearchMethod(tree);
  ne.setKSearch(12);
  ne.compute(normals);
  const auto n = static_cast<Eigen::Index>(sample->size());
  c.points.resize(3, n);
  c.normals.resize(3, n);
  std::vector<float> ranges(sample->size());
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    c.points.col(k) = (*sample)[kk].getVector3fMap();
    c.normals.col(k) = normals[kk].getNormalVector3fMap();
    ranges[kk] = (c.points.col(k) - viewpoint).norm();
  }
  // RANSAC's seed threshold: 2 % of the typical range (the bands are measured afterwards).
  std::nth_element(ranges.begin(), ranges.begin() + n / 2, ranges.end());
  c.seed_distance =
    plane_distance > 0.f ? plane_distance : 0.02f * ranges[static_cast<std::size_t>(n / 2)];
  return c;
}

void
ransacPlaneSeeds(const SampledPlaneCues& cues, std::size_t max_planes, double scale,
                 std::size_t min_plane_points,
                 const std::function<void(const std::vector<std::uint8_t>&)>& grow,
                 std::vector<std::uint8_t>& taken)
{
  // Planes one after another, each seeded on what the previous ones left: RANSAC on positions
  // (cheap), then the inliers whose normal agrees with the plane's.
  const std::size_t n = cues.cloud->size();
  pcl::SACSegmentation<pcl::PointXYZ> sac;
  sac.setOptimizeCoefficients(true);
  sac.setModelType(pcl::SACMODEL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setDistanceThreshold(cues.seed_distance);
  sac.setMaxIterations(200);
  sac.setInputCloud(cues.cloud);
  const float cos_normal = std::cos(0.3f);
  for (std::size_t k = 0; k < max_planes; ++k) {
    pcl::IndicesPtr remaining(new pcl::Indices);
    for (std::size_t i = 0; i < n; ++i)
      if (!taken[i])
        remaining->push_back(static_cast<pcl::index_t>(i));
    if (remaining->size() < 10 || !spansPlane(*cues.cloud, *remaining))
      break;
    sac.setIndices(remaining);
    pcl::PointIndices inliers;
    pcl::ModelCoefficients coefficients;
    sac.segment(inliers, coefficients);
    if (coefficients.values.size() != 4)
      break;
    const auto& c = coefficients.values;
    const Eigen::Vector3f normal = Eigen::Vector3f(c[0], c[1], c[2]).normalized();
    std::vector<std::uint8_t> seed(n, 0);
    std::size_t seeded = 0;
    for (const auto i : inliers.indices)
      if (std::abs(cues.normals.col(i).dot(normal)) >= cos_normal)
        seed[static_cast<std::size_t>(i)] = 1, ++seeded;
    if (static_cast<double>(seeded) * scale < static_cast<double>(min_plane_points))
      break;
    grow(seed);
    for (const auto i : inliers.indices) // the next search looks elsewhere
      taken[static_cast<std::size_t>(i)] = 1;
  }
}

bool
facesImageTop(const Eigen::Vector4f& plane, const Eigen::Vector3f& image_down)
{
  return plane.head<3>().dot(image_down) <= -0.1f;
}

std::vector<std::vector<std::size_t>>
rankSupportFamilies(const std::vector<Eigen::Vector4f>& planes,
                    const std::vector<std::size_t>& points, bool up_known,
                    const Eigen::Vector3f& image_down)
{
  std::vector<Eigen::Vector4f> normals;
  std::vector<std::size_t> order;
  for (std::size_t s = 0; s < planes.size(); ++s) {
    normals.push_back(Eigen::Vector4f(planes[s][0], planes[s][1], planes[s][2], 0.f));
    order.push_back(s); // largest first
  }
  // Supports are level: a table, the floor under it and a shelf are parallel within degrees.
  auto families = groupCoplanar(normals, order, 0.1f, std::numeric_limits<float>::infinity());
  // An upright camera's supports face the top of the image (their normal points against the
  // image's down direction, measured on organized clouds); walls and ceilings do not. Those
  // come first (the order breaks ties), then the family with most points.
  const auto faces_up = [&](const std::vector<std::size_t>& f) {
    return up_known || facesImageTop(planes[f.front()], image_down);
  };
  const auto sum = [&](const std::vector<std::size_t>& f) {
    std::size_t total = 0;
    for (const std::size_t s : f)
      total += points[s];
    return total;
  };
  std::stable_sort(families.begin(), families.end(), [&](const auto& a, const auto& b) {
    const bool ua = faces_up(a), ub = faces_up(b);
    return ua != ub ? ua : sum(a) > sum(b);
  });
  return families;
}

PlaneSorter::PlaneSorter(std::vector<Eigen::Vector4f> planes, std::vector<DepthBand> bands,
                         const Eigen::Vector3f& viewpoint, float floor, float top)
    : planes_(std::move(planes))
    , bands_(std::move(bands))
    , viewpoint_(viewpoint)
    , floor_(floor)
    , top_(top)
{
  const std::size_t n = planes_.size();
  if (n > 8 || bands_.size() != n)
    throw std::invalid_argument("facyl::PlaneSorter: at most 8 planes, one band each");
  half_.resize(kHalfWidthBins * n);
  for (std::size_t s = 0; s < n; ++s) {
    const std::vector<float> half = tabulateHalfWidths(bands_[s]);
    for (std::size_t b = 0; b < kHalfWidthBins; ++b)
      half_[b * n + s] = half[b];
  }
}

void
PlaneSorter::sortOne(pcl::index_t i, const float* p, pcl::index_t** ends,
                     std::vector<PointOverPlanes>& above) const
{
  const Eigen::Vector3f q(p[0], p[1], p[2]);
  if (!q.allFinite())
    return;
  const std::size_t n = planes_.size();
  const float range = (q - viewpoint_).norm();
  const auto b = static_cast<std::size_t>(range / kHalfWidthBin);
  const float* widths = b < kHalfWidthBins ? half_.data() + b * n : nullptr;
  std::uint8_t on = 0, over = 0;
  for (std::size_t s = 0; s < n; ++s) {
    const float h = planes_[s].head<3>().dot(q) + planes_[s][3];
    const float w = widths ? widths[s] : bands_[s].halfWidth(range);
    if (std::abs(h) <= w) {
      on |= static_cast<std::uint8_t>(1u << s);
      *ends[s]++ = i;
    }
    else if (h > std::max(floor_, w) && h <= top_)
      over |= static_cast<std::uint8_t>(1u << s);
  }
  if (over)
    above.push_back({i, on, over});
}

#if defined(__SSE2__)
std::size_t
PlaneSorter::sortByFour(const float* xyz, std::size_t stride, std::size_t count,
                        pcl::index_t** ends, std::vector<PointOverPlanes>& above) const
{
  // The same floats as sortOne: the same operations in Eigen's association (x * x' + (y * y' +
  // z * z')) and no other rounding; the lists in the same order.
  const std::size_t n = planes_.size();
  const __m128 zero = _mm_setzero_ps(), vx = _mm_set1_ps(viewpoint_.x()),
               vy = _mm_set1_ps(viewpoint_.y()), vz = _mm_set1_ps(viewpoint_.z()),
               bin = _mm_set1_ps(kHalfWidthBin),
               last = _mm_set1_ps(static_cast<float>(kHalfWidthBins)), floor = _mm_set1_ps(floor_),
               top = _mm_set1_ps(top_), magnitude = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  alignas(16) std::int32_t bin_of[4];
  int on_lanes[8], over_lanes[8];
  std::size_t k = 0;
  for (; k + 4 <= count; k += 4) {
    __m128 x = _mm_loadu_ps(xyz + k * stride), y = _mm_loadu_ps(xyz + (k + 1) * stride),
           z = _mm_loadu_ps(xyz + (k + 2) * stride), t = _mm_loadu_ps(xyz + (k + 3) * stride);
    _MM_TRANSPOSE4_PS(x, y, z, t);
    // v - v is 0 for a finite v, NaN for NaN and infinities.
    const __m128 finite = _mm_and_ps(
      _mm_and_ps(_mm_cmpeq_ps(_mm_sub_ps(x, x), zero), _mm_cmpeq_ps(_mm_sub_ps(y, y), zero)),
      _mm_cmpeq_ps(_mm_sub_ps(z, z), zero));
    const int lanes = _mm_movemask_ps(finite);
    if (lanes == 0)
      continue;
    const __m128 dx = _mm_sub_ps(x, vx), dy = _mm_sub_ps(y, vy), dz = _mm_sub_ps(z, vz);
    const __m128 range = _mm_sqrt_ps(
      _mm_add_ps(_mm_mul_ps(dx, dx), _mm_add_ps(_mm_mul_ps(dy, dy), _mm_mul_ps(dz, dz))));
    const __m128 b = _mm_div_ps(range, bin);
    if ((_mm_movemask_ps(_mm_cmplt_ps(b, last)) & lanes) != lanes) {
      for (std::size_t j = k; j < k + 4; ++j) // one beyond the tabulated ranges
        sortOne(static_cast<pcl::index_t>(j), xyz + j * stride, ends, above);
      continue;
    }
    // Bins of the finite points (0 for the others, never read).
    _mm_store_si128(reinterpret_cast<__m128i*>(bin_of),
                    _mm_and_si128(_mm_cvttps_epi32(b), _mm_castps_si128(finite)));
    int any_over = 0;
    for (std::size_t s = 0; s < n; ++s) {
      const Eigen::Vector4f& c = planes_[s];
      const __m128 h = _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(_mm_set1_ps(c[0]), x),
                   _mm_add_ps(_mm_mul_ps(_mm_set1_ps(c[1]), y), _mm_mul_ps(_mm_set1_ps(c[2]), z))),
        _mm_set1_ps(c[3]));
      const __m128 w = _mm_set_ps(half_[static_cast<std::size_t>(bin_of[3]) * n + s],
                                  half_[static_cast<std::size_t>(bin_of[2]) * n + s],
                                  half_[static_cast<std::size_t>(bin_of[1]) * n + s],
                                  half_[static_cast<std::size_t>(bin_of[0]) * n + s]);
      const __m128 on = _mm_and_ps(_mm_cmple_ps(_mm_and_ps(h, magnitude), w), finite);
      const __m128 over = _mm_andnot_ps(
        on, _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(h, _mm_max_ps(floor, w)), _mm_cmple_ps(h, top)),
                       finite));
      on_lanes[s] = _mm_movemask_ps(on);
      over_lanes[s] = _mm_movemask_ps(over);
      any_over |= over_lanes[s];
      for (int m = on_lanes[s]; m != 0; m &= m - 1)
        *ends[s]++ = static_cast<pcl::index_t>(
          k + static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(m))));
    }
    for (int m = any_over; m != 0; m &= m - 1) {
      const int lane = __builtin_ctz(static_cast<unsigned>(m));
      std::uint8_t on = 0, over = 0;
      for (std::size_t s = 0; s < n; ++s) {
        on |= static_cast<std::uint8_t>(((on_lanes[s] >> lane) & 1) << s);
        over |= static_cast<std::uint8_t>(((over_lanes[s] >> lane) & 1) << s);
      }
      above.push_back({static_cast<pcl::index_t>(k + static_cast<std::size_t>(lane)), on, over});
    }
  }
  return k;
}
#endif

void
PlaneSorter::sort(const float* xyz, std::size_t stride, std::size_t count,
                  const pcl::index_t* indices, pcl::index_t** ends,
                  std::vector<PointOverPlanes>& above, bool vectorized) const
{
  if (planes_.empty())
    return;
  std::size_t k = 0;
#if defined(__SSE2__)
  if (vectorized && !indices && stride >= 4)
    k = sortByFour(xyz, stride, count, ends, above);
#else
  (void)vectorized;
#endif
  for (; k < count; ++k) {
    const std::size_t i = indices ? static_cast<std::size_t>(indices[k]) : k;
    sortOne(static_cast<pcl::index_t>(i), xyz + i * stride, ends, above);
  }
}

std::vector<pcl::Indices>
organizedEuclideanClusters(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud, float tolerance,
                           pcl::PointCloud<pcl::Label>& labels)
{
  pcl::EuclideanClusterComparator<pcl::PointXYZ, pcl::Label>::Ptr comparator(
    new pcl::EuclideanClusterComparator<pcl::PointXYZ, pcl::Label>);
  comparator->setInputCloud(cloud);
  comparator->setDistanceThreshold(tolerance, false);
  pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> components(comparator);
  components.setInputCloud(cloud);
  labels.clear(); // PCL's segment() resizes without resetting: start empty (capacity stays)
  std::vector<pcl::PointIndices> groups;
  components.segment(labels, groups);
  std::vector<pcl::Indices> out;
  out.reserve(groups.size());
  for (auto& g : groups)
    out.push_back(std::move(g.indices));
  return out;
}

std::vector<std::vector<std::size_t>>
voxelEuclideanClusters(const Eigen::Matrix3Xf& points, float tolerance)
{
  const float leaf = 0.25f * tolerance;
  std::unordered_map<std::uint64_t, std::size_t> voxel_of_key;
  pcl::PointCloud<pcl::PointXYZ>::Ptr representatives(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<std::size_t> voxel(static_cast<std::size_t>(points.cols()));
  for (Eigen::Index k = 0; k < points.cols(); ++k) {
    const Eigen::Vector3f p = points.col(k) / leaf;
    const auto cell = [](float v) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v)) + (1 << 20)) &
             0x1fffffULL;
    };
    const std::uint64_t key = cell(p.x()) | (cell(p.y()) << 21) | (cell(p.z()) << 42);
    const auto it = voxel_of_key.emplace(key, representatives->size());
    if (it.second) {
      pcl::PointXYZ q;
      q.getVector3fMap() = points.col(k);
      representatives->push_back(q);
    }
    voxel[static_cast<std::size_t>(k)] = it.first->second;
  }
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(representatives);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(tolerance);
  ec.setMinClusterSize(1);
  ec.setMaxClusterSize(std::numeric_limits<pcl::uindex_t>::max());
  ec.setSearchMethod(tree);
  ec.setInputCloud(representatives);
  std::vector<pcl::PointIndices> groups;
  ec.extract(groups);
  std::vector<std::size_t> group_of(representatives->size());
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (const auto i : groups[g].indices)
      group_of[static_cast<std::size_t>(i)] = g;
  std::vector<std::vector<std::size_t>> out(groups.size());
  for (std::size_t k = 0; k < voxel.size(); ++k)
    out[group_of[voxel[k]]].push_back(k);
  return out;
}

} // namespace facyl
