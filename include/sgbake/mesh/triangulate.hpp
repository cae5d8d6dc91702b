/// @file triangulate.hpp
/// @brief Splitting polygons into triangles (n-gons for MikkTSpace and the texel raster).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sgbake/core/vec.hpp"

namespace sgbake {

/// @brief Ear-clipping triangulation of one planar-ish polygon.
///
/// The polygon is projected onto the coordinate plane most perpendicular to its Newell normal,
/// oriented so that it winds counter-clockwise there, and ears (convex corners whose triangle
/// contains no other corner) are clipped, scanning from the first corner. Triangles keep the
/// polygon's winding. When no ear exists (self-intersecting or degenerate polygons) the most
/// convex corner is clipped anyway, so the result always has k-2 triangles.
///
/// @param[in]  points the polygon's k >= 3 corner positions, in order
/// @param[out] triangles cleared, then k-2 triangles of corner indices into @p points
void triangulatePolygon(std::span<const Vec3f> points,
                        std::vector<std::array<std::uint32_t, 3>>& triangles);

}  // namespace sgbake
