/*
 * facyl: fast cylinder detection for PCL.
 * Streams of frames with ground truth: a camera moving along a smooth path around a static
 * tabletop scene, optionally with one object taken away or put down half-way.
 */
#pragma once

#include <facyl/simulation/tabletop_scene.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace facyl {

/** \brief Settings of a camera path around a static scene. */
struct TabletopSequenceParameters {
  std::size_t frames{30}; ///< in [2, 100000]
  /** The camera turns this far (rad) about the vertical through the point it looks at over the
   * sequence (its direction drawn), in [0, 6.3]: 0.9 rad over 30 frames is 1.8 degrees per
   * frame, a slow hand or a robot's head. */
  float orbit{0.9f};
  /** Amplitude (rad) of one slow period of change of the camera's elevation, in [0, 0.6]; the
   * elevation stays within 15-83 degrees. */
  float elevation_swing{0.12f};
  /** Relative amplitude of one slow period of change of the camera's distance, in [0, 0.5]. */
  float distance_swing{0.1f};
  /** An object taken away (Remove: visible before change_frame) or put down (Add: visible from
   * change_frame on); one that nothing stands or leans on, a cylinder when there is one. */
  enum class Change : std::uint8_t { None, Remove, Add } change{Change::None};
  /** The frame of the change, in [1, frames - 1]; 0: the middle. */
  std::size_t change_frame{0};
};

/** \brief "none", "remove" or "add". */
std::string toString(TabletopSequenceParameters::Change c);

/** \brief "none", "remove" or "add" into \a c. \return false for another name. */
bool parseSequenceChange(const std::string& name, TabletopSequenceParameters::Change& c);

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string validate(const TabletopSequenceParameters& params);

/** \brief A static scene and the camera's path. */
struct TabletopSequence {
  /** Every object of the sequence (the changed one too), in the world (table) frame; its
   * camera_to_world is the first frame's. */
  TabletopScene scene;
  std::vector<Eigen::Isometry3f> cameras; ///< camera_to_world of each frame
  TabletopSequenceParameters::Change change{TabletopSequenceParameters::Change::None};
  int changed_object{-1};      ///< index into scene.objects of the object taken or put, -1
  std::size_t change_frame{0}; ///< the frame of the change

  /** \brief True when object \a object is on the table in frame \a frame. */
  bool present(std::size_t object, std::size_t frame) const;
  /** \brief The scene as frame \a frame sees it: its camera, without the object that is not
   * there (the other objects keep their order; support and contact indices follow). */
  TabletopScene sceneAt(std::size_t frame) const;
};

/** \brief The scene of \a scene_params (generateTabletopScene, the same for a seed as a single
 * frame's) and a smooth camera path starting at its camera: an orbit about the vertical through
 * the point the camera looks at, with slow changes of elevation and distance, the roll kept,
 * never nearer than the sensor's minimum range to the tallest object. The path's random
 * choices are drawn from their own stream of scene_params.seed (facyl::Random), so the scene
 * is unchanged. Deterministic for a seed.
 * \throws std::invalid_argument if a parameter is invalid. */
TabletopSequence generateTabletopSequence(const TabletopSceneParameters& scene_params,
                                          const TabletopSequenceParameters& params);

/** \brief Frame \a frame of \a sequence rendered (renderTabletopScene on sceneAt(frame) with
 * \a seed). Ground truth keeps the sequence's object numbering: object_id 2 + i is
 * scene.objects[i] in every frame, visible_pixels has one entry per object of the sequence
 * (0 when absent), and the result's scene is the whole sequence's with the frame's camera.
 * \throws std::out_of_range for a frame beyond the path. */
RenderedScene renderSequenceFrame(const TabletopSequence& sequence, std::size_t frame,
                                  const CameraIntrinsics& camera, const DepthSensorModel& sensor,
                                  std::uint64_t seed);

/** \brief The seed with which frame \a frame of the sequence of scene seed \a seed is rendered
 * by the tools (facyl_synth --sequence, facyl_track_eval). */
std::uint64_t sequenceFrameSeed(std::uint64_t seed, std::size_t frame);

/** \brief The sequence's ground truth as JSON: the change, and per frame the camera pose
 * (camera_to_world, row-major 4 x 4) and the ids (2 + object index) present. */
std::string sequenceJson(const TabletopSequence& sequence);

} // namespace facyl
