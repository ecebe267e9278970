/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <pcl/ModelCoefficients.h>
#include <pcl/types.h>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace facyl {

/** \brief A fitted finite cylinder: the typed result of facyl's estimators. */
struct CylinderModel {
  Eigen::Vector3f point_on_axis{Eigen::Vector3f::Zero()}; ///< the base centre
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()};         ///< unit, from base to top
  float radius{0.f};
  Eigen::Vector3f base{Eigen::Vector3f::Zero()}; ///< centre of the lowest inlier section
  Eigen::Vector3f top{Eigen::Vector3f::Zero()};  ///< centre of the highest inlier section
  float height{0.f};                             ///< |top - base|
  pcl::Indices inliers;                          ///< indices into the input cloud, ascending
  float inlier_ratio{0.f}; ///< paper eq. 4: inliers / points given to the estimator
  /** Share of the orientation evidence (sum of vote weights of all points considered) carried
   * by this cylinder's inliers: near 1 when the curved surface is all explained, lower when
   * other curved structure remains. Planar points weigh little with SoftCurvature voting. */
  float confidence{0.f};
  float rms_error{0.f};          ///< RMS of the inliers' distance to the surface
  float angular_coverage{0.f};   ///< share of the circumference (36 sectors) with inliers
  float distance_threshold{0.f}; ///< the inlier threshold used (given or estimated)

  /** \brief PCL's SACMODEL_CYLINDER layout: point_on_axis(3), axis_direction(3), radius. */
  void toCoefficients(pcl::ModelCoefficients& coefficients) const;
  /** \brief Signed distance of \a p to the infinite cylinder surface (> 0 outside). */
  float signedDistance(const Eigen::Vector3f& p) const;
};

/** \brief facyl's convention for a cylinder whose surroundings are known: the axis runs from
 * the base (point_on_axis) to the top and points to the side of \a up (gravity's opposite, a
 * support's normal); when it lies across \a up (within about 6 degrees of perpendicular: a lying
 * can), to the side of \a viewpoint. Flips \a model (axis, base and top) when needed. */
void orientCylinder(CylinderModel& model, const Eigen::Vector3f& up,
                    const Eigen::Vector3f& viewpoint);

/** \brief Angle (rad, in [0, pi/2]) between two axes, which have no sign. */
float axisAngle(const Eigen::Vector3f& a, const Eigen::Vector3f& b);

/** \brief Distance from point \a p to the line through \a point with unit direction \a axis. */
float distanceToLine(const Eigen::Vector3f& p, const Eigen::Vector3f& point,
                     const Eigen::Vector3f& axis);

} // namespace facyl
