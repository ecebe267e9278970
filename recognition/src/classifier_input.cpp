/*
 * facyl: fast cylinder detection for PCL.
 * The classifier's input images, and objectView for the common point types.
 */
#include <facyl/recognition/impl/classifier_input.hpp>

#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facyl {

std::string
toString(ClassifierChannels channels)
{
  switch (channels) {
  case ClassifierChannels::Rgb:
    return "rgb";
  case ClassifierChannels::Depth:
    return "depth";
  case ClassifierChannels::DepthRgb:
    return "depthrgb";
  }
  return "unknown";
}

bool
parseClassifierChannels(const std::string& text, ClassifierChannels& channels)
{
  if (text == "rgb")
    channels = ClassifierChannels::Rgb;
  else if (text == "depth")
    channels = ClassifierChannels::Depth;
  else if (text == "depthrgb")
    channels = ClassifierChannels::DepthRgb;
  else
    return false;
  return true;
}

int
channelCount(ClassifierChannels channels)
{
  switch (channels) {
  case ClassifierChannels::Rgb:
    return 3;
  case ClassifierChannels::Depth:
    return 2;
  case ClassifierChannels::DepthRgb:
    return 5;
  }
  return 0;
}

namespace {

/** The square about the box's centre that the image samples: its left, top and side. */
struct Square {
  int u0, v0, side;
};

Square
squareOf(const PixelBox& b)
{
  const int w = b[2] - b[0] + 1, h = b[3] - b[1] + 1;
  const int side = std::max(w, h);
  return {b[0] - (side - w) / 2, b[1] - (side - h) / 2, side};
}

/** Source pixel (relative to the square) of image pixel i of size. */
inline int
sourceOf(int i, int size, int side)
{
  return static_cast<int>((static_cast<long long>(2 * i + 1) * side) / (2LL * size));
}

std::vector<std::uint8_t>
rgbImage(const ObjectView& view, const Square& sq, int size)
{
  const RgbImage& crop = view.crop;
  if (crop.empty())
    return {};
  std::vector<std::uint8_t> out(static_cast<std::size_t>(3 * size * size), 0);
  const std::size_t plane = static_cast<std::size_t>(size) * size;
  for (int y = 0; y < size; ++y) {
    const int v = sq.v0 + sourceOf(y, size, sq.side) - view.box[1];
    if (v < 0 || v >= crop.height)
      continue;
    for (int x = 0; x < size; ++x) {
      const int u = sq.u0 + sourceOf(x, size, sq.side) - view.box[0];
      if (u < 0 || u >= crop.width)
        continue;
      const std::uint8_t* px = &crop.data[3 * (static_cast<std::size_t>(v) * crop.width + u)];
      const std::size_t o = static_cast<std::size_t>(y) * size + x;
      out[o] = px[0];
      out[plane + o] = px[1];
      out[2 * plane + o] = px[2];
    }
  }
  return out;
}

std::vector<std::uint8_t>
depthImage(const ObjectView& view, const Square& sq, int size)
{
  // The object's depth per pixel of its square (NaN: not the object's).
  const int side = sq.side;
  std::vector<float> depth(static_cast<std::size_t>(side) * side,
                           std::numeric_limits<float>::quiet_NaN());
  std::vector<float> z;
  Eigen::Vector2f lo = Eigen::Vector2f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector2f hi = -lo;
  for (Eigen::Index k = 0; k < view.points.cols(); ++k) {
    const Eigen::Vector3f p = view.points.col(k);
    const int u = view.pixels(0, k) - sq.u0, v = view.pixels(1, k) - sq.v0;
    if (!p.allFinite() || view.pixels(0, k) < 0 || u < 0 || v < 0 || u >= side || v >= side)
      continue;
    depth[static_cast<std::size_t>(v) * side + u] = p.z();
    z.push_back(p.z());
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  if (z.empty())
    return {};
  std::nth_element(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2), z.end());
  const float median = z[z.size() / 2];
  const float extent = std::max(0.01f, (hi - lo).maxCoeff());
  std::vector<std::uint8_t> out(static_cast<std::size_t>(2 * size * size), 0);
  const std::size_t plane = static_cast<std::size_t>(size) * size;
  std::fill(out.begin() + static_cast<std::ptrdiff_t>(plane), out.end(), 128);
  for (int y = 0; y < size; ++y) {
    const int v = sourceOf(y, size, side);
    for (int x = 0; x < size; ++x) {
      const float d = depth[static_cast<std::size_t>(v) * side + sourceOf(x, size, side)];
      if (!std::isfinite(d))
        continue;
      const std::size_t o = static_cast<std::size_t>(y) * size + x;
      out[o] = 255;
      const float r = std::clamp((d - median) / extent, -1.f, 1.f);
      out[plane + o] = static_cast<std::uint8_t>(std::lround(128.f + 127.f * r));
    }
  }
  return out;
}

} // namespace

void
viewBox(ObjectView& view)
{
  PixelBox& b = view.box;
  b = {-1, -1, -1, -1};
  for (Eigen::Index k = 0; k < view.pixels.cols(); ++k) {
    const int u = view.pixels(0, k), v = view.pixels(1, k);
    if (u < 0)
      continue;
    if (b[0] < 0)
      b = {u, v, u, v};
    b = {std::min(b[0], u), std::min(b[1], v), std::max(b[2], u), std::max(b[3], v)};
  }
}

std::vector<std::uint8_t>
classifierImage(const ObjectView& view, const ClassifierInputSpec& spec)
{
  const PixelBox& b = view.box;
  if (b[0] < 0 || b[2] < b[0] || b[3] < b[1] || spec.size < 8 || spec.size > 512)
    return {};
  const Square sq = squareOf(b);
  if (spec.channels == ClassifierChannels::Rgb)
    return rgbImage(view, sq, spec.size);
  if (view.pixels.cols() != view.points.cols())
    return {};
  std::vector<std::uint8_t> depth = depthImage(view, sq, spec.size);
  if (spec.channels == ClassifierChannels::Depth || depth.empty())
    return depth;
  const std::vector<std::uint8_t> rgb = rgbImage(view, sq, spec.size);
  if (rgb.empty())
    return {};
  depth.insert(depth.end(), rgb.begin(), rgb.end());
  return depth;
}

} // namespace facyl

FACYL_INSTANTIATE_objectView(pcl::PointXYZ)
FACYL_INSTANTIATE_objectView(pcl::PointXYZRGB)
FACYL_INSTANTIATE_objectView(pcl::PointXYZRGBA)
