/*
 * facyl: fast cylinder detection for PCL.
 * Depth sensor models applied to a ray-cast image: structured light, active stereo and
 * time of flight, with their response to materials (docs/simulation.md).
 */
#include <facyl/simulation/random.h>
#include <facyl/simulation/scene_rendering.h>
#include <facyl/simulation/sensor_effects.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facyl {

DepthSensorModel
DepthSensorModel::structuredLight()
{
  return DepthSensorModel{};
}

DepthSensorModel
DepthSensorModel::activeStereo()
{
  DepthSensorModel s;
  s.noise_coefficient = 3e-3f; // ~3 mm at 1 m, 12 mm at 2 m
  s.baseline_focal = 0.05f * 615.f;
  s.disparity_step = 1.f / 32.f;
  s.edge_jump = 0.03f;
  s.grazing_cos = 0.1f;
  s.dropout = 0.004f;
  s.hole_rate = 0.0015f; // about 3% of the pixels in blobs
  s.hole_radius = 2.5f;
  s.edge_fattening = 0.5f;
  s.colour_shift_u = 2;
  s.colour_shift_v = 1;
  s.min_range = 0.28f;
  s.colour_noise = 0.03f;
  return s;
}

CameraIntrinsics
resizedCamera(const CameraIntrinsics& camera, int width, int height)
{
  CameraIntrinsics c = camera;
  const float su = static_cast<float>(width) / static_cast<float>(camera.width);
  const float sv = static_cast<float>(height) / static_cast<float>(camera.height);
  c.fx *= su;
  c.fy *= sv;
  c.cx = (camera.cx + 0.5f) * su - 0.5f;
  c.cy = (camera.cy + 0.5f) * sv - 0.5f;
  c.width = width;
  c.height = height;
  return c;
}

bool
parseSensorPreset(const std::string& name, DepthSensorModel& sensor, CameraIntrinsics& camera)
{
  if (name == "kinect") {
    sensor = DepthSensorModel::structuredLight();
    camera = CameraIntrinsics{};
    return true;
  }
  if (name == "stereo") {
    sensor = DepthSensorModel::activeStereo();
    camera = CameraIntrinsics{};
    camera.fx = camera.fy = 615.f;
    return true;
  }
  if (name == "random") {
    sensor = DepthSensorModel::structuredLight();
    sensor.randomize = true;
    camera = CameraIntrinsics{};
    return true;
  }
  return false;
}

namespace {

/** Pixels inside blobs of missing depth (speckled holes of stereo matching). */
std::vector<std::uint8_t>
holeMask(int w, int h, const DepthSensorModel& sensor, Random& rng)
{
  std::vector<std::uint8_t> hole(static_cast<std::size_t>(w) * h, 0);
  if (sensor.hole_rate <= 0.f)
    return hole;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      if (!rng.chance(sensor.hole_rate))
        continue;
      const float r = sensor.hole_radius * rng.uniform(0.5f, 1.5f);
      const int ri = static_cast<int>(std::ceil(r));
      for (int dv = -ri; dv <= ri; ++dv)
        for (int du = -ri; du <= ri; ++du) {
          const int uu = u + du, vv = v + dv;
          if (uu >= 0 && vv >= 0 && uu < w && vv < h &&
              static_cast<float>(du * du + dv * dv) <= r * r)
            hole[static_cast<std::size_t>(vv) * w + uu] = 1;
        }
    }
  return hole;
}

/** True if a 4-neighbour of (u, v) has no surface or a depth jump > edge_jump * z. */
bool
besideJump(const RayCastImage& image, int u, int v, float z, float edge_jump)
{
  for (const auto& [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
    const int uu = u + du, vv = v + dv;
    if (uu < 0 || vv < 0 || uu >= image.width || vv >= image.height)
      continue;
    const float zn = image.depth[static_cast<std::size_t>(vv) * image.width + uu];
    if (!std::isfinite(zn) || std::abs(zn - z) > edge_jump * z)
      return true;
  }
  return false;
}

/** The depth of the nearest 4-neighbour in front of (u, v) by more than edge_jump * z, or
 * NaN: where stereo matching spreads a foreground edge over the background. */
float
foregroundBeside(const RayCastImage& image, int u, int v, float z, float edge_jump)
{
  float best = std::numeric_limits<float>::quiet_NaN();
  for (const auto& [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
    const int uu = u + du, vv = v + dv;
    if (uu < 0 || vv < 0 || uu >= image.width || vv >= image.height)
      continue;
    const float zn = image.depth[static_cast<std::size_t>(vv) * image.width + uu];
    if (std::isfinite(zn) && zn < z - edge_jump * z && !(zn >= best))
      best = zn;
  }
  return best;
}

/** The depth of the 4-neighbour farthest from z, if it differs by more than edge_jump * z,
 * or NaN: the other side of a depth edge. */
float
acrossJump(const RayCastImage& image, int u, int v, float z, float edge_jump)
{
  float best = std::numeric_limits<float>::quiet_NaN(), gap = edge_jump * z;
  for (const auto& [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
    const int uu = u + du, vv = v + dv;
    if (uu < 0 || vv < 0 || uu >= image.width || vv >= image.height)
      continue;
    const float zn = image.depth[static_cast<std::size_t>(vv) * image.width + uu];
    if (std::isfinite(zn) && std::abs(zn - z) > gap) {
      gap = std::abs(zn - z);
      best = zn;
    }
  }
  return best;
}

/** A flying pixel (time of flight: the pixel mixes the returns of both sides of a depth edge):
 * with probability flying_pixels, \a z moves to a random point between itself and the other
 * side. \return false if the pixel does not fly. */
bool
flyingDepth(const RayCastImage& image, int u, int v, const DepthSensorModel& sensor, Random& rng,
            float& z)
{
  if (!(sensor.flying_pixels > 0.f) || !rng.chance(sensor.flying_pixels))
    return false;
  const float other = acrossJump(image, u, v, z, sensor.edge_jump);
  if (!std::isfinite(other))
    return false;
  z += static_cast<float>(rng.unit()) * (other - z);
  return true;
}

SurfaceMaterial
materialAt(const RayCastImage& image, std::size_t idx)
{
  return image.material.empty() ? SurfaceMaterial{} : image.material[idx];
}

/** Blobs of missing depth on surfaces of weak return (weakReturnDropout), each kept within the
 * surface (pixel id) it starts on; empty when every surface returns fully. */
std::vector<std::uint8_t>
weakReturnMask(const RayCastImage& image, const DepthSensorModel& sensor, Random& rng)
{
  constexpr float kRadius = 2.5f; // mean blob radius (px); radii are kRadius * U(0.6, 1.4)
  constexpr float kMeanArea = 3.14159265f * kRadius * kRadius * 1.0533f; // pi E[r^2]
  const int w = image.width, h = image.height;
  std::vector<std::uint8_t> mask;
  if (image.material.empty())
    return mask;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t idx = static_cast<std::size_t>(v) * w + u;
      if (!std::isfinite(image.depth[idx]))
        continue;
      const float p = weakReturnDropout(sensor, diffuseReturn(image.material[idx]));
      if (!(p > 0.f))
        continue;
      // Blob centres at the rate that covers a share p of a uniform surface:
      // 1 - exp(-rate * area) = p.
      const float rate = -std::log(1.f - std::min(p, 0.95f)) / kMeanArea;
      if (!rng.chance(rate))
        continue;
      if (mask.empty())
        mask.assign(static_cast<std::size_t>(w) * h, 0);
      const float r = kRadius * rng.uniform(0.6f, 1.4f);
      const int ri = static_cast<int>(std::ceil(r));
      for (int dv = -ri; dv <= ri; ++dv)
        for (int du = -ri; du <= ri; ++du) {
          const int uu = u + du, vv = v + dv;
          const std::size_t k = static_cast<std::size_t>(vv) * w + uu;
          if (uu >= 0 && vv >= 0 && uu < w && vv < h &&
              static_cast<float>(du * du + dv * dv) <= r * r && image.id[k] == image.id[idx])
            mask[k] = 1;
        }
    }
  return mask;
}

/** Seed offset of the random numbers of the effects added after the first sensor model (weak
 * returns, highlights, flying pixels): the pixels of the older effects draw the same numbers
 * as before. */
constexpr std::uint64_t kEffectsStream = 0x2545f4914f6cdd1dULL;

} // namespace

void
applySensorModel(const RayCastImage& image, const CameraIntrinsics& camera,
                 const DepthSensorModel& sensor, std::uint64_t seed,
                 pcl::PointCloud<pcl::PointXYZRGBA>& cloud,
                 std::vector<std::size_t>& visible_pixels)
{
  const int w = image.width, h = image.height;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  Random rng(seed ^ 0x9e3779b97f4a7c15ULL);
  Random effects(seed ^ kEffectsStream);
  const std::vector<std::uint8_t> hole = holeMask(w, h, sensor, rng);
  const std::vector<std::uint8_t> weak = weakReturnMask(image, sensor, effects);
  cloud.width = static_cast<std::uint32_t>(w);
  cloud.height = static_cast<std::uint32_t>(h);
  cloud.is_dense = false;
  cloud.resize(n);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t idx = static_cast<std::size_t>(v) * w + u;
      pcl::PointXYZRGBA& pt = cloud[idx];
      // Colour, seen a few pixels off the depth (misregistration).
      const int cu = std::clamp(u + sensor.colour_shift_u, 0, w - 1);
      const int cv = std::clamp(v + sensor.colour_shift_v, 0, h - 1);
      Eigen::Vector3f c = image.colour[static_cast<std::size_t>(cv) * w + cu];
      for (int k = 0; k < 3; ++k)
        c[k] = std::clamp(c[k] + sensor.colour_noise * rng.normal(), 0.f, 1.f);
      pt.r = static_cast<std::uint8_t>(std::lround(255.f * c[0]));
      pt.g = static_cast<std::uint8_t>(std::lround(255.f * c[1]));
      pt.b = static_cast<std::uint8_t>(std::lround(255.f * c[2]));
      pt.a = 255;
      pt.x = pt.y = pt.z = nan;
      float z = image.depth[idx];
      const float noise = rng.normal();
      const float drop = static_cast<float>(rng.unit());
      const float fatten = static_cast<float>(rng.unit());
      const SurfaceMaterial material = materialAt(image, idx);
      const float rho = diffuseReturn(material); // 1 on the reference material
      const float cos_incidence = image.incidence[idx];
      if (!std::isfinite(z) || rho * cos_incidence < sensor.grazing_cos || drop < sensor.dropout ||
          hole[idx])
        continue;
      if (!weak.empty() && weak[idx])
        continue;
      if (material.gloss > 0.f &&
          effects.chance(highlightProbability(sensor, material.gloss, cos_incidence)))
        continue;
      if (sensor.edge_jump > 0.f && besideJump(image, u, v, z, sensor.edge_jump)) {
        const float front = foregroundBeside(image, u, v, z, sensor.edge_jump);
        if (fatten < sensor.edge_fattening && std::isfinite(front))
          z = front; // the foreground spreads over this background pixel
        else if (!flyingDepth(image, u, v, sensor, effects, z))
          continue;
      }
      if (z < sensor.min_range || z > reach(sensor, rho))
        continue;
      z +=
        depthBias(sensor, z, radialPosition2(camera, static_cast<float>(u), static_cast<float>(v)),
                  cos_incidence);
      z += axialNoiseSigma(sensor, z, rho) * noise;
      if (sensor.disparity_step > 0.f) {
        const float disparity = sensor.baseline_focal / z;
        z = sensor.baseline_focal /
            (std::round(disparity / sensor.disparity_step) * sensor.disparity_step);
      }
      pt.x = (static_cast<float>(u) - camera.cx) / camera.fx * z;
      pt.y = (static_cast<float>(v) - camera.cy) / camera.fy * z;
      pt.z = z;
    }
  std::fill(visible_pixels.begin(), visible_pixels.end(), 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = image.id[i] - 2u;
    if (image.id[i] >= 2 && k < visible_pixels.size() && std::isfinite(cloud[i].z))
      ++visible_pixels[k];
  }
}

} // namespace facyl
