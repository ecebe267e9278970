/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/segmentation/tabletop_geometry.h>
#include <facyl/segmentation/tabletop_segmentation.h>
#include <facyl/tracking/tracking_numerics.h>

#include <pcl/common/point_tests.h>
#include <pcl/point_cloud.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace facyl {

struct TrackObservation; // tracker_steps.h
struct AnchorChoice;     // tracker_steps.h

/** \brief Settings of CylinderTracker. Lengths in metres, angles in radians, counts in frames
 * given to update(). */
struct CylinderTrackerParameters {
  // ---- life of a track
  /** Frames a new track must be matched in (counting its first) before it is confirmed and
   * reported, in [1, 100]. 2: a cylinder seen in one frame only never becomes a track. */
  int confirm_hits{2};
  /** A confirmed track is ended after more than this many missed frames in a row (in view,
   * not hidden, not seen), in [1, 1000]. */
  int max_misses{5};
  /** A tentative track is ended after more than this many frames without a match, in
   * [0, 100]; 0: at its first. */
  int max_tentative_misses{0};
  /** A confirmed track hidden behind nearer surfaces (the sensor's depth at its place is
   * nearer), or merged into another segment, is kept this many frames, in [0, 100000]. */
  int max_occluded{60};
  /** A confirmed track outside the image is kept this many frames, in [0, 1000000]. */
  int max_out_of_view{300};
  /** Misses counted for a frame in which the sensor sees through the track's place (depth
   * beyond it: the object was taken away), in [1, 1000]. */
  int see_through_misses{3};

  // ---- where the frame is (re-anchoring)
  /** A support continues the tracks' plane when, under the pose predicted for the frame, its
   * normal is within this angle of the plane's (rad, in (0, pi/2]) ... */
  float max_plane_angle{0.35f};
  /** ... and its height within this distance (m, > 0). The support prior handed to the
   * recognizer (supportPrior) takes the same two tolerances. */
  float max_plane_offset{0.15f};
  /** The tracks' plane stays the table, in the recognizer (the support prior, supportPrior)
   * and as the anchor, until this many frames in a row, in [1, 1000]:
   * - show supports none of which continues it (a wall or a far plane filling the view,
   *   another table): until then such a frame is not anchored (its pose is predicted); the
   *   last one anchors on its own support, which becomes the tracks' plane;
   * - or would alone have chosen another family of supports, with more objects standing on
   *   it (SupportPriorResult::challenged): after the last one the next frame chooses alone.
   * Frames without any support count for neither. */
  int support_switch_frames{3};
  /** A frame is of a new scene (every track ends, new ones start) when the registration
   * matches fewer than this share of the confirmed tracks expected in view (at least 3
   * expected and 3 objects seen), or, when its support does not continue the plane, fewer than
   * two; in [0, 1]; 0: never by share. */
  float min_overlap{0.3f};
  RegistrationSettings registration;

  // ---- association
  AssociationSettings association;
  /** An unmatched object whose centroid lies within this distance (m, >= 0) of the cylinder
   * (or the centroid) of a track matched in the same frame is a fragment of that object (a
   * split segment): it is reported with that track's id and starts no track. */
  float fragment_margin{0.03f};

  // ---- filtering (per observation: the measurement's standard deviation; per frame: the
  // process noise, what re-anchoring may move a static object by)
  float measurement_centroid{0.02f}; ///< m, the centroid of the visible points, > 0
  float measurement_extent{0.01f};   ///< m, each end of a cylinder along its axis, > 0
  float process_position{0.002f};    ///< m per frame, >= 0
  /** An observed end of a cylinder inside the tracked extent counts with this weight (an
   * occluded end), one beyond it fully; in (0, 1]. */
  float shrink_weight{0.3f};
  float huber_k{2.f}; ///< outlying observations pull by at most this many sigmas, > 0
  /** The cylinder is estimated from its last this many observations, in [1, 1000]: the
   * axis that most of them agree with (consensusAxis, within axis_agreement), the axis line
   * where the agreeing ones put it (weighted medians across the axis) and their weighted
   * median radius. A fit's radius errs mostly by a few percent and sometimes by tens (a
   * partial arc, a neighbour's points), its axis now and then by tens of degrees: a mean,
   * even a robust one, follows such a fit too far, and a wrong first fit for a long time. */
  int history{30};
  float axis_agreement{0.14f}; ///< rad (8 degrees), in (0, pi/2]
  /** How much an observation counts grows with what the frame saw of the object: its points
   * times the angular coverage of its fit (a fit on few points, or on a narrow arc, errs more
   * in radius: docs/tracking.md, "Design in brief"). The measurement variances above are those
   * of an object of this quality (points x coverage, > 0), divided by an observation's quality
   * over it (within [1/4, 4]); the history weighs each observation by its quality squared (the
   * inverse of its variance). */
  float reference_quality{600.f};

  // ---- confidence
  /** The track's log-odds of being a cylinder stay within +-this (4.6: p in [0.01, 0.99]),
   * > 0. */
  float confidence_limit{4.6f};
  /** A track is a cylinder when its p_cylinder is at least this (and it has a cylinder
   * estimate), in [0, 1], with hysteresis: once decided, the decision changes only when the
   * log-odds cross this threshold's by more than the standard deviation of the track's
   * per-frame evidence (decisionMargin), so that frames that disagree about an object do not
   * flip it at every frame. */
  float min_probability{0.5f};
  /** A frame's evidence: its decision sets the side, its p_cylinder (when known) the
   * strength. An accepted cylinder counts as p_cylinder clamped to at least this, another
   * object as p_cylinder clamped to at most 1 - this; without a classifier (p_cylinder NaN)
   * as this and 1 - this. In [0.5, 0.99]. */
  float decision_probability{0.6f};
};

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string validate(const CylinderTrackerParameters& params);

/** \brief What happened to a track in the last frame. */
enum class TrackStatus : std::uint8_t {
  Seen,        ///< matched to an object of the frame
  Missed,      ///< in view, not seen, nothing explains it
  Occluded,    ///< in view, behind a nearer surface
  Merged,      ///< in view, its place inside another object's segment at its depth
  SeenThrough, ///< in view, the sensor measured beyond its place: taken away
  OutOfView,   ///< outside the image (or behind the camera)
  NotUpdated,  ///< the frame could not tell (no support, or a failed frame)
};

/** \brief "seen", "missed", "occluded", "merged", "seen_through", "out_of_view" or
 * "not_updated". */
std::string toString(TrackStatus s);

/** \brief One tracked object. Geometry in the tracker's world frame: the plane of the support
 * it was first anchored on (z up, z = 0 on the support), fixed to the table, so that a camera
 * moving over a static table leaves it unchanged. */
struct CylinderTrack {
  int id{0};             ///< stable, unique within the tracker's life
  bool confirmed{false}; ///< reported (CylinderTrackerParameters::confirm_hits reached)
  std::size_t age{0};    ///< frames since it started (this one included)
  std::size_t hits{0};   ///< frames it was matched in
  int misses{0};         ///< missed frames in a row (see_through_misses each when seen through)
  int occluded{0};       ///< hidden or merged frames in a row
  int out_of_view{0};    ///< frames in a row outside the image
  /** Frames in a row the sensor saw through its place: while > 0 only an object right at its
   * place (a quarter of the association gate) continues it; what appears behind a taken-away
   * object does not take over its id. */
  int seen_through{0};
  TrackStatus status{TrackStatus::Seen};
  int object{-1};      ///< the last frame's object matched to it, -1: none
  int merged_into{-1}; ///< status Merged: the track whose object holds its place, -1: none
  int support{-1};     ///< the support of its last observation (last frame's index), -1

  Eigen::Vector3f centroid{Eigen::Vector3f::Zero()}; ///< of the visible points, filtered
  float var_centroid{0.f};
  /** A cylinder estimate (from the frames that fitted one): axis through centre, extent
   * [lo, hi] along the axis from centre. */
  bool has_cylinder{false};
  Eigen::Vector3f centre{Eigen::Vector3f::Zero()};
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()}; ///< unit; sign: away from the support
  float radius{0.f};
  float lo{0.f}, hi{0.f};
  float var_extent{0.f};        ///< of lo and hi
  std::size_t cylinder_hits{0}; ///< frames that gave a cylinder
  /** One fitted cylinder of a frame, in the world frame. */
  struct Fit {
    Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()}; ///< unit, sign free
    Eigen::Vector3f centre{Eigen::Vector3f::Zero()};
    float radius{0.f};
    float weight{0.f}; ///< quality squared (less in a frame without a support)
  };
  std::vector<Fit> fits; ///< the last observations (history), oldest first
  float log_odds{0.f};   ///< of being a cylinder, from every frame's evidence
  /** Mean and variance of the frames' evidence (log-odds of each frame's p), over about the
   * last history frames (updateEvidenceSpread). */
  float evidence_mean{0.f}, evidence_var{0.f};
  /** The decision on log_odds with hysteresis (see CylinderTrackerParameters::
   * min_probability): what isCylinder reports for a confirmed track with a cylinder. */
  bool decided_cylinder{false};

  /** \brief The filtered probability that the object is a cylinder. */
  float pCylinder() const
  {
    return probability(log_odds);
  }
  /** \brief The cylinder estimate in the world frame (base = centre + lo axis). */
  CylinderModel worldCylinder() const;
};

/** \brief What the tracker made of one object of the frame. */
struct TrackAssignment {
  enum class Role : std::uint8_t {
    Ignored,  ///< not usable (no finite centroid)
    Matched,  ///< continues a track
    Started,  ///< started a new (tentative) track
    Fragment, ///< a piece of an object matched to a track in the same frame (a split)
  } role{Role::Ignored};
  int track_id{-1};        ///< the track's id, -1 for Ignored
  std::vector<int> merged; ///< ids of tracks whose place lies inside this object (a merge)
};

/** \brief "ignored", "matched", "started" or "fragment". */
std::string toString(TrackAssignment::Role r);

/** \brief What the tracker knows of the sensor of a frame, all optional: its intrinsics and a
 * depth lookup let it tell a missed track from one out of view, hidden behind a nearer surface
 * or taken away (the sensor sees through its place). */
struct TrackerView {
  PinholeCamera camera; ///< invalid (default): every track counts as in view
  /** The sensor's pose in the cloud's frame (sensor to cloud; PCL's sensor_origin_ and
   * sensor_orientation_). */
  Eigen::Affine3f sensor_pose{Eigen::Affine3f::Identity()};
  /** Depth along the optical axis (m, sensor frame) at pixel (u, v), NaN where none; empty:
   * unknown. */
  std::function<float(int, int)> depth;
};

/** \brief The view of an organized \a cloud (intrinsics estimated from its points unless
 * \a camera is valid; depth from its points); of an unorganized one with \a camera only. */
template <typename PointT>
TrackerView trackerViewOf(const typename pcl::PointCloud<PointT>::ConstPtr& cloud,
                          const PinholeCamera& camera = {});

/** \brief Index of the table in \a supports: the support whose plane is \a table_coefficients
 * (TabletopCylinderRecognizer::getTableCoefficients); -1 when there is none. */
int tableIndex(const std::vector<SupportPlane>& supports,
               const std::vector<float>& table_coefficients);

/** \brief Where the frame was, for the last update(). */
struct TrackerFrameInfo {
  std::size_t frame{0};      ///< frames given (update() and skipFrame()), this one included
  std::size_t scene{0};      ///< scenes started (a new one when the tracks' scene is left)
  int anchor{-1};            ///< the support the frame was anchored on, -1: none
  bool anchored{false};      ///< the pose comes from a support (else predicted)
  bool new_scene{false};     ///< this frame started a scene
  bool skipped{false};       ///< skipFrame(): nothing known about this frame
  std::size_t registered{0}; ///< objects the in-plane registration matched to tracks
  PlanarRigid registration;  ///< the anchor's plane coordinates to the world's
  /** The tracks' plane was the table to keep in this frame (the support prior supportPrior
   * gave before it). */
  bool prior_held{false};
  /** The recognizer was given a support prior for this frame (SupportPriorResult::given: the
   * caller handed supportPrior on, see prepare). */
  bool prior_given{false};
  /** The recognizer reported that the frame alone would have chosen another support
   * (SupportPriorResult::challenged). */
  bool prior_challenged{false};
  /** The frame's table was the prior's plane where the frame found none (a top without depth:
   * SupportPriorResult::predicted); the frame took no motion off the plane from it. */
  bool prior_predicted{false};
  /** Frames in a row, this one included, whose supports did not continue the tracks' plane
   * (see support_switch_frames), and frames in a row the recognizer reported challenged; 0 when
   * this one did, or held no support. */
  int prior_unseen_frames{0}, prior_challenged_frames{0};
};

/** \brief Tracks objects and cylinders across the frames of a stream: each frame's result of
 * TabletopCylinderRecognizer (supports, objects, cylinders) goes to update(), which keeps
 * tracks with a stable id per object and filtered axis, radius, extent and position, and a
 * confidence from the history (p_cylinder over time).
 *
 * The tracks live in a world frame fixed to the support: a support's frame (SupportPlane::
 * frame) has its origin at the centre of the visible support points and its x from the
 * camera's, so it moves with the camera. Each frame is re-anchored: its support's plane gives
 * the tilt and height of the camera, and the in-plane motion (a 2-D rigid transform about the
 * support's normal) is estimated robustly from the objects matched to tracks
 * (registerInPlane, with the pose predicted from the last two frames as prior). Objects are then
 * matched to tracks by minimum cost (associationCost, assignMinimumCost) and filtered (filterPoint,
 * filterAxis, filterScalar, filterExtent; robust to a bad fit); a confidence is updated from
 * every frame's p_cylinder (updateLogOdds).
 *
 * - A new track is tentative until confirm_hits frames matched it: a one-frame false positive
 *   never becomes a track. A confirmed one survives max_misses missed frames (occlusion), and
 *   longer when the sensor shows why it is not seen (a nearer surface in front of it, its
 *   place outside the image, its place inside another segment: a merge); it ends sooner when
 *   the sensor sees through its place (taken away). An object near one matched in the same
 *   frame is a fragment of it (a split) and starts no track.
 * - A frame without a support (no supports, objects with support -1) keeps the previous pose:
 *   its objects are matched and filtered with less weight, and no confirmed track's misses
 *   count (a tentative one unmatched ends, as in any frame).
 * - skipFrame() for a frame that could not be processed: nothing changes but the frame count.
 * - A frame whose support does not continue the tracks' plane and whose objects do not match
 *   them, or one that matches too few of the tracks expected in view (min_overlap), starts a
 *   new scene: the old tracks end, new ones start.
 *
 * \code
 * facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
 * facyl::CylinderTracker tracker;
 * for (const auto& frame : frames) {
 *   rec.setInputCloud(frame);
 *   std::vector<facyl::RecognizedObject> objects;
 *   if (!rec.recognize(objects)) { tracker.skipFrame(); continue; }
 *   tracker.update(rec, objects);
 *   for (std::size_t k = 0; k < objects.size(); ++k)
 *     use(tracker.getAssignments()[k].track_id, objects[k]);
 *   for (const auto& t : tracker.getTracks())
 *     if (t.confirmed && tracker.isCylinder(t)) use(tracker.cylinderInFrame(t));
 * }
 * \endcode
 * Thread safety: update() and skipFrame() are not reentrant on one tracker; the const members
 * may be called concurrently while neither runs. Distinct trackers are independent. Cost per
 * frame: docs/tracking.md, "Cost" (facyl_benchmarks BM_TrackerUpdate).
 */
class CylinderTracker {
public:
  using Ptr = std::shared_ptr<CylinderTracker>;
  using ConstPtr = std::shared_ptr<const CylinderTracker>;

  CylinderTracker() = default;
  /** \throws std::invalid_argument when \a params are invalid (validate). */
  explicit CylinderTracker(const CylinderTrackerParameters& params)
  {
    setParameters(params);
  }

  /** \brief All settings; the tracks are kept. \throws std::invalid_argument when \a params are
   * invalid (validate), naming the call. */
  void setParameters(const CylinderTrackerParameters& params);
  const CylinderTrackerParameters& getParameters() const
  {
    return params_;
  }

  /** \brief One frame's result: \a supports and the index of the table among them (\a table,
   * -1: none; the support most objects stand on is then the anchor), \a objects (the
   * recognizer's, in the same cloud frame), what is known of the sensor (\a view), and what
   * the segmentation made of the support prior handed to it (\a prior; see prepare).
   * \return false (PCL_ERROR, nothing changed but the frame count) when \a table is out of
   * range. Objects without a finite centroid are ignored (Role::Ignored). */
  bool update(const std::vector<SupportPlane>& supports, int table,
              const std::vector<RecognizedObject>& objects, const TrackerView& view = {},
              const SupportPriorResult& prior = {});

  /** \brief update() with the last result of \a rec: its supports and table, the view of its
   * input cloud (trackerViewOf; intrinsics estimated from an organized cloud unless
   * setCamera) and its support prior's result. */
  template <typename PointT>
  bool update(const TabletopCylinderRecognizer<PointT>& rec,
              const std::vector<RecognizedObject>& objects)
  {
    return update(rec.getSupports(),
                  tableIndex(rec.getSupports(), rec.getTableCoefficients().values), objects,
                  trackerViewOf<PointT>(rec.getInputCloud(), camera_), rec.getSupportPriorResult());
  }

  /** \brief Where the next frame's support is expected: the tracks' plane (the support the
   * last frames were anchored on) in the next frame's cloud frame, as the camera's motion
   * predicts it (constant velocity), with tolerances of 3 times the
   * root-mean-square error of that prediction in the last frames (predictionTolerance, at most
   * max_plane_angle and max_plane_offset). Invalid (SupportPrior::valid false) before the first
   * frame anchored on a support, after reset(), and for the frame after support_switch_frames
   * dissenting ones. */
  SupportPrior supportPrior() const;

  /** \brief Hands supportPrior() to \a rec for the next frame (call it before
   * rec.recognize()): the recognizer then keeps the tracks' plane as the table while it is in
   * view and a wall or a far plane with more objects in one frame does not replace it. */
  template <typename PointT> void prepare(TabletopCylinderRecognizer<PointT>& rec) const
  {
    rec.setSupportPrior(supportPrior());
  }

  /** \brief A frame that could not be processed (unreadable, empty, recognition failed): the
   * tracks stay as they are, nobody's misses count. */
  void skipFrame();

  /** \brief Ends every track and forgets the world frame (the frame count and the ids go on). */
  void reset();

  /** \brief Intrinsics for the template update() (unorganized clouds; organized ones are
   * estimated when this is invalid, the default). */
  void setCamera(const PinholeCamera& camera)
  {
    camera_ = camera;
  }

  /** \brief The live tracks (tentative and confirmed), by id. */
  const std::vector<CylinderTrack>& getTracks() const
  {
    return tracks_;
  }
  /** \brief The track with id \a id, or nullptr. */
  const CylinderTrack* findTrack(int id) const;
  /** \brief One per object of the last update(), in order. */
  const std::vector<TrackAssignment>& getAssignments() const
  {
    return assignments_;
  }
  /** \brief Where the last frame was. */
  const TrackerFrameInfo& getFrameInfo() const
  {
    return info_;
  }
  /** \brief The world frame in the last frame's cloud frame (world to cloud). */
  Eigen::Affine3f getWorldToFrame() const
  {
    return frame_to_world_.inverse();
  }
  /** \brief The last frame's cloud frame in the world (cloud to world). */
  const Eigen::Affine3f& getFrameToWorld() const
  {
    return frame_to_world_;
  }
  /** \brief True when \a t is confirmed, has a cylinder estimate and is decided a cylinder:
   * its p_cylinder reached min_probability and did not fall back below it by its hysteresis
   * margin since (CylinderTrack::decided_cylinder). */
  bool isCylinder(const CylinderTrack& t) const;
  /** \brief \a t's cylinder in the last frame's cloud frame, with the recognizer's convention
   * (base nearest the support, axis away from it; lying: towards the sensor; orientCylinder);
   * its inlier fields are empty. */
  CylinderModel cylinderInFrame(const CylinderTrack& t) const;
  /** \brief \a t's centroid in the last frame's cloud frame. */
  Eigen::Vector3f centroidInFrame(const CylinderTrack& t) const
  {
    return getWorldToFrame() * t.centroid;
  }

  /** \brief "CylinderTracker". */
  static std::string getClassName()
  {
    return "CylinderTracker";
  }

private:
  // The steps of update(), in order (the rules are free functions, tracker_steps.h).
  /** The frame's anchor and its pose in the world (frame_to_world_; \a info's anchor, scene
   * and registration): the tracks move into the support's plane when the world becomes one,
   * and end when the frame starts a new scene. */
  void locateFrame(const std::vector<SupportPlane>& supports, int table,
                   const std::vector<RecognizedObject>& objects, const TrackerView& view,
                   const SupportPriorResult& prior, TrackerFrameInfo& info);
  /** The anchor \a choice under the support prior: counts the frame's dissent (\a info) and
   * drops a plane jump while the tracks' plane is kept; releases the prior after
   * support_switch_frames dissenting frames. */
  void keepTracksPlane(const std::vector<SupportPlane>& supports, const SupportPriorResult& prior,
                       AnchorChoice& choice, TrackerFrameInfo& info);
  /** The next frame's cloud to the world: the last pose, moved on by the camera's motion
   * between the last two frames when both were anchored one after the other. */
  Eigen::Affine3f predictedPose() const;
  /** The tracks' plane in the cloud of a frame at \a cloud_to_world, with the prediction's
   * tolerances (predictionTolerance of the innovations). */
  SupportPrior expectedPlane(const Eigen::Affine3f& cloud_to_world) const;
  /** The prediction's error for a frame anchored on the tracks' plane: the \a expected plane
   * (expectedPlane) against the anchor's measured \a plane. */
  void recordPlaneInnovation(const SupportPrior& expected, const Eigen::Vector4f& plane);
  /** The region hull of the frame's \a anchor (on the tracks' plane) in the world, the frame at
   * \a cloud_to_world: one more of the extents seen (seen_extents_). */
  void recordExtent(const SupportPlane& anchor, const Eigen::Affine3f& cloud_to_world);
  /** The frame, anchored on the support at \a plane_to_cloud that continues the tracks' plane,
   * registered against the tracks (\a pose: cloud to world). \return true when it starts a
   * new scene (the tracks ended, \a pose the support's plane); never without \a may_be_new
   * (an anchor that is the prior's plane itself, SupportPriorResult::predicted). */
  bool registerFrame(const std::vector<RecognizedObject>& objects, const TrackerView& view,
                     const Eigen::Affine3f& plane_to_cloud, const Eigen::Affine3f& cloud_to_plane,
                     const Eigen::Affine3f& predicted, const Eigen::Affine3f& last_pose,
                     bool plane_jump, bool may_be_new, Eigen::Affine3f& pose,
                     TrackerFrameInfo& info);
  /** The tracks matched (\a match) corrected by their objects, counting with \a weight.
   * \return a flag per track: matched. */
  std::vector<char> correctMatched(const std::vector<RecognizedObject>& objects,
                                   const std::vector<TrackObservation>& obs,
                                   const std::vector<int>& match, float weight);
  /** Each object left: a fragment of the matched track it looks most like a piece of
   * (fragmentGain), else a new track. */
  void startOrAttach(const std::vector<TrackObservation>& obs, const std::vector<int>& match,
                     const std::vector<char>& matched_track);
  /** The tracks not matched: their status (viewStatus) and counters; without an anchor only
   * the tentative ones' misses count. */
  void updateUnseen(const TrackerView& view, const std::vector<RecognizedObject>& objects,
                    const std::vector<TrackObservation>& obs,
                    const std::vector<char>& matched_track, bool anchored);
  /** Confirmed track \a t, merged into \a object that started a new track, takes it back. */
  void takeBack(CylinderTrack& t, int object, const TrackObservation& o);
  /** Two tracks of one object become the older one (areOneObject, absorbTrack); the tracks
   * that end go (trackEnded); the rest sorted by id. */
  void joinAndEndTracks();
  void predict();
  void endTracks();

  CylinderTrackerParameters params_;
  PinholeCamera camera_;
  std::vector<CylinderTrack> tracks_;
  std::vector<TrackAssignment> assignments_;
  TrackerFrameInfo info_;
  Eigen::Affine3f frame_to_world_{Eigen::Affine3f::Identity()};
  Eigen::Affine3f sensor_pose_{Eigen::Affine3f::Identity()}; ///< of the last frame
  /** The frame before the last one: with it, the camera's motion between two frames predicts
   * the next pose (constant velocity), when both were anchored and consecutive. */
  Eigen::Affine3f previous_frame_to_world_{Eigen::Affine3f::Identity()};
  bool has_velocity_{false};
  /** The last frame was anchored on the prior's plane itself: its motion off the plane is not
   * carried on (predictedPose). */
  bool velocity_in_plane_{false};
  bool has_pose_{false};         ///< frame_to_world_ holds a pose
  bool world_on_support_{false}; ///< the world frame is a support's plane
  /** The tracks' plane is the table to keep (handed on by supportPrior): from the first frame
   * anchored on a support, until support_switch_frames frames in a row dissent. */
  bool prior_held_{false};
  int prior_unseen_{0};     ///< frames in a row whose supports did not continue the plane
  int prior_challenged_{0}; ///< frames in a row that alone chose another family
  /** The centre of that support's points, in the world (on its plane, z near 0). */
  Eigen::Vector3f anchor_centre_{Eigen::Vector3f::Zero()};
  /** Of the last frames (history) anchored on the tracks' plane: the angle (rad) between its
   * predicted and measured normal, and its measured height over the predicted plane (m): the
   * support prior's tolerances (predictionTolerance). */
  std::vector<float> plane_angle_innovations_, plane_offset_innovations_;
  /** Of the last frames (history) anchored on the tracks' plane: the hull of its region (the
   * anchor's polygon), in the world's plane (x, y): the support prior's extent. */
  std::vector<std::vector<Eigen::Vector2f>> seen_extents_;
  int next_id_{0};
};

} // namespace facyl

#define FACYL_INSTANTIATE_trackerViewOf(T)                                                         \
  template facyl::TrackerView facyl::trackerViewOf<T>(                                             \
    const typename pcl::PointCloud<T>::ConstPtr&, const facyl::PinholeCamera&);

#ifdef PCL_NO_PRECOMPILE
#include <facyl/tracking/impl/cylinder_tracker.hpp>
#endif
