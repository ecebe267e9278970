/*
 * facyl: fast cylinder detection for PCL.
 * The per-pixel numerics of the depth sensor model (applySensorModel): how strongly a
 * surface returns the sensor's light, systematic depth errors, axial noise and missing
 * depth on weak returns and highlights. Free functions, for tests and other renderers.
 */
#pragma once

#include <facyl/simulation/tabletop_scene.h>

namespace facyl {

/** \brief Diffuse return of \a m relative to the reference surface:
 * reflectance x (1 - gloss) x (1 - transparency); 1 for the reference material. */
float diffuseReturn(const SurfaceMaterial& m);

/** \brief Squared distance of pixel (u, v) from the principal point of \a camera,
 * relative to the image's half diagonal (1 in the corners). */
float radialPosition2(const CameraIntrinsics& camera, float u, float v);

/** \brief Systematic depth error (m, to add to z) of \a sensor at depth \a z, squared
 * radial position \a r2 (radialPosition2) and |cos| of the incidence angle
 * \a cos_incidence: depth_scale_error z + radial_depth_bias z^2 r2
 * + incidence_bias z (1 / cos - 1). Exactly 0 when the three settings are 0. */
float depthBias(const DepthSensorModel& sensor, float z, float r2, float cos_incidence);

/** \brief Standard deviation (m) of the axial noise at depth \a z on a surface of
 * diffuse return \a rho: (noise_constant + noise_linear z + noise_coefficient z^2) /
 * sqrt(rho) for rho < 1 (weak returns are noisier), without the division for rho >= 1. */
float axialNoiseSigma(const DepthSensorModel& sensor, float z, float rho);

/** \brief Share of the pixels of a surface of diffuse return \a rho lost to the weak
 * return (on top of the grazing and range limits): weak_return_dropout (1 - rho)^2 for
 * rho < 1, else 0. */
float weakReturnDropout(const DepthSensorModel& sensor, float rho);

/** \brief Probability that a pixel of a surface with \a gloss, seen with |cos| of the
 * incidence angle \a cos_incidence, is lost in the specular highlight:
 * min(1, 2 gloss exp(-theta^2 / (2 highlight_width^2))); 0 without gloss or highlights. */
float highlightProbability(const DepthSensorModel& sensor, float gloss, float cos_incidence);

/** \brief The farthest depth a surface of diffuse return \a rho is measured at:
 * max_range sqrt(rho) for rho < 1, else max_range. */
float reach(const DepthSensorModel& sensor, float rho);

} // namespace facyl
