/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/segmentation/segmentation_score.h>

#include <cmath>
#include <map>

namespace facyl {

std::vector<SegmentOutcome>
scoreSegments(const std::vector<int>& truth, const std::vector<pcl::PointIndices>& segments,
              std::size_t min_points)
{
  std::map<int, std::size_t> size_of; // object -> points
  for (const int t : truth)
    if (t > 0)
      ++size_of[t];
  // Per segment: its size and how many of its points each object has.
  std::vector<std::map<int, std::size_t>> overlap(segments.size());
  std::vector<std::size_t> segment_size(segments.size(), 0);
  std::vector<std::size_t> segment_objects(segments.size(), 0); // points of any object
  for (std::size_t s = 0; s < segments.size(); ++s)
    for (const auto i : segments[s].indices) {
      if (i < 0 || static_cast<std::size_t>(i) >= truth.size())
        continue;
      ++segment_size[s];
      const int t = truth[static_cast<std::size_t>(i)];
      if (t > 0) {
        ++overlap[s][t];
        ++segment_objects[s];
      }
    }
  std::vector<SegmentOutcome> out;
  for (const auto& [object, points] : size_of) {
    if (points < min_points)
      continue;
    SegmentOutcome o;
    o.object = object;
    o.points = points;
    std::size_t best_overlap = 0, large_parts = 0;
    for (std::size_t s = 0; s < segments.size(); ++s) {
      const auto it = overlap[s].find(object);
      if (it == overlap[s].end())
        continue;
      const std::size_t inter = it->second;
      large_parts += 5 * inter >= points; // >= 20% of the object
      const float iou =
        static_cast<float>(inter) / static_cast<float>(points + segment_size[s] - inter);
      if (inter > best_overlap) {
        best_overlap = inter;
        o.best_segment = static_cast<int>(s);
        o.best_iou = iou;
      }
    }
    o.recovered = o.best_iou >= 0.5f;
    o.split = large_parts >= 2;
    if (o.best_segment >= 0) {
      const auto s = static_cast<std::size_t>(o.best_segment);
      o.merged = 5 * (segment_objects[s] - best_overlap) >= segment_size[s];
    }
    out.push_back(o);
  }
  return out;
}

double
SegmentTotals::recoveredShare() const
{
  return objects ? static_cast<double>(recovered) / static_cast<double>(objects) : NAN;
}

} // namespace facyl
