/*
 * facyl_viewer --stream: frames from a grabber (facyl_cli::FrameStream: a folder of PCD frames
 * through pcl::PCDGrabber, or an OpenNI2 device), recognized, tracked (facyl::CylinderTracker)
 * and drawn as they come, one JSON line per frame on standard output.
 */
#pragma once

#include <facyl/recognition/tabletop_cylinder_recognizer.h>

#include <Eigen/Core>

#include <string>

namespace facyl_viewer {

/** What --stream needs of the viewer's settings. */
struct StreamSettings {
  std::string source;                         ///< --stream SOURCE
  float rate{0.f};                            ///< --rate; 0: every frame
  bool loop{false};                           ///< --loop
  long long frames{0};                        ///< --frames; 0: all
  facyl::TabletopRecognizerParameters params; ///< the recognizer's options
  Eigen::Vector3f up{Eigen::Vector3f::Zero()};
  facyl::ShapeClassifier::Ptr classifier;
  std::string screenshot; ///< render the last frame to it and exit; empty: a window
  int width{0}, height{0};
};

/** Plays the stream \a s in a window (or renders its last frame to s.screenshot).
 * \return the exit status: 0, or 1 when no frame could be shown. \throws
 * std::invalid_argument for a source without a usable frame, std::runtime_error when a device
 * cannot be opened. */
int runStream(const StreamSettings& s);

} // namespace facyl_viewer
