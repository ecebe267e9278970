/*
 * facyl_viewer: how a scene is drawn (scene_drawing.h).
 */
#include "scene_drawing.h"

#include <facyl/tools/depth_colours.h>

#include <facyl/segmentation/tabletop_geometry.h>
#include <facyl/segmentation/tabletop_segmentation.h>

#include <pcl/common/point_tests.h>
#include <pcl/conversions.h>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facyl_viewer {

void
boxOf(const Cloud& cloud, const pcl::Indices& indices, Eigen::Vector3f& box_min,
      Eigen::Vector3f& box_max)
{
  box_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  box_max = -box_min;
  for (const auto i : indices) {
    const Eigen::Vector3f p = cloud[static_cast<std::size_t>(i)].getVector3fMap();
    box_min = box_min.cwiseMin(p);
    box_max = box_max.cwiseMax(p);
  }
}

std::vector<Eigen::Vector3f>
tableOutline(const facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>& rec)
{
  std::vector<Eigen::Vector3f> outline;
  const auto& supports = rec.getSupports();
  const auto& t = rec.getTableCoefficients().values;
  if (supports.empty() || t.size() != 4)
    return outline;
  // The support whose plane is the table's.
  const Eigen::Vector4f table(t[0], t[1], t[2], t[3]);
  const auto best =
    std::min_element(supports.begin(), supports.end(), [&](const auto& a, const auto& b) {
      return (a.plane - table).norm() < (b.plane - table).norm();
    });
  for (const auto& q : best->polygon)
    outline.push_back(best->frame * Eigen::Vector3f(q.x(), q.y(), 0.f));
  return outline;
}

pcl::PolygonMesh
cylinderMesh(const facyl::CylinderModel& m, int segments)
{
  Eigen::Vector3f a = m.top - m.base;
  if (!(a.norm() > 1e-6f))
    a = m.axis * std::max(m.height, 1e-3f);
  const Eigen::Vector3f axis = a.normalized();
  Eigen::Vector3f u = axis.unitOrthogonal(), v = axis.cross(u);
  pcl::PointCloud<pcl::PointXYZ> vertices;
  for (int ring = 0; ring < 2; ++ring)
    for (int k = 0; k < segments; ++k) {
      const float t =
        2.f * static_cast<float>(M_PI) * static_cast<float>(k) / static_cast<float>(segments);
      const Eigen::Vector3f p = m.base + (ring ? a : Eigen::Vector3f::Zero()) +
                                m.radius * (std::cos(t) * u + std::sin(t) * v);
      vertices.push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    }
  vertices.push_back(pcl::PointXYZ(m.base.x(), m.base.y(), m.base.z()));
  const Eigen::Vector3f top = m.base + a;
  vertices.push_back(pcl::PointXYZ(top.x(), top.y(), top.z()));
  pcl::PolygonMesh mesh;
  pcl::toPCLPointCloud2(vertices, mesh.cloud);
  const pcl::index_t n = segments;
  for (pcl::index_t k = 0; k < n; ++k) {
    const pcl::index_t k1 = (k + 1) % n;
    for (pcl::Indices face : {pcl::Indices{k, k1, n + k1, n + k}, pcl::Indices{2 * n, k1, k},
                              pcl::Indices{2 * n + 1, n + k, n + k1}}) {
      pcl::Vertices v;
      v.vertices = std::move(face); // side, bottom, lid
      mesh.polygons.push_back(std::move(v));
    }
  }
  return mesh;
}

void
drawCylinder(pcl::visualization::PCLVisualizer& viewer, const facyl::CylinderModel& m,
             const std::string& id, int viewport, double r, double g, double b)
{
  // Meshes live with the clouds in PCLVisualizer: their properties are point-cloud ones.
  viewer.addPolygonMesh(cylinderMesh(m, kMeshSegments), id, viewport);
  viewer.setPointCloudRenderingProperties(pcl::visualization::PCL_VISUALIZER_COLOR, r, g, b, id,
                                          viewport);
  viewer.setPointCloudRenderingProperties(pcl::visualization::PCL_VISUALIZER_OPACITY, 0.85, id,
                                          viewport);
}

namespace {

/** Shape \a id drawn in its own colour whatever the light. */
void
unlit(pcl::visualization::PCLVisualizer& viewer, const std::string& id)
{
  const auto shapes = viewer.getShapeActorMap();
  const auto it = shapes->find(id);
  if (it == shapes->end())
    return;
  if (auto* actor = vtkActor::SafeDownCast(it->second))
    actor->GetProperty()->LightingOff();
}

} // namespace

void
drawCylinderOutline(pcl::visualization::PCLVisualizer& viewer, const facyl::CylinderModel& m,
                    const std::string& id, int viewport, double r, double g, double b, double width)
{
  const pcl::PolygonMesh mesh = cylinderMesh(m, kMeshSegments);
  pcl::PointCloud<pcl::PointXYZ> corners;
  pcl::fromPCLPointCloud2(mesh.cloud, corners); // the two rings, then the two centres
  vtkNew<vtkPoints> points;
  for (const auto& p : corners)
    points->InsertNextPoint(p.x, p.y, p.z);
  vtkNew<vtkCellArray> lines;
  const auto segment = [&lines](vtkIdType i, vtkIdType j) {
    const vtkIdType ends[2] = {i, j};
    lines->InsertNextCell(2, ends);
  };
  const vtkIdType n = kMeshSegments;
  for (vtkIdType k = 0; k < n; ++k) {
    segment(k, (k + 1) % n);         // base ring
    segment(n + k, n + (k + 1) % n); // top ring
  }
  for (vtkIdType k = 0; k < n; k += n / 4)
    segment(k, n + k); // four generators
  vtkSmartPointer<vtkPolyData> polydata = vtkSmartPointer<vtkPolyData>::New();
  polydata->SetPoints(points);
  polydata->SetLines(lines);
  viewer.addModelFromPolyData(polydata, id, viewport);
  viewer.setShapeRenderingProperties(pcl::visualization::PCL_VISUALIZER_COLOR, r, g, b, id,
                                     viewport);
  viewer.setShapeRenderingProperties(pcl::visualization::PCL_VISUALIZER_LINE_WIDTH, width, id,
                                     viewport);
  unlit(viewer, id);
}

void
drawBox(pcl::visualization::PCLVisualizer& viewer, const Eigen::Vector3f& box_min,
        const Eigen::Vector3f& box_max, const std::string& id, int viewport, double r, double g,
        double b, double width)
{
  viewer.addCube(box_min.x(), box_max.x(), box_min.y(), box_max.y(), box_min.z(), box_max.z(), r, g,
                 b, id, viewport);
  viewer.setShapeRenderingProperties(pcl::visualization::PCL_VISUALIZER_REPRESENTATION,
                                     pcl::visualization::PCL_VISUALIZER_REPRESENTATION_WIREFRAME,
                                     id, viewport);
  viewer.setShapeRenderingProperties(pcl::visualization::PCL_VISUALIZER_LINE_WIDTH, width, id,
                                     viewport);
  unlit(viewer, id);
}

void
drawLabel(pcl::visualization::PCLVisualizer& viewer, const std::string& text,
          const Eigen::Vector3f& at, const Eigen::Vector3f& eye, const std::string& id,
          int viewport, double r, double g, double b)
{
  // A quarter of the way to the eye: where the sensor sees it at, in front of the object.
  const Eigen::Vector3f shown = eye + 0.75f * (at - eye);
  const float distance = std::max(0.1f, (shown - eye).norm());
  viewer.addText3D(text, pcl::PointXYZ(shown.x(), shown.y(), shown.z()), kLabelHeight * distance, r,
                   g, b, id, viewport);
}

void
drawTable(pcl::visualization::PCLVisualizer& viewer, const std::vector<Eigen::Vector3f>& outline,
          const std::string& tag, int viewport)
{
  if (outline.size() < 3)
    return;
  pcl::PointCloud<pcl::PointXYZ>::Ptr polygon(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& p : outline)
    polygon->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  viewer.addPolygon<pcl::PointXYZ>(polygon, 0.2, 0.5, 1.0, tag + "table", viewport);
  viewer.setShapeRenderingProperties(pcl::visualization::PCL_VISUALIZER_LINE_WIDTH, 3,
                                     tag + "table", viewport);
}

void
sensorCamera(pcl::visualization::PCLVisualizer& viewer, const Cloud& cloud, int viewport)
{
  const Eigen::Affine3f pose = facyl::plausibleSensorPose(cloud);
  const Eigen::Vector3f o = pose.translation();
  const Eigen::Matrix3f r = pose.linear();
  const Eigen::Vector3f look = o + r.col(2), up = -r.col(1);
  viewer.setCameraPosition(o.x(), o.y(), o.z(), look.x(), look.y(), look.z(), up.x(), up.y(),
                           up.z(), viewport);
  double fov = 49.0 * M_PI / 180.0; // a Kinect's vertical field of view
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  if (cloud.isOrganized() && cloud.height > 1) {
    const Eigen::Affine3f to_sensor = pose.inverse();
    const std::size_t step = std::max<std::size_t>(1, cloud.size() / 4000);
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(cloud.size() / step + 1));
    Eigen::Matrix2Xf px(2, pts.cols());
    Eigen::Index n = 0;
    for (std::size_t i = 0; i < cloud.size(); i += step)
      if (pcl::isFinite(cloud[i])) {
        pts.col(n) = to_sensor * cloud[i].getVector3fMap();
        px.col(n++) =
          Eigen::Vector2f(static_cast<float>(i % cloud.width), static_cast<float>(i / cloud.width));
      }
    facyl::PinholeCamera camera;
    const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height);
    if (facyl::estimatePinhole(pts.leftCols(n), px.leftCols(n), w, h, camera) && camera.fy > 0.f) {
      fov = 2.0 * std::atan(0.5 * h / camera.fy);
      // VTK moves the optical axis to -WindowCenter in normalized device coordinates.
      centre =
        Eigen::Vector2d(1.0 - 2.0 * (camera.cx + 0.5) / w, 2.0 * (camera.cy + 0.5) / h - 1.0);
    }
  }
  viewer.setCameraFieldOfView(fov, viewport);
  viewer.setCameraClipDistances(0.01, 50.0, viewport);
  auto renderers = viewer.getRendererCollection();
  renderers->InitTraversal();
  int i = 0;
  while (vtkRenderer* renderer = renderers->GetNextItem()) {
    if (viewport == 0 || viewport == i)
      renderer->GetActiveCamera()->SetWindowCenter(centre.x(), centre.y());
    ++i;
  }
}

Cloud::ConstPtr
drawnCloud(const Cloud& cloud)
{
  Cloud::Ptr drawn(new Cloud(cloud));
  if (!facyl_cli::hasColour(cloud))
    facyl_cli::colourByDepth(*drawn); // in the sensor's pose, before it is dropped
  drawn->sensor_origin_ = Eigen::Vector4f::Zero();
  drawn->sensor_orientation_ = Eigen::Quaternionf::Identity();
  return drawn;
}

} // namespace facyl_viewer
