/*
 * facyl: tabletop scenes made by hand for the tests (a table from the generator, the objects
 * placed by the test), rendered, segmented or recognized, and scored against their ground
 * truth. Shared by test_clutter.cpp and test_piles.cpp.
 */
#pragma once

#include <facyl/recognition/shape_classifier.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/segmentation/segmentation_score.h>
#include <facyl/segmentation/tabletop_segmentation.h>
#include <facyl/simulation/scene_rendering.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/common/point_tests.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace facyl_test {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

constexpr float kPi = 3.14159265358979f;

/** Camera at \a eye looking at \a target (world z up), as the simulator's cameras. */
inline Eigen::Isometry3f
lookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target)
{
  const Eigen::Vector3f forward = (target - eye).normalized();
  const Eigen::Vector3f right = forward.cross(Eigen::Vector3f::UnitZ()).normalized();
  Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
  pose.linear().col(0) = right;
  pose.linear().col(1) = forward.cross(right);
  pose.linear().col(2) = forward;
  pose.translation() = eye;
  return pose;
}

/** A table (and its legs, floor) without objects, from the generator; the test adds them. */
inline facyl::TabletopScene
emptyTable(const facyl::TabletopSceneParameters& base = {})
{
  facyl::TabletopSceneParameters p = base;
  p.min_objects = p.max_objects = 0;
  return facyl::generateTabletopScene(p);
}

inline facyl::SceneObject
box(const Eigen::Vector3f& size, const Eigen::Vector3f& base, float yaw = 0.f)
{
  facyl::SceneObject o;
  o.cls = facyl::SceneClass::Box;
  o.kind = "box";
  o.size = size;
  o.pose.linear() = Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  o.pose.translation() = base;
  o.colour[0] = Eigen::Vector3f(0.8f, 0.3f, 0.2f);
  return o;
}

inline facyl::SceneObject
can(float radius, float height, const Eigen::Vector3f& base, const std::string& kind = "can")
{
  facyl::SceneObject o;
  o.cls = facyl::SceneClass::Cylinder;
  o.kind = kind;
  o.radius = radius;
  o.height = height;
  o.pose.translation() = base;
  o.colour[0] = Eigen::Vector3f(0.2f, 0.5f, 0.8f);
  return o;
}

inline facyl::RenderedScene
render(facyl::TabletopScene scene, const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
       const std::string& sensor = "kinect", std::uint64_t seed = 7)
{
  scene.camera_to_world = lookAt(eye, target);
  facyl::TabletopSceneParameters p;
  facyl::parseSensorPreset(sensor, p.sensor, p.camera);
  return facyl::renderTabletopScene(scene, p.camera, p.sensor, seed);
}

/** Per point: the object id (>= 2) or 0 (table, background), -1 without depth. */
inline std::vector<int>
truthOf(const facyl::RenderedScene& s)
{
  std::vector<int> t(s.cloud.size());
  for (std::size_t i = 0; i < t.size(); ++i)
    t[i] = !pcl::isFinite(s.cloud[i]) ? -1 : (s.object_id[i] >= 2 ? s.object_id[i] : 0);
  return t;
}

inline std::vector<facyl::SegmentOutcome>
segmentAndScore(const facyl::RenderedScene& s, facyl::TabletopSegmentationParameters params = {})
{
  Cloud::Ptr cloud(new Cloud(s.cloud));
  facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
  seg.setParameters(params);
  seg.setInputCloud(cloud);
  std::vector<facyl::TabletopCluster> clusters;
  EXPECT_TRUE(seg.segment(clusters));
  std::vector<pcl::PointIndices> segments;
  for (const auto& c : clusters)
    segments.push_back(c.indices);
  return facyl::scoreSegments(truthOf(s), segments, 300);
}

inline std::vector<facyl::RecognizedObject>
recognize(const facyl::RenderedScene& s, facyl::TabletopRecognizerParameters params = {},
          const facyl::ShapeClassifier::Ptr& classifier = nullptr)
{
  Cloud::Ptr cloud(new Cloud(s.cloud));
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setParameters(params);
  rec.setClassifier(classifier);
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  EXPECT_TRUE(rec.recognize(objects));
  return objects;
}

/** The output object most of whose points are ground-truth object \a id, or nullptr. */
inline const facyl::RecognizedObject*
objectOf(const std::vector<facyl::RecognizedObject>& objects, const facyl::RenderedScene& s, int id)
{
  const facyl::RecognizedObject* best = nullptr;
  std::size_t best_count = 0;
  for (const auto& o : objects) {
    std::size_t count = 0;
    for (const auto i : o.cluster.indices.indices)
      count += s.object_id[static_cast<std::size_t>(i)] == id;
    if (2 * count > o.cluster.indices.indices.size() && count > best_count)
      best = &o, best_count = count;
  }
  return best;
}

} // namespace facyl_test
