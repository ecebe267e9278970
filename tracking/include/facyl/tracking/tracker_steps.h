/*
 * facyl: fast cylinder detection for PCL.
 * The steps of CylinderTracker::update as free functions on tracks and observations, so that
 * each rule has a home and a test: which support anchors the frame, how the frame's objects
 * are registered against the tracks and when a frame starts a new scene, what an object of the
 * frame is in the world, how objects are matched to tracks, how a track is started and
 * corrected, what a track not seen is, what makes an object a fragment of a matched one, when
 * two tracks are one object, and when a track ends. The tracker keeps the state and calls them
 * in this order; tracking_numerics.h holds the numerics under them.
 */
#pragma once

#include <facyl/tracking/cylinder_tracker.h>
#include <facyl/tracking/tracking_numerics.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

namespace facyl {

/** \brief An object of a frame as the tracker sees it, in the world frame (or, while the frame
 * is registered, in the frame's support plane). */
struct TrackObservation {
  bool valid{false};            ///< the object has a finite centroid
  AssociationGeometry geometry; ///< centroid; a fitted cylinder when geometry.cylinder
  Eigen::Vector3f base{Eigen::Vector3f::Zero()}; ///< the cylinder's ends (geometry.cylinder)
  Eigen::Vector3f top{Eigen::Vector3f::Zero()};
  float p{0.5f};         ///< evidence that it is a cylinder (the decision's side, see observe)
  float quality{1.f};    ///< points x angular coverage of the fit (cylinders)
  int support{-1};       ///< the support it stands on (the frame's index), -1: none
  std::size_t points{0}; ///< its points
};

// --------------------------------------------------------------------------- anchoring

/** \brief Where a frame is anchored: the support (an index into the frame's supports, -1:
 * none) and whether it breaks with the tracks' plane (\a plane_jump). */
struct AnchorChoice {
  int anchor{-1};
  bool plane_jump{false};
};

/** \brief The frame's anchor among \a supports: in order of preference the table (\a table, -1:
 * none), then the others by the number of \a objects standing on them (most first, ties in
 * their order), supports without a finite frame left out. With \a tracks_plane (the plane the
 * tracks stand on, as expected in this frame: CylinderTracker's support prior), the first that
 * is that plane (consistentWithPrior); when none is, the first with plane_jump. Without
 * (nullptr: a new world), the first. */
AnchorChoice chooseAnchor(const std::vector<SupportPlane>& supports, int table,
                          const std::vector<RecognizedObject>& objects,
                          const SupportPrior* tracks_plane);

/** \brief The correspondences that may register a frame's \a objects (in the support's plane)
 * against \a tracks (world): every valid object with every track whose size and height agree.
 * Two cylinders agree when the radii differ by at most 1 cm + 20% and the centres' heights by
 * 4 cm + a quarter of the track's height; they count fully (tentative tracks half) within 2 cm
 * (4 cm when tilted between 28 and 60 degrees from the normal: their fitted centre wanders). A
 * pair that is not two cylinders agrees when the reference points' (centre or centroid) heights
 * differ by at most 6 cm, and counts 0.4 as much within 5 cm. */
std::vector<RegistrationCandidate>
registrationCandidates(const std::vector<TrackObservation>& objects,
                       const std::vector<CylinderTrack>& tracks);

/** \brief The in-plane registration (registerInPlane) of \a objects (in the support's plane)
 * against \a tracks from \a prior. When \a fallback (optional) is given and the answer matched
 * fewer than half of the valid objects, the registration is tried from \a fallback too, and
 * the one that matches more objects is kept: the camera's velocity predicts a smooth path, and
 * when it jumped instead (back to where it was: a looped recording, a dropped run of frames)
 * the last frame's pose is the better prior. */
PlanarRegistration registerObservations(const std::vector<TrackObservation>& objects,
                                        const std::vector<CylinderTrack>& tracks,
                                        const PlanarRigid& prior,
                                        const RegistrationSettings& settings,
                                        const PlanarRigid* fallback = nullptr);

/** \brief True when a frame starts a new scene: some tracks are \a confirmed, and either its
 * support broke with the tracks' plane (\a plane_jump) and the registration matched fewer than
 * two objects (\a matched), or it matched fewer than \a min_overlap (0: never) of the
 * confirmed tracks expected in view (\a expected_in_view, at most the \a seen valid objects,
 * and at least 3). */
bool isNewScene(std::size_t confirmed, std::size_t expected_in_view, std::size_t seen,
                std::size_t matched, bool plane_jump, float min_overlap);

// ------------------------------------------------------------------------ observations

/** \brief What the tracker takes of the recognizer's object \a r, in the frame given by
 * \a cloud_to_world: its centroid and points; a cylinder when it was accepted and fitted with
 * finite ends and a positive radius (its axis from base to top, the fit's when they coincide;
 * quality = points x angular coverage, at least 5%); the evidence \a p: the decision sets the
 * side, p_cylinder the strength (an accepted one counts at least \a decision_probability, any
 * other at most 1 - it; without p_cylinder exactly that). */
TrackObservation observe(const RecognizedObject& r, const Eigen::Affine3f& cloud_to_world,
                         float decision_probability);

/** \brief What association compares of track \a t: its centroid and cylinder estimate. */
AssociationGeometry associationGeometry(const CylinderTrack& t);

/** \brief \a t moved by \a m (its centroid, centre, axis and the fits of its history), its axis
 * then turned up (world z: the extent follows). */
void transformTrack(CylinderTrack& t, const Eigen::Affine3f& m);

// ------------------------------------------------------------------------- association

/** \brief The track (index into \a tracks) of each of \a observations, or -1: the minimum-cost
 * assignment (associationCost, assignMinimumCost within settings.gate); a track whose place the
 * sensor saw through takes only an object right at its place (a quarter of the gate). Then a
 * second chance, with every sigma doubled, for what is left on both sides (seen-through tracks
 * excepted): an object whose fit changed much is still the one at the track's place. Invalid
 * observations are not matched. */
std::vector<int> associate(const std::vector<TrackObservation>& observations,
                           const std::vector<CylinderTrack>& tracks,
                           const AssociationSettings& settings);

// -------------------------------------------------------------------------- filtering

/** \brief A new (tentative unless confirm_hits is 1) track with id \a id from observation
 * \a o, object \a object of the frame; the variances are \a params' measurement sigmas. */
CylinderTrack newTrack(const TrackObservation& o, int id, int object,
                       const CylinderTrackerParameters& params);

/** \brief \a t's cylinder from its history of fits (t.fits): the axis most of them agree with
 * (consensusAxis within \a axis_agreement; \a t's sense kept, its extent turned with it), the
 * axis line where the agreeing fits put it (a weighted median in each direction across the
 * axis, twice) and their weighted median radius. Estimates that cannot be formed (no agreeing
 * fit) are kept. */
void cylinderFromHistory(CylinderTrack& t, float axis_agreement);

/** \brief \a t's decision (decided_cylinder) on its log-odds, with hysteresis
 * (decideWithHysteresis at the log-odds of params.min_probability, decisionMargin of the spread
 * of its evidence); a track with no evidence before (\a first) decides without. */
void decide(CylinderTrack& t, bool first, const CylinderTrackerParameters& params);

/** \brief The evidence \a p of one frame (a probability that the object is a cylinder, see
 * observe) added to \a t: its log-odds (updateLogOdds), the spread of its evidence
 * (updateEvidenceSpread over params.history frames; \a n: the frames of evidence, this one
 * included) and its decision (decide). */
void recordEvidence(CylinderTrack& t, float p, std::size_t n,
                    const CylinderTrackerParameters& params);

/** \brief \a t corrected by observation \a o, which counts with \a weight (less in a frame
 * without a support): the centroid filtered (filterPoint); a cylinder started from the first
 * fit, then estimated from the last params.history fits (cylinderFromHistory) with its extent
 * filtered (filterExtent, the measurement's variance scaled by reference_quality over the
 * observation's quality, within [1/4, 4]) and the centre moved to the extent's middle; the
 * confidence updated; the track seen (its miss counters reset; confirmed at confirm_hits). */
void correctTrack(CylinderTrack& t, const TrackObservation& o, float weight,
                  const CylinderTrackerParameters& params);

// -------------------------------------------------------------- objects left, tracks not seen

/** \brief How much observation \a o looks like a piece of track \a t, which is matched in the
 * same frame to observation \a matched: 1 when o's centroid lies within t's cylinder grown by
 * \a margin; else, when the two pieces' centroid (weighted by their points) is nearer t's than
 * \a matched's alone (by 5 mm at least) and o's centroid is within 3 \a sigma_centroid of t's,
 * the relative gain; else 0. */
float fragmentGain(const TrackObservation& o, const CylinderTrack& t,
                   const TrackObservation& matched, float margin, float sigma_centroid);

/** \brief What the sensor tells of the in-view track \a t that no object matched, with the
 * world frame at \a world_to_cloud in the frame's cloud: OutOfView (behind the camera or
 * outside the image), Occluded (most probes of its visible surface have a nearer depth),
 * SeenThrough (most are farther: taken away), Merged (its image centre inside an object's pixel
 * box; \a inside: that object's index), or Missed (an invalid camera, no depth, fewer than 3
 * probes with a depth, or nothing explains it). The probes: a cylinder's front at three heights
 * (not at its base, where the support lies right behind it) and three offsets across; another
 * object's visible centroid and four points around it, nearer surfaces counting only well in
 * front of it (the centroid lies behind the visible surface). */
TrackStatus viewStatus(const CylinderTrack& t, const Eigen::Affine3f& world_to_cloud,
                       const TrackerView& view, const std::vector<RecognizedObject>& objects,
                       int& inside);

/** \brief True when \a younger (a confirmed track) and \a older (a smaller id) are one object:
 * not both seen in this frame, neither ending, and within one sigma (associationCost < 1) or,
 * both cylinders, each holding the other's centre (within its radius of its axis and its
 * extent along it: two solid objects do not overlap, whatever their axes). */
bool areOneObject(const CylinderTrack& older, const CylinderTrack& younger,
                  const AssociationSettings& settings);

/** \brief \a younger goes into \a older, whose id stays: when \a younger was seen in this frame
 * \a older takes its object, centroid and cylinder (its fits appended, the last \a history
 * kept); the hits add up, the log-odds too (within +-\a confidence_limit). \a younger is ended
 * (unconfirmed, misses beyond any limit). */
void absorbTrack(CylinderTrack& older, CylinderTrack& younger, int history, float confidence_limit);

/** \brief True when \a t ends: a tentative track missed more than max_tentative_misses frames;
 * a confirmed one more than max_misses, or hidden more than max_occluded, or out of view more
 * than max_out_of_view. */
bool trackEnded(const CylinderTrack& t, const CylinderTrackerParameters& params);

} // namespace facyl
