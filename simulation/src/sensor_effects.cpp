/*
 * facyl: fast cylinder detection for PCL.
 * Per-pixel numerics of the depth sensor model (see sensor_effects.h and
 * docs/simulation.md).
 */
#include <facyl/simulation/sensor_effects.h>

#include <algorithm>
#include <cmath>

namespace facyl {

float
diffuseReturn(const SurfaceMaterial& m)
{
  return m.reflectance * (1.f - m.gloss) * (1.f - m.transparency);
}

float
radialPosition2(const CameraIntrinsics& camera, float u, float v)
{
  const float du = u - camera.cx, dv = v - camera.cy;
  const float hw = 0.5f * static_cast<float>(camera.width);
  const float hh = 0.5f * static_cast<float>(camera.height);
  return (du * du + dv * dv) / (hw * hw + hh * hh);
}

float
depthBias(const DepthSensorModel& sensor, float z, float r2, float cos_incidence)
{
  if (sensor.depth_scale_error == 0.f && sensor.radial_depth_bias == 0.f &&
      sensor.incidence_bias == 0.f)
    return 0.f;
  // Beyond 84 degrees the offset stops growing (such pixels are mostly missing anyway).
  const float c = std::max(std::abs(cos_incidence), 0.1f);
  return sensor.depth_scale_error * z + sensor.radial_depth_bias * z * z * r2 +
         sensor.incidence_bias * z * (1.f / c - 1.f);
}

float
axialNoiseSigma(const DepthSensorModel& sensor, float z, float rho)
{
  float sigma = sensor.noise_coefficient * z * z;
  if (sensor.noise_constant > 0.f || sensor.noise_linear > 0.f)
    sigma += sensor.noise_constant + sensor.noise_linear * z;
  if (rho < 1.f) // fewer photons: the noise grows as 1 / sqrt(signal)
    sigma /= std::sqrt(std::max(rho, 0.01f));
  return sigma;
}

float
weakReturnDropout(const DepthSensorModel& sensor, float rho)
{
  if (!(rho < 1.f))
    return 0.f;
  const float deficit = 1.f - std::max(rho, 0.f);
  return sensor.weak_return_dropout * deficit * deficit;
}

float
highlightProbability(const DepthSensorModel& sensor, float gloss, float cos_incidence)
{
  if (!(gloss > 0.f) || !(sensor.highlight_width > 0.f))
    return 0.f;
  const float theta = std::acos(std::clamp(std::abs(cos_incidence), 0.f, 1.f));
  const float w = sensor.highlight_width;
  return std::min(1.f, 2.f * gloss * std::exp(-theta * theta / (2.f * w * w)));
}

float
reach(const DepthSensorModel& sensor, float rho)
{
  return rho < 1.f ? sensor.max_range * std::sqrt(std::max(rho, 0.f)) : sensor.max_range;
}

} // namespace facyl
