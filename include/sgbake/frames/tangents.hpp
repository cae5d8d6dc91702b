/// @file tangents.hpp
/// @brief MikkTSpace tangent frames per face corner, identical to Blender's.
#pragma once

#include <string>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake {

/// @brief Per-corner tangent frames: unit tangent and bitangent sign.
///
/// The bitangent is `sign · cross(normal, tangent)` with the corner's normal, the convention of
/// Blender, Unity, Unreal and every other MikkTSpace consumer.
struct CornerTangents {
  std::vector<Vec3f> tangent;  ///< #C unit object-space tangents, in corner order
  std::vector<float> sign;     ///< #C, +1 or -1
};

/// @brief Options for computeTangents.
struct TangentOptions {
  /// Maximum number of threads; 0 = all cores. The result is bit-identical for every value.
  int threads = 0;
};

/// @brief MikkTSpace (Mikkelsen 2008) over a polygon mesh.
///
/// Triangles and quads are handed to the algorithm as they are (it splits quads on the shorter
/// UV diagonal and gives both halves one orientation). N-gons are triangulated by ear clipping in
/// the plane of their Newell normal; each n-gon triangle is a face of its own to the algorithm and
/// a corner shared by several of them keeps the frame of the last one, as Blender's looptri path
/// does. Corners are welded only where position, normal and UV are exactly equal.
///
/// @param[in] mesh corner normals must be unit; corner UVs must be present
/// @return kBadInput when the mesh has no UVs
Result<CornerTangents> computeTangents(const MeshView& mesh, const TangentOptions& options = {});

/// @brief A warning about corners left without a tangent (a zero tangent, which MikkTSpace
/// leaves where no triangle has usable position and UV differences: single-precision overflow
/// of coordinates beyond ~1e19, where Blender's tangents are NaN; degenerate UVs alone get
/// their neighbours' frames), naming @p meshName; "" when every corner has one.
std::string missingTangentsWarning(const CornerTangents& tangents, const std::string& meshName);

}  // namespace sgbake
