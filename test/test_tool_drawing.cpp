/*
 * The tools' drawing (apps/common): colours by depth for clouds without colour
 * (depth_colours.h), the overlays' canvas (overlay_canvas.h) and what facyl_detect's overlay
 * draws of an object (detect_overlay.h).
 */
#include <facyl/tools/depth_colours.h>
#include <facyl/tools/detect_overlay.h>
#include <facyl/tools/overlay_canvas.h>

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

using Colour = std::array<unsigned char, 3>;

facyl_cli::Canvas
blankCanvas(int width, int height, unsigned char grey)
{
  facyl_cli::Canvas canvas;
  canvas.width = width;
  canvas.height = height;
  canvas.rgb.assign(3 * static_cast<std::size_t>(width) * height, grey);
  return canvas;
}

Colour
pixel(const facyl_cli::Canvas& canvas, int u, int v)
{
  const auto* p = &canvas.rgb[3 * (static_cast<std::size_t>(v) * canvas.width + u)];
  return {p[0], p[1], p[2]};
}

TEST(OverlayCanvas, DashedLinesAlternateAlongAPolyline)
{
  auto canvas = blankCanvas(40, 3, 0);
  const Colour white{255, 255, 255}, black{0, 0, 0};
  // Two segments of one dashed polyline, 4 pixels on and 4 off: the pattern runs on.
  const float travelled = canvas.line({0.f, 1.f}, {10.f, 1.f}, white, 1, 4);
  EXPECT_FLOAT_EQ(travelled, 10.f);
  canvas.line({10.f, 1.f}, {39.f, 1.f}, white, 1, 4, travelled);
  for (int u = 0; u < 39; ++u)
    EXPECT_EQ(pixel(canvas, u, 1), u % 8 < 4 ? white : black) << u;
  // Solid (dash 0) draws every pixel, as it always did.
  auto solid = blankCanvas(40, 3, 0);
  solid.line({0.f, 1.f}, {39.f, 1.f}, white);
  for (int u = 0; u < 40; ++u)
    EXPECT_EQ(pixel(solid, u, 1), white) << u;
}

TEST(OverlayCanvas, LabelsAreGlyphsOnBlack)
{
  const Colour green{0, 230, 0}, black{0, 0, 0};
  EXPECT_EQ(facyl_cli::labelSize("#12", 2), Eigen::Vector2i(38, 18));
  auto canvas = blankCanvas(50, 30, 128);
  facyl_cli::drawLabel(canvas, 3, 4, "#1", green, 2);
  // '#' starts one font pixel in; its top row is .#.#. ; '1' (second glyph) .. #..
  const auto font = [&](int glyph, int col, int row) {
    return pixel(canvas, 3 + (6 * glyph + 1) * 2 + 2 * col, 4 + 2 + 2 * row);
  };
  EXPECT_EQ(font(0, 0, 0), black);
  EXPECT_EQ(font(0, 1, 0), green);
  EXPECT_EQ(font(0, 3, 0), green);
  EXPECT_EQ(font(0, 0, 2), green); // the crossbar: #####
  EXPECT_EQ(font(1, 2, 0), green);
  EXPECT_EQ(font(1, 0, 0), black);
  EXPECT_EQ(pixel(canvas, 3, 4), black);                   // the backing's corner
  EXPECT_EQ(pixel(canvas, 3 + 26 - 1, 4 + 18 - 1), black); // and the opposite one
  EXPECT_EQ(pixel(canvas, 3 + 26, 4), (Colour{128, 128, 128}));
  EXPECT_EQ(facyl_cli::labelGlyph('x'), (std::array<std::uint8_t, 7>{})); // a gap
}

TEST(DetectOverlay, TrackedObjectsShowTheirIdInTheTracksColour)
{
  const Colour green{0, 230, 0}, red{230, 0, 0}, grey{128, 128, 128};
  auto canvas = blankCanvas(200, 120, 128); // scale 1: 120 rows
  facyl_cli::OverlayObject cylinder, other, untracked;
  cylinder.box = {20, 40, 60, 100};
  cylinder.is_cylinder = true;
  cylinder.track_id = 7;
  other.box = {100, 2, 150, 50}; // no room above: the label goes inside
  other.track_id = 12;
  untracked.box = {160, 60, 190, 90};
  facyl_cli::drawOverlayObjects(canvas, facyl::PinholeCamera{}, {cylinder, other, untracked});
  EXPECT_EQ(pixel(canvas, 20, 70), green); // the boxes in the decision's colour
  EXPECT_EQ(pixel(canvas, 100, 30), red);
  const Eigen::Vector2i size = facyl_cli::labelSize("#7", 1);
  // "#7" above the cylinder's box: black backing, '#' top row .#.#.
  EXPECT_EQ(pixel(canvas, 20, 40 - size.y() - 1), (Colour{0, 0, 0}));
  EXPECT_EQ(pixel(canvas, 20 + 1 + 1, 40 - size.y()), green);
  // "#12" inside the other box's top (2 pixels below its top edge).
  EXPECT_EQ(pixel(canvas, 100 + 1 + 1, 2 + 2 + 1), red);
  // Nothing over the untracked box.
  for (int v = 40; v < 60; ++v)
    EXPECT_EQ(pixel(canvas, 170, v), grey) << v;
}

} // namespace
