/*
 * facyl: tracking across frames (CylinderTracker, its numerics, simulated streams, the PCD
 * grabber stream).
 */
#include "test_helpers.h"

#include <facyl/tools/frame_stream.h>

#include <facyl/features/polygon.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/segmentation/tabletop_geometry.h>
#include <facyl/simulation/random.h>
#include <facyl/simulation/tabletop_sequence.h>
#include <facyl/tracking/cylinder_tracker.h>
#include <facyl/tracking/tracker_steps.h>

#include <pcl/io/pcd_io.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numeric>
#include <set>

namespace {

constexpr float kPi = 3.14159265f;

// ------------------------------------------------------------------ a synthetic stream

/** What a recognizer would report of a static table seen by a camera orbiting it: one support
 * (its frame's origin at a jittered "centre of the visible points", its x from the camera's, as
 * TabletopSegmentation makes it) and noisy objects, in the camera's frame. Fast and exact: the
 * tracker's behaviour without the recognizer's. */
struct SyntheticTable {
  struct Item {
    bool cylinder{true};
    Eigen::Vector3f base{Eigen::Vector3f::Zero()}; ///< world; cylinders: the base centre
    float radius{0.04f}, height{0.12f};
  };
  std::vector<Item> items;
  float distance{1.1f}, elevation{0.75f}, azimuth0{-0.3f}, step{0.03f};
  facyl::Random rng{7};

  SyntheticTable()
  {
    items = {{true, {0.f, 0.f, 0.f}, 0.04f, 0.12f},
             {true, {0.18f, 0.05f, 0.f}, 0.03f, 0.10f},
             {true, {-0.15f, 0.12f, 0.f}, 0.06f, 0.08f},
             {false, {0.05f, -0.16f, 0.04f}, 0.f, 0.f},
             {true, {-0.1f, -0.12f, 0.f}, 0.025f, 0.15f}};
  }
  /** Camera to world of frame \a k (x right, y down, z forward). */
  Eigen::Affine3f camera(int k) const
  {
    const float az = azimuth0 + step * static_cast<float>(k);
    const Eigen::Vector3f eye =
      distance * Eigen::Vector3f(std::sin(az) * std::cos(elevation),
                                 -std::cos(az) * std::cos(elevation), std::sin(elevation));
    const Eigen::Vector3f f = (-eye).normalized();
    const Eigen::Vector3f right = f.cross(Eigen::Vector3f::UnitZ()).normalized();
    Eigen::Affine3f pose = Eigen::Affine3f::Identity();
    pose.linear().col(0) = right;
    pose.linear().col(1) = f.cross(right);
    pose.linear().col(2) = f;
    pose.translation() = eye;
    return pose;
  }
  std::vector<facyl::SupportPlane> supports(int k)
  {
    const Eigen::Affine3f to_camera = camera(k).inverse();
    Eigen::Vector4f plane;
    plane.head<3>() = to_camera.linear() * Eigen::Vector3f::UnitZ();
    plane[3] = -plane.head<3>().dot(to_camera * Eigen::Vector3f::Zero());
    facyl::SupportPlane s;
    s.plane = plane;
    const Eigen::Vector3f hint(rng.uniform(-0.15f, 0.15f), rng.uniform(-0.15f, 0.15f), 0.f);
    s.frame = facyl::planeFrame(plane, to_camera * hint);
    return {s};
  }
  facyl::RecognizedObject observe(const Item& it, const Eigen::Affine3f& to_camera,
                                  bool noise = true)
  {
    facyl::RecognizedObject o;
    o.cluster.support = 0;
    o.cluster.indices.indices.resize(1500);
    const float n = noise ? 1.f : 0.f;
    if (it.cylinder) {
      const Eigen::Vector3f axis =
        (Eigen::Vector3f::UnitZ() + n * 0.015f * Eigen::Vector3f(rng.normal(), rng.normal(), 0.f))
          .normalized();
      const Eigen::Vector3f shift = n * 0.002f * Eigen::Vector3f(rng.normal(), rng.normal(), 0.f);
      o.cylinder.base = to_camera * (it.base + shift);
      o.cylinder.top = to_camera * (it.base + shift + it.height * axis);
      o.cylinder.point_on_axis = o.cylinder.base;
      o.cylinder.axis = (o.cylinder.top - o.cylinder.base).normalized();
      o.cylinder.radius = it.radius * (1.f + n * 0.02f * rng.normal());
      o.cylinder.height = it.height;
      o.cylinder.angular_coverage = 0.4f;
      o.evidence.fitted = true;
      o.is_cylinder = true;
      o.cluster.centroid = to_camera * (it.base + Eigen::Vector3f(0, 0, 0.5f * it.height));
    }
    else
      o.cluster.centroid =
        to_camera *
        (it.base + n * 0.01f * Eigen::Vector3f(rng.normal(), rng.normal(), rng.normal()));
    return o;
  }
  std::vector<facyl::RecognizedObject> objects(int k, const std::vector<int>& hidden = {})
  {
    const Eigen::Affine3f to_camera = camera(k).inverse();
    std::vector<facyl::RecognizedObject> out;
    for (std::size_t i = 0; i < items.size(); ++i)
      if (std::find(hidden.begin(), hidden.end(), static_cast<int>(i)) == hidden.end())
        out.push_back(observe(items[i], to_camera));
    // Reported in another order each frame: ids must not depend on it.
    for (std::size_t i = out.size(); i > 1; --i)
      std::swap(out[i - 1], out[static_cast<std::size_t>(rng.integer(0, static_cast<int>(i) - 1))]);
    return out;
  }
};

/** The track id of the object nearest \a world_point (its centroid), -1 when none is within
 * 5 cm. */
int
idNear(const facyl::CylinderTracker& tracker, const std::vector<facyl::RecognizedObject>& objects,
       const Eigen::Affine3f& camera_to_world, const Eigen::Vector3f& world_point)
{
  int best = -1;
  float nearest = 0.05f;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const Eigen::Vector3f p = camera_to_world * objects[k].cluster.centroid;
    const float d = (p.head<2>() - world_point.head<2>()).norm();
    if (d < nearest) {
      nearest = d;
      best = tracker.getAssignments()[k].track_id;
    }
  }
  return best;
}

} // namespace

// ----------------------------------------------------------------------------- numerics

TEST(TrackingNumerics, PlanarRigidFromNoisyPoints)
{
  // Weighted Procrustes: the error of the yaw falls with the points' spread and count as the
  // noise over their extent (sigma / (sqrt(n) * spread)); bound at 5 such sigmas.
  facyl::Random rng(3);
  const facyl::PlanarRigid truth{0.4f, Eigen::Vector2f(0.3f, -0.2f)};
  const int n = 40;
  const float sigma = 0.002f, spread = 0.2f;
  Eigen::Matrix2Xf from(2, n), to(2, n);
  for (int i = 0; i < n; ++i) {
    from.col(i) = Eigen::Vector2f(rng.uniform(-spread, spread), rng.uniform(-spread, spread));
    to.col(i) = truth.apply(from.col(i)) + sigma * Eigen::Vector2f(rng.normal(), rng.normal());
  }
  const auto fit = facyl::fitPlanarRigid(from, to, Eigen::VectorXf::Ones(n), 0.f);
  const float yaw_sigma = sigma / (std::sqrt(static_cast<float>(n)) * spread * 0.58f);
  EXPECT_NEAR(fit.yaw, truth.yaw, 5.f * yaw_sigma);
  EXPECT_LT((fit.t - truth.t).norm(), 5.f * sigma);
  // One point: the rotation cannot be observed; the fallback is kept.
  const auto one =
    facyl::fitPlanarRigid(from.leftCols(1), to.leftCols(1), Eigen::VectorXf::Ones(1), 0.25f);
  EXPECT_FLOAT_EQ(one.yaw, 0.25f);
  EXPECT_LT((one.apply(from.col(0)) - to.col(0)).norm(), 1e-5f);
  // inPlaneComponent of a planar motion is itself.
  const auto back = facyl::inPlaneComponent(truth.asAffine());
  EXPECT_NEAR(back.yaw, truth.yaw, 1e-5f);
  EXPECT_LT((back.t - truth.t).norm(), 1e-6f);
}

TEST(TrackingNumerics, RegistrationIgnoresWrongCandidates)
{
  // Six landmarks, every object a candidate of every track (the worst case: no attribute
  // tells them apart), a prior 5 cm and 0.1 rad off: the robust registration finds the motion.
  facyl::Random rng(11);
  const facyl::PlanarRigid truth{-0.35f, Eigen::Vector2f(0.12f, 0.07f)};
  const int n = 6;
  Eigen::Matrix2Xf objects(2, n), tracks(2, n);
  for (int i = 0; i < n; ++i) {
    objects.col(i) = Eigen::Vector2f(rng.uniform(-0.25f, 0.25f), rng.uniform(-0.25f, 0.25f));
    tracks.col(i) =
      truth.apply(objects.col(i)) + 0.001f * Eigen::Vector2f(rng.normal(), rng.normal());
  }
  std::vector<facyl::RegistrationCandidate> candidates;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      candidates.push_back({i, j, 1.f, 0.02f});
  const facyl::PlanarRigid prior{truth.yaw + 0.1f, truth.t + Eigen::Vector2f(0.05f, 0.f)};
  const auto reg = facyl::registerInPlane(objects, tracks, candidates, prior);
  EXPECT_EQ(reg.matched_objects, static_cast<std::size_t>(n));
  EXPECT_FALSE(reg.from_prior);
  EXPECT_NEAR(reg.transform.yaw, truth.yaw, 0.01f);
  EXPECT_LT((reg.transform.t - truth.t).norm(), 0.004f);
  for (const int c : reg.inliers)
    EXPECT_EQ(candidates[static_cast<std::size_t>(c)].object,
              candidates[static_cast<std::size_t>(c)].track);
  // No candidate: the prior.
  const auto none = facyl::registerInPlane(objects, tracks, {}, prior);
  EXPECT_TRUE(none.from_prior);
  EXPECT_FLOAT_EQ(none.transform.yaw, prior.yaw);
}

TEST(TrackingNumerics, AssignmentIsOptimalAgainstBruteForce)
{
  facyl::Random rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const int rows = rng.integer(0, 5), cols = rng.integer(0, 5);
    Eigen::MatrixXf cost(rows, cols);
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j)
        cost(i, j) =
          rng.chance(0.2) ? std::numeric_limits<float>::infinity() : rng.uniform(0.f, 12.f);
    const float gate = 9.f;
    const std::vector<int> a = facyl::assignMinimumCost(cost, gate);
    ASSERT_EQ(a.size(), static_cast<std::size_t>(rows));
    // Brute force: the most admissible pairs, then the least cost.
    std::vector<int> perm(static_cast<std::size_t>(std::max(rows, cols)));
    std::iota(perm.begin(), perm.end(), 0);
    int best_pairs = -1;
    float best_cost = 0.f;
    do {
      int pairs = 0;
      float sum = 0.f;
      for (int i = 0; i < rows; ++i) {
        const int j = perm[static_cast<std::size_t>(i)];
        if (j < cols && cost(i, j) <= gate) {
          ++pairs;
          sum += cost(i, j);
        }
      }
      if (pairs > best_pairs || (pairs == best_pairs && sum < best_cost)) {
        best_pairs = pairs;
        best_cost = sum;
      }
    } while (std::next_permutation(perm.begin(), perm.end()));
    int pairs = 0;
    float sum = 0.f;
    std::set<int> used;
    for (int i = 0; i < rows; ++i)
      if (a[static_cast<std::size_t>(i)] >= 0) {
        EXPECT_LE(cost(i, a[static_cast<std::size_t>(i)]), gate);
        EXPECT_TRUE(used.insert(a[static_cast<std::size_t>(i)]).second);
        ++pairs;
        sum += cost(i, a[static_cast<std::size_t>(i)]);
      }
    EXPECT_EQ(pairs, std::max(best_pairs, 0));
    EXPECT_NEAR(sum, best_cost, 1e-3f);
  }
}

TEST(TrackingNumerics, FiltersAreRobustAndSignFree)
{
  // An outlier moves a scalar by at most huber_k sigmas of the innovation, times var / var_z.
  float x = 1.f, var = 0.01f;
  facyl::filterScalar(x, var, 100.f, 0.01f, 2.f);
  EXPECT_LT(x - 1.f, 2.f * std::sqrt(0.02f) * (0.01f / 0.01f) + 1e-4f);
  EXPECT_GT(x - 1.f, 0.f);
  // The axis has no sign: z and -z update it alike.
  Eigen::Vector3f a = Eigen::Vector3f::UnitZ(), b = a;
  float va = 0.01f, vb = 0.01f;
  const Eigen::Vector3f z = Eigen::Vector3f(0.05f, 0.f, 1.f).normalized();
  facyl::filterAxis(a, va, z, 0.01f);
  facyl::filterAxis(b, vb, -z, 0.01f);
  EXPECT_LT((a - b).norm(), 1e-6f);
  EXPECT_NEAR(std::acos(a.z()), 0.5f * std::acos(z.z()), 1e-3f); // equal variances: half way
  // Extent: an end seen inside (occluded) pulls less than one seen beyond.
  float lo = -0.05f, hi = 0.05f, ve = 1e-4f;
  facyl::filterExtent(lo, hi, ve, -0.02f, 0.08f, 1e-4f, 0.3f);
  EXPECT_GT(hi - 0.05f, lo + 0.05f); // hi moved out more than lo moved in
  // Confidence: clamped log-odds; medians.
  float l = 0.f;
  for (int i = 0; i < 50; ++i)
    l = facyl::updateLogOdds(l, 0.95f, 4.6f);
  EXPECT_FLOAT_EQ(l, 4.6f);
  l = facyl::updateLogOdds(l, 0.05f, 4.6f);
  l = facyl::updateLogOdds(l, 0.05f, 4.6f);
  EXPECT_LT(facyl::probability(l), 0.5f); // a long history is overturned by two frames
  EXPECT_FLOAT_EQ(facyl::median({3.f, 1.f, 2.f}), 2.f);
  EXPECT_FLOAT_EQ(facyl::weightedMedian({1.f, 2.f, 10.f}, {1.f, 5.f, 1.f}), 2.f);
  // The consensus axis: a wrong first fit is outvoted by the agreeing later ones, whatever
  // their signs; the flags say which agreed.
  {
    const Eigen::Vector3f wrong = Eigen::Vector3f(1.f, 0.f, 0.2f).normalized();
    const Eigen::Vector3f up1 = Eigen::Vector3f(0.02f, 0.f, 1.f).normalized();
    const Eigen::Vector3f up2 = Eigen::Vector3f(-0.02f, 0.f, -1.f).normalized();
    std::vector<char> agree;
    const Eigen::Vector3f c =
      facyl::consensusAxis({wrong, up1, up2}, {2.f, 1.5f, 1.5f}, 0.14f, &agree);
    EXPECT_GT(std::abs(c.z()), 0.999f);
    EXPECT_NEAR(c.norm(), 1.f, 1e-5f);
    EXPECT_EQ(agree, (std::vector<char>{0, 1, 1}));
    EXPECT_EQ(facyl::consensusAxis({}, {}, 0.14f), Eigen::Vector3f::Zero());
  }
  // Association: an occluded end (the visible centre moves along the axis) costs nothing.
  facyl::AssociationGeometry t, o;
  t.cylinder = o.cylinder = true;
  t.radius = o.radius = 0.04f;
  t.height = 0.12f;
  o.height = 0.06f;
  o.centre = Eigen::Vector3f(0.f, 0.f, 0.03f);
  t.centroid = o.centroid = Eigen::Vector3f::Zero();
  EXPECT_NEAR(facyl::associationCost(t, o), 0.f, 1e-6f);
  o.centre.x() = 0.06f; // beside it: 3 sigmas
  EXPECT_GT(facyl::associationCost(t, o), 8.f);
}

// ------------------------------------------------------ the steps of update (tracker_steps.h)

namespace {

/** An upright cylinder observation (world frame): base centre \a base, \a radius, \a height. */
facyl::TrackObservation
cylinderObservation(const Eigen::Vector3f& base, float radius, float height)
{
  facyl::TrackObservation o;
  o.valid = true;
  o.points = 1000;
  o.quality = 400.f;
  o.p = 0.8f;
  o.base = base;
  o.top = base + height * Eigen::Vector3f::UnitZ();
  o.geometry.cylinder = true;
  o.geometry.axis = Eigen::Vector3f::UnitZ();
  o.geometry.centre = 0.5f * (o.base + o.top);
  o.geometry.centroid = o.geometry.centre;
  o.geometry.radius = radius;
  o.geometry.height = height;
  return o;
}

/** A box-like observation (no cylinder) with its centroid at \a centroid. */
facyl::TrackObservation
boxObservation(const Eigen::Vector3f& centroid)
{
  facyl::TrackObservation o;
  o.valid = true;
  o.points = 1000;
  o.p = 0.2f;
  o.geometry.centroid = centroid;
  return o;
}

/** A confirmed track started from \a o. */
facyl::CylinderTrack
confirmedTrack(const facyl::TrackObservation& o, int id)
{
  facyl::CylinderTrack t = facyl::newTrack(o, id, 0, facyl::CylinderTrackerParameters{});
  t.confirmed = true;
  return t;
}

} // namespace

namespace {

/** A support whose plane is z = 0 of \a frame (its normal, frame's z, towards the sensor). */
facyl::SupportPlane
supportAt(const Eigen::Affine3f& frame)
{
  facyl::SupportPlane s;
  s.frame = frame;
  const Eigen::Vector3f n = frame.linear().col(2);
  s.plane = Eigen::Vector4f(n.x(), n.y(), n.z(), -n.dot(frame.translation()));
  return s;
}

/** The prior of the plane z = \a height, seen last at (0, 0, height), within 0.35 rad and
 * 0.15 m (the tracker's default tolerances). */
facyl::SupportPrior
priorAt(float height)
{
  facyl::SupportPrior p;
  p.plane << 0.f, 0.f, 1.f, -height;
  p.centre << 0.f, 0.f, height;
  p.max_angle = 0.35f;
  p.max_offset = 0.15f;
  return p;
}

} // namespace

TEST(TrackerSteps, AnchorIsTheTableThenTheSupportMostObjectsStandOn)
{
  // Three supports: the world's plane (identity), one tilted 30 degrees, one 40 cm higher.
  const std::vector<facyl::SupportPlane> supports{
    supportAt(Eigen::Affine3f::Identity()),
    supportAt(Eigen::Affine3f(Eigen::AngleAxisf(0.52f, Eigen::Vector3f::UnitX()))),
    supportAt(Eigen::Affine3f(Eigen::Translation3f(0.f, 0.f, 0.4f)))};
  std::vector<facyl::RecognizedObject> objects(4);
  objects[0].cluster.support = 0;
  objects[1].cluster.support = objects[2].cluster.support = objects[3].cluster.support = 2;
  // A new world: the table, else the support most objects stand on.
  auto c = facyl::chooseAnchor(supports, 1, objects, nullptr);
  EXPECT_EQ(c.anchor, 1);
  EXPECT_FALSE(c.plane_jump);
  EXPECT_EQ(facyl::chooseAnchor(supports, -1, objects, nullptr).anchor, 2);
  // A support without a finite frame is never the anchor.
  auto broken = supports;
  broken[2].frame.matrix()(0, 0) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(facyl::chooseAnchor(broken, -1, objects, nullptr).anchor, 0);
  // Continuing the tracks' plane: the first in that order that is it, the table or not.
  const facyl::SupportPrior here = priorAt(0.f);
  c = facyl::chooseAnchor(supports, 1, objects, &here);
  EXPECT_EQ(c.anchor, 0);
  EXPECT_FALSE(c.plane_jump);
  // None is it: the first, a jump.
  const facyl::SupportPrior away = priorAt(1.f);
  c = facyl::chooseAnchor(supports, 1, objects, &away);
  EXPECT_EQ(c.anchor, 1);
  EXPECT_TRUE(c.plane_jump);
  EXPECT_EQ(facyl::chooseAnchor({}, -1, objects, &here).anchor, -1);
}

TEST(TrackerSteps, ConsistentWithPriorWithinItsAngleAndOffset)
{
  const facyl::SupportPrior prior = priorAt(0.f);
  ASSERT_TRUE(prior.valid());
  const auto planeOf = [](const Eigen::Affine3f& frame) { return supportAt(frame).plane; };
  EXPECT_TRUE(facyl::consistentWithPrior(prior, planeOf(Eigen::Affine3f::Identity())));
  // Within the angle (0.3 of 0.35 rad) and the offset (0.14 of 0.15 m, at the centre).
  EXPECT_TRUE(facyl::consistentWithPrior(
    prior, planeOf(Eigen::Affine3f(Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitY())))));
  EXPECT_TRUE(facyl::consistentWithPrior(
    prior, planeOf(Eigen::Affine3f(Eigen::Translation3f(0.f, 0.f, 0.14f)))));
  // Beyond either, or the normal away from the sensor (the underside of the plane).
  EXPECT_FALSE(facyl::consistentWithPrior(
    prior, planeOf(Eigen::Affine3f(Eigen::AngleAxisf(0.4f, Eigen::Vector3f::UnitY())))));
  EXPECT_FALSE(facyl::consistentWithPrior(
    prior, planeOf(Eigen::Affine3f(Eigen::Translation3f(0.f, 0.f, 0.16f)))));
  EXPECT_FALSE(facyl::consistentWithPrior(
    prior, planeOf(Eigen::Affine3f(Eigen::AngleAxisf(kPi, Eigen::Vector3f::UnitX())))));
  // The offset is measured at the prior's centre: a plane tilted 0.3 rad through the centre is
  // the prior's, one through a point 1 m beside it (0.3 m off at the centre) is not.
  facyl::SupportPrior beside = prior;
  beside.centre << 1.f, 0.f, 0.f;
  const Eigen::Vector4f tilted =
    planeOf(Eigen::Affine3f(Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitY())));
  EXPECT_TRUE(facyl::consistentWithPrior(prior, tilted));
  EXPECT_FALSE(facyl::consistentWithPrior(beside, tilted));
  // An invalid prior (no plane, or no angle) holds no plane.
  EXPECT_FALSE(facyl::consistentWithPrior(facyl::SupportPrior{}, tilted));
  facyl::SupportPrior no_angle = prior;
  no_angle.max_angle = 0.f;
  EXPECT_FALSE(no_angle.valid());
  EXPECT_FALSE(facyl::consistentWithPrior(no_angle, planeOf(Eigen::Affine3f::Identity())));
  // priorMismatch: of the planes that are the prior's, the nearer has the less (a counter 3 cm
  // off against slabs on it 6 cm off); beyond the tolerances, infinity.
  const auto at = [&](float z) {
    return facyl::priorMismatch(prior, planeOf(Eigen::Affine3f(Eigen::Translation3f(0.f, 0.f, z))));
  };
  EXPECT_NEAR(at(0.03f), 0.03f / 0.15f, 1e-5f);
  EXPECT_LT(at(0.03f), at(0.06f));
  EXPECT_LT(at(-0.03f), at(0.06f));
  EXPECT_NEAR(facyl::priorMismatch(prior, tilted), 0.3f / 0.35f, 1e-4f);
  EXPECT_TRUE(std::isinf(at(0.16f)));
  EXPECT_TRUE(std::isinf(facyl::priorMismatch(no_angle, planeOf(Eigen::Affine3f::Identity()))));
}

TEST(TrackerSteps, DecisionsHaveHysteresis)
{
  // decideWithHysteresis: a side changes only beyond the margin; margin 0 is the threshold.
  EXPECT_FALSE(facyl::decideWithHysteresis(false, 0.3f, 0.f, 0.5f));
  EXPECT_TRUE(facyl::decideWithHysteresis(false, 0.6f, 0.f, 0.5f));
  EXPECT_TRUE(facyl::decideWithHysteresis(true, -0.3f, 0.f, 0.5f));
  EXPECT_FALSE(facyl::decideWithHysteresis(true, -0.6f, 0.f, 0.5f));
  EXPECT_TRUE(facyl::decideWithHysteresis(false, 0.f, 0.f, 0.f));
  EXPECT_FALSE(facyl::decideWithHysteresis(true, -1e-3f, 0.f, 0.f));
  // The margin: the spread of the evidence, at most half the clamp of the log-odds.
  EXPECT_FLOAT_EQ(facyl::decisionMargin(0.25f, 4.6f), 0.5f);
  EXPECT_FLOAT_EQ(facyl::decisionMargin(100.f, 4.6f), 2.3f);
  EXPECT_FLOAT_EQ(facyl::decisionMargin(-1.f, 4.6f), 0.f);
  // A static object whose frames disagree (p 0.7, 0.3, 0.7, ...): its log-odds swing across
  // min_probability's every frame, the plain threshold flips every frame, the decision does
  // not; steady evidence still changes it.
  const facyl::CylinderTrackerParameters params;
  facyl::TrackObservation o;
  o.valid = true;
  o.p = 0.4f;
  facyl::CylinderTrack t = facyl::newTrack(o, 0, 0, params);
  EXPECT_FALSE(t.decided_cylinder);
  int plain_flips = 0, flips = 0;
  bool plain = t.pCylinder() >= params.min_probability, decided = t.decided_cylinder;
  for (std::size_t n = 2; n <= 12; ++n) {
    facyl::recordEvidence(t, n % 2 == 0 ? 0.7f : 0.3f, n, params);
    const bool now_plain = t.pCylinder() >= params.min_probability;
    plain_flips += now_plain != plain;
    flips += t.decided_cylinder != decided;
    plain = now_plain;
    decided = t.decided_cylinder;
  }
  EXPECT_EQ(plain_flips, 11);
  EXPECT_EQ(flips, 0);
  EXPECT_FALSE(t.decided_cylinder);
  for (std::size_t n = 13; n <= 15; ++n)
    facyl::recordEvidence(t, 0.9f, n, params);
  EXPECT_TRUE(t.decided_cylinder);
}

TEST(TrackerSteps, RegistrationCandidatesAgreeInSizeAndHeight)
{
  std::vector<facyl::CylinderTrack> tracks{
    confirmedTrack(cylinderObservation({0.f, 0.f, 0.f}, 0.04f, 0.12f), 0),
    confirmedTrack(boxObservation({0.3f, 0.f, 0.05f}), 1)};
  std::vector<facyl::TrackObservation> objects{
    cylinderObservation({0.1f, 0.f, 0.f}, 0.045f, 0.10f), // agrees with track 0
    cylinderObservation({0.1f, 0.f, 0.f}, 0.07f, 0.12f),  // too wide for it
    boxObservation({0.f, 0.2f, 0.09f}),                   // 4 cm off in height: agrees
    boxObservation({0.f, 0.2f, 0.14f}),                   // 9 (8) cm off: does not
    cylinderObservation({0.f, 0.f, 0.f}, 0.04f, 0.12f)};
  objects[4].valid = false;
  auto c = facyl::registrationCandidates(objects, tracks);
  // Object 0 with track 0 (two cylinders) and with track 1 (their reference heights: 5 and 5
  // cm); object 1 with track 1 only; object 2 with both (4 and 3 cm apart).
  std::vector<std::pair<int, int>> pairs;
  for (const auto& k : c)
    pairs.emplace_back(k.object, k.track);
  EXPECT_EQ(pairs, (std::vector<std::pair<int, int>>{{0, 0}, {0, 1}, {1, 1}, {2, 0}, {2, 1}}));
  EXPECT_FLOAT_EQ(c[0].weight, 1.f); // two cylinders, a confirmed track
  EXPECT_FLOAT_EQ(c[0].tolerance, 0.02f);
  EXPECT_FLOAT_EQ(c[1].weight, 0.4f); // a centroid counts less, within more
  EXPECT_FLOAT_EQ(c[1].tolerance, 0.05f);
  // A tentative track counts half; a tilted cylinder (45 degrees) agrees within 4 cm.
  tracks[0].confirmed = false;
  tracks[0].axis = Eigen::Vector3f(1.f, 0.f, 1.f).normalized();
  c = facyl::registrationCandidates(objects, tracks);
  EXPECT_FLOAT_EQ(c[0].weight, 0.5f);
  EXPECT_FLOAT_EQ(c[0].tolerance, 0.04f);
}

TEST(TrackerSteps, RegistrationFallsBackToTheLastPoseWhenThePredictionMatchesLittle)
{
  // The objects are where the tracks are, moved 50 cm: beyond the search radius of the
  // prediction (the identity), at the fallback's place.
  std::vector<facyl::CylinderTrack> tracks;
  std::vector<facyl::TrackObservation> objects;
  const Eigen::Vector3f shift(-0.5f, 0.f, 0.f);
  for (const Eigen::Vector3f& p : {Eigen::Vector3f(0.f, 0.f, 0.f), Eigen::Vector3f(0.2f, 0.f, 0.f),
                                   Eigen::Vector3f(0.f, 0.25f, 0.f)}) {
    tracks.push_back(confirmedTrack(cylinderObservation(p, 0.04f, 0.12f), 0));
    objects.push_back(cylinderObservation(p + shift, 0.04f, 0.12f));
  }
  const facyl::RegistrationSettings settings;
  const facyl::PlanarRigid prior;
  const facyl::PlanarRigid fallback{0.f, Eigen::Vector2f(0.5f, 0.f)};
  const auto alone = facyl::registerObservations(objects, tracks, prior, settings);
  EXPECT_EQ(alone.matched_objects, 0u);
  const auto with = facyl::registerObservations(objects, tracks, prior, settings, &fallback);
  EXPECT_EQ(with.matched_objects, 3u);
  EXPECT_LT((with.transform.t - fallback.t).norm(), 1e-4f);
  EXPECT_NEAR(with.transform.yaw, 0.f, 1e-4f);
}

TEST(TrackerSteps, NewSceneWhenTooFewExpectedTracksMatch)
{
  // No confirmed track: never.
  EXPECT_FALSE(facyl::isNewScene(0, 0, 5, 0, true, 0.3f));
  // A plane jump with fewer than two matched objects.
  EXPECT_TRUE(facyl::isNewScene(2, 2, 5, 1, true, 0.3f));
  EXPECT_FALSE(facyl::isNewScene(2, 2, 5, 2, true, 0.3f));
  EXPECT_FALSE(facyl::isNewScene(2, 2, 5, 1, false, 0.3f));
  // Fewer than min_overlap of at least three expected (and seen) tracks.
  EXPECT_TRUE(facyl::isNewScene(10, 10, 10, 2, false, 0.3f));
  EXPECT_FALSE(facyl::isNewScene(10, 10, 10, 3, false, 0.3f));
  EXPECT_FALSE(facyl::isNewScene(10, 10, 2, 0, false, 0.3f)); // two objects seen: too few
  EXPECT_FALSE(facyl::isNewScene(10, 2, 10, 0, false, 0.3f)); // two expected in view
  EXPECT_FALSE(facyl::isNewScene(10, 10, 10, 0, false, 0.f)); // never by share
}

TEST(TrackerSteps, ObservationTakesTheDecisionsSideAndAFittedCylinder)
{
  facyl::RecognizedObject r;
  r.cluster.centroid = Eigen::Vector3f(0.f, 0.f, 1.f);
  r.cluster.indices.indices.resize(500);
  r.cluster.support = 1;
  r.is_cylinder = true;
  r.evidence.fitted = true;
  r.cylinder.base = Eigen::Vector3f(0.f, 0.1f, 1.f);
  r.cylinder.top = Eigen::Vector3f(0.f, -0.1f, 1.f);
  r.cylinder.axis = Eigen::Vector3f(0.f, -1.f, 0.f);
  r.cylinder.radius = 0.04f;
  r.cylinder.angular_coverage = 0.01f;
  const Eigen::Affine3f pose(Eigen::Translation3f(1.f, 0.f, 0.f));
  auto o = facyl::observe(r, pose, 0.6f);
  EXPECT_TRUE(o.valid);
  EXPECT_EQ(o.support, 1);
  EXPECT_EQ(o.points, 500u);
  EXPECT_TRUE(o.geometry.centroid.isApprox(Eigen::Vector3f(1.f, 0.f, 1.f)));
  ASSERT_TRUE(o.geometry.cylinder);
  EXPECT_TRUE(o.geometry.centre.isApprox(Eigen::Vector3f(1.f, 0.f, 1.f)));
  EXPECT_TRUE(o.geometry.axis.isApprox(Eigen::Vector3f(0.f, -1.f, 0.f)));
  EXPECT_NEAR(o.geometry.height, 0.2f, 1e-6f);
  EXPECT_FLOAT_EQ(o.quality, 500.f * 0.05f); // coverage counts at least 5%
  // The decision sets the side, p_cylinder the strength.
  EXPECT_FLOAT_EQ(o.p, 0.6f); // no classifier
  r.evidence.p_cylinder = 0.3f;
  EXPECT_FLOAT_EQ(facyl::observe(r, pose, 0.6f).p, 0.6f);
  r.evidence.p_cylinder = 0.9f;
  EXPECT_FLOAT_EQ(facyl::observe(r, pose, 0.6f).p, 0.9f);
  r.is_cylinder = false;
  EXPECT_FLOAT_EQ(facyl::observe(r, pose, 0.6f).p, 0.4f);
  EXPECT_FALSE(facyl::observe(r, pose, 0.6f).geometry.cylinder); // rejected: no cylinder
  // Ends that coincide: the fit's axis; a radius that is not finite: no cylinder.
  r.is_cylinder = true;
  r.cylinder.top = r.cylinder.base;
  EXPECT_TRUE(
    facyl::observe(r, pose, 0.6f).geometry.axis.isApprox(Eigen::Vector3f(0.f, -1.f, 0.f)));
  r.cylinder.radius = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(facyl::observe(r, pose, 0.6f).geometry.cylinder);
  r.cluster.centroid.x() = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(facyl::observe(r, pose, 0.6f).valid);
}

TEST(TrackerSteps, AssociationGivesASecondChanceButNotToATakenAwayObject)
{
  const facyl::AssociationSettings s; // sigma_centroid 4 cm, gate 9: 12 cm
  std::vector<facyl::CylinderTrack> tracks{confirmedTrack(boxObservation({0.f, 0.f, 0.f}), 0),
                                           confirmedTrack(boxObservation({1.f, 0.f, 0.f}), 1)};
  // 2 cm and 15 cm from their tracks: the second matches only with doubled sigmas (24 cm).
  std::vector<facyl::TrackObservation> obs{boxObservation({1.02f, 0.f, 0.f}),
                                           boxObservation({0.15f, 0.f, 0.f}),
                                           boxObservation({0.5f, 0.f, 0.f})};
  EXPECT_EQ(facyl::associate(obs, tracks, s), (std::vector<int>{1, 0, -1}));
  // A track whose place the sensor saw through takes only an object right at it (a quarter
  // of the gate: 6 cm), and gets no second chance.
  tracks[0].seen_through = 1;
  EXPECT_EQ(facyl::associate(obs, tracks, s), (std::vector<int>{1, -1, -1}));
  obs[1].geometry.centroid.x() = 0.05f;
  EXPECT_EQ(facyl::associate(obs, tracks, s), (std::vector<int>{1, 0, -1}));
  obs[0].valid = false;
  EXPECT_EQ(facyl::associate(obs, tracks, s), (std::vector<int>{-1, 0, -1}));
}

TEST(TrackerSteps, TracksStartUpAndCorrectTheirExtentAroundTheCentre)
{
  facyl::CylinderTrackerParameters params;
  params.confirm_hits = 2;
  // Seen upside down: the track's axis is turned up, its extent with it.
  auto o = cylinderObservation({0.f, 0.f, 0.f}, 0.04f, 0.12f);
  std::swap(o.base, o.top);
  o.geometry.axis = -o.geometry.axis;
  facyl::CylinderTrack t = facyl::newTrack(o, 7, 3, params);
  EXPECT_EQ(t.id, 7);
  EXPECT_EQ(t.object, 3);
  EXPECT_FALSE(t.confirmed);
  EXPECT_TRUE(t.has_cylinder);
  EXPECT_GT(t.axis.z(), 0.99f);
  EXPECT_FLOAT_EQ(t.lo, -0.06f);
  EXPECT_FLOAT_EQ(t.hi, 0.06f);
  EXPECT_EQ(t.fits.size(), 1u);
  // A taller observation: the top end beyond the extent pulls it; the centre stays in the
  // middle of the extent; the second hit confirms the track.
  t.misses = 2;
  facyl::correctTrack(t, cylinderObservation({0.f, 0.f, 0.f}, 0.04f, 0.16f), 1.f, params);
  EXPECT_TRUE(t.confirmed);
  EXPECT_EQ(t.misses, 0);
  EXPECT_EQ(t.status, facyl::TrackStatus::Seen);
  EXPECT_EQ(t.fits.size(), 2u);
  EXPECT_GT(t.hi - t.lo, 0.12f);
  EXPECT_NEAR(t.lo, -t.hi, 1e-6f);
  EXPECT_GT(t.centre.z(), 0.06f);
  // An observation without a cylinder moves the centroid and the confidence only.
  const float height = t.hi - t.lo;
  facyl::correctTrack(t, boxObservation({0.f, 0.f, 0.06f}), 1.f, params);
  EXPECT_EQ(t.hits, 3u);
  EXPECT_EQ(t.cylinder_hits, 2u);
  EXPECT_FLOAT_EQ(t.hi - t.lo, height);
  EXPECT_LT(t.log_odds, facyl::updateLogOdds(facyl::updateLogOdds(0.f, 0.8f, 4.6f), 0.8f, 4.6f));
}

TEST(TrackerSteps, CylinderFromHistoryOutvotesAWrongFit)
{
  // One wrong fit (tilted, wide) and three that agree (either sign), one of which is off
  // across the axis: the axis, line and radius are the agreeing ones' (weighted medians).
  facyl::CylinderTrack t;
  t.has_cylinder = true;
  t.axis = Eigen::Vector3f(1.f, 0.f, 0.2f).normalized();
  t.lo = -0.05f;
  t.hi = 0.05f;
  t.radius = 0.08f;
  t.fits = {{t.axis, Eigen::Vector3f(0.1f, 0.f, 0.f), 0.08f, 1.5f},
            {Eigen::Vector3f::UnitZ(), Eigen::Vector3f(0.01f, 0.f, 0.f), 0.040f, 1.f},
            {-Eigen::Vector3f::UnitZ(), Eigen::Vector3f(0.012f, 0.f, 0.05f), 0.041f, 1.f},
            {Eigen::Vector3f::UnitZ(), Eigen::Vector3f(0.3f, 0.f, 0.f), 0.05f, 1.f}};
  facyl::cylinderFromHistory(t, 0.14f);
  EXPECT_GT(t.axis.z(), 0.9999f); // the track's sense kept
  EXPECT_NEAR(t.radius, 0.041f, 1e-6f);
  EXPECT_NEAR(t.centre.x(), 0.012f, 1e-5f);
  EXPECT_NEAR(t.centre.y(), 0.f, 1e-5f);
  EXPECT_NEAR(t.centre.z(), 0.f, 1e-5f); // moved across the axis only
  EXPECT_FLOAT_EQ(t.hi - t.lo, 0.1f);
}

TEST(TrackerSteps, FragmentsLieInsideTheCylinderOrBringItsCentroidNearer)
{
  auto t = confirmedTrack(cylinderObservation({0.f, 0.f, 0.f}, 0.04f, 0.12f), 0);
  const auto matched = cylinderObservation({0.f, 0.f, 0.f}, 0.04f, 0.12f);
  EXPECT_FLOAT_EQ(facyl::fragmentGain(boxObservation({0.06f, 0.f, 0.1f}), t, matched, 0.03f, 0.04f),
                  1.f); // within the radius and the margin
  EXPECT_FLOAT_EQ(facyl::fragmentGain(boxObservation({0.08f, 0.f, 0.1f}), t, matched, 0.03f, 0.04f),
                  0.f); // beyond them, and the pieces' centroid is farther than the match's
  // A box-like track matched to a piece 3 cm off its centroid: the other piece, 5 cm on the
  // other side, brings the centroid to 1 cm (gain 2/3); one 20 cm away is too far.
  auto box = confirmedTrack(boxObservation({0.f, 0.f, 0.f}), 1);
  const auto piece = boxObservation({0.03f, 0.f, 0.f});
  EXPECT_NEAR(facyl::fragmentGain(boxObservation({-0.05f, 0.f, 0.f}), box, piece, 0.03f, 0.04f),
              2.f / 3.f, 1e-5f);
  EXPECT_FLOAT_EQ(facyl::fragmentGain(boxObservation({-0.2f, 0.f, 0.f}), box, piece, 0.03f, 0.04f),
                  0.f);
}

TEST(TrackerSteps, ViewStatusTellsWhyATrackIsNotSeen)
{
  facyl::TrackerView view;
  view.camera = facyl::PinholeCamera{500.f, 500.f, 320.f, 240.f, 640, 480};
  const Eigen::Affine3f identity = Eigen::Affine3f::Identity();
  auto box = confirmedTrack(boxObservation({0.f, 0.f, 1.f}), 0); // 1 m in front of the sensor
  int inside = 0;
  std::vector<facyl::RecognizedObject> objects(2);
  objects[1].cluster.box = {300, 200, 340, 280};
  // Without depth the sensor cannot tell; outside the image or behind it: out of view.
  EXPECT_EQ(facyl::viewStatus(box, identity, view, objects, inside), facyl::TrackStatus::Missed);
  EXPECT_EQ(inside, -1);
  EXPECT_EQ(facyl::viewStatus(box, Eigen::Affine3f(Eigen::Translation3f(1.f, 0.f, 0.f)), view,
                              objects, inside),
            facyl::TrackStatus::OutOfView);
  EXPECT_EQ(facyl::viewStatus(box, Eigen::Affine3f(Eigen::Translation3f(0.f, 0.f, -2.f)), view,
                              objects, inside),
            facyl::TrackStatus::OutOfView);
  float depth = 0.5f;
  view.depth = [&depth](int, int) { return depth; };
  EXPECT_EQ(facyl::viewStatus(box, identity, view, objects, inside), facyl::TrackStatus::Occluded);
  depth = 1.5f;
  EXPECT_EQ(facyl::viewStatus(box, identity, view, objects, inside),
            facyl::TrackStatus::SeenThrough);
  depth = 1.f; // a surface at its depth, inside object 1's box: merged into it
  EXPECT_EQ(facyl::viewStatus(box, identity, view, objects, inside), facyl::TrackStatus::Merged);
  EXPECT_EQ(inside, 1);
  objects[1].cluster.box = {0, 0, 10, 10};
  EXPECT_EQ(facyl::viewStatus(box, identity, view, objects, inside), facyl::TrackStatus::Missed);
  depth = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(facyl::viewStatus(box, identity, view, objects, inside), facyl::TrackStatus::Missed);
  // A cylinder's probes lie on its front: its surface 4 cm before its axis is no occluder.
  auto can = confirmedTrack(cylinderObservation({0.f, 0.06f, 1.f}, 0.04f, 0.12f), 1);
  can.axis = Eigen::Vector3f(0.f, -1.f, 0.f);
  can.centre = Eigen::Vector3f(0.f, 0.f, 1.f);
  depth = 0.96f;
  EXPECT_EQ(facyl::viewStatus(can, identity, view, objects, inside), facyl::TrackStatus::Missed);
  depth = 0.9f;
  EXPECT_EQ(facyl::viewStatus(can, identity, view, objects, inside), facyl::TrackStatus::Occluded);
  view.camera = facyl::PinholeCamera{};
  EXPECT_EQ(facyl::viewStatus(can, identity, view, objects, inside), facyl::TrackStatus::Missed);
}

TEST(TrackerSteps, TwoTracksOfOneObjectBecomeTheOlder)
{
  const facyl::CylinderTrackerParameters params;
  auto older = confirmedTrack(cylinderObservation({0.f, 0.f, 0.f}, 0.04f, 0.12f), 1);
  auto younger = confirmedTrack(cylinderObservation({0.005f, 0.f, 0.f}, 0.041f, 0.12f), 4);
  older.status = facyl::TrackStatus::Occluded;
  older.occluded = 3;
  older.hits = 10;
  older.log_odds = 4.f;
  younger.hits = 2;
  younger.log_odds = 2.f;
  younger.object = 5;
  EXPECT_TRUE(facyl::areOneObject(older, younger, params.association));
  EXPECT_FALSE(facyl::areOneObject(younger, older, params.association)); // the older keeps its id
  older.status = facyl::TrackStatus::Seen; // both seen in one frame: two objects
  EXPECT_FALSE(facyl::areOneObject(older, younger, params.association));
  older.status = facyl::TrackStatus::Occluded;
  auto far = younger;
  far.centre.x() += 0.05f;
  EXPECT_FALSE(facyl::areOneObject(older, far, params.association));
  // Each holding the other's centre, their axes 20 degrees apart (the older one's fits off by
  // a tilt): one object; beside each other, touching (centres 2 r apart), two.
  auto tilted = older;
  tilted.axis = Eigen::Vector3f(std::sin(0.35f), 0.f, std::cos(0.35f));
  EXPECT_GT(facyl::associationCost(facyl::associationGeometry(tilted),
                                   facyl::associationGeometry(younger), params.association),
            1.f);
  EXPECT_TRUE(facyl::areOneObject(tilted, younger, params.association));
  auto beside = older;
  beside.centre.x() -= 0.08f;
  beside.axis = tilted.axis;
  EXPECT_FALSE(facyl::areOneObject(beside, younger, params.association));
  younger.confirmed = false;
  EXPECT_FALSE(facyl::areOneObject(older, younger, params.association));
  younger.confirmed = true;

  facyl::absorbTrack(older, younger, 1, params.confidence_limit);
  EXPECT_EQ(older.status, facyl::TrackStatus::Seen); // takes the younger one's object
  EXPECT_EQ(older.object, 5);
  EXPECT_EQ(older.occluded, 0);
  EXPECT_EQ(older.hits, 12u);
  EXPECT_FLOAT_EQ(older.log_odds, params.confidence_limit);
  EXPECT_EQ(older.fits.size(), 1u); // the last history (1) kept
  EXPECT_TRUE(older.centre.isApprox(younger.centre));
  EXPECT_FALSE(younger.confirmed);
  EXPECT_TRUE(facyl::trackEnded(younger, params));
}

TEST(TrackerSteps, TracksEndAfterTheirLimits)
{
  facyl::CylinderTrackerParameters p;
  p.max_tentative_misses = 0;
  p.max_misses = 5;
  p.max_occluded = 60;
  p.max_out_of_view = 300;
  facyl::CylinderTrack t;
  EXPECT_FALSE(facyl::trackEnded(t, p));
  t.misses = 1;
  EXPECT_TRUE(facyl::trackEnded(t, p)); // tentative: at its first miss
  t.confirmed = true;
  t.misses = 5;
  EXPECT_FALSE(facyl::trackEnded(t, p));
  t.misses = 6;
  EXPECT_TRUE(facyl::trackEnded(t, p));
  t.misses = 0;
  t.occluded = 61;
  EXPECT_TRUE(facyl::trackEnded(t, p));
  t.occluded = 60;
  t.out_of_view = 300;
  EXPECT_FALSE(facyl::trackEnded(t, p));
  t.out_of_view = 301;
  EXPECT_TRUE(facyl::trackEnded(t, p));
}

TEST(CylinderTracker, ParametersAreChecked)
{
  facyl::CylinderTrackerParameters p;
  EXPECT_TRUE(facyl::validate(p).empty());
  p.confirm_hits = 0;
  p.min_probability = 2.f;
  const std::string why = facyl::validate(p);
  EXPECT_NE(why.find("confirm_hits"), std::string::npos);
  EXPECT_NE(why.find("min_probability"), std::string::npos);
  facyl::CylinderTracker tracker;
  try {
    tracker.setParameters(p);
    FAIL() << "invalid parameters were accepted";
  }
  catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("CylinderTracker::setParameters"), std::string::npos);
  }
}

// ------------------------------------------------------------------- tracker behaviour

TEST(CylinderTracker, IdsStayUnderCameraMotionAndReanchoring)
{
  // 40 frames, the camera turning 70 degrees around the table; the support frame's origin
  // jumps with what the camera sees of the table. Every object keeps its id, and the tracked
  // positions stay where the objects are (within a few mm): re-anchoring works.
  SyntheticTable table;
  facyl::CylinderTracker tracker;
  std::map<std::size_t, int> first_id;
  for (int k = 0; k < 40; ++k) {
    const auto supports = table.supports(k);
    const auto objects = table.objects(k);
    ASSERT_TRUE(tracker.update(supports, 0, objects));
    EXPECT_TRUE(tracker.getFrameInfo().anchored);
    EXPECT_FALSE(tracker.getFrameInfo().new_scene);
    for (std::size_t i = 0; i < table.items.size(); ++i) {
      const int id = idNear(tracker, objects, table.camera(k), table.items[i].base);
      ASSERT_GE(id, 0) << "frame " << k << " object " << i;
      if (k == 0)
        first_id[i] = id;
      else
        EXPECT_EQ(id, first_id[i]) << "frame " << k << " object " << i;
    }
  }
  EXPECT_EQ(tracker.getTracks().size(), table.items.size());
  // The tracked cylinders, in the last frame, where they are.
  const Eigen::Affine3f to_world = table.camera(39);
  for (const auto& t : tracker.getTracks()) {
    EXPECT_TRUE(t.confirmed);
    if (!t.has_cylinder)
      continue;
    EXPECT_TRUE(tracker.isCylinder(t));
    const facyl::CylinderModel m = tracker.cylinderInFrame(t);
    const Eigen::Vector3f base = to_world * m.base;
    float nearest = 1.f;
    for (const auto& it : table.items)
      if (it.cylinder) {
        nearest = std::min(nearest, (base.head<2>() - it.base.head<2>()).norm());
        if ((base.head<2>() - it.base.head<2>()).norm() < 0.01f) {
          EXPECT_NEAR(m.radius, it.radius, 0.02f * it.radius); // 2% noise per frame, averaged
        }
      }
    EXPECT_LT(nearest, 0.006f);
    EXPECT_GT((to_world.linear() * m.axis).z(), std::cos(0.02f)); // upright, away from the table
  }
}

TEST(CylinderTracker, LoopedRecordingKeepsTheIds)
{
  // A recording played in a loop: the camera turns 0.15 rad a frame for 5 frames, then jumps
  // back to where it started. The velocity predicts the path going on; the jump back is found
  // from the last pose instead: the same scene, the same ids.
  SyntheticTable table;
  table.step = 0.15f;
  facyl::CylinderTracker tracker;
  std::map<std::size_t, int> first_id;
  for (int k = 0; k < 10; ++k) {
    const int f = k % 5;
    const auto objects = table.objects(f);
    ASSERT_TRUE(tracker.update(table.supports(f), 0, objects));
    EXPECT_FALSE(tracker.getFrameInfo().new_scene) << "frame " << k;
    if (k < 2)
      continue;
    for (std::size_t i = 0; i < table.items.size(); ++i) {
      const int id = idNear(tracker, objects, table.camera(f), table.items[i].base);
      if (k == 2)
        first_id[i] = id;
      else
        EXPECT_EQ(id, first_id[i]) << "frame " << k << " object " << i;
    }
  }
}

TEST(CylinderTracker, OneFrameFalsePositiveIsNeverConfirmed)
{
  SyntheticTable table;
  facyl::CylinderTracker tracker;
  SyntheticTable::Item ghost{true, {0.25f, -0.2f, 0.f}, 0.05f, 0.1f};
  int ghost_id = -1;
  for (int k = 0; k < 12; ++k) {
    auto objects = table.objects(k);
    if (k == 5)
      objects.push_back(table.observe(ghost, table.camera(k).inverse()));
    tracker.update(table.supports(k), 0, objects);
    if (k == 5) {
      ghost_id = tracker.getAssignments().back().track_id;
      EXPECT_EQ(tracker.getAssignments().back().role, facyl::TrackAssignment::Role::Started);
      const auto* t = tracker.findTrack(ghost_id);
      ASSERT_NE(t, nullptr);
      EXPECT_FALSE(t->confirmed);
      EXPECT_FALSE(tracker.isCylinder(*t)); // not reported
    }
    if (k > 5) {
      EXPECT_EQ(tracker.findTrack(ghost_id), nullptr) << "frame " << k;
    }
  }
  EXPECT_EQ(tracker.getTracks().size(), table.items.size());
}

TEST(CylinderTracker, AWallForOneFrameDoesNotReplaceTheTable)
{
  // Frame 6 of a stream over a table reports a wall behind it as its table (its objects on
  // it): the tracks' plane stays the table (the frame is not anchored, its pose predicted, no
  // new scene), every track keeps its id, and the prior handed on is still the table's.
  SyntheticTable table;
  facyl::CylinderTracker tracker;
  std::set<int> ids;
  for (int k = 0; k < 12; ++k) {
    auto supports = table.supports(k);
    auto objects = table.objects(k);
    if (k == 6) {
      const Eigen::Affine3f to_camera = table.camera(k).inverse();
      const Eigen::Vector3f n = to_camera.linear() * Eigen::Vector3f(0.f, -1.f, 0.f);
      const Eigen::Vector4f wall(n.x(), n.y(), n.z(),
                                 -n.dot(to_camera * Eigen::Vector3f(0.f, 0.5f, 0.3f)));
      supports[0].plane = wall;
      supports[0].frame = facyl::planeFrame(wall, to_camera * Eigen::Vector3f(0.f, 0.5f, 0.3f));
    }
    tracker.update(supports, 0, objects);
    const auto& info = tracker.getFrameInfo();
    EXPECT_FALSE(info.new_scene) << "frame " << k;
    EXPECT_EQ(info.scene, 0u);
    EXPECT_EQ(info.anchored, k != 6) << "frame " << k;
    for (const auto& t : tracker.getTracks()) {
      if (k == 5)
        ids.insert(t.id);
      else if (k > 5) {
        EXPECT_EQ(ids.count(t.id), 1u) << "frame " << k << ", track " << t.id;
      }
    }
    // The prior for the next frame: the table as the next camera sees it.
    const facyl::SupportPrior prior = tracker.supportPrior();
    ASSERT_TRUE(prior.valid()) << "frame " << k;
    EXPECT_TRUE(facyl::consistentWithPrior(prior, table.supports(k + 1)[0].plane)) << k;
  }
  EXPECT_EQ(ids.size(), table.items.size());
}

TEST(CylinderTracker, ThePriorCarriesTheTablesExtentSeen)
{
  // Each frame sees a 0.4 m square of the table around a point that moves from frame to frame:
  // the prior handed on carries the hull of what the last frames saw, on the table's plane, so
  // a frame that sees less of the table (a dark top) keeps the objects over the rest of it.
  SyntheticTable table;
  facyl::CylinderTracker tracker;
  float first_area = 0.f;
  for (int k = 0; k < 8; ++k) {
    auto supports = table.supports(k);
    supports[0].polygon = {{-0.2f, -0.2f}, {0.2f, -0.2f}, {0.2f, 0.2f}, {-0.2f, 0.2f}};
    tracker.update(supports, 0, table.objects(k));
    ASSERT_TRUE(tracker.getFrameInfo().anchored) << k;
    const facyl::SupportPrior prior = tracker.supportPrior();
    ASSERT_TRUE(prior.valid()) << k;
    ASSERT_GE(prior.extent.size(), 4u) << k;
    // On the prior's plane; its area, in the next frame's plane coordinates.
    const auto next = table.supports(k + 1)[0];
    std::vector<Eigen::Vector2f> flat;
    for (const auto& e : prior.extent) {
      EXPECT_NEAR(prior.plane.head<3>().dot(e) + prior.plane[3], 0.f, 1e-3f) << k;
      flat.push_back((next.frame.inverse() * e).head<2>());
    }
    const float area = facyl::polygonArea(facyl::convexHull2D(flat));
    if (k == 0) {
      first_area = area;
      EXPECT_NEAR(area, 0.16f, 0.01f);
    }
    else
      EXPECT_GE(area, first_area - 0.01f) << k; // the union of the squares seen
  }
  tracker.reset();
  EXPECT_TRUE(tracker.supportPrior().extent.empty());
}

TEST(CylinderTracker, AnotherSupportOfTheRoomKeepsTheTracks)
{
  // From frame 6 on the frames find only a lower table beside the tracks' one (parallel, 0.25
  // m below: the counter's top without depth, the wooden table in front), while the objects
  // on the tracks' table stay in view. After support_switch_frames frames the lower table
  // becomes the world's plane: the tracks move into its frame where the camera's pose puts
  // them, match their objects again, and keep their ids (no new scene).
  SyntheticTable table;
  facyl::CylinderTracker tracker;
  std::set<int> ids;
  const int hold = facyl::CylinderTrackerParameters{}.support_switch_frames;
  for (int k = 0; k < 12; ++k) {
    auto supports = table.supports(k);
    if (k >= 6) {
      const Eigen::Affine3f to_camera = table.camera(k).inverse();
      const Eigen::Vector3f n = to_camera.linear() * Eigen::Vector3f::UnitZ();
      const Eigen::Vector3f at = to_camera * Eigen::Vector3f(0.3f, -0.4f, -0.25f);
      supports[0].plane = Eigen::Vector4f(n.x(), n.y(), n.z(), -n.dot(at));
      supports[0].frame = facyl::planeFrame(supports[0].plane, at);
    }
    tracker.update(supports, 0, table.objects(k));
    const auto& info = tracker.getFrameInfo();
    EXPECT_FALSE(info.new_scene) << "frame " << k;
    EXPECT_EQ(info.scene, 0u) << "frame " << k;
    EXPECT_EQ(info.anchored, k < 6 || k >= 6 + hold - 1) << "frame " << k;
    for (const auto& t : tracker.getTracks()) {
      if (k == 5)
        ids.insert(t.id);
      else if (k > 5) {
        EXPECT_EQ(ids.count(t.id), 1u) << "frame " << k << ", track " << t.id;
      }
    }
  }
  EXPECT_EQ(ids.size(), table.items.size());
}

TEST(CylinderTracker, OneFrameMissKeepsTheTrack)
{
  SyntheticTable table;
  facyl::CylinderTracker tracker;
  int id = -1;
  for (int k = 0; k < 12; ++k) {
    const auto objects = table.objects(k, k == 6 ? std::vector<int>{1} : std::vector<int>{});
    tracker.update(table.supports(k), 0, objects);
    if (k == 5)
      id = idNear(tracker, objects, table.camera(k), table.items[1].base);
    if (k == 6) {
      const auto* t = tracker.findTrack(id);
      ASSERT_NE(t, nullptr) << "a one-frame miss ended the track";
      EXPECT_EQ(t->status, facyl::TrackStatus::Missed);
      EXPECT_TRUE(tracker.isCylinder(*t)); // still reported, from its history
    }
    if (k == 7) {
      EXPECT_EQ(idNear(tracker, objects, table.camera(k), table.items[1].base), id);
    }
  }
}

TEST(CylinderTracker, FramesWithoutSupportOrFailedKeepTheTracks)
{
  SyntheticTable table;
  facyl::CylinderTracker tracker;
  std::vector<int> ids;
  for (int k = 0; k < 14; ++k) {
    auto objects = table.objects(k);
    if (k == 5) { // no support: objects with support -1
      for (auto& o : objects)
        o.cluster.support = -1;
      ASSERT_TRUE(tracker.update({}, -1, objects));
      EXPECT_FALSE(tracker.getFrameInfo().anchored);
      for (const auto& t : tracker.getTracks())
        EXPECT_EQ(t.misses, 0);
    }
    else if (k == 6)
      tracker.skipFrame(); // unreadable, empty, failed
    else if (k == 7) {     // an empty frame: no support, no object
      ASSERT_TRUE(tracker.update({}, -1, {}));
      for (const auto& t : tracker.getTracks())
        EXPECT_EQ(t.status, facyl::TrackStatus::NotUpdated);
    }
    else if (k == 8) { // a table index out of range: refused, nothing lost
      EXPECT_FALSE(tracker.update(table.supports(k), 3, objects));
      EXPECT_TRUE(tracker.getFrameInfo().skipped);
    }
    else
      ASSERT_TRUE(tracker.update(table.supports(k), 0, objects));
    if (k == 4 || k == 13) {
      std::vector<int> now;
      for (const auto& it : table.items)
        now.push_back(idNear(tracker, objects, table.camera(k), it.base));
      if (ids.empty())
        ids = now;
      else
        EXPECT_EQ(now, ids);
    }
    EXPECT_EQ(tracker.getTracks().size(), table.items.size()) << "frame " << k;
  }
  EXPECT_EQ(tracker.getFrameInfo().frame, 14u);
}

TEST(CylinderTracker, UnanchoredStreamDoesNotPileUpTentativeTracks)
{
  // A long stream without any support (a moving camera, no table: nothing to anchor on) whose
  // objects are somewhere else in every frame: each frame's new tracks are tentative and end
  // when the next frame does not see them again, so the tracks stay as many as one frame's
  // objects.
  facyl::Random rng(13);
  facyl::CylinderTracker tracker;
  for (int k = 0; k < 50; ++k) {
    std::vector<facyl::RecognizedObject> objects(5);
    for (std::size_t i = 0; i < objects.size(); ++i) {
      auto& o = objects[i];
      o.cluster.support = -1;
      o.cluster.indices.indices.resize(800);
      o.cluster.centroid =
        Eigen::Vector3f(rng.uniform(-2.f, 2.f), rng.uniform(-2.f, 2.f), rng.uniform(1.f, 4.f));
      o.evidence.p_cylinder = 0.3f;
    }
    ASSERT_TRUE(tracker.update({}, -1, objects));
    EXPECT_FALSE(tracker.getFrameInfo().anchored);
    EXPECT_LE(tracker.getTracks().size(), 2 * objects.size()) << "frame " << k;
  }
}

TEST(CylinderTracker, SplitSegmentsAreFragmentsOfOneTrack)
{
  // For three frames the recognizer reports a cylinder as two segments (its fit, and a piece
  // beside it): the piece gets the cylinder's id and starts no track.
  SyntheticTable table;
  facyl::CylinderTracker tracker;
  for (int k = 0; k < 10; ++k) {
    auto objects = table.objects(k);
    if (k >= 4 && k < 7) {
      facyl::RecognizedObject piece;
      piece.cluster.support = 0;
      piece.cluster.indices.indices.resize(300);
      piece.cluster.centroid =
        table.camera(k).inverse() * (table.items[0].base + Eigen::Vector3f(0.03f, 0.f, 0.1f));
      objects.push_back(piece);
    }
    tracker.update(table.supports(k), 0, objects);
    if (k >= 4 && k < 7) {
      const auto& a = tracker.getAssignments().back();
      EXPECT_EQ(a.role, facyl::TrackAssignment::Role::Fragment) << "frame " << k;
      EXPECT_EQ(a.track_id, idNear(tracker, objects, table.camera(k), table.items[0].base));
    }
    EXPECT_EQ(tracker.getTracks().size(), table.items.size());
  }
}

TEST(CylinderTracker, TakenAwayObjectEndsWhenTheSensorSeesThroughItsPlace)
{
  // With the sensor's depth (an empty table where the object stood), a taken-away object's
  // track ends within two frames; without it, after max_misses.
  SyntheticTable table;
  facyl::PinholeCamera cam{525.f, 525.f, 319.5f, 239.5f, 640, 480};
  for (const bool with_depth : {true, false}) {
    facyl::CylinderTracker tracker;
    int id = -1, last_seen = -1;
    for (int k = 0; k < 14; ++k) {
      const auto objects = table.objects(k, k >= 6 ? std::vector<int>{2} : std::vector<int>{});
      facyl::TrackerView view;
      view.camera = cam;
      if (with_depth) {
        const Eigen::Affine3f pose = table.camera(k);
        view.depth = [pose, cam](int u, int v) { // the table plane along the pixel's ray
          const Eigen::Vector3f d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.f);
          const Eigen::Vector3f w = pose.linear() * d;
          return -pose.translation().z() / w.z();
        };
      }
      tracker.update(table.supports(k), 0, objects, view);
      if (k == 5)
        id = idNear(tracker, objects, table.camera(k), table.items[2].base);
      if (id >= 0 && tracker.findTrack(id))
        last_seen = k;
    }
    if (with_depth)
      EXPECT_LE(last_seen, 7);
    else
      EXPECT_EQ(last_seen, 6 + facyl::CylinderTrackerParameters{}.max_misses - 1);
  }
}

TEST(CylinderTracker, NewSceneStartsNewTracks)
{
  // Another table, seen from elsewhere (its plane does not continue the tracks' and its
  // objects match none), frame after frame: every track ends, new ones start.
  SyntheticTable first, second;
  second.items = {{true, {0.3f, 0.3f, 0.f}, 0.09f, 0.05f},
                  {false, {-0.2f, 0.25f, 0.06f}, 0.f, 0.f},
                  {true, {0.f, 0.35f, 0.f}, 0.02f, 0.2f}};
  second.distance = 0.7f;
  second.elevation = 1.2f;
  facyl::CylinderTracker tracker;
  std::set<int> first_ids;
  for (int k = 0; k < 6; ++k)
    tracker.update(first.supports(k), 0, first.objects(k));
  for (const auto& t : tracker.getTracks())
    first_ids.insert(t.id);
  // The tracks' plane stays for support_switch_frames - 1 frames of another plane (not
  // anchored, the pose predicted); the next one anchors on it: a new scene.
  const int hold = facyl::CylinderTrackerParameters{}.support_switch_frames;
  for (int k = 0; k + 1 < hold; ++k) {
    tracker.update(second.supports(0), 0, second.objects(0));
    EXPECT_FALSE(tracker.getFrameInfo().anchored);
    EXPECT_FALSE(tracker.getFrameInfo().new_scene);
    EXPECT_EQ(tracker.getFrameInfo().prior_unseen_frames, k + 1);
  }
  tracker.update(second.supports(0), 0, second.objects(0));
  EXPECT_TRUE(tracker.getFrameInfo().anchored);
  EXPECT_TRUE(tracker.getFrameInfo().new_scene);
  EXPECT_EQ(tracker.getFrameInfo().scene, 1u);
  for (const auto& t : tracker.getTracks())
    EXPECT_EQ(first_ids.count(t.id), 0u);
  EXPECT_EQ(tracker.getTracks().size(), second.items.size());
}

// ------------------------------------------------------------------- simulated streams

TEST(TabletopSequence, KeepsTheSceneAndMovesSmoothly)
{
  facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
  p.seed = 42;
  facyl::TabletopSequenceParameters sp;
  sp.frames = 20;
  sp.change = facyl::TabletopSequenceParameters::Change::Remove;
  const auto seq = facyl::generateTabletopSequence(p, sp);
  const auto single = facyl::generateTabletopScene(p); // the same scene as a single frame
  ASSERT_EQ(seq.scene.objects.size(), single.objects.size());
  for (std::size_t i = 0; i < single.objects.size(); ++i)
    EXPECT_TRUE(seq.scene.objects[i].pose.matrix().isApprox(single.objects[i].pose.matrix()));
  EXPECT_TRUE(seq.cameras.front().matrix().isApprox(single.camera_to_world.matrix()));
  for (std::size_t k = 1; k < seq.cameras.size(); ++k) {
    const Eigen::AngleAxisf turn(seq.cameras[k - 1].linear().transpose() * seq.cameras[k].linear());
    EXPECT_LT(std::abs(turn.angle()), 0.1f); // smooth: under 6 degrees a frame
    EXPECT_LT((seq.cameras[k].translation() - seq.cameras[k - 1].translation()).norm(), 0.1f);
  }
  ASSERT_GE(seq.changed_object, 0);
  const auto gone = static_cast<std::size_t>(seq.changed_object);
  EXPECT_TRUE(seq.present(gone, seq.change_frame - 1));
  EXPECT_FALSE(seq.present(gone, seq.change_frame));
  // Ids keep the sequence's numbering in a frame without the object.
  const auto r = facyl::renderSequenceFrame(seq, seq.change_frame, p.camera, p.sensor, 1);
  EXPECT_EQ(r.visible_pixels.size(), seq.scene.objects.size());
  EXPECT_EQ(r.visible_pixels[gone], 0u);
  EXPECT_EQ(
    std::count(r.object_id.begin(), r.object_id.end(), static_cast<std::uint16_t>(2 + gone)), 0);
  for (std::size_t i = 0; i < seq.scene.objects.size(); ++i)
    EXPECT_EQ(static_cast<std::size_t>(std::count(r.object_id.begin(), r.object_id.end(),
                                                  static_cast<std::uint16_t>(2 + i))) >=
                r.visible_pixels[i],
              true);
  // Deterministic.
  const auto again = facyl::generateTabletopSequence(p, sp);
  EXPECT_TRUE(again.cameras.back().matrix().isApprox(seq.cameras.back().matrix()));
  EXPECT_EQ(again.changed_object, seq.changed_object);
}

TEST(CylinderTracker, IdsAreStableOnASimulatedStream)
{
  // The recognizer on 12 rendered frames of a cluttered table, the camera moving: each
  // cylinder seen well keeps one id (the id most of its frames carry covers at least 80% of
  // them), the tracked report loses no cylinder that the frames find in most frames (it may
  // turn a frame after them, and a frame later for each frame that reports it as no cylinder:
  // the track decides on the evidence its frames gave), and it adds no false one.
  // A cylinder the frames call one less often may stay unconfirmed: the track weighs every
  // frame's evidence and holds its decision while the frames disagree (here object 4, not a
  // cylinder in frames 0-5, one in 6-9). Object 7 (p 0.25, 0.04, then 0.88-0.89 from its lid
  // alone in frames 2-4, 0.10, and 0.54-0.78 in frames 6-11: frames 0, 1 and 5 against) is
  // tracked as a cylinder from frame 7 on.
  facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
  p.seed = 3003;
  facyl::TabletopSequenceParameters sp;
  sp.frames = 12;
  const auto seq = facyl::generateTabletopSequence(p, sp);
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  facyl::CylinderTracker tracker;
  std::map<int, std::map<int, int>> ids_of; // true object -> track id -> frames
  std::map<int, int> frames_found, counted_found, counted_tracked; // true object -> frames
  std::map<int, int> frames_against; // true object -> frames that report it, not a cylinder
  std::size_t frame_false = 0, tracked_false = 0;
  for (std::size_t f = 0; f < sp.frames; ++f) {
    const auto r =
      facyl::renderSequenceFrame(seq, f, p.camera, p.sensor, facyl::sequenceFrameSeed(p.seed, f));
    pcl::PointCloud<pcl::PointXYZRGBA>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZRGBA>(r.cloud));
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    ASSERT_TRUE(rec.recognize(objects));
    ASSERT_TRUE(tracker.update(rec, objects));
    // Which true cylinder a reported cylinder is (its axis centre within r/2 + 2 cm, its axis
    // within 10 degrees: a fit across the cylinder is not the cylinder).
    const auto truthOf = [&](const facyl::CylinderModel& m) {
      for (std::size_t i = 0; i < seq.scene.objects.size(); ++i) {
        const auto& o = seq.scene.objects[i];
        if (o.cls != facyl::SceneClass::Cylinder)
          continue;
        const auto c = facyl::cylinderTruth(r.scene, o);
        const Eigen::Vector3f centre = 0.5f * (m.base + m.top), a = c.base,
                              b = c.base + c.height * c.axis;
        const float t = std::clamp((centre - a).dot(b - a) / (b - a).squaredNorm(), 0.f, 1.f);
        if ((centre - (a + t * (b - a))).norm() < 0.5f * c.radius + 0.02f &&
            std::abs(m.axis.normalized().dot(c.axis)) >
              std::cos(10.f * static_cast<float>(M_PI) / 180.f))
          return static_cast<int>(i);
      }
      return -1;
    };
    std::set<int> by_frame, by_track;
    for (const auto& o : objects)
      if (o.is_cylinder) {
        const int g = truthOf(o.cylinder);
        g >= 0 ? (void)by_frame.insert(g) : (void)++frame_false;
      }
    for (const auto& t : tracker.getTracks())
      if (tracker.isCylinder(t) && t.status != facyl::TrackStatus::OutOfView) {
        const int g = truthOf(tracker.cylinderInFrame(t));
        if (g < 0) {
          ++tracked_false;
          continue;
        }
        by_track.insert(g);
        if (r.visible_pixels[static_cast<std::size_t>(g)] >= 800)
          ++ids_of[g][t.id];
      }
    for (const int g : by_frame)
      ++frames_found[g];
    std::set<int> against; // the objects mostly of a true object's pixels, not cylinders
    for (const auto& o : objects) {
      std::map<int, std::size_t> of;
      for (const auto i : o.cluster.indices.indices)
        ++of[static_cast<int>(r.object_id[static_cast<std::size_t>(i)]) - 2];
      for (const auto& [g, n] : of)
        if (g >= 0 && 2 * n > o.cluster.indices.indices.size() && !o.is_cylinder &&
            !by_frame.count(g))
          against.insert(g);
    }
    for (const int g : against)
      ++frames_against[g];
    if (f + 1 >= static_cast<std::size_t>(tracker.getParameters().confirm_hits)) {
      for (const int g : by_frame) // from the first frame a track can be confirmed in
        ++counted_found[g];
      for (const int g : by_track)
        ++counted_tracked[g];
    }
  }
  std::size_t checked = 0;
  for (const auto& [object, found] : frames_found)
    if (2 * static_cast<std::size_t>(found) > sp.frames) {
      ++checked;
      EXPECT_GE(counted_tracked[object] + 1 + frames_against[object], counted_found[object])
        << "object " << object;
    }
  EXPECT_GE(checked, 2u);
  EXPECT_LE(tracked_false, frame_false);
  ASSERT_FALSE(ids_of.empty());
  for (const auto& [object, ids] : ids_of) {
    int total = 0, most = 0;
    for (const auto& [id, n] : ids) {
      total += n;
      most = std::max(most, n);
    }
    if (total >= 5) {
      EXPECT_GE(most, 0.8 * total) << "object " << object << " changed ids";
    }
  }
}

TEST(FrameStream, PcdGrabberPlaysAFolderOfFrames)
{
  // A temporary folder: four frames of a simulated stream, a file that is not a PCD, an empty
  // cloud and a truncated file. The grabber plays the four in order, the others are left out
  // with their reasons; the tracker keeps its ids over them.
  const auto dir = std::filesystem::temp_directory_path() / "facyl_test_frame_stream";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
  p.seed = 21;
  facyl::TabletopSequenceParameters sp;
  sp.frames = 4;
  const auto seq = facyl::generateTabletopSequence(p, sp);
  for (std::size_t f = 0; f < sp.frames; ++f) {
    const auto r = facyl::renderSequenceFrame(seq, f, p.camera, p.sensor, f);
    pcl::io::savePCDFileBinaryCompressed((dir / ("frame" + std::to_string(f) + ".pcd")).string(),
                                         r.cloud);
  }
  {
    std::ofstream((dir / "frame1_notes.pcd").string()) << "not a point cloud\n";
  }
  std::ofstream((dir / "frame2_empty.pcd").string())
    << "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 0\nHEIGHT 1\n"
       "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\nDATA ascii\n";
  {
    const auto full = (dir / "frame0.pcd").string();
    std::ifstream in(full, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream((dir / "frame3_truncated.pcd").string(), std::ios::binary)
      << bytes.substr(0, bytes.size() / 3);
  }
  facyl_cli::FrameStream stream(dir.string(), 0.f, false);
  EXPECT_EQ(stream.rejected().size(), 3u);
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  facyl::CylinderTracker tracker;
  facyl_cli::StreamFrame frame;
  std::vector<std::string> names;
  std::set<int> confirmed_ids;
  while (stream.next(frame)) {
    names.push_back(std::filesystem::path(frame.name).filename().string());
    ASSERT_EQ(frame.cloud->width, 640u);
    rec.setInputCloud(frame.cloud);
    std::vector<facyl::RecognizedObject> objects;
    ASSERT_TRUE(rec.recognize(objects));
    tracker.update(rec, objects);
    if (frame.index == 1)
      for (const auto& t : tracker.getTracks())
        if (t.confirmed)
          confirmed_ids.insert(t.id);
  }
  EXPECT_EQ(names,
            (std::vector<std::string>{"frame0.pcd", "frame1.pcd", "frame2.pcd", "frame3.pcd"}));
  ASSERT_FALSE(confirmed_ids.empty());
  std::size_t kept = 0;
  for (const int id : confirmed_ids)
    kept += tracker.findTrack(id) != nullptr;
  EXPECT_GE(kept, confirmed_ids.size() - 1); // the camera moved a little: ids persist

  { // Looping at a rate: the grabber's thread publishes; at least one frame arrives.
    facyl_cli::FrameStream live(dir.string(), 50.f, true);
    EXPECT_TRUE(live.next(frame, 5.0));
    EXPECT_EQ(frame.cloud->width, 640u);
  }
  // No usable frame, no such folder: clear errors.
  const auto bad = dir / "bad";
  std::filesystem::create_directories(bad);
  {
    std::ofstream((bad / "x.pcd").string()) << "junk\n";
  }
  EXPECT_THROW(facyl_cli::FrameStream(bad.string(), 0.f, false), std::invalid_argument);
  EXPECT_THROW(facyl_cli::FrameStream((dir / "missing").string(), 0.f, false),
               std::invalid_argument);
  std::filesystem::remove_all(dir);
}

TEST(CylinderTracker, ADarkCounterStaysTheTableOfTheKitchenStream)
{
  // 7-Scenes' kitchen stream (Kinect v1, 25 frames at 15 Hz): from frame180 on the black
  // granite counter gives no plane candidate, only a few pixels of depth. The prior's plane is
  // then the table where the image supports it (SupportPriorResult::predicted): every frame
  // has a table with objects standing on it, the counter's plane throughout (its normal within
  // the prior's angle of the first frame's), and the stream stays one scene. Before, frames
  // 180-188 reported no table and the compact segments of the whole kitchen (24-30 objects).
  const std::string first = facyl_test::realFile("rgbd/sevenscenes_stream/frame150.pcd");
  if (first.empty())
    GTEST_SKIP() << "../shared/data/real/rgbd/sevenscenes_stream is absent";
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  facyl::CylinderTracker tracker;
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  int predicted = 0;
  for (int f = 150; f <= 198; f += 2) {
    const std::string file =
      facyl_test::realFile("rgbd/sevenscenes_stream/frame" + std::to_string(f) + ".pcd");
    ASSERT_FALSE(file.empty()) << f;
    pcl::PointCloud<pcl::PointXYZRGBA>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZRGBA>);
    ASSERT_EQ(pcl::io::loadPCDFile(file, *cloud), 0) << f;
    tracker.prepare(rec);
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    ASSERT_TRUE(rec.recognize(objects)) << f;
    ASSERT_TRUE(tracker.update(rec, objects)) << f;
    const auto& info = tracker.getFrameInfo();
    EXPECT_TRUE(rec.tableFound()) << f;
    EXPECT_FALSE(info.new_scene) << f;
    EXPECT_LE(objects.size(), 12u) << f;
    const auto& v = rec.getTableCoefficients().values;
    ASSERT_EQ(v.size(), 4u) << f;
    const Eigen::Vector3f n(v[0], v[1], v[2]);
    if (f == 150)
      normal = n;
    EXPECT_GT(n.dot(normal), std::cos(0.2f)) << f;
    predicted += info.prior_predicted;
  }
  std::printf("[ figures ] frames whose table is the prior's plane held without depth: %d\n",
              predicted);
  EXPECT_GE(predicted, 5);
}
