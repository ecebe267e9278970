/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

namespace facyl {

/** \brief Per-point cues for cylinder voting: a surface normal and the principal curvatures.
 *
 * Field names follow pcl::Normal (normal_x.., curvature) and pcl::PrincipalCurvatures
 * (principal_curvature_x.., pc1, pc2), so pcl::copyPointCloud converts to either type.
 * - normal_*: unit surface normal, oriented towards the view point;
 * - curvature: surface variation lambda0 / (lambda0 + lambda1 + lambda2), as PCL's;
 * - principal_curvature_*: c_max, the unit direction of largest normal change (paper III-C2);
 * - pc1, pc2: k_max >= k_min >= 0, eigenvalues of the covariance of the neighbours' normals
 *   projected on the tangent plane (the values of pcl::PrincipalCurvaturesEstimation).
 * Points without a valid neighbourhood hold NaN everywhere.
 */
struct EIGEN_ALIGN16 NormalCurvature {
  PCL_ADD_NORMAL4D;
  union {
    struct {
      float principal_curvature_x;
      float principal_curvature_y;
      float principal_curvature_z;
      float curvature;
    };
    float data_c[4];
  };
  float pc1{0.f};
  float pc2{0.f};

  NormalCurvature()
      : normal_x(0.f)
      , normal_y(0.f)
      , normal_z(0.f)
      , principal_curvature_x(0.f)
      , principal_curvature_y(0.f)
      , principal_curvature_z(0.f)
      , curvature(0.f)
  {
    data_n[3] = 0.f;
  }

  Eigen::Map<Eigen::Vector3f> principalCurvatureVector3fMap()
  {
    return Eigen::Map<Eigen::Vector3f>(data_c);
  }
  Eigen::Map<const Eigen::Vector3f> principalCurvatureVector3fMap() const
  {
    return Eigen::Map<const Eigen::Vector3f>(data_c);
  }
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

} // namespace facyl

// clang-format off
POINT_CLOUD_REGISTER_POINT_STRUCT(facyl::NormalCurvature,
    (float, normal_x, normal_x)(float, normal_y, normal_y)(float, normal_z, normal_z)
    (float, principal_curvature_x, principal_curvature_x)
    (float, principal_curvature_y, principal_curvature_y)
    (float, principal_curvature_z, principal_curvature_z)
    (float, curvature, curvature)(float, pc1, pc1)(float, pc2, pc2))
// clang-format on
