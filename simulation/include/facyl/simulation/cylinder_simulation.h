/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace facyl {

/** \brief Settings of one simulated cylinder (paper III-D1). The defaults are a can 0.8 m in
 * front of a camera looking along z, within every fit's default radius limits; the paper's
 * study (facyl_bench) uses r = 0.3 m. facyl_simulate and Python's simulate_cylinder take
 * their defaults from here. */
struct CylinderSimulationParameters {
  float radius{0.05f};                            ///< > 0
  float height{0.2f};                             ///< > 0
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()}; ///< non-zero; ignored if random_axis
  Eigen::Vector3f base{0.f, 0.f, 0.8f};           ///< centre of the bottom cap
  bool random_axis{false};                        ///< draw the axis uniformly on the sphere
  std::size_t lateral_points{900};                ///< |P|, points of the full lateral surface
  /** Lid outliers of eq. 5: (total points / |P|) - 1 of the unoccluded cylinder; e.g. 3 puts
   * 3 |P| points on the two caps, half on each, uniform on the discs. >= 0. */
  float lid_ratio{0.f};
  float noise{0.f}; ///< std. dev. of isotropic Gaussian noise, relative to the radius, >= 0
  /** Occlusion of eq. 6, 1 - |P'| / |P| in [0, 1): an angular sector of the lateral surface,
   * along the whole axis, is removed. */
  float occlusion{0.f};
  std::uint64_t seed{0};
};

/** \brief What was simulated. */
struct CylinderGroundTruth {
  Eigen::Vector3f base{Eigen::Vector3f::Zero()};
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()}; ///< unit, base to top
  float radius{0.f};
  float height{0.f};
  std::size_t lateral_points{0}; ///< |P'| after occlusion
  std::size_t lid_points{0};
};

/** \brief A simulated cloud with exact (noise-free) normals and per-point labels. */
struct SimulatedCylinder {
  pcl::PointCloud<pcl::PointNormal> cloud; ///< lateral points first, then the lids
  std::vector<std::uint8_t> is_lid;        ///< 1 for lid points
  CylinderGroundTruth truth;
};

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string validate(const CylinderSimulationParameters& params);

/** \brief Simulates one cylinder with lids, noise and occlusion. Deterministic for a seed.
 * \throws std::invalid_argument if the parameters are invalid (see validate). */
SimulatedCylinder simulateCylinder(const CylinderSimulationParameters& params);

/** \brief A rectangular planar patch (a table top) of \a size_u x \a size_v centred at
 * \a centre with normal \a normal, \a points points uniformly spread, noise \a sigma (absolute,
 * along every axis), exact normals. \throws std::invalid_argument on bad sizes or normal. */
pcl::PointCloud<pcl::PointNormal> simulatePlane(const Eigen::Vector3f& centre,
                                                const Eigen::Vector3f& normal, float size_u,
                                                float size_v, std::size_t points, float sigma,
                                                std::uint64_t seed);

} // namespace facyl
