/*
 * libFuzzer target: the estimators on arbitrary arrays and parameters. The bytes are read as
 * a parameter block (voting mode, prior, radius limits, thresholds, counts, seed) followed by
 * points (x, y, z) and cues (normal, curvature direction, k_max, k_min) as raw floats: NaN,
 * infinities, huge and denormal values included. Invalid parameters must be refused with an
 * error, never crash; valid ones must give models with finite, consistent fields.
 */
#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/console/print.h>

#include <cmath>
#include <cstdint>
#include <cstring>

namespace {

class Bytes {
public:
  Bytes(const std::uint8_t* data, std::size_t size)
      : data_(data)
      , size_(size)
  {
  }
  template <typename T> T take()
  {
    T v{};
    if (pos_ + sizeof(T) <= size_)
      std::memcpy(&v, data_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::size_t left() const
  {
    return pos_ < size_ ? size_ - pos_ : 0;
  }

private:
  const std::uint8_t* data_;
  std::size_t size_, pos_{0};
};

} // namespace

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  static const bool quiet = [] {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
    return true;
  }();
  (void)quiet;
  Bytes in(data, size);
  const auto flags = in.take<std::uint8_t>();
  facyl::HoughCylinderParameters p;
  p.voting_mode = static_cast<facyl::VotingMode>(flags % 3);
  p.outward_normals = (flags >> 2) & 1;
  p.refine = (flags >> 3) & 1;
  const bool estimate_cues = (flags >> 4) & 1;
  p.radius_min = in.take<float>();
  p.radius_max = in.take<float>();
  p.distance_threshold = in.take<float>();
  p.normal_angle_threshold = in.take<float>();
  p.kernel_exponent = in.take<std::uint8_t>();
  p.max_cylinders = in.take<std::uint8_t>() % 8;
  p.orientation_candidates = in.take<std::uint8_t>() % 16;
  p.circle_grid = in.take<std::uint16_t>() % 600;
  const auto prior = static_cast<facyl::OrientationPrior>(in.take<std::uint8_t>() % 4);
  const std::size_t orientations = in.take<std::uint16_t>() % 2000;
  const auto seed = in.take<std::uint64_t>();
  const int k = in.take<std::uint8_t>() % 40;

  const std::size_t n = std::min<std::size_t>(in.left() / (12 * sizeof(float)), 2000);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<facyl::NormalCurvature>::Ptr cues(new pcl::PointCloud<facyl::NormalCurvature>);
  for (std::size_t i = 0; i < n; ++i) {
    pcl::PointXYZ q;
    q.x = in.take<float>(), q.y = in.take<float>(), q.z = in.take<float>();
    cloud->push_back(q);
    facyl::NormalCurvature c;
    c.normal_x = in.take<float>(), c.normal_y = in.take<float>(), c.normal_z = in.take<float>();
    c.principal_curvature_x = in.take<float>(), c.principal_curvature_y = in.take<float>();
    c.principal_curvature_z = in.take<float>();
    c.pc1 = in.take<float>(), c.pc2 = in.take<float>(), c.curvature = in.take<float>();
    cues->push_back(c);
  }
  if (estimate_cues) {
    facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
    ne.setInputCloud(cloud);
    ne.setKSearch(k);
    ne.setNumberOfThreads(1 + (flags >> 5) % 3);
    ne.compute(*cues);
    if (cues->size() != cloud->size())
      return 0;
  }
  facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature> hough;
  hough.setParameters(p);
  hough.setOrientationPrior(prior);
  hough.setNumberOfOrientations(orientations);
  hough.setSeed(seed);
  hough.setInputCloud(cloud);
  hough.setInputNormals(cues);
  std::vector<facyl::CylinderModel> models;
  const bool found = hough.segment(models);
  if (found != !models.empty())
    __builtin_trap();
  for (const auto& m : models) {
    const bool finite = m.point_on_axis.allFinite() && m.axis.allFinite() &&
                        std::isfinite(m.radius) && m.radius >= 0.f;
    if (!finite || std::abs(m.axis.norm() - 1.f) > 1e-3f || m.inliers.size() > cloud->size())
      __builtin_trap();
    for (const auto i : m.inliers)
      if (i < 0 || static_cast<std::size_t>(i) >= cloud->size())
        __builtin_trap();
  }
  return 0;
}
