/*
 * facyl: streams of RGB-D frames the PCL way, for the tools that track (facyl_viewer
 * --stream): pcl::PCDGrabber over a folder of PCD frames (at a given rate, looping
 * optionally) or, when PCL was built with it, pcl::io::OpenNI2Grabber on a device.
 *
 * The grabbers call back in their own thread (a rate, a device); FrameStream hands the frames
 * over one at a time, and a live source keeps only the newest frame (the others are counted
 * as dropped). A PCD folder at rate 0 (every frame, as fast as they are processed) is read
 * through the grabber's pcl::FileGrabber interface (frame k on demand): PCL 1.13's trigger mode
 * (PCDGrabber at 0 frames per second, start() or trigger()) aborts the program (it destroys a
 * joinable std::thread).
 * The PCD files' headers are checked first (pcd_input.h): a file facyl would refuse is left
 * out of the stream with its reason, and a file that PCL's reader then cannot read is skipped
 * with a message; neither ends the stream.
 */
#pragma once

#include <facyl/tools/pcd_input.h>

#include <pcl/io/pcd_grabber.h>
#include <pcl/pcl_config.h>
#ifdef HAVE_OPENNI2
#include <pcl/io/openni2_grabber.h>
#endif

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace facyl_cli {

/** One frame of a stream. */
struct StreamFrame {
  pcl::PointCloud<pcl::PointXYZRGBA>::ConstPtr cloud;
  std::string name;     ///< the file, or the device
  std::size_t index{0}; ///< frames handed over before this one
  /** Frames of the source that could not be used just before this one (each with its
   * reason): unreadable files of a PCD stream. */
  std::vector<std::string> skipped;
};

/** The header check of readPcd (checkPcdHeader), without reading the data. \return an empty
 * string, or why facyl would refuse \a file. */
inline std::string
checkPcdFile(const std::string& file)
{
  PcdHeader h;
  return checkPcdHeader(file, h);
}

/** The frames of a stream source: the PCD files of folder \a source sorted by name (or
 * \a source itself when it is a PCD file); each file facyl would refuse goes to \a rejected
 * as "FILE: reason". \throws std::invalid_argument when there is no usable frame. */
inline std::vector<std::string>
pcdFrames(const std::string& source, std::vector<std::string>& rejected)
{
  std::vector<std::string> files;
  std::error_code ec;
  if (std::filesystem::is_directory(source, ec)) {
    for (const auto& entry : std::filesystem::directory_iterator(source, ec))
      if (entry.path().extension() == ".pcd")
        files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
    if (files.empty())
      throw std::invalid_argument("--stream " + source + ": the folder holds no .pcd file");
  }
  else if (std::filesystem::exists(source, ec))
    files.push_back(source);
  else
    throw std::invalid_argument("--stream " + source +
                                ": no such folder or file (a folder of "
                                "PCD frames, a PCD file, or openni2[:DEVICE])");
  std::vector<std::string> usable;
  for (const auto& f : files) {
    const std::string why = checkPcdFile(f);
    if (why.empty())
      usable.push_back(f);
    else
      rejected.push_back(f + ": " + why);
  }
  if (usable.empty())
    throw std::invalid_argument("--stream " + source + ": no usable PCD frame (" +
                                rejected.front() + (rejected.size() > 1 ? ", ..." : "") + ")");
  return usable;
}

/** True when PCL was built with OpenNI2 (a device may then be opened). */
inline bool
openni2Available()
{
#ifdef HAVE_OPENNI2
  return true;
#else
  return false;
#endif
}

/** A stream of frames from a PCD folder (pcl::PCDGrabber) or an OpenNI2 device
 * (pcl::io::OpenNI2Grabber). Not thread safe: one consumer calls next(). */
class FrameStream {
public:
  using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

  /** \a source: a folder of PCD frames (played in name order) or one PCD file; or "openni2"
   * or "openni2:DEVICE" (PCL's device id: "#1", a URI). \a rate: frames per second (a PCD
   * folder at 0, the default: one frame per next(), as fast as they are processed). \a loop:
   * start again after the last file. \throws std::invalid_argument for a source without a
   * usable frame, std::runtime_error when the device cannot be opened or PCL has no OpenNI2. */
  FrameStream(const std::string& source, float rate, bool loop)
      : rate_(rate)
      , loop_(loop)
  {
    if (!(rate >= 0.f && rate <= 1000.f))
      throw std::invalid_argument("--rate must be in [0, 1000] frames per second");
    if (source == "openni2" || source.rfind("openni2:", 0) == 0) {
#ifdef HAVE_OPENNI2
      const std::string device = source.size() > 8 ? source.substr(8) : std::string();
      try {
        auto grabber = std::make_unique<pcl::io::OpenNI2Grabber>(device);
        std::function<void(const Cloud::ConstPtr&)> on_cloud = [this](const Cloud::ConstPtr& c) {
          deliver(c, name_);
        };
        grabber->registerCallback(on_cloud);
        name_ = "openni2:" + (device.empty() ? grabber->getName() : device);
        grabber_ = std::move(grabber);
      }
      catch (const std::exception& e) {
        throw std::runtime_error("--stream " + source + ": cannot open the OpenNI2 device (" +
                                 e.what() + ")");
      }
      live_ = true;
      grabber_->start();
      return;
#else
      throw std::runtime_error("--stream " + source +
                               ": this PCL was built without OpenNI2; "
                               "record the device's frames to a folder of PCD files instead");
#endif
    }
    files_ = pcdFrames(source, rejected_);
    // PCL indexes the files whose header its reader takes: keep exactly those, so that frame k
    // is files_[k].
    std::vector<std::string> readable;
    for (const auto& f : files_) {
      pcl::PCLPointCloud2 header;
      if (pcl::PCDReader().readHeader(f, header) == 0)
        readable.push_back(f);
      else
        rejected_.push_back(f + ": PCL's reader cannot read its header");
    }
    files_ = std::move(readable);
    if (files_.empty())
      throw std::invalid_argument("--stream " + source + ": no PCD frame PCL can read");
    auto grabber = std::make_unique<pcl::PCDGrabber<pcl::PointXYZRGBA>>(files_, rate, loop);
    std::function<void(const Cloud::ConstPtr&)> on_cloud = [this](const Cloud::ConstPtr& c) {
      std::lock_guard<std::mutex> lock(mutex_);
      pending_ = c; // the file's name follows (PCDGrabber signals it after the cloud)
    };
    std::function<void(const std::string&)> on_name = [this](const std::string& file) {
      Cloud::ConstPtr c;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        c = std::move(pending_);
        pending_.reset();
      }
      if (c)
        deliver(c, file);
    };
    grabber->registerCallback(on_cloud);
    grabber->registerCallback(on_name);
    name_ = source;
    live_ = rate > 0.f;
    grabber_ = std::move(grabber);
    if (live_)
      grabber_->start();
  }

  ~FrameStream()
  {
    if (grabber_)
      grabber_->stop();
  }

  /** The next frame, waiting at most \a timeout_s seconds for a live source. \return false at
   * the end of a PCD stream, or when a live source gave nothing in time (timedOut()). */
  bool next(StreamFrame& frame, double timeout_s = 5.0)
  {
    timed_out_ = false;
    std::vector<std::string> skipped;
    if (!live_) {
      // Every frame in order, through pcl::FileGrabber; one PCL cannot read gives an empty
      // cloud and is reported.
      const auto& files = *static_cast<pcl::PCDGrabber<pcl::PointXYZRGBA>*>(grabber_.get());
      while (true) {
        if (!loop_ && triggered_ >= files_.size())
          return false;
        const std::size_t k = triggered_ % files_.size();
        ++triggered_;
        const Cloud::ConstPtr cloud = files[k];
        if (cloud && !cloud->empty()) {
          frame = StreamFrame{cloud, files_[k], delivered_++, std::move(skipped)};
          return true;
        }
        skipped.push_back(files_[k] + ": PCL's reader could not read it (skipped)");
        if (loop_ && skipped.size() >= files_.size())
          return false; // no file of the loop is readable
      }
    }
    std::unique_lock<std::mutex> lock(mutex_);
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(timeout_s));
    while (!latest_) {
      if (!grabber_->isRunning() && !latest_)
        return false; // a PCD folder played to its end
      if (cv_.wait_until(lock, deadline) == std::cv_status::timeout && !latest_) {
        timed_out_ = grabber_->isRunning();
        return false;
      }
    }
    frame = std::move(*latest_);
    latest_.reset();
    frame.index = delivered_++;
    return true;
  }

  /** The files left out before the stream started, each "FILE: reason". */
  const std::vector<std::string>& rejected() const
  {
    return rejected_;
  }
  /** Frames a live source delivered while the previous one was still being processed. */
  std::size_t dropped() const
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }
  /** The last next() returned false because a live source gave nothing in time. */
  bool timedOut() const
  {
    return timed_out_;
  }
  /** "PCD folder DIR (N frames, R fps, looping)" or the device. */
  std::string description() const
  {
    if (files_.empty())
      return name_;
    char rate[64];
    std::snprintf(rate, sizeof rate, "%g fps", static_cast<double>(rate_));
    return "PCD frames " + name_ + " (" + std::to_string(files_.size()) + " files, " +
           (rate_ > 0.f ? std::string(rate) : std::string("as fast as processed")) +
           (loop_ ? ", looping" : "") + ")";
  }

private:
  void deliver(const Cloud::ConstPtr& cloud, const std::string& name)
  {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      dropped_ += latest_.has_value();
      latest_ = StreamFrame{cloud, name, 0, {}};
    }
    cv_.notify_one();
  }

  std::unique_ptr<pcl::Grabber> grabber_;
  std::vector<std::string> files_, rejected_;
  std::string name_;
  float rate_{0.f};
  bool loop_{false};
  bool live_{false};
  bool timed_out_{false};
  std::size_t triggered_{0}, delivered_{0}, dropped_{0};
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  Cloud::ConstPtr pending_;
  std::optional<StreamFrame> latest_;
};

} // namespace facyl_cli
