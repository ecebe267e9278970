/*
 * facyl: fast cylinder detection for PCL.
 * The joins of the edge-aware object segmentation (segmentObjectsOrganized, steps 2 and 3):
 * fragments and enclosed segments join a neighbour, and parts of one surface seen on both
 * sides of a nearer occluder are joined; internal to the library.
 */
#pragma once

#include "object_grid.h"

#include <pcl/types.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace facyl {
namespace edge_aware {

/** Segments as groups of labels, with the statistics the merges need. */
/** Segments as groups of labels, with the statistics the merges need. */
class Segments {
public:
  Segments(const Grid& grid, std::vector<int> label, int count);

  /** Fragments, then enclosed segments, join a neighbour, until nothing changes. */
  void mergeNeighbours(std::size_t min_fragment, float enclosed_share);

  /** Joins the parts of one surface on both sides of a nearer occluder. */
  void bridgeOcclusions(const std::vector<std::uint8_t>& has_depth, std::size_t min_part,
                        const ObjectSegmentationParameters& p);

  /** Point indices of every group, ascending. */
  std::vector<pcl::Indices> indices() const;

private:
  struct Link {
    std::size_t all{0};       ///< 4-neighbour pairs across the border
    std::size_t connected{0}; ///< of which without a depth discontinuity
  };
  /** A link from one group to another, summed over their labels. */
  struct GroupLink {
    int from{0}, to{0};
    std::size_t all{0}, connected{0};
  };
  /** Per group (indexed by its root label; size 0 for other labels): size, boundary, and its
   * links to other groups, links[first[g] .. first[g + 1]). */
  struct GroupStats {
    std::vector<std::size_t> size, boundary, first;
    std::vector<GroupLink> links;
  };

  static std::uint64_t key(int a, int b)
  {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
  }
  int find(int a)
  {
    while (group_[static_cast<std::size_t>(a)] != a)
      a = group_[static_cast<std::size_t>(a)] =
        group_[static_cast<std::size_t>(group_[static_cast<std::size_t>(a)])];
    return a;
  }
  int findConst(int a) const
  {
    while (group_[static_cast<std::size_t>(a)] != a)
      a = group_[static_cast<std::size_t>(a)];
    return a;
  }

  /** The groups now, with their sizes, boundaries and links. */
  GroupStats groupStats();

  /** Boundary pixels of a part (a 4-neighbour in another group or none), at most 100; \a root:
   * each pixel's group now. */
  std::vector<int> border(const std::vector<int>& px, int g, const std::vector<int>& root) const;

  /** Plane (centroid, unit normal) of the points of \a px within \a radius of \a centre. */
  bool localPlane(const std::vector<int>& px, const Eigen::Vector3f& centre, float radius,
                  Eigen::Vector3f& centroid, Eigen::Vector3f& normal) const;

  /** Whether the parts \a pa and \a pb (groups \a g and \a h, borders \a ba and \a bb, at
   * the image positions \a at_a and \a at_b) are one surface seen on both sides of a nearer
   * occluder. */
  bool sameSurfaceBehind(const std::vector<int>& pa, const std::vector<int>& pb,
                         const std::vector<int>& ba, const std::vector<int>& bb,
                         const PixelList& at_a, const PixelList& at_b, int g, int h,
                         const std::vector<std::uint8_t>& has_depth,
                         const ObjectSegmentationParameters& p) const;

  const Grid& grid_;
  std::vector<int> label_; ///< per valid pixel
  std::vector<int> group_;
  std::vector<std::size_t> size_, boundary_;
  std::vector<std::pair<std::uint64_t, Link>> links_; ///< by pair of labels (key), ascending
};

} // namespace edge_aware
} // namespace facyl
