/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

namespace facyl {
namespace detail {

/** The median of \a v (its upper middle for an even count; NaN when empty), by nth_element on
 * the copy. The recognition module's one median (sample_consensus_alt keeps its own). */
inline float
medianOf(std::vector<float> v)
{
  if (v.empty())
    return std::numeric_limits<float>::quiet_NaN();
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

} // namespace detail
} // namespace facyl
