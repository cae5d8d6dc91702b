/// @file corners.hpp
/// @brief Per-corner evaluation of bump layers over a Mesh, and the per-corner table.
///
/// A thin driver over the kernels of surface_gradient.hpp, projection.hpp and layers.hpp: it
/// builds one SurfacePoint per face corner, evaluates the layers there in parallel, and formats
/// the result. No bump math lives here.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/surface_gradient.hpp"
#include "sgbake/gradient/surface_point.hpp"
#include "sgbake/gradient/world_shading.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake {

/// Smallest sine of the corner angle (in UV space and in object space) for which a corner's
/// triangle defines its UV derivatives. UVs and positions are floats (unit round-off 6e-8), so a
/// corner flatter than ~16 float ulps is indistinguishable from a straight angle.
inline constexpr double kMinCornerSine = 1e-6;

/// @brief Options of evaluateCorners.
struct CornerOptions {
  /// Maximum number of threads; 0 = all cores. The result is bit-identical for every value.
  int threads = 0;
  /// cof(M) of the object's linear transform for the perturbed normal (eq. 33); identity keeps it
  /// in object space. Γ itself is always reported in object space.
  Mat3 objectScaleCofactor = Mat3::identity();
  /// Non-null: the layers are shaded in world space through this transform, as a bake with
  /// BakeInput::transform does (shadeLayersInWorld; the corner's normal is its Ng): Γ is then
  /// the object-space Γ of the world-space result and objectScaleCofactor is not used.
  const WorldSpace* world = nullptr;
  double minCornerSine = kMinCornerSine;  ///< see kMinCornerSine
  /// Per UV set, the tangent frames (per corner, in corner order) that tangent-space layers on
  /// that set decode with, or nullptr: the bake's are the loop triangles'
  /// (loopTriangleFramesAtCorners of BakeInput::triangleTangents), as Cycles' Normal Map node's.
  /// Without them a layer on set 0 decodes with the polygon mesh's MikkTSpace frame (the
  /// `tangent` column, which these never change), on another set as TangentNormalOptions::frame
  /// says.
  std::array<const CornerTangents*, kMaxUvSets> layerTangents{};
};

/// @brief The evaluated bump at one face corner. Object space throughout.
struct CornerSample {
  std::uint32_t face = 0;  ///< face index
  std::uint32_t corner =
      0;              ///< global corner index (Blender's loop index), not the index in the face
  Vec3d position{};   ///< P
  Vec3d normal{};     ///< N, unit corner normal
  Vec3d tangent{};    ///< MikkTSpace tangent of UV set 0; 0 when the mesh has no UVs
  double sign = 1;    ///< MikkTSpace bitangent sign (±1); 1 when the mesh has no UVs
  Vec2d uv{};         ///< UV set 0 (0 when the mesh has none)
  Vec3d gradient{};   ///< Γ, composite surface gradient (eq. 34-35)
  Vec3d perturbed{};  ///< N' = resolveNormal(N, Γ, cof) (eq. 33)
};

/// @brief The SurfacePoint of global corner @p corner of face @p face.
///
/// - position: the corner's vertex; normal: the corner normal, renormalized in double.
/// - UV sets 0 .. min(#sets, kMaxUvSets)-1, each with uv = the corner's UV and ∂P/∂u, ∂P/∂v of the
///   affine map of one triangle of the face through the corner, chosen per UV set:
///   1. the **corner triangle** (previous corner, this corner, next corner). For a triangle it is
///      the face; for a quad it is the triangle whose affine map has the derivatives of the
///      quad's bilinear interpolant at this corner (exact for parallelogram quads), so the frame
///      follows a non-planar quad's local tangent plane;
///   2. when that triangle is degenerate — sine of its angle at the corner below minCornerSine in
///      UV space or in object space (e.g. a corner on a straight edge of an n-gon, a collapsed
///      UV edge) — the triangle of the face's ear-clipping triangulation (triangulatePolygon)
///      containing the corner with the largest such sine;
///   3. when every candidate is degenerate, ∂P/∂u = ∂P/∂v = 0 (UV-based sources then give Γ = 0).
/// - tangent frame: @p tangents (MikkTSpace of UV set 0) when given, else hasTangentFrame = false.
///
/// @param[in] tangents computeTangents of @p mesh's UV set 0, or nullptr
/// @note Preconditions: @p mesh satisfies the Mesh invariants; @p corner belongs to @p face.
SurfacePoint cornerSurfacePoint(const Mesh& mesh, const CornerTangents* tangents, std::size_t face,
                                std::uint32_t corner, double minCornerSine = kMinCornerSine);

/// @brief Evaluates @p layers at every corner of @p mesh (TBB, faces in parallel).
///
/// Computes MikkTSpace tangents of UV set 0 when the mesh has UVs.
/// @return one sample per corner in corner order; kBadInput when the mesh violates its
///         invariants or a layer fails validateLayers (e.g. it names a UV set the mesh lacks)
Result<std::vector<CornerSample>> evaluateCorners(const Mesh& mesh, std::span<const Layer> layers,
                                                  const CornerOptions& options = {});

/// The table's header line (no newline).
inline constexpr const char* kCornerTableHeader =
    "face,corner,px,py,pz,nx,ny,nz,tx,ty,tz,sign,u,v,gx,gy,gz,mx,my,mz";

/// @brief The per-corner table as CSV text: kCornerTableHeader, then one line per sample in the
/// given order, every real number with 9 significant digits (shortest "%.9g" form via
/// std::to_chars: locale-independent; −0 is written as 0). Lines end with '\n'.
std::string formatCornerTable(std::span<const CornerSample> samples);

/// @brief Writes formatCornerTable(@p samples) to @p out.
void writeCornerTable(std::ostream& out, std::span<const CornerSample> samples);

}  // namespace sgbake
