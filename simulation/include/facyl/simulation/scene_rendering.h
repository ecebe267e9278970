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
 * (infinity where no surface), |cos| of the incidence angle, the shaded colour, the id
 * and class of the surface (as in RenderedScene) and its material. */
struct RayCastImage {
  int width{0}, height{0};
  std::vector<float> depth;
  std::vector<float> incidence;
  std::vector<Eigen::Vector3f> colour; ///< RGB in [0, 1]
  std::vector<std::uint16_t> id;
  std::vector<SceneClass> cls;
  std::vector<SurfaceMaterial> material; ///< empty: the reference material everywhere
};

/** \brief Ray casts \a scene through every pixel of \a camera: table (rectangle or disc at
 * z = 0, curved by its top_sag), floor, wall, furniture, objects and scenery, with Lambertian
 * shading, textures and the highlights of glossy surfaces. */
RayCastImage castRays(const TabletopScene& scene, const CameraIntrinsics& camera);

/** \brief True if a pixel of \a image sees a transparent surface. */
bool hasTransparentSurfaces(const RayCastImage& image);

/** \brief What lies behind the transparent surfaces of \a front: the pixels whose surface is
 * transparent, cast again through the transparent objects; the others are empty (infinite
 * depth). */
RayCastImage castRaysBehindTransparent(const TabletopScene& scene, const CameraIntrinsics& camera,
                                       const RayCastImage& front);

/** \brief Resolves the transparent pixels of \a image: their colour mixes in what lies
 * \a behind (castRaysBehindTransparent) by the transparency; with probability transparency x
 * sensor.see_through the pixel becomes the surface behind (depth, incidence, material, id,
 * class), otherwise it keeps its weak front return. Deterministic for a seed. */
void seeThroughTransparent(RayCastImage& image, const RayCastImage& behind,
                           const DepthSensorModel& sensor, std::uint64_t seed);

/** \brief Applies \a sensor to \a image: range limits, missing pixels (grazing angles, depth
 * edges, random dropouts, speckled holes, weak returns of dark, glossy and transparent
 * surfaces, highlights), edge fattening, flying pixels, systematic bias, axial noise,
 * disparity quantisation, colour noise and colour/depth misregistration (sensor_effects.h
 * holds the numerics). sensor.randomize is ignored here (see drawSensor). Fills \a cloud
 * (organized, camera frame, NaN without depth) and counts the pixels with depth of object id
 * 2 + k in visible_pixels[k] (sized by the caller: one per object).
 * Deterministic for a seed on every platform. */
void applySensorModel(const RayCastImage& image, const CameraIntrinsics& camera,
                      const DepthSensorModel& sensor, std::uint64_t seed,
                      pcl::PointCloud<pcl::PointXYZRGBA>& cloud,
                      std::vector<std::size_t>& visible_pixels);

} // namespace facyl
