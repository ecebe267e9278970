/*
 * facyl: the tabletop segmentation's core (segment_tabletop.h): its workspace, its frames,
 * the lattice's settings, and the PCL front over it.
 */
#define PCL_NO_PRECOMPILE // TabletopSegmentation for the test's own point type below
#include <facyl/segmentation/segment_tabletop.h>
#include <facyl/segmentation/tabletop_segmentation.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/register_point_struct.h>

#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

/** A point type whose x, y, z do not start it (not PCL_ADD_POINT4D): pointFrame copies it. */
struct alignas(16) TrailingXyz {
  float intensity;
  float pad[3];
  union {
    float data[4];
    struct {
      float x, y, z;
    };
  };
  Eigen::Map<Eigen::Vector3f> getVector3fMap()
  {
    return Eigen::Map<Eigen::Vector3f>(&x);
  }
  Eigen::Map<const Eigen::Vector3f> getVector3fMap() const
  {
    return Eigen::Map<const Eigen::Vector3f>(&x);
  }
};
POINT_CLOUD_REGISTER_POINT_STRUCT(TrailingXyz, (float, intensity,
                                                intensity)(float, x, x)(float, y, y)(float, z, z))

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

/** A simulated tabletop frame of \a width x \a height pixels with VGA's field of view. */
Cloud::Ptr
frame(std::uint64_t seed, int width = 640, int height = 480)
{
  facyl::TabletopSceneParameters p;
  p.seed = seed;
  const float scale = static_cast<float>(width) / 640.f;
  p.camera.fx *= scale;
  p.camera.fy *= scale;
  p.camera.cx = 0.5f * static_cast<float>(width - 1);
  p.camera.cy = 0.5f * static_cast<float>(height - 1);
  p.camera.width = width;
  p.camera.height = height;
  return Cloud::Ptr(new Cloud(facyl::simulateTabletopScene(p).cloud));
}

/** The finite points of \a cloud, unorganized. */
Cloud::Ptr
finitePoints(const Cloud& cloud)
{
  Cloud::Ptr out(new Cloud);
  for (const auto& p : cloud)
    if (pcl::isFinite(p))
      out->push_back(p);
  return out;
}

/** Every output of two segmentations is the same, float for float. */
void
expectSame(const facyl::TabletopSegments& a, const facyl::TabletopSegments& b)
{
  ASSERT_EQ(a.supports.size(), b.supports.size());
  EXPECT_EQ(a.table, b.table);
  EXPECT_EQ(a.table_found, b.table_found);
  EXPECT_EQ(a.focal, b.focal);
  for (std::size_t s = 0; s < a.supports.size(); ++s) {
    EXPECT_EQ(a.supports[s].plane, b.supports[s].plane);
    EXPECT_EQ(a.supports[s].frame.matrix(), b.supports[s].frame.matrix());
    EXPECT_EQ(a.supports[s].inliers.indices, b.supports[s].inliers.indices);
    EXPECT_EQ(a.supports[s].band.sigmas, b.supports[s].band.sigmas);
    EXPECT_EQ(a.supports[s].polygon, b.supports[s].polygon);
    EXPECT_EQ(a.supports[s].standing_points, b.supports[s].standing_points);
  }
  ASSERT_EQ(a.clusters.size(), b.clusters.size());
  for (std::size_t k = 0; k < a.clusters.size(); ++k) {
    EXPECT_EQ(a.clusters[k].indices.indices, b.clusters[k].indices.indices);
    EXPECT_EQ(a.clusters[k].centroid, b.clusters[k].centroid);
    EXPECT_EQ(a.clusters[k].box, b.clusters[k].box);
    EXPECT_EQ(a.clusters[k].support, b.clusters[k].support);
  }
}

facyl::TabletopSegments
segmentFresh(const facyl::PointFrame& f, const facyl::TabletopSegmentationParameters& p,
             const facyl::PinholeCamera& camera = {})
{
  facyl::TabletopWorkspace fresh;
  return facyl::segmentTabletop(f, camera, Eigen::Vector3f::Zero(), p, fresh);
}

} // namespace

TEST(SegmentTabletop, AWorkspaceUsedBeforeGivesWhatANewOneGives)
{
  // One workspace through frames of different sizes and kinds (VGA, QVGA, a point set, a
  // lattice of a 1280 x 720 frame, VGA again), for both clusterings: each result equals that
  // of a new workspace. The buffers grow, shrink and keep what earlier frames wrote (two VGA
  // frames in a row leave the Euclidean clustering's masked copy the other frame's points).
  // The used workspace runs on 1 or 3 threads, the new ones on the default (the hardware's):
  // the same segments.
  const Cloud::Ptr vga = frame(21), qvga = frame(22, 320, 240), big = frame(23, 1280, 720),
                   other = frame(24);
  const Cloud::Ptr points = finitePoints(*frame(25));
  std::vector<float> none;
  facyl::TabletopSegmentationParameters edge, euclid, lattice;
  euclid.clustering = facyl::TabletopSegmentationParameters::Clustering::Euclidean;
  lattice.lattice_width = 640;
  const facyl::PinholeCamera vga_camera{525.f, 525.f, 319.5f, 239.5f, 640, 480};
  struct Run {
    const Cloud::Ptr cloud;
    const facyl::TabletopSegmentationParameters& params;
    facyl::PinholeCamera camera;
  };
  const std::vector<Run> runs = {
    {vga, edge, {}},     {qvga, edge, {}},     {points, edge, vga_camera}, {big, lattice, {}},
    {other, euclid, {}}, {vga, euclid, {}},    {qvga, euclid, {}},         {vga, euclid, {}},
    {vga, edge, {}},     {points, euclid, {}},
  };
  facyl::TabletopWorkspace used;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    SCOPED_TRACE("run " + std::to_string(r));
    used.threads = r % 2 ? 1 : 3;
    const facyl::PointFrame f = facyl::pointFrame(*runs[r].cloud, nullptr, none);
    const facyl::TabletopSegments again =
      facyl::segmentTabletop(f, runs[r].camera, Eigen::Vector3f::Zero(), runs[r].params, used);
    const facyl::TabletopSegments fresh = segmentFresh(f, runs[r].params, runs[r].camera);
    ASSERT_FALSE(fresh.clusters.empty());
    expectSame(again, fresh);
  }
}

TEST(SegmentTabletop, TheFrontIsTheCore)
{
  // TabletopSegmentation on a cloud in the sensor's frame gives segmentTabletop's results on
  // the cloud's points, with its header; with given indices too; and its workspace, a copy's
  // or its own, changes nothing from frame to frame.
  const Cloud::Ptr cloud = frame(21);
  cloud->header.frame_id = "camera";
  pcl::IndicesPtr some(new pcl::Indices);
  for (std::size_t i = 0; i < cloud->size(); ++i)
    if (i % 640 >= 60)
      some->push_back(static_cast<pcl::index_t>(i));
  facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
  seg.setInputCloud(cloud);
  std::vector<float> none;
  for (const pcl::IndicesPtr& indices : {pcl::IndicesPtr(), some}) {
    if (indices)
      seg.setIndices(indices);
    auto copy = seg; // a copy starts with a new workspace
    for (auto* s : {&seg, &copy}) {
      std::vector<facyl::TabletopCluster> clusters;
      ASSERT_TRUE(s->segment(clusters));
      const facyl::TabletopSegments core = segmentFresh(
        facyl::pointFrame(*cloud, indices.get(), none), facyl::TabletopSegmentationParameters{});
      ASSERT_EQ(clusters.size(), core.clusters.size());
      ASSERT_GE(clusters.size(), 3u);
      for (std::size_t k = 0; k < clusters.size(); ++k) {
        EXPECT_EQ(clusters[k].indices.indices, core.clusters[k].indices.indices);
        EXPECT_EQ(clusters[k].centroid, core.clusters[k].centroid);
        EXPECT_EQ(clusters[k].indices.header.frame_id, "camera");
      }
      ASSERT_EQ(s->getSupports().size(), core.supports.size());
      EXPECT_EQ(s->getTableIndices().indices, core.supports[core.table].inliers.indices);
      EXPECT_EQ(s->getFocalLength(), core.focal);
      const Eigen::Vector4f& plane = core.supports[core.table].plane;
      EXPECT_EQ(s->getTableCoefficients().values,
                std::vector<float>({plane[0], plane[1], plane[2], plane[3]}));
      EXPECT_EQ(s->getTableHull().size(), core.supports[core.table].polygon.size());
    }
  }
}

TEST(SegmentTabletop, PointFrameReadsTheCloudOrACopyOfItsCoordinates)
{
  // PCL's types start with x, y, z: the frame reads the cloud itself. A type whose
  // coordinates come later is copied, and segments as the same points in PointXYZ do.
  const Cloud::Ptr cloud = frame(26);
  std::vector<float> buffer;
  const facyl::PointFrame own = facyl::pointFrame(*cloud, nullptr, buffer);
  EXPECT_EQ(own.xyz, reinterpret_cast<const float*>(cloud->points.data()));
  EXPECT_EQ(own.stride, sizeof(pcl::PointXYZRGBA) / sizeof(float));
  EXPECT_TRUE(buffer.empty());
  EXPECT_EQ(own.size, cloud->size());
  EXPECT_TRUE(own.isOrganized());
  // Its colours too (blue, green, red at the rgba field), for the colour edges.
  EXPECT_EQ(own.bgr, reinterpret_cast<const std::uint8_t*>(&cloud->points.front().rgba));
  EXPECT_EQ(own.bgr_stride, sizeof(pcl::PointXYZRGBA));
  EXPECT_EQ(own.bgr[1000 * own.bgr_stride + 2], (*cloud)[1000].r);
  // Without colour (as the copy below), the same points segment as PointXYZ's do.
  facyl::PointFrame own_xyz = own;
  own_xyz.bgr = nullptr;

  pcl::PointCloud<TrailingXyz>::Ptr trailing(new pcl::PointCloud<TrailingXyz>);
  trailing->resize(cloud->size());
  trailing->width = cloud->width;
  trailing->height = cloud->height;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    (*trailing)[i].intensity = 0.5f;
    (*trailing)[i].getVector3fMap() = (*cloud)[i].getVector3fMap();
  }
  const facyl::PointFrame copied = facyl::pointFrame(*trailing, nullptr, buffer);
  EXPECT_EQ(copied.xyz, buffer.data());
  EXPECT_EQ(copied.stride, 4u);
  ASSERT_EQ(buffer.size(), 4 * cloud->size());
  EXPECT_EQ(std::memcmp(copied.xyz + 4 * 1000, &(*cloud)[1000].x, 3 * sizeof(float)), 0);
  EXPECT_EQ(copied.bgr, nullptr);
  const facyl::TabletopSegmentationParameters p;
  expectSame(segmentFresh(copied, p), segmentFresh(own_xyz, p));
  // The front on that type, through the same copy.
  facyl::TabletopSegmentation<TrailingXyz> seg;
  seg.setInputCloud(trailing);
  std::vector<facyl::TabletopCluster> clusters;
  ASSERT_TRUE(seg.segment(clusters));
  const facyl::TabletopSegments core = segmentFresh(own_xyz, p);
  ASSERT_EQ(clusters.size(), core.clusters.size());
  for (std::size_t k = 0; k < clusters.size(); ++k)
    EXPECT_EQ(clusters[k].indices.indices, core.clusters[k].indices.indices);
}

TEST(SegmentTabletop, LatticeStepOfAFrame)
{
  facyl::TabletopSegmentationParameters p;
  facyl::PointFrame f;
  f.width = 1280;
  f.height = 720;
  f.size = 1280u * 720u;
  EXPECT_EQ(facyl::latticeStep(f, p), 1); // off by default
  p.lattice_width = 640;
  EXPECT_EQ(facyl::latticeStep(f, p), 2);
  p.lattice_width = 500;
  EXPECT_EQ(facyl::latticeStep(f, p), 3); // round(2.56)
  p.lattice_width = 854;
  EXPECT_EQ(facyl::latticeStep(f, p), 1); // not wider than 1.5 times it
  p.lattice_width = 853;
  EXPECT_EQ(facyl::latticeStep(f, p), 2);
  p.lattice_width = 640;
  const pcl::Indices some{0, 1, 2};
  f.indices = &some;
  EXPECT_EQ(facyl::latticeStep(f, p), 1); // given indices: every pixel
  f.indices = nullptr;
  f.height = 1; // a point set
  f.width = f.size = 1280u * 720u;
  EXPECT_EQ(facyl::latticeStep(f, p), 1);
  f.width = 1920;
  f.height = 12; // organized, but too few plane-grid cells high to be searched as an image
  f.size = 1920u * 12u;
  EXPECT_EQ(facyl::latticeStep(f, p), 1);
}

TEST(SegmentTabletop, LatticeSettingsScaleCountsNotLengths)
{
  facyl::TabletopSegmentationParameters p;
  p.plane_step = 6;
  p.max_cluster_size = 100000;
  const facyl::TabletopSegmentationParameters l = facyl::latticeParameters(p, 2);
  // Counts of points by 1 / step^2, the plane grid's block by 1 / step.
  EXPECT_EQ(l.min_plane_points, p.min_plane_points / 4);
  EXPECT_EQ(l.min_cluster_size, p.min_cluster_size / 4);
  EXPECT_EQ(l.max_cluster_size, 25000u);
  EXPECT_EQ(l.objects.min_fragment, p.objects.min_fragment / 4);
  EXPECT_EQ(l.plane_step, 3);
  // Lengths, angles, areas and the rest stay.
  EXPECT_EQ(l.cluster_tolerance, p.cluster_tolerance);
  EXPECT_EQ(l.max_height, p.max_height);
  EXPECT_EQ(l.min_support_area, p.min_support_area);
  EXPECT_EQ(l.objects.min_gap, p.objects.min_gap);
  EXPECT_EQ(l.objects.max_gap, p.objects.max_gap);
  EXPECT_EQ(l.plane_angle, p.plane_angle);
  EXPECT_EQ(l.lattice_width, p.lattice_width);
  EXPECT_TRUE(facyl::validate(l).empty());
  // Counts stay at least 1, the largest cluster at least the smallest; an automatic block
  // size stays automatic (it follows the lattice's width).
  facyl::TabletopSegmentationParameters small;
  small.min_plane_points = 3;
  small.min_cluster_size = 1;
  small.max_cluster_size = 3;
  small.objects.min_fragment = 2;
  small.plane_step = 2;
  const facyl::TabletopSegmentationParameters s = facyl::latticeParameters(small, 3);
  EXPECT_EQ(s.min_plane_points, 1u);
  EXPECT_EQ(s.min_cluster_size, 1u);
  EXPECT_EQ(s.max_cluster_size, 1u);
  EXPECT_EQ(s.objects.min_fragment, 1u);
  EXPECT_EQ(s.plane_step, 1);
  EXPECT_EQ(facyl::latticeParameters(facyl::TabletopSegmentationParameters{}, 2).plane_step, 0);
  // The camera of the lattice: intrinsics by 1 / step, the lattice's image; an unknown one
  // stays unknown.
  const facyl::PinholeCamera c = facyl::latticeCamera(
    facyl::PinholeCamera{1050.f, 1040.f, 639.5f, 359.5f, 1280, 720}, 2, 640, 360);
  EXPECT_FLOAT_EQ(c.fx, 525.f);
  EXPECT_FLOAT_EQ(c.fy, 520.f);
  EXPECT_FLOAT_EQ(c.cx, 319.75f);
  EXPECT_FLOAT_EQ(c.cy, 179.75f);
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 360);
  EXPECT_FALSE(facyl::latticeCamera(facyl::PinholeCamera{}, 2, 640, 360).valid());
}

TEST(SegmentTabletop, RejectsWhatItCannotSegment)
{
  const Cloud::Ptr cloud = frame(21);
  std::vector<float> none;
  const facyl::PointFrame f = facyl::pointFrame(*cloud, nullptr, none);
  facyl::TabletopWorkspace w;
  facyl::TabletopSegmentationParameters bad;
  bad.max_planes = 0;
  facyl::TabletopSegmentation<pcl::PointXYZ> seg;
  EXPECT_EQ(seg.getNumberOfThreads(), 0u);
  seg.setNumberOfThreads(2);
  EXPECT_EQ(seg.getNumberOfThreads(), 2u);
  EXPECT_THROW(seg.setNumberOfThreads(65), std::invalid_argument);
  EXPECT_THROW(facyl::segmentTabletop(f, {}, Eigen::Vector3f::Zero(), bad, w),
               std::invalid_argument);
  const facyl::TabletopSegmentationParameters p;
  EXPECT_THROW(facyl::segmentTabletop(f, {}, Eigen::Vector3f(0.f, NAN, 1.f), p, w),
               std::invalid_argument);
  EXPECT_THROW(facyl::segmentTabletop(f, facyl::PinholeCamera{525.f, 525.f, 0.f, 0.f, 9000, 10},
                                      Eigen::Vector3f::Zero(), p, w),
               std::invalid_argument);
  facyl::PointFrame no_memory = f;
  no_memory.xyz = nullptr;
  EXPECT_THROW(facyl::segmentTabletop(no_memory, {}, Eigen::Vector3f::Zero(), p, w),
               std::invalid_argument);
  facyl::PointFrame narrow = f;
  narrow.stride = 2;
  EXPECT_THROW(facyl::segmentTabletop(narrow, {}, Eigen::Vector3f::Zero(), p, w),
               std::invalid_argument);
  // An empty frame is no error: nothing found.
  const facyl::TabletopSegments empty =
    facyl::segmentTabletop(facyl::PointFrame{}, {}, Eigen::Vector3f::Zero(), p, w);
  EXPECT_TRUE(empty.clusters.empty());
  EXPECT_TRUE(empty.supports.empty());
}
