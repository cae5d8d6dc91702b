/// @file surface_point.hpp
/// @brief Where bump sources are evaluated: a surface point with its geometric context.
///
/// The same SurfacePoint describes a mesh corner, a texel's point on a triangle, or a point of a
/// limit surface, so every source kernel serves the per-corner table, the baker and the add-on.
#pragma once

#include <array>

#include "sgbake/core/vec.hpp"

namespace sgbake {

/// Maximum number of UV sets a SurfacePoint carries.
inline constexpr int kMaxUvSets = 4;

/// @brief One UV set at a surface point: the coordinates and the surface's derivatives w.r.t.
/// them (T = ∂P/∂u and B = ∂P/∂v of seed 001 eq. 3; not normalized, not orthogonal).
///
/// On a mesh these are the triangle's constant derivatives; on a limit surface the exact ones.
/// When the UV triangle is degenerate both are zero (kernels then return Γ = 0, see
/// gradientFromUvDerivatives).
struct UvFrame {
  Vec2d uv{};    ///< (u, v); u right, v up (Blender), no tiling applied
  Vec3d dPdu{};  ///< object-space ∂P/∂u
  Vec3d dPdv{};  ///< object-space ∂P/∂v
};

/// @brief Where Blender's Bump node reads a height again around a point (Cycles' ray
/// differentials dP.dx, dP.dy of the shading point, in the point's space): the offsets a height
/// layer with HeightGradient::kBumpNode differences over. Both zero when the point has none
/// (heights are then differentiated exactly).
struct BumpOffsets {
  Vec3d dx{}, dy{};
  /// Seen from behind (a back-facing point): Cycles flips Ng, so dP.dx flips, and UV heights
  /// are read through the flipped ∂P/∂u, ∂P/∂v. See uvReads and positionReads.
  bool behind = false;
  bool empty() const { return dx == Vec3d{} && dy == Vec3d{}; }
  /// The offsets whose front bump is what a UV-mapped height makes here: (dx, −dy) behind.
  BumpOffsets uvReads() const { return {dx, behind ? -dy : dy}; }
  /// The offsets whose front bump, its heights negated, is what a height read at positions
  /// makes here: (−dx, dy) behind.
  BumpOffsets positionReads() const { return {behind ? -dx : dx, dy}; }
};

/// @brief A point on the surface, in object space.
struct SurfacePoint {
  Vec3d position{};  ///< P
  Vec3d normal{0, 0, 1};  ///< N, the unit shading normal (interpolated and renormalized)
  /// |Σ bi·Ni|, the length of the interpolated normal N was renormalized from (< 1 inside a
  /// curved smooth triangle; 1 where N is not interpolated: flat faces, corners, limit
  /// surfaces). Blender's Normal Map node decodes with the unnormalized normal.
  double normalLength = 1;
  std::array<UvFrame, kMaxUvSets> uv{};  ///< UV sets 0 .. numUvSets-1
  int numUvSets = 0;
  /// MikkTSpace frame of UV set 0, interpolated as the consumer of a tangent-space normal map
  /// does (unit tangent per corner, interpolated; see docs): tangent and bitangent sign.
  Vec3d tangent{1, 0, 0};
  double bitangentSign = 1;
  bool hasTangentFrame = false;
  /// MikkTSpace frames of UV sets 1 … numUvSets − 1 (entry 0 unused: set 0's is the tangent
  /// above), where hasUvTangentFrame says so: a tangent-space layer on such a set decodes in
  /// its own (Cycles computes one for the UV map a Normal Map node names).
  std::array<Vec3d, kMaxUvSets> uvTangent{};
  std::array<double, kMaxUvSets> uvBitangentSign{};
  std::array<bool, kMaxUvSets> hasUvTangentFrame{};
  /// The unit geometric normal Ng of the triangle the point lies on: heights defined in space
  /// take their slopes along its plane (projectOntoTangentPlaneAlong), a layer on the layers
  /// above bumps along it, and Cycles' guards and back-facing test read it. Zero where the
  /// point has no triangle (per-corner tables, limit surfaces): N serves then (planeNormal).
  Vec3d geometricNormal{};
  /// Where a Bump node would read the heights again here (set by the baker for layers that
  /// ask for it, see bakeBumpOffsets); empty elsewhere.
  BumpOffsets bump{};

  /// The normal Cycles shades with here: N, or −N at a point seen from behind (bump.behind,
  /// where Cycles flips N before any node runs). Box projections pick their mirrors by it.
  Vec3d seenNormal() const { return bump.behind ? -normal : normal; }
  /// Ng, or N where the point has no triangle (geometricNormal zero): the plane's normal every
  /// guard and stacked layer takes.
  const Vec3d& planeNormal() const { return geometricNormal == Vec3d{} ? normal : geometricNormal; }
};

}  // namespace sgbake
