/*
 * facyl_viewer --stream (stream_view.h): frames from a grabber, recognized, tracked and drawn.
 */
#include "stream_view.h"

#include "scene_drawing.h"

#include <facyl/tools/frame_stream.h>
#include <facyl/tools/json_writer.h>

#include <facyl/tracking/cylinder_tracker.h>

#include <pcl/common/point_tests.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace facyl_viewer {

namespace {

using facyl_cli::Json;

/** A colour of its own for each track id (golden-ratio hues). */
std::array<double, 3>
trackColour(int id)
{
  const double h = std::fmod(0.13 + 0.618034 * id, 1.0) * 6.0;
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  const int sector = static_cast<int>(h);
  const std::array<std::array<double, 3>, 6> rgb{
    {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}}};
  auto c = rgb[static_cast<std::size_t>(sector % 6)];
  for (auto& v : c)
    v = 0.25 + 0.75 * v;
  return c;
}

/** One frame of --stream: the cloud, the table, every confirmed track in its colour with its
 * id (cylinders as meshes, faint when the frame did not see them; other objects as the box of
 * their points), tentative ones as thin boxes. */
void
drawTracked(pcl::visualization::PCLVisualizer& viewer, const Cloud::ConstPtr& cloud,
            const facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>& rec,
            const std::vector<facyl::RecognizedObject>& objects,
            const facyl::CylinderTracker& tracker, const std::string& title, const Layers& layers)
{
  viewer.removeAllPointClouds();
  viewer.removeAllShapes();
  const Cloud::ConstPtr drawn = drawnCloud(*cloud);
  pcl::visualization::PointCloudColorHandlerRGBField<pcl::PointXYZRGBA> rgb(drawn);
  viewer.addPointCloud<pcl::PointXYZRGBA>(drawn, rgb, "cloud");
  if (layers.table) {
    drawTable(viewer, tableOutline(rec), "s_", 0);
  }
  for (const auto& t : tracker.getTracks()) {
    const auto c = trackColour(t.id);
    const std::string id = "t" + std::to_string(t.id);
    const bool seen = t.status == facyl::TrackStatus::Seen;
    Eigen::Vector3f label_at = tracker.centroidInFrame(t);
    std::string label;
    char buf[160];
    if (tracker.isCylinder(t)) {
      const facyl::CylinderModel m = tracker.cylinderInFrame(t);
      if (layers.cylinders) {
        drawCylinder(viewer, m, id + "_cyl", 0, c[0], c[1], c[2]);
        viewer.setPointCloudRenderingProperties(pcl::visualization::PCL_VISUALIZER_OPACITY,
                                                seen ? 0.85 : 0.3, id + "_cyl", 0);
      }
      std::snprintf(buf, sizeof buf, "#%d r=%.1fmm h=%.1fmm p=%.2f%s", t.id, m.radius * 1e3f,
                    m.height * 1e3f, t.pCylinder(),
                    seen ? "" : (" " + facyl::toString(t.status)).c_str());
      label_at = m.top;
    }
    else if (seen && t.object >= 0 && static_cast<std::size_t>(t.object) < objects.size()) {
      Eigen::Vector3f box_min, box_max;
      boxOf(*cloud, objects[static_cast<std::size_t>(t.object)].cluster.indices.indices, box_min,
            box_max);
      if (layers.boxes) {
        viewer.addCube(box_min.x(), box_max.x(), box_min.y(), box_max.y(), box_min.z(), box_max.z(),
                       c[0], c[1], c[2], id + "_box");
        viewer.setShapeRenderingProperties(
          pcl::visualization::PCL_VISUALIZER_REPRESENTATION,
          pcl::visualization::PCL_VISUALIZER_REPRESENTATION_WIREFRAME, id + "_box");
        viewer.setShapeRenderingProperties(pcl::visualization::PCL_VISUALIZER_LINE_WIDTH,
                                           t.confirmed ? 2 : 1, id + "_box");
      }
      std::snprintf(buf, sizeof buf, "#%d%s", t.id, t.confirmed ? "" : " (new)");
      label_at = box_min;
    }
    else
      continue;
    label = buf;
    if (layers.labels)
      viewer.addText3D(label, pcl::PointXYZ(label_at.x(), label_at.y(), label_at.z()), 0.008, c[0],
                       c[1], c[2], id + "_label");
  }
  viewer.addText(title, 10, 10, 14, 0.8, 0.8, 0.8, "title");
}

/** The frame's tracks as one JSON line: {"frame", "file", "objects", "tracks": [{"track_id",
 * "confirmed", "is_cylinder", "status", "object"}]}, or {"frame", "file", "error"}. */
std::string
streamLine(std::size_t frame, const std::string& file, const facyl::CylinderTracker* tracker,
           std::size_t objects, const std::string& error = {})
{
  Json out;
  out["frame"] = frame;
  out["file"] = file;
  if (!error.empty()) {
    out["error"] = error;
    return facyl_cli::dumpJson(out);
  }
  out["objects"] = objects;
  out["tracks"] = Json::array();
  for (const auto& t : tracker->getTracks()) {
    Json j;
    j["track_id"] = t.id;
    j["confirmed"] = t.confirmed;
    j["is_cylinder"] = tracker->isCylinder(t);
    j["status"] = facyl::toString(t.status);
    j["object"] = t.object >= 0 ? Json(t.object) : Json(nullptr);
    out["tracks"].push_back(std::move(j));
  }
  return facyl_cli::dumpJson(out);
}

} // namespace

int
runStream(const StreamSettings& s)
{
  facyl_cli::FrameStream stream(s.source, s.rate, s.loop);
  for (const auto& r : stream.rejected())
    std::fprintf(stderr, "facyl_viewer: %s: left out of the stream\n", r.c_str());
  pcl::visualization::PCLVisualizer viewer("facyl_viewer: " + stream.description());
  viewer.setSize(s.width, s.height);
  viewer.setBackgroundColor(0.05, 0.05, 0.08);
  viewer.setShowFPS(false);
  Layers layers;
  bool redraw = false;
  viewer.registerKeyboardCallback([&](const pcl::visualization::KeyboardEvent& e) {
    if (!e.keyDown())
      return;
    const std::string key = e.getKeySym();
    bool* layer = key == "t"   ? &layers.table
                  : key == "c" ? &layers.cylinders
                  : key == "b" ? &layers.boxes
                  : key == "l" ? &layers.labels
                               : nullptr;
    if (layer) {
      *layer = !*layer;
      redraw = true;
    }
  });
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setParameters(s.params);
  rec.setUpDirection(s.up);
  rec.setClassifier(s.classifier);
  facyl::CylinderTracker tracker;
  std::vector<facyl::RecognizedObject> objects;
  Cloud::ConstPtr shown;
  std::string title;
  std::size_t processed = 0, number = 0;
  while (!viewer.wasStopped() && !(s.frames > 0 && static_cast<long long>(processed) >= s.frames)) {
    facyl_cli::StreamFrame frame;
    if (!stream.next(frame, 0.05)) {
      if (stream.timedOut()) { // a live source between frames
        viewer.spinOnce(20);
        continue;
      }
      break; // the end of the frames
    }
    for (const auto& why : frame.skipped) { // unreadable: nothing known, the tracks are kept
      std::fprintf(stderr, "facyl_viewer: %s\n", why.c_str());
      tracker.skipFrame();
      std::cout << streamLine(number++, why.substr(0, why.find(": ")), nullptr, 0,
                              "PCL's reader could not read it")
                << std::endl;
    }
    const Cloud::ConstPtr& cloud = frame.cloud;
    std::string error;
    if (std::none_of(cloud->begin(), cloud->end(), [](const auto& p) { return pcl::isFinite(p); }))
      error = "the cloud has no finite point";
    else {
      rec.setInputCloud(cloud);
      if (!rec.recognize(objects))
        error = "recognition failed (see the message above)";
    }
    if (!error.empty()) {
      tracker.skipFrame();
      std::fprintf(stderr, "facyl_viewer: %s: %s (the tracks are kept)\n", frame.name.c_str(),
                   error.c_str());
      std::cout << streamLine(number++, frame.name, nullptr, 0, error) << std::endl;
      ++processed;
      continue;
    }
    tracker.update(rec, objects);
    std::cout << streamLine(number++, frame.name, &tracker, objects.size()) << std::endl;
    title = frame.name + "  (frame " + std::to_string(frame.index) + ", " +
            std::to_string(tracker.getTracks().size()) + " tracks)";
    drawTracked(viewer, cloud, rec, objects, tracker, title, layers);
    if (!shown)
      sensorCamera(viewer, *cloud, 0); // the sensor's view once; the user may move it then
    shown = cloud;
    ++processed;
    viewer.spinOnce(1, true);
  }
  if (stream.dropped() > 0)
    std::fprintf(stderr,
                 "facyl_viewer: %zu frames arrived while one was processed and were "
                 "dropped\n",
                 stream.dropped());
  if (!shown) {
    std::fprintf(stderr, "facyl_viewer: --stream %s: no frame could be shown\n", s.source.c_str());
    return 1;
  }
  if (!s.screenshot.empty()) {
    viewer.spinOnce(1, true);
    viewer.saveScreenshot(s.screenshot);
    Json line;
    line["stream"] = s.source;
    line["frames"] = processed;
    line["screenshot"] = s.screenshot;
    std::printf("%s\n", facyl_cli::dumpJson(line).c_str());
    return 0;
  }
  while (!viewer.wasStopped()) { // the last frame stays on screen
    if (redraw) {
      drawTracked(viewer, shown, rec, objects, tracker, title, layers);
      redraw = false;
    }
    viewer.spinOnce(50);
  }
  return 0;
}

} // namespace facyl_viewer
