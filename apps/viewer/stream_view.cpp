/*
 * facyl_viewer --stream (stream_view.h): frames from a grabber, recognized, tracked and drawn.
 */
#include "stream_view.h"

#include "scene_drawing.h"

#include <facyl/tools/frame_stream.h>
#include <facyl/tools/json_writer.h>
#include <facyl/tools/track_json.h>

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

/** Track \a t as drawn over its frame, in its colour, with its id: a confirmed cylinder as the
 * mesh of its filtered cylinder (faint when the frame did not see it; its label right of its
 * top) and, when this frame's own fit of its object is a cylinder, that fit's white outline
 * beside it; other objects seen as the box of their points (thin while tentative); a
 * confirmed track not seen as its label at its place. \a sensor: the frame's sensor pose. */
void
drawTrack(pcl::visualization::PCLVisualizer& viewer, const facyl::CylinderTrack& t,
          const facyl::CylinderTracker& tracker, const Cloud& cloud,
          const std::vector<facyl::RecognizedObject>& objects, const Eigen::Affine3f& sensor,
          const Layers& layers)
{
  const auto c = trackColour(t.id);
  const std::string id = "t" + std::to_string(t.id);
  const bool seen = t.status == facyl::TrackStatus::Seen;
  const facyl::RecognizedObject* object =
    seen && t.object >= 0 && static_cast<std::size_t>(t.object) < objects.size()
      ? &objects[static_cast<std::size_t>(t.object)]
      : nullptr;
  const std::string status = seen ? "" : " " + facyl::toString(t.status);
  Eigen::Vector3f label_at = tracker.centroidInFrame(t);
  char label[160];
  if (tracker.isCylinder(t)) {
    const facyl::CylinderModel m = tracker.cylinderInFrame(t);
    if (layers.cylinders) {
      drawCylinder(viewer, m, id + "_cyl", 0, c[0], c[1], c[2]);
      viewer.setPointCloudRenderingProperties(pcl::visualization::PCL_VISUALIZER_OPACITY,
                                              seen ? 0.85 : 0.3, id + "_cyl", 0);
      if (object && object->is_cylinder)
        drawCylinderOutline(viewer, object->cylinder, id + "_frame", 0, 1.0, 1.0, 1.0);
    }
    std::snprintf(label, sizeof label, "#%d r=%.1fmm h=%.1fmm p=%.2f%s", t.id, m.radius * 1e3f,
                  m.height * 1e3f, t.pCylinder(), status.c_str());
    label_at = m.top + 1.2f * m.radius * sensor.linear().col(0); // not over the mesh's colour
  }
  else if (object) {
    Eigen::Vector3f box_min, box_max;
    boxOf(cloud, object->cluster.indices.indices, box_min, box_max);
    if (layers.boxes)
      drawBox(viewer, box_min, box_max, id + "_box", 0, c[0], c[1], c[2], t.confirmed ? 2 : 1);
    std::snprintf(label, sizeof label, "#%d%s", t.id, t.confirmed ? "" : " (new)");
    label_at = box_min;
  }
  else if (t.confirmed)
    std::snprintf(label, sizeof label, "#%d%s", t.id, status.c_str());
  else
    return;
  if (layers.labels)
    drawLabel(viewer, label, label_at, sensor.translation(), id + "_label", 0, c[0], c[1], c[2]);
}

/** One frame of --stream: the cloud, the table, and every track (drawTrack). */
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
  const Eigen::Affine3f sensor = facyl::plausibleSensorPose(*cloud);
  for (const auto& t : tracker.getTracks())
    drawTrack(viewer, t, tracker, *cloud, objects, sensor, layers);
  viewer.addText(title, 10, 10, 14, 0.8, 0.8, 0.8, "title");
}

/** The frame's JSON line: "frame" (its number in the stream), then what facyl_detect --track
 * prints for it (track_json.h: the objects with their tracks, "stream" and "tracks" with their
 * geometry). */
std::string
streamLine(std::size_t frame, const std::string& file, const Cloud& cloud,
           const facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>& rec,
           const std::vector<facyl::RecognizedObject>& objects,
           const facyl::CylinderTracker& tracker)
{
  Json scene = facyl_cli::trackedSceneJson(file, cloud, rec, objects, rec.getTiming(), tracker);
  Json out;
  out["frame"] = frame;
  for (auto& [key, value] : scene.items())
    out[key] = std::move(value);
  return facyl_cli::dumpJson(out);
}

/** The JSON line of a frame that could not be tracked (after tracker.skipFrame()): "frame",
 * "file", "error", and the stream's fields as facyl_detect --track prints them. */
std::string
errorLine(std::size_t frame, const std::string& file, const std::string& error,
          const facyl::CylinderTracker& tracker)
{
  Json out;
  out["frame"] = frame;
  out["file"] = file;
  out["error"] = error;
  facyl_cli::addStreamFields(out, tracker, nullptr);
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
      std::cout << errorLine(number++, why.substr(0, why.find(": ")),
                             "PCL's reader could not read it", tracker)
                << std::endl;
    }
    const Cloud::ConstPtr& cloud = frame.cloud;
    std::string error;
    if (std::none_of(cloud->begin(), cloud->end(), [](const auto& p) { return pcl::isFinite(p); }))
      error = "the cloud has no finite point";
    else {
      rec.setInputCloud(cloud);
      tracker.prepare(rec); // the tracks' table, where the camera's motion puts it
      if (!rec.recognize(objects))
        error = "recognition failed (see the message above)";
    }
    if (!error.empty()) {
      tracker.skipFrame();
      std::fprintf(stderr, "facyl_viewer: %s: %s (the tracks are kept)\n", frame.name.c_str(),
                   error.c_str());
      std::cout << errorLine(number++, frame.name, error, tracker) << std::endl;
      ++processed;
      continue;
    }
    tracker.update(rec, objects);
    std::cout << streamLine(number++, frame.name, *cloud, rec, objects, tracker) << std::endl;
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
