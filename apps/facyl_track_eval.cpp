/*
 * facyl_track_eval: measures CylinderTracker against ground truth on simulated streams (a
 * camera moving around a static cluttered table; facyl_synth --sequence's renderer): tracked
 * against per-frame detection.
 */
#include <facyl/tools/cli.h>
#include <facyl/tools/recognizer_options.h>
#include <facyl/tools/scene_options.h>
#include <facyl/tools/tracker_options.h>

#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/simulation/tabletop_sequence.h>
#include <facyl/tracking/cylinder_tracker.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <numeric>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;
using Recognizer = facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>;

/** A ground-truth cylinder is counted in a frame when this many of its pixels have depth (as
 * facyl_tabletop_eval counts objects). */
constexpr std::size_t kMinVisiblePixels = 300;

struct Options {
  std::size_t sequences{20};
  std::uint64_t seed{3000};
  std::string sensor{"kinect"};
  std::string change{"mixed"};
  facyl::TabletopSceneParameters scene;
  facyl::TabletopSequenceParameters sequence;
  facyl::TabletopRecognizerParameters params;
  Eigen::Vector3f up{Eigen::Vector3f::Zero()};
  facyl::ShapeClassifier::Ptr classifier;
  facyl::CylinderTrackerParameters tracking;
  std::string csv;
};

double
median(std::vector<double> v)
{
  if (v.empty())
    return NAN;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

double
percentile(std::vector<double> v, double q)
{
  if (v.empty())
    return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

/** Distance from \a p to the segment [a, b]. */
float
segmentDistance(const Eigen::Vector3f& p, const Eigen::Vector3f& a, const Eigen::Vector3f& b)
{
  const Eigen::Vector3f d = b - a;
  const float t =
    d.squaredNorm() > 0.f ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.f, 1.f) : 0.f;
  return (p - (a + t * d)).norm();
}

/** Cylinders reported in a frame, scored against the truth. */
struct Score {
  std::size_t tp{0}, fp{0}, fn{0};
  std::vector<double> radius_error, axis_error_deg; ///< of the true positives
};

struct Truth {
  int object{-1};
  facyl::CylinderTruth cylinder;
  bool visible{false};
};

/** Greedy one-to-one matching of \a reports to \a truth by the distance of a report's axis
 * centre to a true axis segment (at most half the true radius + 2 cm). A report on a true
 * cylinder that is not visible enough is neither true nor false. \return per report the true
 * object, or -1. */
std::vector<int>
scoreReports(const std::vector<facyl::CylinderModel>& reports, const std::vector<Truth>& truth,
             Score& score)
{
  struct Pair {
    float d;
    std::size_t r, t;
  };
  std::vector<Pair> pairs;
  for (std::size_t r = 0; r < reports.size(); ++r)
    for (std::size_t t = 0; t < truth.size(); ++t) {
      const auto& c = truth[t].cylinder;
      const float d = segmentDistance(0.5f * (reports[r].base + reports[r].top), c.base,
                                      c.base + c.height * c.axis);
      if (d <= 0.5f * c.radius + 0.02f)
        pairs.push_back({d, r, t});
    }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d < b.d; });
  std::vector<int> of_report(reports.size(), -1);
  std::vector<char> used(truth.size(), 0);
  for (const auto& p : pairs) {
    if (of_report[p.r] >= 0 || used[p.t])
      continue;
    of_report[p.r] = static_cast<int>(p.t);
    used[p.t] = 1;
  }
  for (std::size_t r = 0; r < reports.size(); ++r) {
    if (of_report[r] < 0) {
      ++score.fp;
      continue;
    }
    const Truth& t = truth[static_cast<std::size_t>(of_report[r])];
    if (!t.visible)
      continue;
    ++score.tp;
    score.radius_error.push_back(std::abs(reports[r].radius - t.cylinder.radius) /
                                 t.cylinder.radius);
    score.axis_error_deg.push_back(facyl::axisAngle(reports[r].axis, t.cylinder.axis) * 180.0 /
                                   M_PI);
  }
  for (std::size_t t = 0; t < truth.size(); ++t)
    score.fn += truth[t].visible && !used[t];
  for (auto& v : of_report)
    v = v >= 0 ? truth[static_cast<std::size_t>(v)].object : -1;
  return of_report;
}

/** Everything measured on one sensor's sequences. */
struct Totals {
  Score frame, tracked;
  /** Paired errors: a true cylinder reported by both in the same frame. */
  std::vector<double> paired_radius_frame, paired_radius_tracked, paired_axis_frame,
    paired_axis_tracked;
  /** Per paired cylinder-frame, the error of its object's median per-frame radius over the
   * sequence: what remains when every frame's noise is averaged away (the fits' bias per
   * object, which no temporal filter removes). */
  std::vector<double> paired_radius_bias;
  std::size_t id_switches{0}, track_frames{0};         ///< every object
  std::size_t cyl_id_switches{0}, cyl_track_frames{0}; ///< the cylinders
  std::vector<double> confirm_delay, frame_delay;      ///< frames after first visible
  std::size_t never_confirmed{0}, never_detected{0}, new_objects{0};
  std::vector<double> added_delay;                    ///< objects put down half-way
  std::size_t removed{0}, removed_reported_frames{0}; ///< objects taken away
  std::vector<double> tracker_ms;
  /** Re-anchoring against the true camera motion: per frame, how far the tracker's world
   * moved against the table (the in-plane turn in degrees, the shift in mm, the tilt in
   * degrees) since the sequence's first anchored frame. */
  std::vector<double> anchor_yaw_deg, anchor_shift_mm, anchor_tilt_deg;
  std::size_t frames{0}, failed_frames{0}, new_scenes{0}, tracks_started{0};
};

/** The object (2 + index) most points of each of \a objects lie on, or -1 when none has half. */
std::vector<int>
truthOfObjects(const std::vector<facyl::RecognizedObject>& objects,
               const std::vector<std::uint16_t>& ids)
{
  std::vector<int> out;
  for (const auto& o : objects) {
    std::map<int, std::size_t> count;
    for (const auto i : o.cluster.indices.indices) {
      const int id = ids[static_cast<std::size_t>(i)];
      if (id >= 2 && id < facyl::kFirstSceneryId)
        ++count[id - 2];
    }
    int best = -1;
    std::size_t most = 0;
    for (const auto& [id, n] : count)
      if (n > most) {
        most = n;
        best = id;
      }
    out.push_back(2 * most >= o.cluster.indices.indices.size() ? best : -1);
  }
  return out;
}

void
evaluateSequence(const Options& opt, std::uint64_t seed,
                 facyl::TabletopSequenceParameters::Change change, Recognizer& rec, Totals& totals,
                 std::ofstream* csv)
{
  facyl::TabletopSceneParameters p = opt.scene;
  p.seed = seed;
  facyl::TabletopSequenceParameters sp = opt.sequence;
  sp.change = change;
  const facyl::TabletopSequence seq = facyl::generateTabletopSequence(p, sp);
  facyl::CylinderTracker tracker(opt.tracking);
  const std::size_t n_objects = seq.scene.objects.size();
  std::vector<int> last_track(n_objects, -1);
  bool anchored = false;
  Eigen::Affine3f first_anchor = Eigen::Affine3f::Identity(); ///< true world to tracker world
  std::vector<long> first_visible(n_objects, -1), first_tracked(n_objects, -1),
    first_detected(n_objects, -1);
  std::vector<std::vector<double>> signed_radius_frame(n_objects); ///< per-frame fits
  std::vector<int> paired_objects;
  for (std::size_t f = 0; f < seq.cameras.size(); ++f) {
    const facyl::RenderedScene r =
      facyl::renderSequenceFrame(seq, f, p.camera, p.sensor, facyl::sequenceFrameSeed(seed, f));
    Cloud::Ptr cloud(new Cloud(r.cloud));
    rec.setInputCloud(cloud);
    tracker.prepare(rec); // the tracks' table, where the camera's motion puts it
    std::vector<facyl::RecognizedObject> objects;
    const bool ok = rec.recognize(objects);
    const auto t0 = std::chrono::steady_clock::now();
    if (ok)
      tracker.update(rec, objects);
    else
      tracker.skipFrame();
    totals.tracker_ms.push_back(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (ok && tracker.getFrameInfo().anchored) {
      const Eigen::Affine3f camera_to_world(seq.cameras[f].matrix());
      const Eigen::Affine3f a = tracker.getFrameToWorld() * camera_to_world.inverse();
      if (!anchored || tracker.getFrameInfo().new_scene) {
        first_anchor = a;
        anchored = true;
      }
      else {
        const Eigen::Affine3f d = a * first_anchor.inverse();
        const Eigen::Vector3f x = d.linear().col(0);
        totals.anchor_yaw_deg.push_back(std::abs(std::atan2(x.y(), x.x())) * 180.0 / M_PI);
        totals.anchor_tilt_deg.push_back(std::acos(std::min(1.f, d.linear().col(2).z())) * 180.0 /
                                         M_PI);
        // The shift where the objects are: at the true world's origin (the table's centre).
        totals.anchor_shift_mm.push_back(
          1e3 * (a * Eigen::Vector3f::Zero() - first_anchor * Eigen::Vector3f::Zero()).norm());
      }
    }
    ++totals.frames;
    totals.failed_frames += !ok;
    totals.new_scenes += tracker.getFrameInfo().new_scene;
    for (const auto& a : tracker.getAssignments())
      totals.tracks_started += a.role == facyl::TrackAssignment::Role::Started;

    // Truth: the cylinders on the table in this frame.
    std::vector<Truth> truth;
    for (std::size_t i = 0; i < n_objects; ++i) {
      const auto& o = seq.scene.objects[i];
      if (!seq.present(i, f))
        continue;
      if (r.visible_pixels[i] >= kMinVisiblePixels && first_visible[i] < 0)
        first_visible[i] = static_cast<long>(f);
      if (o.cls != facyl::SceneClass::Cylinder)
        continue;
      truth.push_back({static_cast<int>(i), facyl::cylinderTruth(r.scene, o),
                       r.visible_pixels[i] >= kMinVisiblePixels});
    }
    // Per frame: the objects called cylinders. Tracked: the confirmed cylinder tracks that the
    // frame saw or that it cannot have seen (hidden, merged, missed for a few frames); not
    // those out of view or seen through.
    std::vector<facyl::CylinderModel> frame_reports, tracked_reports;
    for (const auto& o : objects)
      if (o.is_cylinder)
        frame_reports.push_back(o.cylinder);
    for (const auto& t : tracker.getTracks())
      if (tracker.isCylinder(t) && t.status != facyl::TrackStatus::OutOfView &&
          t.status != facyl::TrackStatus::SeenThrough)
        tracked_reports.push_back(tracker.cylinderInFrame(t));
    Score fs, ts;
    const std::vector<int> frame_truth = scoreReports(frame_reports, truth, fs);
    const std::vector<int> tracked_truth = scoreReports(tracked_reports, truth, ts);
    for (Score* s : {&fs, &ts}) {
      Score& total = s == &fs ? totals.frame : totals.tracked;
      total.tp += s->tp;
      total.fp += s->fp;
      total.fn += s->fn;
      total.radius_error.insert(total.radius_error.end(), s->radius_error.begin(),
                                s->radius_error.end());
      total.axis_error_deg.insert(total.axis_error_deg.end(), s->axis_error_deg.begin(),
                                  s->axis_error_deg.end());
    }
    // Paired errors and first detections.
    for (const Truth& t : truth) {
      if (!t.visible)
        continue;
      const auto fr = std::find(frame_truth.begin(), frame_truth.end(), t.object);
      const auto tr = std::find(tracked_truth.begin(), tracked_truth.end(), t.object);
      const auto i = static_cast<std::size_t>(t.object);
      if (fr != frame_truth.end() && first_detected[i] < 0)
        first_detected[i] = static_cast<long>(f);
      if (fr != frame_truth.end())
        signed_radius_frame[i].push_back(
          (frame_reports[static_cast<std::size_t>(fr - frame_truth.begin())].radius -
           t.cylinder.radius) /
          t.cylinder.radius);
      if (tr != tracked_truth.end() && first_tracked[i] < 0)
        first_tracked[i] = static_cast<long>(f);
      if (fr != frame_truth.end() && tr != tracked_truth.end()) {
        const auto& a = frame_reports[static_cast<std::size_t>(fr - frame_truth.begin())];
        const auto& b = tracked_reports[static_cast<std::size_t>(tr - tracked_truth.begin())];
        totals.paired_radius_frame.push_back(std::abs(a.radius - t.cylinder.radius) /
                                             t.cylinder.radius);
        paired_objects.push_back(t.object);
        totals.paired_radius_tracked.push_back(std::abs(b.radius - t.cylinder.radius) /
                                               t.cylinder.radius);
        totals.paired_axis_frame.push_back(facyl::axisAngle(a.axis, t.cylinder.axis) * 180.0 /
                                           M_PI);
        totals.paired_axis_tracked.push_back(facyl::axisAngle(b.axis, t.cylinder.axis) * 180.0 /
                                             M_PI);
      }
    }
    // The taken-away object: frames after the change in which a track still reports it.
    if (seq.change == facyl::TabletopSequenceParameters::Change::Remove &&
        seq.changed_object >= 0 && f >= seq.change_frame) {
      const auto& gone = seq.scene.objects[static_cast<std::size_t>(seq.changed_object)];
      if (gone.cls == facyl::SceneClass::Cylinder) {
        const facyl::CylinderTruth c = facyl::cylinderTruth(r.scene, gone);
        for (const auto& m : tracked_reports)
          if (segmentDistance(0.5f * (m.base + m.top), c.base, c.base + c.height * c.axis) <=
              0.5f * c.radius + 0.02f) {
            ++totals.removed_reported_frames;
            break;
          }
      }
    }
    // Identities: each true object's largest segment with a confirmed track.
    const std::vector<int> owner = truthOfObjects(objects, r.object_id);
    const auto& assignments = tracker.getAssignments();
    std::vector<int> track_of(n_objects, -1);
    std::vector<std::size_t> size_of(n_objects, 0);
    for (std::size_t k = 0; k < objects.size() && k < assignments.size(); ++k) {
      if (owner[k] < 0)
        continue;
      const facyl::CylinderTrack* t = tracker.findTrack(assignments[k].track_id);
      if (!t || !t->confirmed)
        continue;
      const auto g = static_cast<std::size_t>(owner[k]);
      if (objects[k].cluster.indices.indices.size() > size_of[g]) {
        size_of[g] = objects[k].cluster.indices.indices.size();
        track_of[g] = t->id;
      }
    }
    for (std::size_t g = 0; g < n_objects; ++g) {
      if (track_of[g] < 0)
        continue;
      const bool cylinder = seq.scene.objects[g].cls == facyl::SceneClass::Cylinder;
      ++totals.track_frames;
      totals.cyl_track_frames += cylinder;
      if (last_track[g] >= 0 && last_track[g] != track_of[g]) {
        ++totals.id_switches;
        totals.cyl_id_switches += cylinder;
      }
      last_track[g] = track_of[g];
    }
    if (csv) // one row per report
      for (int tracked = 0; tracked < 2; ++tracked) {
        const auto& reports = tracked ? tracked_reports : frame_reports;
        const auto& of = tracked ? tracked_truth : frame_truth;
        for (std::size_t k = 0; k < reports.size(); ++k) {
          const auto& m = reports[k];
          *csv << seed << "," << f << "," << (tracked ? "tracked" : "frame") << "," << of[k] << ",";
          if (of[k] >= 0) {
            const auto& o = seq.scene.objects[static_cast<std::size_t>(of[k])];
            const facyl::CylinderTruth c = facyl::cylinderTruth(r.scene, o);
            *csv << o.kind << (o.lying ? "_lying" : "") << (o.handle ? "_handle" : "") << ","
                 << r.visible_pixels[static_cast<std::size_t>(of[k])] << ","
                 << (m.radius - c.radius) / c.radius << ","
                 << facyl::axisAngle(m.axis, c.axis) * 180.0 / M_PI;
          }
          else
            *csv << ",,,";
          *csv << "," << m.radius << "," << m.angular_coverage << "," << m.inliers.size() << "\n";
        }
      }
  }
  for (std::size_t i = 0; i < n_objects; ++i) {
    if (seq.scene.objects[i].cls != facyl::SceneClass::Cylinder || first_visible[i] < 0)
      continue;
    ++totals.new_objects;
    if (first_tracked[i] >= 0)
      totals.confirm_delay.push_back(static_cast<double>(first_tracked[i] - first_visible[i]));
    else
      ++totals.never_confirmed;
    if (first_detected[i] >= 0)
      totals.frame_delay.push_back(static_cast<double>(first_detected[i] - first_visible[i]));
    else
      ++totals.never_detected;
    if (seq.change == facyl::TabletopSequenceParameters::Change::Add &&
        static_cast<int>(i) == seq.changed_object && first_tracked[i] >= 0)
      totals.added_delay.push_back(static_cast<double>(first_tracked[i] - first_visible[i]));
  }
  if (seq.change == facyl::TabletopSequenceParameters::Change::Remove && seq.changed_object >= 0 &&
      seq.scene.objects[static_cast<std::size_t>(seq.changed_object)].cls ==
        facyl::SceneClass::Cylinder)
    ++totals.removed;
  for (const int o : paired_objects)
    totals.paired_radius_bias.push_back(
      std::abs(median(signed_radius_frame[static_cast<std::size_t>(o)])));
}

void
printTotals(const Options& opt, const Totals& t)
{
  const auto pr = [](const Score& s, double& precision, double& recall) {
    precision = s.tp + s.fp ? static_cast<double>(s.tp) / static_cast<double>(s.tp + s.fp) : NAN;
    recall = s.tp + s.fn ? static_cast<double>(s.tp) / static_cast<double>(s.tp + s.fn) : NAN;
  };
  double fp_, fr_, tp_, tr_;
  pr(t.frame, fp_, fr_);
  pr(t.tracked, tp_, tr_);
  std::printf("\n## %zu sequences of %zu frames, sensor %s, change %s (seeds %llu..)\n\n",
              opt.sequences, opt.sequence.frames, opt.sensor.c_str(), opt.change.c_str(),
              static_cast<unsigned long long>(opt.seed));
  std::printf("frames %zu (recognition failed: %zu), new scenes detected: %zu, tracks started: "
              "%zu\n\n",
              t.frames, t.failed_frames, t.new_scenes, t.tracks_started);
  std::printf("| cylinders (>= %zu visible pixels) | TP | FP | FN | precision | recall | radius "
              "error median (p90) | axis error median (p90) |\n|---|---|---|---|---|---|---|---|\n",
              kMinVisiblePixels);
  std::printf(
    "| per frame | %zu | %zu | %zu | %.3f | %.3f | %.2f %% (%.2f %%) | %.2f deg (%.2f deg) |\n",
    t.frame.tp, t.frame.fp, t.frame.fn, fp_, fr_, 100 * median(t.frame.radius_error),
    100 * percentile(t.frame.radius_error, 0.9), median(t.frame.axis_error_deg),
    percentile(t.frame.axis_error_deg, 0.9));
  std::printf(
    "| tracked | %zu | %zu | %zu | %.3f | %.3f | %.2f %% (%.2f %%) | %.2f deg (%.2f deg) |\n\n",
    t.tracked.tp, t.tracked.fp, t.tracked.fn, tp_, tr_, 100 * median(t.tracked.radius_error),
    100 * percentile(t.tracked.radius_error, 0.9), median(t.tracked.axis_error_deg),
    percentile(t.tracked.axis_error_deg, 0.9));
  std::printf("Paired (%zu cylinder-frames reported by both): radius error median %.2f %% per "
              "frame, %.2f %% tracked; axis %.2f deg per frame, %.2f deg tracked\n",
              t.paired_radius_frame.size(), 100 * median(t.paired_radius_frame),
              100 * median(t.paired_radius_tracked), median(t.paired_axis_frame),
              median(t.paired_axis_tracked));
  std::printf("Bias per object (the same pairs): the median of each object's per-frame radii over "
              "its sequence errs by median %.2f %% (p90 %.2f %%): what no temporal filter of the "
              "fits removes\n",
              100 * median(t.paired_radius_bias), 100 * percentile(t.paired_radius_bias, 0.9));
  std::printf("Identities: %zu switches in %zu track-frames (%.2f per 100) of all objects; "
              "cylinders %zu in %zu (%.2f per 100)\n",
              t.id_switches, t.track_frames,
              t.track_frames
                ? 100.0 * static_cast<double>(t.id_switches) / static_cast<double>(t.track_frames)
                : NAN,
              t.cyl_id_switches, t.cyl_track_frames,
              t.cyl_track_frames ? 100.0 * static_cast<double>(t.cyl_id_switches) /
                                     static_cast<double>(t.cyl_track_frames)
                                 : NAN);
  const auto mean = [](const std::vector<double>& v) {
    return v.empty() ? NAN
                     : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  };
  std::printf("Frames from a cylinder's first visible frame to its first report: tracked median "
              "%.1f (mean %.2f, never %zu of %zu), per frame median %.1f (mean %.2f, never %zu)\n",
              median(t.confirm_delay), mean(t.confirm_delay), t.never_confirmed, t.new_objects,
              median(t.frame_delay), mean(t.frame_delay), t.never_detected);
  std::printf("Cylinders put down half-way: %zu confirmed, median %.1f frames after they became "
              "visible; taken away: %zu, reported by a track in %zu frames after\n",
              t.added_delay.size(), median(t.added_delay), t.removed, t.removed_reported_frames);
  std::printf("Re-anchoring against the true camera motion (%zu frames): in-plane turn median "
              "%.2f deg (p90 %.2f), shift at the table's centre median %.1f mm (p90 %.1f), tilt "
              "median %.2f deg (p90 %.2f)\n",
              t.anchor_yaw_deg.size(), median(t.anchor_yaw_deg), percentile(t.anchor_yaw_deg, 0.9),
              median(t.anchor_shift_mm), percentile(t.anchor_shift_mm, 0.9),
              median(t.anchor_tilt_deg), percentile(t.anchor_tilt_deg, 0.9));
  std::printf("Tracker per frame (update incl. its view of the cloud): median %.3f ms, p90 %.3f "
              "ms, max %.3f ms\n",
              median(t.tracker_ms), percentile(t.tracker_ms, 0.9),
              t.tracker_ms.empty() ? NAN
                                   : *std::max_element(t.tracker_ms.begin(), t.tracker_ms.end()));
}

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [--sequences N] [--frames F] [--first-seed S] [--sensor kinect|stereo]\n"
    "          [--layout cluttered|spread|realistic] [--change mixed|none|remove|add]\n"
    "          [--orbit RAD] [--track-confirm-hits N] [--track-max-misses N]\n"
    "          [--track-support-switch-frames N] [--csv FILE]\n"
    "          [recognizer options]\n"
    "Renders N simulated streams (default 20) of F frames (default 30): a camera moving\n"
    "around a static table (facyl_synth --sequence; seeds S.., default 3000; --change mixed:\n"
    "none, remove, add in turn), runs the recognizer on every frame and CylinderTracker on\n"
    "the stream, and prints, tracked against per frame: cylinder precision and recall (a\n"
    "cylinder counts in a frame with >= 300 visible pixels; a report on a hidden one is\n"
    "neither true nor false), radius and axis errors, identity switches per 100 track-frames,\n"
    "frames until a new cylinder is reported, what happens to objects put down or taken\n"
    "away, and the tracker's time per frame. --csv FILE: one row per cylinder reported.\n%s%s",
    self, facyl_cli::recognizerOptionsHelp(), facyl_cli::commonHelp());
}

Options
parseOptions(int argc, char** argv)
{
  Options opt;
  const facyl_cli::Arguments args(
    argc, argv,
    facyl_cli::joined(facyl_cli::joined(facyl_cli::recognizerValueOptions(),
                                        facyl_cli::valueOptions(facyl_cli::trackerOptions())),
                      facyl_cli::joined(facyl_cli::sceneImageOptions(),
                                        {"--sequences", "--frames", "--first-seed", "--sensor",
                                         "--layout", "--change", "--orbit", "--csv"})),
    facyl_cli::recognizerSwitches(), facyl_cli::recognizerAliases());
  if (!args.positional().empty())
    throw std::invalid_argument("unexpected argument " + args.positional()[0]);
  opt.sequences = static_cast<std::size_t>(args.integer("--sequences", 20, 1, 100000));
  opt.sequence.frames = static_cast<std::size_t>(args.integer("--frames", 30, 2, 100000));
  opt.seed = static_cast<std::uint64_t>(args.integer("--first-seed", 3000, 0, facyl_cli::kMaxSeed));
  if (!facyl::parseLayoutPreset(args.text("--layout", "cluttered"), opt.scene))
    throw std::invalid_argument("--layout must be spread, cluttered or realistic");
  opt.sensor = args.text("--sensor", "kinect");
  if (opt.sensor == "random" ||
      !facyl::parseSensorPreset(opt.sensor, opt.scene.sensor, opt.scene.camera))
    throw std::invalid_argument("--sensor must be kinect or stereo");
  facyl_cli::applySceneImageOptions(args, opt.scene);
  opt.change = args.text("--change", "mixed");
  facyl::TabletopSequenceParameters::Change c;
  if (opt.change != "mixed" && !facyl::parseSequenceChange(opt.change, c))
    throw std::invalid_argument("--change must be mixed, none, remove or add");
  opt.sequence.orbit = static_cast<float>(args.number("--orbit", opt.sequence.orbit, 0.0, 6.3));
  facyl_cli::applyOptions(facyl_cli::trackerOptions(), args, opt.tracking);
  opt.csv = args.text("--csv", "");
  if (!opt.csv.empty())
    facyl_cli::checkOutputFile("--csv", opt.csv, {".csv"}, "CSV table", {});
  facyl_cli::RecognizerSettings recognizer;
  opt.classifier = facyl_cli::applyRecognizerOptions(args, recognizer);
  opt.params = recognizer.params;
  opt.up = recognizer.up;
  return opt;
}

} // namespace

int
main(int argc, char** argv)
{
  Options opt;
  const int rc = facyl_cli::startTool(argc, argv, "facyl_track_eval", printHelp,
                                      [&] { opt = parseOptions(argc, argv); });
  if (rc >= 0)
    return rc;
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  Recognizer rec;
  rec.setParameters(opt.params);
  rec.setUpDirection(opt.up);
  rec.setClassifier(opt.classifier);
  std::ofstream csv;
  if (!opt.csv.empty()) {
    csv.open(opt.csv);
    csv << "seed,frame,report,object,kind,visible_pixels,radius_error,axis_error_deg,radius,"
           "angular_coverage,n_inliers\n";
  }
  Totals totals;
  using Change = facyl::TabletopSequenceParameters::Change;
  for (std::size_t k = 0; k < opt.sequences; ++k) {
    Change change = Change::None;
    if (opt.change == "mixed")
      change = k % 3 == 0 ? Change::None : (k % 3 == 1 ? Change::Remove : Change::Add);
    else
      facyl::parseSequenceChange(opt.change, change);
    evaluateSequence(opt, opt.seed + k, change, rec, totals, csv.is_open() ? &csv : nullptr);
    std::fprintf(stderr, "\rsequence %zu/%zu", k + 1, opt.sequences);
  }
  std::fprintf(stderr, "\n");
  printTotals(opt, totals);
  return 0;
}
