/*
 * facyl: fast cylinder detection for PCL.
 * Scoring a segmentation against per-point ground truth (for tests and evaluators).
 */
#pragma once

#include <pcl/PointIndices.h>

#include <cstddef>
#include <vector>

namespace facyl {

/** \brief How one ground-truth object came out of a segmentation. */
struct SegmentOutcome {
  int object{0};         ///< ground-truth id
  std::size_t points{0}; ///< its points in the cloud
  int best_segment{-1};  ///< the segment holding most of its points, -1 if none
  float best_iou{0.f};   ///< intersection over union with that segment
  bool recovered{false}; ///< one segment with IoU >= 0.5
  /** Under-segmented: at least 20% of the points of its best segment belong to other
   * ground-truth objects. */
  bool merged{false};
  /** Over-segmented: at least two segments each hold at least 20% of its points. */
  bool split{false};
};

/** \brief Outcome of every object with at least \a min_points points.
 * \param truth per cloud point: the object id (> 0) of objects to score, 0 for the rest
 *        (table, background), < 0 for invalid points.
 * \param segments point indices of each segment (a point in several segments counts for each).
 * \param min_points objects with fewer points are skipped (they cannot be a segment).
 * Objects come out in increasing id. */
std::vector<SegmentOutcome> scoreSegments(const std::vector<int>& truth,
                                          const std::vector<pcl::PointIndices>& segments,
                                          std::size_t min_points);

/** \brief Totals over outcomes. */
struct SegmentTotals {
  std::size_t objects{0}, recovered{0}, merged{0}, split{0};
  void add(const SegmentOutcome& o)
  {
    ++objects;
    recovered += o.recovered;
    merged += o.merged;
    split += o.split;
  }
  /** \brief recovered / objects (NaN for none). */
  double recoveredShare() const;
};

} // namespace facyl
