/*
 * facyl: what facyl_detect --overlay draws of each object, and the drawing. A box (green: a
 * cylinder, red: not) and the cylinder's outline (solid yellow). With --track the overlay shows
 * what the frame's JSON line says: the box's colour and the solid outline are the track's
 * decision and filtered cylinder ("is_cylinder", "cylinder"), this frame's own fit is dashed
 * magenta beside it ("cylinder_frame", when "is_cylinder_frame"), and the track's id is written
 * over the box's top-left corner ("#7", in the box's colour).
 */
#pragma once

#include <facyl/tools/overlay_canvas.h>
#include <facyl/tools/track_json.h>

#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/tracking/cylinder_tracker.h>

#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace facyl_cli {

/** One object as the overlay draws it. */
struct OverlayObject {
  facyl::PixelBox box{-1, -1, -1, -1};                ///< none when box[0] < 0
  bool is_cylinder{false};                            ///< the box's colour
  std::optional<facyl::CylinderModel> cylinder;       ///< solid outline
  std::optional<facyl::CylinderModel> frame_cylinder; ///< dashed: the frame's own, with a track
  int track_id{-1};                                   ///< "#id" over the box; -1: none
};

/** The objects of a frame on its own: each box, and the outline of each cylinder. */
inline std::vector<OverlayObject>
overlayObjects(const std::vector<facyl::RecognizedObject>& objects)
{
  std::vector<OverlayObject> shown;
  for (const auto& o : objects) {
    OverlayObject s;
    s.box = o.cluster.box;
    s.is_cylinder = o.is_cylinder;
    if (o.is_cylinder)
      s.cylinder = o.cylinder;
    shown.push_back(std::move(s));
  }
  return shown;
}

/** The objects of a tracked frame (after \a tracker's update with \a objects), as its JSON line
 * has them (trackedView): the track's decision and filtered cylinder, the frame's own cylinder
 * (when the frame alone takes the object for one) and the track's id. */
inline std::vector<OverlayObject>
trackedOverlayObjects(const std::vector<facyl::RecognizedObject>& objects,
                      const facyl::CylinderTracker& tracker)
{
  const auto& assignments = tracker.getAssignments();
  std::vector<OverlayObject> shown;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const facyl::TrackAssignment a =
      k < assignments.size() ? assignments[k] : facyl::TrackAssignment{};
    const facyl::RecognizedObject tracked = trackedView(objects[k], a, tracker);
    OverlayObject s;
    s.box = objects[k].cluster.box;
    s.is_cylinder = tracked.is_cylinder;
    if (tracked.is_cylinder && tracked.evidence.fitted)
      s.cylinder = tracked.cylinder;
    if (objects[k].is_cylinder)
      s.frame_cylinder = objects[k].cylinder;
    s.track_id = a.track_id;
    shown.push_back(std::move(s));
  }
  return shown;
}

/** Draws \a shown on \a canvas: boxes and outlines (outlines need a valid \a camera), then the
 * labels (a scale of one font pixel per 240 image rows, at least 1) over the box's top-left
 * corner, inside the box when there is no room above it. */
inline void
drawOverlayObjects(Canvas& canvas, const facyl::PinholeCamera& camera,
                   const std::vector<OverlayObject>& shown)
{
  const std::array<unsigned char, 3> green{0, 230, 0}, red{230, 0, 0}, yellow{255, 230, 0},
    magenta{255, 0, 255};
  constexpr int kDash = 4;
  for (const auto& o : shown) {
    const auto& b = o.box;
    if (b[0] >= 0) {
      const auto& c = o.is_cylinder ? green : red;
      const Eigen::Vector2f p00(b[0], b[1]), p10(b[2], b[1]), p11(b[2], b[3]), p01(b[0], b[3]);
      canvas.line(p00, p10, c, 2), canvas.line(p10, p11, c, 2);
      canvas.line(p11, p01, c, 2), canvas.line(p01, p00, c, 2);
    }
    if (o.cylinder && camera.valid())
      drawCylinderOutline(canvas, camera, *o.cylinder, yellow);
    if (o.frame_cylinder && camera.valid())
      drawCylinderOutline(canvas, camera, *o.frame_cylinder, magenta, kDash);
  }
  const int scale = std::max(1, canvas.height / 240);
  for (const auto& o : shown) {
    if (o.track_id < 0 || o.box[0] < 0)
      continue;
    const std::string text = "#" + std::to_string(o.track_id);
    const Eigen::Vector2i size = labelSize(text, scale);
    const int u = std::clamp(o.box[0], 0, std::max(0, canvas.width - size.x()));
    const int v = o.box[1] - size.y() - 1 >= 0 ? o.box[1] - size.y() - 1 : o.box[1] + 2;
    drawLabel(canvas, u, v, text, o.is_cylinder ? green : red, scale);
  }
}

} // namespace facyl_cli
