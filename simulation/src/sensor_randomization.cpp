/*
 * facyl: fast cylinder detection for PCL.
 * Domain randomization of the depth sensor: one frame's sensor drawn from its seed over
 * the ranges of real structured-light, active-stereo and time-of-flight cameras
 * (docs/simulation.md gives the sources of the ranges).
 */
#include <facyl/simulation/random.h>
#include <facyl/simulation/tabletop_scene.h>

namespace facyl {

namespace {

/** Seed offset of the sensor draw: independent of the scene's and the pixels' numbers. */
constexpr std::uint64_t kSensorStream = 0x6a09e667f3bcc909ULL;

float
draw(Random& rng, float lo, float hi)
{
  return rng.uniform(lo, hi);
}

/** Settings every family draws the same way: colour noise and misregistration. */
void
drawColour(Random& rng, int max_shift, DepthSensorModel& s)
{
  s.colour_noise = draw(rng, 0.01f, 0.04f);
  s.colour_shift_u = rng.integer(-max_shift, max_shift);
  s.colour_shift_v = rng.integer(-max_shift, max_shift);
}

/** Kinect v1-like: noise 1.2-3 mm at 1 m growing with z^2, 1/8 px disparity of a 7.5 cm
 * baseline, depth missing at edges (little fattening), calibration errors up to 1%. */
DepthSensorModel
structuredLight(Random& rng, float fx)
{
  DepthSensorModel s;
  s.noise_coefficient = draw(rng, 1.2e-3f, 3e-3f);
  s.baseline_focal = draw(rng, 0.072f, 0.078f) * fx;
  s.disparity_step = 0.125f;
  s.edge_jump = draw(rng, 0.02f, 0.05f);
  s.grazing_cos = draw(rng, 0.1f, 0.25f);
  s.dropout = draw(rng, 0.001f, 0.008f);
  s.hole_rate = draw(rng, 0.f, 8e-4f);
  s.hole_radius = draw(rng, 1.5f, 4.f);
  s.edge_fattening = draw(rng, 0.f, 0.15f);
  s.flying_pixels = draw(rng, 0.f, 0.05f);
  s.min_range = draw(rng, 0.45f, 0.6f);
  s.max_range = draw(rng, 3.5f, 4.5f);
  s.depth_scale_error = draw(rng, -0.01f, 0.01f);
  s.radial_depth_bias = draw(rng, -0.006f, 0.006f);
  s.incidence_bias = draw(rng, 0.f, 0.002f);
  s.weak_return_dropout = draw(rng, 0.4f, 0.9f);
  s.highlight_width = draw(rng, 0.06f, 0.2f);
  s.see_through = draw(rng, 0.f, 0.2f);
  drawColour(rng, 4, s);
  return s;
}

/** RealSense D4xx-like: RMS 0.4-2% of the depth at 2 m growing with z^2, 1/32-1/8 px
 * sub-pixel disparity of a 5-5.5 cm baseline, speckled holes, fattened edges. */
DepthSensorModel
activeStereo(Random& rng, float fx)
{
  DepthSensorModel s;
  s.noise_coefficient = draw(rng, 2e-3f, 1e-2f);
  s.baseline_focal = draw(rng, 0.05f, 0.055f) * fx;
  s.disparity_step = 1.f / static_cast<float>(8 << rng.integer(0, 2)); // 1/8, 1/16, 1/32
  s.edge_jump = draw(rng, 0.02f, 0.04f);
  s.grazing_cos = draw(rng, 0.05f, 0.15f);
  s.dropout = draw(rng, 0.002f, 0.01f);
  s.hole_rate = draw(rng, 5e-4f, 4e-3f);
  s.hole_radius = draw(rng, 1.5f, 4.f);
  s.edge_fattening = draw(rng, 0.3f, 0.9f);
  s.flying_pixels = draw(rng, 0.f, 0.1f);
  s.min_range = draw(rng, 0.2f, 0.35f);
  s.max_range = draw(rng, 4.f, 6.f);
  s.depth_scale_error = draw(rng, -0.015f, 0.015f);
  s.radial_depth_bias = draw(rng, -0.008f, 0.008f);
  s.incidence_bias = draw(rng, 0.f, 0.003f);
  s.weak_return_dropout = draw(rng, 0.2f, 0.7f); // the projector helps, passive texture too
  s.highlight_width = draw(rng, 0.05f, 0.2f);
  s.see_through = draw(rng, 0.f, 0.4f);
  drawColour(rng, 4, s);
  return s;
}

/** Azure Kinect-like: noise 0.5-2 mm plus up to 1.5 mm per m (nearly constant in z), no
 * disparity, flying pixels at edges, larger bias at grazing angles (multipath), glass
 * seen through. */
DepthSensorModel
timeOfFlight(Random& rng)
{
  DepthSensorModel s;
  s.noise_coefficient = draw(rng, 0.f, 5e-4f);
  s.noise_constant = draw(rng, 5e-4f, 2e-3f);
  s.noise_linear = draw(rng, 0.f, 1.5e-3f);
  s.disparity_step = 0.f;
  s.edge_jump = draw(rng, 0.01f, 0.03f);
  s.grazing_cos = draw(rng, 0.05f, 0.15f);
  s.dropout = draw(rng, 0.001f, 0.005f);
  s.hole_rate = draw(rng, 0.f, 3e-4f);
  s.hole_radius = 2.f;
  s.edge_fattening = 0.f;
  s.flying_pixels = draw(rng, 0.4f, 0.95f);
  s.min_range = draw(rng, 0.25f, 0.5f);
  s.max_range = draw(rng, 3.8f, 5.5f);
  s.depth_scale_error = draw(rng, -0.005f, 0.005f);
  s.radial_depth_bias = draw(rng, -0.004f, 0.004f);
  s.incidence_bias = draw(rng, 0.001f, 0.004f);
  s.weak_return_dropout = draw(rng, 0.5f, 0.95f); // amplitude invalidation
  s.highlight_width = draw(rng, 0.05f, 0.15f);
  s.see_through = draw(rng, 0.4f, 1.f);
  drawColour(rng, 2, s);
  return s;
}

} // namespace

std::string
toString(SensorFamily f)
{
  switch (f) {
  case SensorFamily::StructuredLight:
    return "structured_light";
  case SensorFamily::ActiveStereo:
    return "active_stereo";
  case SensorFamily::TimeOfFlight:
    return "time_of_flight";
  }
  return "unknown";
}

DrawnSensor
drawSensor(const CameraIntrinsics& base, std::uint64_t seed)
{
  Random rng(seed ^ kSensorStream);
  DrawnSensor d;
  d.family = static_cast<SensorFamily>(rng.integer(0, 2));
  d.camera = base;
  const float zoom = draw(rng, 0.9f, 1.2f); // horizontal fields of view of 54-68 degrees
  d.camera.fx *= zoom;
  d.camera.fy *= zoom;
  switch (d.family) {
  case SensorFamily::StructuredLight:
    d.sensor = structuredLight(rng, d.camera.fx);
    break;
  case SensorFamily::ActiveStereo:
    d.sensor = activeStereo(rng, d.camera.fx);
    break;
  case SensorFamily::TimeOfFlight:
    d.sensor = timeOfFlight(rng);
    break;
  }
  return d;
}

} // namespace facyl
