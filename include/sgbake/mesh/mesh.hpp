/// @file mesh.hpp
/// @brief The one mesh representation every sgbake stage reads: polygons with per-corner data.
///
/// A "corner" is one (face, vertex) incidence, Blender's "loop" and OpenMesh's halfedge that
/// points at the vertex. Corners are stored face after face, each face's corners in the order the
/// file lists them, so seams (a vertex with several UVs) and flat-shaded faces (a vertex with
/// several normals) survive loading.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sgbake/core/vec.hpp"

namespace sgbake {

/// @brief Where a mesh's corner normals came from.
enum class NormalSource {
  kFile,      ///< read from the file (OBJ `vn`, per corner; PLY/OFF per vertex)
  kComputed,  ///< the file had none: smooth, angle-weighted vertex normals (see computeSmoothNormals)
};

/// @brief A non-owning view of a polygon mesh as flat arrays: what kernels, the C ABI and the
/// Blender add-on hand around. Every array is object space, right-handed, unitless.
struct MeshView {
  std::span<const Vec3f> positions;        ///< #V vertex positions
  std::span<const std::uint32_t> faceStart;  ///< #F+1 offsets: face f owns corners [faceStart[f], faceStart[f+1])
  std::span<const std::uint32_t> cornerVertex;  ///< #C vertex index of each corner, < #V
  std::span<const Vec3f> cornerNormals;    ///< #C unit normal of each corner
  std::span<const Vec2f> cornerUvs;        ///< #C texture coordinate of each corner (u right, v up), or empty

  std::size_t numFaces() const { return faceStart.empty() ? 0 : faceStart.size() - 1; }
  std::size_t numCorners() const { return cornerVertex.size(); }
  std::uint32_t faceSize(std::size_t f) const { return faceStart[f + 1] - faceStart[f]; }
};

/// @brief One named set of per-corner texture coordinates.
struct UvSet {
  std::string name;
  std::vector<Vec2f> uvs;  ///< #C, u right, v up; Blender's convention (origin bottom-left)
};

/// @brief An owning polygon mesh with per-corner normals and any number of UV sets.
///
/// @note Invariants (established by loadMesh and checked by validate()): faceStart starts at 0,
/// is strictly increasing by at least 3, ends at #C; every cornerVertex < #V; every position and
/// normal is finite; normals have unit length; every UV set has #C finite entries.
struct Mesh {
  std::string source;                  ///< the file this mesh was read from (for messages)
  std::vector<Vec3f> positions;        ///< #V
  std::vector<std::uint32_t> faceStart{0};  ///< #F+1
  std::vector<std::uint32_t> cornerVertex;  ///< #C
  std::vector<Vec3f> cornerNormals;    ///< #C
  std::vector<UvSet> uvSets;           ///< zero or more sets of #C UVs
  NormalSource normalSource = NormalSource::kFile;
  /// #F, 1 for a flat-shaded face (Blender's smooth flag off: OBJ `s 0` / `s off`), or empty:
  /// every face smooth. Read where sgbake computes normals (computeSmoothNormals, Auto Smooth,
  /// subdivideMesh); normals read from the file already say how a face is shaded.
  std::vector<std::uint8_t> faceFlat;
  /// @brief Whether face @p f is flat-shaded (faceFlat says so).
  bool isFlat(std::size_t f) const { return f < faceFlat.size() && faceFlat[f] != 0; }
  /// #F material indices (Blender's material slot of each face; OBJ: `usemtl` names numbered
  /// in order of first use), or empty: every face material 0. A layer with a material
  /// (Layer::material) applies to that material's faces only; subdivision keeps each face's.
  std::vector<std::uint32_t> faceMaterial;
  /// The material names of an OBJ (per index of faceMaterial; faces before the first `usemtl`
  /// have the name ""), or empty.
  std::vector<std::string> materialNames;
  /// @brief The material index of face @p f (0 without faceMaterial).
  std::uint32_t material(std::size_t f) const {
    return f < faceMaterial.size() ? faceMaterial[f] : 0;
  }
  /// Blender's Auto Smooth is on (split or custom normals; computeSplitNormals sets it): Cycles
  /// then shades every face, flat ones included, with its corner normals. Off (an OBJ does not
  /// say; Blender's default), a flat face is shaded with each of its triangles' own normal. A
  /// flat face's tangent frame uses its polygon normal either way.
  bool autoSmooth = false;

  std::size_t numVertices() const { return positions.size(); }
  std::size_t numFaces() const { return faceStart.size() - 1; }
  std::size_t numCorners() const { return cornerVertex.size(); }
  std::uint32_t faceSize(std::size_t f) const { return faceStart[f + 1] - faceStart[f]; }
  bool hasUvSet(std::size_t set) const { return set < uvSets.size(); }

  /// @brief Flat view with UV set @p uvSet (empty UVs when the set does not exist).
  MeshView view(std::size_t uvSet = 0) const {
    MeshView v{positions, faceStart, cornerVertex, cornerNormals, {}};
    if (hasUvSet(uvSet)) v.cornerUvs = uvSets[uvSet].uvs;
    return v;
  }
};

/// @brief Each vertex's corners, in corner order: corners[start[v] … start[v+1]) are those of
/// vertex v (a counting sort of MeshView::cornerVertex).
struct VertexCorners {
  std::vector<std::uint32_t> start;    ///< #V+1
  std::vector<std::uint32_t> corners;  ///< #C

  /// @brief The corners of vertex @p v, ascending.
  std::span<const std::uint32_t> of(std::size_t v) const {
    return {corners.data() + start[v], corners.data() + start[v + 1]};
  }
};

/// @brief The corners of every vertex of @p mesh (whose corner vertices are < @p numVertices).
VertexCorners cornersByVertex(std::span<const std::uint32_t> cornerVertex, std::size_t numVertices);

/// @brief The face of every corner (#C), from @p faceStart (#F+1 offsets).
std::vector<std::uint32_t> cornerFaces(std::span<const std::uint32_t> faceStart);

}  // namespace sgbake
