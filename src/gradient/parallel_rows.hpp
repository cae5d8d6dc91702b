/// @file parallel_rows.hpp
/// @brief Private: a parallel loop over the rows of an image or height plane.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>

namespace sgbake::gradient_detail {

/// Rows per task of the parallel loops over rows (rows are independent: no result depends on it).
inline constexpr std::size_t kRowGrain = 16;

/// @brief Calls @p body(y) for every row 0 ≤ y < @p height, rows in parallel.
template <class Body>
void forEachRow(int height, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, height, kRowGrain),
                    [&](const tbb::blocked_range<int>& rows) {
                      for (int y = rows.begin(); y != rows.end(); ++y) body(y);
                    });
}

}  // namespace sgbake::gradient_detail
