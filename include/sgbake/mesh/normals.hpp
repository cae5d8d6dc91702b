/// @file normals.hpp
/// @brief Face and vertex normals computed the way Blender computes them.
#pragma once

#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake {

/// @brief Unit face normals, #F. Triangles: normalize((p0-p1)×(p1-p2)); quads: normalize of the
/// cross product of the diagonals (p0-p2)×(p1-p3); n-gons: Newell's method. A face of zero area
/// gets (0, 0, 1), Blender's fallback.
std::vector<Vec3f> computeFaceNormals(const MeshView& mesh);

/// @brief Smooth shading, as Blender's vertex normals: each vertex normal is the normalized sum of
/// the normals of the faces around it (by vertex index), each weighted by the face's interior
/// angle at that vertex. A vertex whose sum vanishes gets its normalized position (Blender's
/// fallback), or (0, 0, 1) at the origin. Writes every corner of @p mesh and sets normalSource.
void computeSmoothNormals(Mesh& mesh);

/// @brief Checks the Mesh invariants (see Mesh); names @p mesh.source in the message.
Status validate(const Mesh& mesh);

}  // namespace sgbake
