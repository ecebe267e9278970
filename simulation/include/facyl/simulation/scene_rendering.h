/*
 * facyl: fast cylinder detection for PCL.
 * The two stages of renderTabletopScene, for tests and for other sensors: exact ray casting
 * of the analytic scene, then the depth sensor model.
 */
#pragma once

#include <facyl/simulation/tabletop_scene.h>

#include <cstdint>
#include <vector>

namespace facyl {

/** \brief What an ideal camera sees: per pixel (row major) the depth along the optical axis
 * (infinity where no surface), |cos| of the incidence angle, the shaded colour, and the id
 * and class of the surface (as in RenderedScene). */
struct RayCastImage {
  int width{0}, height{0};
  std::vector<float> depth;
  std::vector<float> incidence;
  std::vector<Eigen::Vector3f> colour; ///< RGB in [0, 1]
  std::vector<std::uint16_t> id;
  std::vector<SceneClass> cls;
};

/** \brief Ray casts \a scene through every pixel of \a camera: table (rectangle or disc at
 * z = 0), floor, wall, furniture and objects, with Lambertian shading and textures. */
RayCastImage
castRays(const TabletopScene& scene, const CameraIntrinsics& camera);

/** \brief Applies \a sensor to \a image: range limits, missing pixels (grazing angles, depth
 * edges, random dropouts, speckled holes), edge fattening, axial noise, disparity
 * quantisation, colour noise and colour/depth misregistration. Fills \a cloud (organized,
 * camera frame, NaN without depth) and counts the pixels with depth of object id 2 + k in
 * visible_pixels[k] (sized by the caller: one per object).
 * Deterministic for a seed on every platform. */
void
applySensorModel(const RayCastImage& image, const CameraIntrinsics& camera,
                 const DepthSensorModel& sensor, std::uint64_t seed,
                 pcl::PointCloud<pcl::PointXYZRGBA>& cloud,
                 std::vector<std::size_t>& visible_pixels);

} // namespace facyl
