/// @file bump_node.hpp
/// @brief Private: heights differentiated as Blender's Bump node does when Cycles bakes
/// (HeightGradient::kBumpNode).
///
/// Cycles' Bump node does not differentiate a height: it evaluates the height three times, at
/// the shading point and again a ray differential away along dP.dx and dP.dy, and bumps the
/// normal with those forward differences. When Blender bakes, the differentials come from the
/// bake's pixel: Blender's baker hands Cycles the change of the barycentrics over half a texel
/// in x and in y (bake_differentials), Cycles keeps only the mean length of the two position
/// offsets that makes (a "compact" differential, a radius r) and spreads it again along two
/// orthonormal directions of the geometric normal Ng (make_orthonormals). An image texture on a
/// UV map is read at the UV the triangle's plane has there. So the bumped normal depends on the
/// bake's size and on Ng's direction, not on the height's derivatives alone: at 256² a sphere's
/// steep bump differs from the exact one by a median of about 1°.
#pragma once

#include <cmath>

#include "gradient/triplanar_sum.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/projection.hpp"
#include "sgbake/gradient/surface_point.hpp"
#include "sgbake/gradient/texture.hpp"

namespace sgbake::gradient_detail {

/// Two unit vectors orthogonal to unit @p n and to each other, as Cycles' make_orthonormals
/// picks them: a along (1, 1, 1) × n, or (−1, 1, 1) × n where n's components are all equal;
/// b = n × a.
inline void cyclesOrthonormals(const Vec3d& n, Vec3d& a, Vec3d& b) {
  if (n.x != n.y || n.x != n.z) {
    a = Vec3d{n.z - n.y, n.x - n.z, n.y - n.x};
  } else {
    a = Vec3d{n.z - n.y, n.x + n.z, -n.y - n.x};
  }
  a = normalizeOr(a, Vec3d{});
  b = cross(n, a);
}

/// The BumpOffsets of a bake sample on a triangle with geometric normal @p faceNormal (unit)
/// and UV derivatives @p dPdu, @p dPdv of the baked UV map, for texels @p texel = (1/width,
/// 1/height) in UV: r = ½ (|½ ∂P/∂u · texel.x| + |½ ∂P/∂v · texel.y|) along Cycles' orthonormals
/// of Ng. Empty where the UV map collapses.
inline BumpOffsets bakeBumpOffsets(const Vec3d& faceNormal, const Vec3d& dPdu, const Vec3d& dPdv,
                                   Vec2d texel) {
  const double r = 0.5 * (0.5 * texel.x * length(dPdu) + 0.5 * texel.y * length(dPdv));
  if (!(r > 0) || !std::isfinite(r)) return {};
  Vec3d a, b;
  cyclesOrthonormals(faceNormal, a, b);
  return {r * a, r * b};
}

/// The UV offset of the in-plane position offset @p w on a triangle with UV derivatives @p frame
/// (∂P/∂u·Δu + ∂P/∂v·Δv = w, solved in the plane they span); zero where they are degenerate.
inline Vec2d uvOffsetOf(const UvFrame& frame, const Vec3d& w) {
  const double uu = dot(frame.dPdu, frame.dPdu), uv = dot(frame.dPdu, frame.dPdv),
               vv = dot(frame.dPdv, frame.dPdv);
  const double det = uu * vv - uv * uv;
  if (!(det > 0) || !std::isfinite(det)) return {};
  const double pu = dot(frame.dPdu, w), pv = dot(frame.dPdv, w);
  return {(vv * pu - uv * pv) / det, (uu * pv - uv * pu) / det};
}

/// Γ of heights @p scale · h as the Bump node bumps unit normal @p normal with them, h being
/// @p hc here and @p hx, @p hy at @p offsets dx, dy: with Rx = dP.dy × N, Ry = N × dP.dx and
/// det = ⟨dP.dx, Rx⟩ the node's normal is
/// |det|·N − scale·sign(det)·((h_x − h_c)·Rx + (h_y − h_c)·Ry), which is N − Γ scaled.
inline Vec3d bumpNodeGradientFrom(double hc, double hx, double hy, double scale,
                                  const Vec3d& normal, const BumpOffsets& offsets) {
  const Vec3d rx = cross(offsets.dy, normal), ry = cross(normal, offsets.dx);
  const double det = dot(offsets.dx, rx);
  if (!(std::abs(det) > 0) || !std::isfinite(det)) return {};
  const Vec3d gamma = (scale / det) * ((hx - hc) * rx + (hy - hc) * ry);
  return isFinite(gamma) ? gamma : Vec3d{};
}

/// bumpNodeGradientFrom with h read at the offsets by @p heightAt(offset).
template <class HeightAt>
Vec3d bumpNodeGradientOf(const HeightAt& heightAt, double hc, double scale, const Vec3d& normal,
                         const BumpOffsets& offsets) {
  const double hx = heightAt(offsets.dx), hy = heightAt(offsets.dy);
  return bumpNodeGradientFrom(hc, hx, hy, scale, normal, offsets);
}

/// bumpNodeGradientOf a UV height map, read at @p frame's UV, the UV of the triangle's plane
/// @p offsets (its uvReads) away, and there (@p hc, already known); before its Strength.
inline Vec3d bumpNodeGradient(const UvHeightSource& s, const UvFrame& frame, const Vec3d& normal,
                              const BumpOffsets& offsets, double hc) {
  const auto heightAt = [&](const Vec3d& w) {
    return s.texture
        ->sample(textureCoordinates(frame.uv + uvOffsetOf(frame, w), s.tiling, s.offset))
        .value;
  };
  return bumpNodeGradientOf(heightAt, hc, s.scale, normal, offsets.uvReads());
}

/// @p point as backFacingNormal sees it: its BumpOffsets marked `behind`. There Cycles flips
/// Ng, N and ∂P/∂u, ∂P/∂v: the first of its orthonormals flips, the second stays. Solving for
/// the UV offsets with the flipped derivatives reads UV heights at +dP.dx and −dP.dy of the
/// front (BumpOffsets::uvReads); heights read at positions are read at −dP.dx and +dP.dy
/// (positionReads).
inline SurfacePoint seenFromBehind(const SurfacePoint& point) {
  SurfacePoint seen = point;
  seen.bump.behind = true;
  return seen;
}

/// The height of a source read at positions, at object position @p position, before its scale
/// (heightScale): a volume's value, a planar projection's texel, a triplanar projection's
/// blend over the planes Cycles shades normal @p seenNormal with (triplanarPlanes: weights and
/// Box mirrors frozen, as its Γ takes them).
inline double unscaledHeightAt(const VolumeSource& s, const Vec3d& position, const Vec3d&) {
  return s.volume->value(position);
}
inline double unscaledHeightAt(const PlanarSource& s, const Vec3d& position, const Vec3d&) {
  return s.height->sample(planarTextureCoordinates(s.coordinates.apply(position), s.mapping)).value;
}
inline double unscaledHeightAt(const TriplanarSource& s, const Vec3d& position,
                               const Vec3d& seenNormal) {
  return sumOverPlanes<double>(s.options, position, seenNormal,
                               [&](const PlanarMapping&, Vec3d, Vec2d st, double weight) {
                                 return weight * s.height->sample(st).value;
                               });
}
inline double heightScale(const VolumeSource& s) { return s.scale; }
inline double heightScale(const PlanarSource& s) { return s.scale; }
inline double heightScale(const TriplanarSource& s) { return s.options.scale; }

/// bumpNodeGradientOf a height read at positions (a volume, a height projection with a
/// texture): read at @p position, and at the offsets (their positionReads) mapped into the
/// source's space by @p toSource; the Bump node's geometry is @p normal's and the offsets'.
/// (Object space: @p toSource the identity; world space: M⁻¹, the source reading object
/// positions.) Triplanar planes are those of @p seenObjectNormal (SurfacePoint::seenNormal).
template <class Source, class ToSource>
Vec3d positionBumpNodeGradient(const Source& s, const Vec3d& position,
                               const Vec3d& seenObjectNormal, const Vec3d& normal,
                               const BumpOffsets& offsets, const ToSource& toSource) {
  const auto heightAt = [&](const Vec3d& w) {
    return unscaledHeightAt(s, position + toSource(w), seenObjectNormal);
  };
  return bumpNodeGradientOf(heightAt, unscaledHeightAt(s, position, seenObjectNormal),
                            heightScale(s), normal, offsets.positionReads());
}

/// Whether a height with @p gradient is differenced as the Bump node does at @p point.
inline bool usesBumpNode(HeightGradient gradient, const SurfacePoint& point) {
  return gradient == HeightGradient::kBumpNode && !point.bump.empty();
}

/// Whether @p source is a height differenced as the Bump node does (at points with offsets).
inline bool readsBumpOffsets(const LayerSource& source) {
  return std::visit(
      [](const auto& s) {
        if constexpr (requires { s.gradient; }) {
          return s.gradient == HeightGradient::kBumpNode;
        } else {
          return false;
        }
      },
      source);
}

}  // namespace sgbake::gradient_detail
