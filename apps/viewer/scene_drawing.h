/*
 * facyl_viewer: how a scene is drawn in pcl::visualization::PCLVisualizer, shared by its scene
 * mode (facyl_viewer.cpp) and its stream mode (stream_view.h): the cloud in its own frame, the
 * table outline, finite cylinders as meshes, the camera at the cloud's sensor.
 */
#pragma once

#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>

#include <pcl/PolygonMesh.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/visualization/pcl_visualizer.h>

#include <string>
#include <vector>

namespace facyl_viewer {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

constexpr int kMeshSegments = 36;

/** Which layers are shown. */
struct Layers {
  bool table{true}, cylinders{true}, boxes{true}, labels{true};
};

/** The axis-aligned box of the points \a indices of \a cloud. */
void boxOf(const Cloud& cloud, const pcl::Indices& indices, Eigen::Vector3f& box_min,
           Eigen::Vector3f& box_max);

/** The outline of the recognizer's table (its support's polygon), in the cloud's frame; empty
 * without a table. */
std::vector<Eigen::Vector3f>
tableOutline(const facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>& rec);

/** A closed finite cylinder from \a m.base to \a m.top, \a segments around. */
pcl::PolygonMesh cylinderMesh(const facyl::CylinderModel& m, int segments);

/** \a m as a mesh \a id of colour (r, g, b), opacity 0.85. */
void drawCylinder(pcl::visualization::PCLVisualizer& viewer, const facyl::CylinderModel& m,
                  const std::string& id, int viewport, double r, double g, double b);

/** The outline of \a m (its base and top circles and four generators) as lines \a id of colour (r,
 * g, b), \a width pixels wide, unlit: beside a mesh, another estimate of the same cylinder. */
void drawCylinderOutline(pcl::visualization::PCLVisualizer& viewer, const facyl::CylinderModel& m,
                         const std::string& id, int viewport, double r, double g, double b,
                         double width = 2.0);

/** The wireframe box from \a box_min to \a box_max as shape \a id, \a width pixels wide and
 * unlit (every edge in its colour; lit, the edges that face away were drawn black). */
void drawBox(pcl::visualization::PCLVisualizer& viewer, const Eigen::Vector3f& box_min,
             const Eigen::Vector3f& box_max, const std::string& id, int viewport, double r,
             double g, double b, double width);

/** \a text at \a at as the sensor at \a eye sees it, facing the camera: a quarter of the way
 * from \a at to the eye (in front of the object it names, which would hide it), its height
 * kLabelHeight times its distance from the eye (as readable on a far object as on a near
 * one). */
void drawLabel(pcl::visualization::PCLVisualizer& viewer, const std::string& text,
               const Eigen::Vector3f& at, const Eigen::Vector3f& eye, const std::string& id,
               int viewport, double r, double g, double b);

/** Height of a label (drawLabel) per metre of distance from the sensor: about 12 pixels at a
 * Kinect's field of view in a window 480 pixels high. */
constexpr float kLabelHeight = 0.018f;

/** The table \a outline (nothing with fewer than 3 corners) as the blue polygon
 * \a tag + "table". */
void drawTable(pcl::visualization::PCLVisualizer& viewer,
               const std::vector<Eigen::Vector3f>& outline, const std::string& tag, int viewport);

/** The camera at the cloud's sensor, looking along its z (image y down), as pcl_viewer does.
 * The pose is the one the recognizer uses (facyl::plausibleSensorPose): PCL's grabber frames
 * store a 180-degree turn about x with the points in the camera's frame, and the camera must
 * then look along +z to see them. An organized frame is seen with its own intrinsics
 * (estimated from its points and pixels: field of view from fy, the principal point as the
 * window centre), so that a screenshot of its size lies on the frame's image; other clouds
 * with a Kinect's field of view. */
void sensorCamera(pcl::visualization::PCLVisualizer& viewer, const Cloud& cloud, int viewport);

/** The cloud as drawn: its points in its own frame, in their colours, or coloured by depth
 * when they have none (facyl_cli::colourByDepth: near red, far blue; black points on the dark
 * background show nothing). PCLVisualizer would move a cloud by its sensor pose
 * (sensor_origin_, sensor_orientation_), while the recognizer's table, cylinders and boxes are
 * in the cloud's frame: drawn with the pose, a grabber frame (VIEWPOINT 0 0 0 0 1 0 0) ends up
 * turned away from everything found on it. */
Cloud::ConstPtr drawnCloud(const Cloud& cloud);

} // namespace facyl_viewer
