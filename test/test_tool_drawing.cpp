/*
 * The tools' drawing (apps/common): colours by depth for clouds without colour
 * (depth_colours.h).
 */
#include <facyl/tools/depth_colours.h>

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

int
warmth(const facyl_cli::Rgb8& c)
{
  return static_cast<int>(c[0]) - static_cast<int>(c[2]);
}

TEST(DepthColours, NearIsWarmFarIsCoolAndTheEndsAreClamped)
{
  using facyl_cli::depthColour;
  EXPECT_EQ(depthColour(0.f), (facyl_cli::Rgb8{180, 4, 38}));     // coolwarm's warm end
  EXPECT_EQ(depthColour(1.f), (facyl_cli::Rgb8{59, 76, 192}));    // its cool end
  EXPECT_EQ(depthColour(0.5f), (facyl_cli::Rgb8{221, 220, 220})); // light grey
  EXPECT_EQ(depthColour(-3.f), depthColour(0.f));
  EXPECT_EQ(depthColour(7.f), depthColour(1.f));
  EXPECT_EQ(depthColour(kNaN), depthColour(0.5f));
  // Warm (red over blue) on the near half, cool on the far half.
  for (int k = 0; k <= 100; ++k) {
    const int w = warmth(depthColour(static_cast<float>(k) / 100.f));
    EXPECT_TRUE(k < 50 ? w > 0 : k > 50 ? w < 0 : w == 1) << k << ": " << w;
  }
}

TEST(DepthColours, RangeIsThe2ndTo98thPercentile)
{
  std::vector<float> depths;
  for (int k = 0; k <= 1000; ++k)
    depths.push_back(1.f + k / 1000.f);
  depths.push_back(kNaN);
  for (int k = 0; k < 10; ++k)
    depths.push_back(500.f); // stray points far away
  const auto [lo, hi] = facyl_cli::depthRange(depths);
  EXPECT_NEAR(lo, 1.02f, 0.002f);
  EXPECT_NEAR(hi, 1.99f, 0.002f); // not flattened by the 1% of stray points
  const auto none = facyl_cli::depthRange({kNaN, kNaN});
  EXPECT_TRUE(std::isnan(none.first) && std::isnan(none.second));
}

/** Points along the sensor's optical axis from 1 m to 2 m, black (as read without colour),
 * and one without depth. */
pcl::PointCloud<pcl::PointXYZRGBA>
blackRay(const Eigen::Vector3f& direction)
{
  pcl::PointCloud<pcl::PointXYZRGBA> cloud;
  for (int k = 0; k <= 100; ++k) {
    pcl::PointXYZRGBA p;
    p.getVector3fMap() = (1.f + k / 100.f) * direction;
    cloud.push_back(p);
  }
  pcl::PointXYZRGBA nan;
  nan.x = nan.y = nan.z = kNaN;
  nan.r = 255; // a colour without a point is no colour
  cloud.push_back(nan);
  return cloud;
}

TEST(DepthColours, CloudWithoutColourIsColouredByDepth)
{
  auto cloud = blackRay(Eigen::Vector3f::UnitZ());
  EXPECT_FALSE(facyl_cli::hasColour(cloud));
  facyl_cli::colourByDepth(cloud);
  EXPECT_TRUE(facyl_cli::hasColour(cloud));
  const auto rgb = [&cloud](std::size_t i) {
    return facyl_cli::Rgb8{cloud[i].r, cloud[i].g, cloud[i].b};
  };
  EXPECT_EQ(rgb(0), facyl_cli::depthColour(0.f)); // nearer than the 2nd percentile: clamped
  EXPECT_EQ(rgb(100), facyl_cli::depthColour(1.f));
  EXPECT_EQ(rgb(50), facyl_cli::depthColour(0.5f));
  EXPECT_EQ(rgb(101), (facyl_cli::Rgb8{0, 0, 0})); // no depth: black, as an image without it
  EXPECT_EQ(cloud[50].a, 255);
}

TEST(DepthColours, DepthIsAlongTheSensorsAxis)
{
  // A sensor at the origin looking along the cloud's +x (its z turned onto x): depth is x.
  auto cloud = blackRay(Eigen::Vector3f::UnitX());
  for (std::size_t i = 0; i + 1 < cloud.size(); i += 2)
    cloud[i].z = 0.5f; // sideways of the axis: no change of depth
  cloud.sensor_orientation_ =
    Eigen::Quaternionf(Eigen::AngleAxisf(M_PI / 2, Eigen::Vector3f::UnitY()));
  const auto depths = facyl_cli::sensorDepths(cloud);
  for (std::size_t i = 0; i + 1 < cloud.size(); ++i)
    EXPECT_NEAR(depths[i], cloud[i].x, 1e-5f) << i;
  EXPECT_TRUE(std::isnan(depths.back()));
}

TEST(DepthColours, OneColouredPointIsColour)
{
  auto cloud = blackRay(Eigen::Vector3f::UnitZ());
  cloud[7].g = 1;
  EXPECT_TRUE(facyl_cli::hasColour(cloud));
}

} // namespace
