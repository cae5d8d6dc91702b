/// @file normals.hpp
/// @brief Face and vertex normals computed the way Blender computes them.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake {

/// @brief Face @p f's normal direction, not normalized (Blender's polygon normal): triangles
/// (p0-p1)×(p1-p2), quads the cross product of the diagonals (p0-p2)×(p1-p3), larger faces
/// Newell's sum (twice the vector area, well defined for non-planar faces). All three point the
/// same way for a planar face with counter-clockwise corners seen from the front.
Vec3d faceNormalDirection(const MeshView& mesh, std::size_t f);

/// @brief Unit face normals, #F. Triangles: normalize((p0-p1)×(p1-p2)); quads: normalize of the
/// cross product of the diagonals (p0-p2)×(p1-p3); n-gons: Newell's method. All point to the side
/// from which the corners are counter-clockwise. A face of zero area (its cross product, computed
/// in double from the float positions, is exactly zero) gets (0, 0, 1), Blender's fallback.
std::vector<Vec3f> computeFaceNormals(const MeshView& mesh);

/// @brief Smooth shading, as Blender's vertex normals: each vertex normal is the normalized sum of
/// the normals of the faces around it (by vertex index), each weighted by the face's interior
/// angle at that vertex (so splitting a face into several does not change the result). Computed
/// and accumulated in double, stored as float. Degenerate cases follow Blender: a zero-area face
/// contributes (0, 0, 1); a corner with a zero-length edge has weight π/2 (Blender's acos of the
/// dot product with a zero vector). A vertex whose sum vanishes gets its normalized position
/// (Blender's fallback), or (0, 0, 1) at the origin. The corners of faces flagged flat
/// (Mesh::faceFlat) take their face's normal (computeFaceNormals) instead, as Blender shades a
/// flat face; the vertex normals still sum over flat faces too, as Blender's do. Writes every
/// corner of @p mesh and sets normalSource to kComputed.
/// @note Precondition: @p mesh satisfies the index invariants of Mesh (positions may be anything
/// finite; normals are not read).
void computeSmoothNormals(Mesh& mesh);

/// @brief Blender's Auto Smooth (split normals, Mesh.use_auto_smooth): corners around a vertex
/// are grouped into fans separated by sharp edges, and each corner gets the normalized sum of
/// its fan's angle-weighted face normals (computeSmoothNormals's weights). An edge is sharp
/// when its two faces' unit normals (computeFaceNormals) meet at more than @p angle radians
/// (their float dot product below cosf of the angle in float, as Blender tests it), when a
/// face on it is flat (Mesh::faceFlat), when it has one face or more than two, or when its two
/// faces run along it the same way, or when it is one of @p sharpEdges (vertex pairs, lower
/// index first, sorted: Blender's edges marked sharp). Writes every corner of @p mesh and sets
/// normalSource to kComputed.
/// @note Precondition: as computeSmoothNormals.
void computeSplitNormals(
    Mesh& mesh, double angle,
    std::span<const std::pair<std::uint32_t, std::uint32_t>> sharpEdges = {});

/// @brief Whether @p mesh's corner normals (read from a file) can only be Blender's Auto Smooth
/// split or custom normals, which an OBJ does not otherwise say: corners of one vertex on
/// smooth faces with different normals (without Auto Smooth they share the vertex normal), or
/// a flat face with a corner normal more than 0.1° from its polygon normal (without Auto
/// Smooth a flat face's corners carry it). The mesh is then shaded as Cycles shades an Auto
/// Smooth mesh (Mesh::autoSmooth).
bool normalsShowAutoSmooth(const Mesh& mesh);

/// @brief A given normal (read from a file, or handed to the C ABI) as a corner normal: kept
/// bit-exact when its length is 1 within eight float ulps (about 9.5e-7; a normal normalized in
/// float stays as it is), normalized in double otherwise.
/// @note Precondition: @p n is finite and not zero.
Vec3f unitNormal(Vec3f n);

/// @brief Checks the Mesh invariants (see Mesh); names @p mesh.source in the message.
///
/// Unit length means within eight float ulps of 1 (about 9.5e-7). Returns ErrorCode::kBadInput
/// with a one-line message `<source>: <what is wrong>` for the first violation found.
Status validate(const Mesh& mesh);

}  // namespace sgbake
