/// @file triangulate.hpp
/// @brief Splitting polygons into triangles (n-gons for MikkTSpace and the texel raster).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sgbake/core/vec.hpp"

namespace sgbake {

/// @brief Ear-clipping triangulation of one polygon, reproducing Blender 3.4's loop triangles.
///
/// The polygon is projected orthographically onto the plane perpendicular to its Newell normal
/// (a rotation, not a drop of the dominant axis; it matters for non-planar polygons), where it
/// winds counter-clockwise. Each corner caches its turn sign (convex, straight, reflex). An ear
/// is a corner that is not reflex and whose triangle (prev, corner, next) contains, inside or on
/// its boundary, no non-convex corner of the remaining ring. The search starts at corner 0 going
/// forward and returns the first ear met. After clipping ear e, the neighbours' signs are
/// recomputed only if they were not convex, and the next search starts two corners on in the
/// current direction (next(next(e)) forward, prev(prev(e)) backward); if that corner is not
/// convex, it starts one corner further and the direction reverses. With no ear, the first
/// convex corner met is clipped, else the first straight one, else the start. Triangles are
/// (prev, ear, next) in clipping order; the last one is the remaining ring from its lowest
/// corner. Verified against Blender 3.4.1 on 1607 polygons (convex, concave, non-planar,
/// collinear, self-intersecting, rotated and reversed): identical triangles, order and corner
/// order except for float near-ties and polygons with coincident corners.
///
/// @param[in]  points the polygon's k >= 3 corner positions, in order
/// @param[out] triangles cleared, then k-2 triangles of corner indices into @p points
void triangulatePolygon(std::span<const Vec3f> points,
                        std::vector<std::array<std::uint32_t, 3>>& triangles);

}  // namespace sgbake
