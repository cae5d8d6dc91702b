/// @file subdivide.hpp
/// @brief Catmull-Clark subdivision as Blender's Subdivision Surface modifier computes it
/// (OpenSubdiv underneath), so that a coarse mesh plus a level bakes like Blender's modified mesh.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sgbake/core/named.hpp"
#include "sgbake/core/result.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake {

/// @brief Blender's "UV Smooth": how UVs are interpolated (OpenSubdiv's face-varying linear
/// interpolation option, mapped as in shared/CONVENTIONS.md).
enum class SubdivisionUvSmooth {
  kNone,                         ///< "none": UVs interpolated linearly (FVAR_LINEAR_ALL)
  kKeepCorners,                  ///< "keep-corners" (FVAR_LINEAR_CORNERS_ONLY)
  kKeepCornersJunctions,         ///< "keep-corners-junctions" (FVAR_LINEAR_CORNERS_PLUS1)
  kKeepCornersJunctionsConcave,  ///< "keep-corners-junctions-concave" (FVAR_LINEAR_CORNERS_PLUS2)
  kKeepBoundaries,               ///< "keep-boundaries", Blender's default (FVAR_LINEAR_BOUNDARIES)
  kAll,                          ///< "all": UVs smoothed everywhere (FVAR_LINEAR_NONE)
};

/// @brief Blender's "Boundary Smooth": how open boundaries are treated.
enum class SubdivisionBoundary {
  kAll,          ///< "all", Blender's default (VTX_BOUNDARY_EDGE_ONLY)
  kKeepCorners,  ///< "keep-corners": boundary corners stay sharp (VTX_BOUNDARY_EDGE_AND_CORNER)
};

/// @brief Blender's subdivision type.
enum class SubdivisionType {
  kCatmullClark,  ///< "catmull-clark", Blender's default (OpenSubdiv's Catmull-Clark scheme)
  /// "simple": faces are split, the cage's shape kept. As Blender 3.4 computes it: Catmull-Clark
  /// with every edge and vertex infinitely sharp at Quality 1 (not OpenSubdiv's bilinear
  /// scheme); the mesh's creases and the Quality do not apply.
  kSimple,
};

/// @brief How scene files ("type") and the CLI (--subdivision-type) spell SubdivisionType.
inline constexpr Named<SubdivisionType> kSubdivisionTypeNames[] = {
    {"catmull-clark", SubdivisionType::kCatmullClark}, {"simple", SubdivisionType::kSimple}};

/// @brief How scene files ("uv_smooth") and the CLI (--uv-smooth) spell SubdivisionUvSmooth.
inline constexpr Named<SubdivisionUvSmooth> kSubdivisionUvSmoothNames[] = {
    {"none", SubdivisionUvSmooth::kNone},
    {"keep-corners", SubdivisionUvSmooth::kKeepCorners},
    {"keep-corners-junctions", SubdivisionUvSmooth::kKeepCornersJunctions},
    {"keep-corners-junctions-concave", SubdivisionUvSmooth::kKeepCornersJunctionsConcave},
    {"keep-boundaries", SubdivisionUvSmooth::kKeepBoundaries},
    {"all", SubdivisionUvSmooth::kAll}};

/// @brief How scene files ("boundary") and the CLI (--boundary-smooth) spell SubdivisionBoundary.
inline constexpr Named<SubdivisionBoundary> kSubdivisionBoundaryNames[] = {
    {"all", SubdivisionBoundary::kAll}, {"keep-corners", SubdivisionBoundary::kKeepCorners}};

/// @brief Blender's crease of one edge ("Edge Crease", `MeshEdge.crease`).
struct EdgeCrease {
  std::uint32_t v0 = 0;  ///< one end: a 0-based vertex index, in the mesh's vertex order
  std::uint32_t v1 = 0;  ///< the other end (either order)
  float crease = 0;      ///< in [0, 1]; OpenSubdiv sharpness creaseSharpness(crease)
};

/// @brief An edge Blender marks sharp ("Mark Sharp", MeshEdge.use_edge_sharp): with Auto Smooth,
/// the subdivided edges along it split the normals.
struct SharpEdge {
  std::uint32_t v0 = 0;  ///< one end: a 0-based vertex index, in the mesh's vertex order
  std::uint32_t v1 = 0;  ///< the other end (either order)
};

/// @brief Blender's crease of one vertex ("Vertex Crease", `Mesh.vertex_creases`).
struct VertexCrease {
  std::uint32_t vertex = 0;  ///< 0-based vertex index, in the mesh's vertex order
  float crease = 0;          ///< in [0, 1]; OpenSubdiv sharpness creaseSharpness(crease)
};

/// @brief The options of subdivideMesh: those of Blender's modifier that change the result,
/// and the creases of the mesh (which Blender keeps on the mesh, not on the modifier).
struct SubdivisionOptions {
  /// Blender's "Levels" (1..kMaxSubdivisionLevel); 0 leaves the mesh as it is, as the modifier
  /// does, but for autoSmoothDegrees
  int level = 1;
  SubdivisionUvSmooth uvSmooth = SubdivisionUvSmooth::kKeepBoundaries;
  SubdivisionBoundary boundary = SubdivisionBoundary::kAll;
  bool useCreases = true;  ///< Blender's "Use Creases"; false ignores both lists below
  std::vector<EdgeCrease> edgeCreases{};      ///< at most one per edge; edges not listed: 0
  std::vector<VertexCrease> vertexCreases{};  ///< at most one per vertex; others: 0
  /// Blender's "Quality" (kMinSubdivisionQuality … kMaxSubdivisionQuality): the refinement level
  /// to which the patches isolate irregular and semi-sharp features (3, a new modifier's, unless
  /// set); higher follows the exact limit more closely there.
  int quality = 3;
  /// Blender's "Use Limit Surface" (on in a new modifier). Off, the points are those of
  /// `level` rounds of Catmull-Clark refinement, not moved to the limit, and `quality` is
  /// unused (Blender greys it out).
  bool useLimitSurface = true;
  SubdivisionType type = SubdivisionType::kCatmullClark;
  /// The mesh's Auto Smooth angle in degrees, 0 … 180 (Blender keeps it on the mesh:
  /// Mesh.use_auto_smooth, auto_smooth_angle), applied to the subdivided mesh's normals
  /// (computeSplitNormals), or at level 0 to the mesh's own (replacing any normals its file
  /// gave, as subdivision does); unset: Auto Smooth off.
  std::optional<double> autoSmoothDegrees{};
  /// Edges marked sharp (each an edge of the mesh); they matter only with autoSmoothDegrees, as
  /// in Blender, where every subdivided edge along one is sharp too.
  std::vector<SharpEdge> sharpEdges{};

  /// @brief Whether subdivideMesh changes the mesh: it subdivides (level > 0), or it splits the
  /// normals of the mesh as it is by Auto Smooth (level 0).
  bool changesMesh() const { return level > 0 || autoSmoothDegrees.has_value(); }
};

/// @brief The range of SubdivisionOptions::quality (Blender's "Quality" field).
inline constexpr int kMinSubdivisionQuality = 1;
inline constexpr int kMaxSubdivisionQuality = 10;

/// @brief OpenSubdiv's sharpness of a Blender crease @p crease ∈ [0, 1], as Blender 3.4's
/// converter computes it in float: 10·c², so that c = 1 is infinitely sharp (Sdc's
/// SHARPNESS_INFINITE = 10) and sharpness s needs c = √(s/10).
inline float creaseSharpness(float crease) { return crease * crease * 10.0f; }

/// @brief What is wrong with one crease (or sharp edge) of SubdivisionOptions for a given mesh.
struct CreaseIssue {
  bool edge = true;       ///< an entry of edgeCreases (else of vertexCreases), unless sharp
  std::size_t index = 0;  ///< its index in that list
  std::string what;       ///< e.g. "vertices 3 and 7 are not the ends of an edge of the mesh"
  bool sharp = false;     ///< an entry of sharpEdges
  /// @brief The list's scene key: "edge_creases", "vertex_creases" or "sharp_edges".
  const char* key() const {
    return sharp ? "sharp_edges" : edge ? "edge_creases" : "vertex_creases";
  }
  /// @brief The command-line option that gives the list's entries: "--edge-crease",
  /// "--vertex-crease" or "--sharp-edge".
  const char* flag() const {
    return sharp ? "--sharp-edge" : edge ? "--edge-crease" : "--vertex-crease";
  }
  /// @brief The list's entries in words: "edge crease", "vertex crease" or "sharp edge".
  const char* noun() const {
    return sharp ? "sharp edge" : edge ? "edge crease" : "vertex crease";
  }
};

/// @brief The first crease or sharp edge of @p options that does not fit @p mesh: a vertex
/// index out of range, an edge that is not an edge of the mesh (two consecutive corners of a
/// face), a crease outside [0, 1] (or not finite), an edge or vertex listed twice. Checked even
/// when useCreases is false (or Auto Smooth is off).
/// @return std::nullopt when every crease fits
std::optional<CreaseIssue> findCreaseIssue(const Mesh& mesh, const SubdivisionOptions& options);

/// @brief A setting of SubdivisionOptions that does nothing, or contradicts another, as given.
/// Blender accepts each of these silently; the command line and scene files refuse them, each
/// naming the setting in its own words (findSubdivisionConflict finds them for both).
enum class SubdivisionConflict {
  kNone,
  kEdgeCreasesUnsubdivided,      ///< edge creases at level 0, where nothing is subdivided
  kVertexCreasesUnsubdivided,    ///< vertex creases at level 0
  kNoLimitSurfaceUnsubdivided,   ///< Use Limit Surface off at level 0
  kSimpleUnsubdivided,           ///< type Simple at level 0
  kSharpEdgesWithoutAutoSmooth,  ///< sharp edges without Auto Smooth: they split nothing
  kLimitWithoutLimitSurface,     ///< the exact limit surface with Use Limit Surface off
  kLimitSimple,                  ///< the exact limit surface (Catmull-Clark's) with type Simple
  kLimitAutoSmooth,              ///< the exact limit surface, which shades its own normals, with
                                 ///< Auto Smooth
  kLimitSharpEdges,              ///< the exact limit surface with edges marked sharp
};

/// @brief The first conflict of @p options, shaded as a subdivision to options.level or, when
/// @p limit, on the exact limit surface (level is then unused); kNone when there is none. The
/// order is the enumeration's.
SubdivisionConflict findSubdivisionConflict(const SubdivisionOptions& options, bool limit);

/// @brief The highest level subdivideMesh accepts (a quad becomes 4⁶ = 4096 quads).
inline constexpr int kMaxSubdivisionLevel = 6;

/// @brief Where the corners of a subdivided mesh lie on the coarse mesh's limit surface, in the
/// coarse faces' own parameterization: what LimitSurface needs to evaluate the exact surface
/// under any point of a subdivided face. (Subdivided meshes are all quads: face f owns corners
/// 4f … 4f+3.)
struct SurfaceParameters {
  std::vector<std::uint32_t> faceOrigin;     ///< per new face: the coarse face it covers part of
  std::vector<std::uint32_t> cornerSubFace;  ///< per new corner: the sub-face (n-gons: the corner
                                             ///< of the coarse face it lies at; quads: 0)
  std::vector<Vec2f> cornerCoord;            ///< per new corner: (s, t) ∈ [0,1]² on that sub-face
};

/// @brief The mesh Blender's Subdivision Surface modifier makes of @p coarse (Catmull-Clark,
/// or Simple: SubdivisionOptions::type), with every UV set subdivided.
///
/// What Blender does, and so this:
///  - Each quad becomes a (2^level)² grid of quads; any other face of n corners becomes n
///    (2^(level-1))² grids, one per corner, meeting at the face's centre.
///  - Every vertex of the result lies on the limit surface of the coarse mesh, evaluated as
///    Blender evaluates it, float for float: OpenSubdiv's Far patches isolated to level 3
///    (Blender's default "Quality"; irregular regions are approximated there), their points
///    computed and evaluated in float by Osd's CPU evaluator at the vertex's Ptex coordinates.
///  - UVs are the face-varying patches of the coarse UVs, evaluated per corner the same way;
///    corners of a vertex whose UVs lie within 1e-4 of each other (and whose faces have the
///    same UV winding) share one face-varying value, the UV of the last of them.
///  - Each new quad starts at the corner nearest its face's first corner in the face's own
///    parameterization, so that it splits into triangles along the same diagonal as Blender's.
///  - With "Use Limit Surface" off (SubdivisionOptions::useLimitSurface), the control mesh is
///    refined uniformly `level` times instead and every vertex and UV is the refined point, as
///    Blender's bilinear patches over that level give it.
///  - Edge and vertex creases (when useCreases) become OpenSubdiv sharpness creaseSharpness(c)
///    of the edge or vertex, with uniform creasing, as Blender's converter sets them.
///  - Each new face keeps its coarse face's flat/smooth flag (Mesh::faceFlat). Corners of smooth
///    faces get computeSmoothNormals of the new faces (angle-weighted over every face at the
///    vertex, flat ones included), corners of flat faces their face's normal: Blender's normals
///    of the modified mesh with Auto Smooth off. With autoSmoothDegrees, Blender's split normals
///    of the new faces instead (computeSplitNormals: fans split where the new faces meet at more
///    than the angle, around flat faces and along edges marked sharp). The coarse mesh's
///    normals are not used.
///
/// The coarse vertices keep their indices (as in Blender); the points inside each coarse edge
/// follow (in OpenSubdiv's edge order), then those inside each coarse face. Faces are grouped by
/// coarse face, in coarse order, each face's grids in corner order, cells row by row.
///
/// @return the subdivided mesh (source kept), or kBadInput naming @p coarse.source when the
///         level, the quality or the Auto Smooth angle is out of range, a crease or a sharp
///         edge does not fit the mesh (findCreaseIssue) or the mesh cannot be subdivided (a
///         face using one vertex twice, or a topology OpenSubdiv rejects).
/// @param[out] parameters when not null, where each new corner lies (SurfaceParameters); at
///             level 0, only faceOrigin (the identity)
Result<Mesh> subdivideMesh(const Mesh& coarse, const SubdivisionOptions& options,
                           SurfaceParameters* parameters = nullptr);

}  // namespace sgbake
