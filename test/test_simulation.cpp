/*
 * facyl: tests of the cylinder simulator (paper III-D1, eq. 5 and 6).
 */
#include <facyl/simulation/cylinder_simulation.h>

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using facyl::CylinderSimulationParameters;

TEST(CylinderSimulation, LateralPointsLieOnTheSurface)
{
  CylinderSimulationParameters p;
  p.radius = 0.05f;
  p.height = 0.2f;
  p.axis = Eigen::Vector3f(1, 2, 3);
  p.base = Eigen::Vector3f(0.5f, -1.f, 2.f);
  const auto sim = facyl::simulateCylinder(p);
  ASSERT_EQ(sim.cloud.size(), 900u);
  const Eigen::Vector3f a = p.axis.normalized();
  EXPECT_LT((sim.truth.axis - a).norm(), 1e-6f);
  for (const auto& q : sim.cloud) {
    const Eigen::Vector3f w = q.getVector3fMap() - p.base;
    const float t = w.dot(a);
    EXPECT_NEAR((w - t * a).norm(), p.radius, 1e-5f);
    EXPECT_GE(t, -1e-5f);
    EXPECT_LE(t, p.height + 1e-5f);
    EXPECT_NEAR(std::abs(q.getNormalVector3fMap().dot(a)), 0.f, 1e-5f);
  }
}

TEST(CylinderSimulation, LidsFollowEquation5)
{
  CylinderSimulationParameters p;
  p.lid_ratio = 3.f;
  const auto sim = facyl::simulateCylinder(p);
  // eq. 5: outliers = total / |P| - 1
  EXPECT_NEAR(static_cast<float>(sim.cloud.size()) / 900.f - 1.f, 3.f, 1e-6f);
  EXPECT_EQ(sim.truth.lid_points, 2700u);
  std::size_t bottom = 0, top = 0;
  for (std::size_t i = 0; i < sim.cloud.size(); ++i) {
    if (!sim.is_lid[i])
      continue;
    const Eigen::Vector3f q = sim.cloud[i].getVector3fMap();
    EXPECT_LE(Eigen::Vector2f(q.x(), q.y()).norm(), p.radius + 1e-5f);
    if (std::abs(q.z()) < 1e-5f)
      ++bottom;
    else if (std::abs(q.z() - p.height) < 1e-5f)
      ++top;
  }
  EXPECT_EQ(bottom, 1350u);
  EXPECT_EQ(top, 1350u);
}

TEST(CylinderSimulation, OcclusionFollowsEquation6)
{
  CylinderSimulationParameters p;
  p.occlusion = 0.75f;
  const auto sim = facyl::simulateCylinder(p);
  // eq. 6: occlusion = 1 - |P'| / |P|
  EXPECT_NEAR(1.f - static_cast<float>(sim.cloud.size()) / 900.f, 0.75f, 1e-3f);
  // The visible part is one angular sector of a quarter turn.
  const Eigen::Vector3f u = p.axis.unitOrthogonal(), v = p.axis.cross(u);
  for (const auto& q : sim.cloud) {
    float angle = std::atan2(q.getVector3fMap().dot(v), q.getVector3fMap().dot(u));
    if (angle < 0)
      angle += 2.f * static_cast<float>(M_PI);
    EXPECT_LE(angle, 0.25f * 2.f * static_cast<float>(M_PI) + 1e-4f);
  }
}

TEST(CylinderSimulation, NoiseHasTheRequestedSpread)
{
  CylinderSimulationParameters p;
  p.noise = 0.05f;
  p.lateral_points = 20000;
  const auto sim = facyl::simulateCylinder(p);
  double sq = 0.0;
  for (const auto& q : sim.cloud) {
    const float radial = Eigen::Vector2f(q.x, q.y).norm() - p.radius;
    sq += radial * radial;
  }
  // Radial component of isotropic noise: std sigma = 0.05 r.
  EXPECT_NEAR(std::sqrt(sq / sim.cloud.size()), 0.05 * p.radius, 0.05 * 0.05 * p.radius);
}

TEST(CylinderSimulation, IsDeterministicForASeed)
{
  CylinderSimulationParameters p;
  p.random_axis = true;
  p.noise = 0.01f;
  p.lid_ratio = 1.f;
  p.seed = 42;
  const auto a = facyl::simulateCylinder(p);
  const auto b = facyl::simulateCylinder(p);
  ASSERT_EQ(a.cloud.size(), b.cloud.size());
  for (std::size_t i = 0; i < a.cloud.size(); ++i)
    EXPECT_EQ(a.cloud[i].getVector3fMap(), b.cloud[i].getVector3fMap());
  p.seed = 43;
  const auto c = facyl::simulateCylinder(p);
  EXPECT_GT((a.truth.axis - c.truth.axis).norm(), 1e-3f);
  EXPECT_NEAR(a.truth.axis.norm(), 1.f, 1e-6f);
}

TEST(CylinderSimulation, RejectsInvalidParameters)
{
  CylinderSimulationParameters p;
  p.radius = 0.f;
  EXPECT_THROW(facyl::simulateCylinder(p), std::invalid_argument);
  p = {};
  p.occlusion = 1.f;
  EXPECT_THROW(facyl::simulateCylinder(p), std::invalid_argument);
  p = {};
  p.axis = Eigen::Vector3f::Zero();
  EXPECT_THROW(facyl::simulateCylinder(p), std::invalid_argument);
  p = {};
  p.noise = -1.f;
  EXPECT_FALSE(facyl::validate(p).empty());
  EXPECT_THROW(facyl::simulatePlane(Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitZ(), 0.f, 1.f,
                                    10, 0.f, 0),
               std::invalid_argument);
}

TEST(PlaneSimulation, PointsLieOnThePlane)
{
  const Eigen::Vector3f n(0, 1, 1);
  const auto plane =
      facyl::simulatePlane(Eigen::Vector3f(1, 2, 3), n, 2.f, 1.f, 500, 0.f, 7);
  ASSERT_EQ(plane.size(), 500u);
  for (const auto& q : plane)
    EXPECT_NEAR((q.getVector3fMap() - Eigen::Vector3f(1, 2, 3)).dot(n.normalized()), 0.f, 1e-5f);
}
