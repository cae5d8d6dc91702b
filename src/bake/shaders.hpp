/// @file shaders.hpp
/// @brief Private: the map kinds as shaders over the texel raster (raster.hpp), with Blender's
/// per-texel frame (texel_frame.hpp) and the gradient engine's layers. bakeMap (bake.cpp) runs
/// them; the raster tests compare the lane-parallel shadeBatch of TangentNormalShader and
/// ObjectNormalShader with their per-sample shade() bit for bit.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <variant>

#include "bake/height.hpp"
#include "bake/raster.hpp"
#include "bake/texel_frame.hpp"
#include "gradient/bump_node.hpp"
#include "gradient/prepared_uv_frame.hpp"
#include "gradient/stacking.hpp"
#include "gradient/world_shading_detail.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/world_shading.hpp"

namespace sgbake::bake_detail {

/// Whether @p point carries UV set @p uvSet.
inline bool hasUvSet(const SurfacePoint& point, int uvSet) {
  return uvSet >= 0 && uvSet < point.numUvSets && uvSet < kMaxUvSets;
}

/// State every bake shader shares: the mesh, tangents, layers, and the current triangle.
struct BakeShaderBase {
  const Mesh* mesh = nullptr;
  const CornerTangents* tangents = nullptr;
  std::array<const CornerTangents*, kMaxUvSets> triangleTangents{};  ///< BakeInput's
  std::span<const Layer> layers;  ///< the current triangle's (layersByMaterial)
  /// When some layer applies to one material only: the layers of each material index
  /// (layersOfMaterial), the last entry for every higher index; `layers` is set per triangle.
  std::span<const std::vector<Layer>> layersByMaterial;
  int uvSet = 0;
  /// How normal maps store a unit normal (putEncoded): the output's storedChannels.
  NormalSwizzle channels = kIdentitySwizzle;
  ShadingTriangle tri;
  SurfacePoint point;  ///< constant fields set per triangle, the rest per sample

  /// (1/width, 1/height) of the bake when a layer reads heights as the Bump node does
  /// (HeightGradient::kBumpNode): each triangle's points get the BumpOffsets of a bake texel
  /// there (bakeBumpOffsets). Zero otherwise.
  Vec2d bumpTexel{};

  /// The current triangle's UV frames with their normal-independent eq. 31 terms (unit ∂P/∂u,
  /// ∂P/∂v, lengths, T̂ × B̂) computed once, for the UV height layers (see gradient()).
  std::array<gradient_detail::PreparedUvFrame, kMaxUvSets> preparedUv{};

  /// Non-null: the object is shaded in world space through this transform, as Cycles shades
  /// it (world_shading.hpp): by shade(), and by the lane-parallel paths through
  /// batchShadeInWorld.
  const WorldSpace* world = nullptr;
  /// What shading in world space keeps per triangle and per sample.
  struct WorldScratch {
    ShadingTriangle tri;  ///< `tri` in world space (worldTriangle)
    SurfacePoint point;   ///< constant fields set per triangle, the rest per sample
    std::array<gradient_detail::PreparedUvFrame, kMaxUvSets> preparedUv{};  ///< of `tri`
  };
  /// A T made on first use, one per copy of the shader (a copy starts without one): kept off
  /// the shader itself, which every row block copies onto its stack (2 KB more there made the
  /// lane-parallel paths 10 % slower).
  template <class T>
  class LazyScratch {
   public:
    LazyScratch() = default;
    LazyScratch(const LazyScratch&) {}
    LazyScratch& operator=(const LazyScratch&) { return *this; }
    T& get() {
      if (!scratch_) scratch_ = std::make_unique<T>();
      return *scratch_;
    }

   private:
    std::unique_ptr<T> scratch_;
  };
  LazyScratch<WorldScratch> worldScratch;

  /// Non-empty (maps of Cycles' normals): the corners Cycles shades each loop triangle with
  /// (cyclesShadingTriangles); the texel's frame stays its own triangle's.
  std::span<const std::array<std::uint32_t, 3>> shadingCorners;
  /// The triangles triangleTangents' frames are of (3 per triangle), given with them: Cycles'
  /// own (cyclesTriangles), the loop triangles but on the quads Blender's baker and Cycles split
  /// on different diagonals.
  std::span<const std::array<std::uint32_t, 3>> frameTriangles;
  /// The current triangle is shaded with other corners (`tri`) than its own (ownTriangle).
  bool shadedElsewhere = false;
  LazyScratch<ShadingTriangle> ownTriangle;

  void beginTriangle(std::uint32_t triangle, const std::array<std::uint32_t, 3>& corners) {
    if (!layersByMaterial.empty()) selectLayersOfFace(corners[0]);
    shadedElsewhere = !shadingCorners.empty() && shadingCorners[triangle] != corners;
    if (shadedElsewhere) [[unlikely]] {
      loadShadingTriangle(*mesh, tangents, corners, uvSet, ownTriangle.get());
      loadShadingTriangle(*mesh, tangents, shadingCorners[triangle], uvSet, tri);
    } else {
      loadShadingTriangle(*mesh, tangents, corners, uvSet, tri);
    }
    loadLayerTangents(triangle, shadedElsewhere ? shadingCorners[triangle] : corners);
    triangleChanged();
  }
  /// `tri`'s frames for tangent-space layers (triangleTangents) at @p shaded, the corners loop
  /// triangle @p triangle is shaded with: Cycles' triangle of the same number, or on a quad
  /// split two ways each corner's frame in the first of the quad's Cycles triangles through it.
  void loadLayerTangents(std::uint32_t triangle, const std::array<std::uint32_t, 3>& shaded) {
    tri.hasLayerTangents.fill(false);
    if (frameTriangles.empty()) return;  // no triangleTangents
    const bool ownFrames = frameTriangles[triangle] == shaded;
    for (std::size_t s = 0; s < kMaxUvSets; ++s) {
      const CornerTangents* frames = triangleTangents[s];
      tri.hasLayerTangents[s] = frames != nullptr;
      if (frames == nullptr) continue;
      for (std::size_t i = 0; i < 3; ++i) {
        const std::size_t k =
            ownFrames ? 3 * std::size_t{triangle} + i : frameIndexElsewhere(triangle, shaded[i]);
        tri.layerTangent[s][i] = cast<double>(frames->tangent[k]);
        tri.layerSign[s][i] = frames->sign[k];
      }
    }
  }
  /// Where corner @p c sits among Cycles' triangles of loop triangle @p triangle's quad (it and
  /// its neighbour): 3·t + i.
  [[gnu::noinline]] std::size_t frameIndexElsewhere(std::uint32_t triangle, std::uint32_t c) const {
    for (const std::size_t t :
         {std::size_t{triangle}, std::size_t{triangle} + 1, std::size_t{triangle} - 1}) {
      if (t >= frameTriangles.size()) continue;
      for (std::size_t i = 0; i < 3; ++i)
        if (frameTriangles[t][i] == c) return 3 * t + i;
    }
    return 3 * std::size_t{triangle};  // (every corner of the quad is in one of them)
  }
  /// The frame Blender's baker expresses the texel's normal in: its own triangle's at @p b,
  /// which is @p f unless Cycles shades the texel elsewhere.
  TexelFrame outputFrame(const Vec3d& b, const TexelFrame& f) {
    return shadedElsewhere ? ownFrame(b) : f;
  }
  [[gnu::noinline]] TexelFrame ownFrame(const Vec3d& b) { return texelFrame(ownTriangle.get(), b); }
  /// Updates what is derived from `tri` (after beginTriangle, or after LimitShader rewrote it).
  void triangleChanged() {
    beginSurfacePoint(tri, point);
    if (bumpTexel.x > 0) point.bump = bumpOffsets(tri);
    for (std::size_t s = 0; s < static_cast<std::size_t>(tri.numUvSets); ++s)
      preparedUv[s] = gradient_detail::prepareUvFrame(point.uv[s]);
    if (world != nullptr) beginWorldTriangle();
  }
  // The world and material cases are out of line (noinline), as the rare cases they are:
  // inlined into shade(), and shade() into the lane-parallel paths' slow lanes, they made the
  // compiler stop inlining batchTexelFrames there (10 % of a one-thread bake).
  /// Where the Bump node reads heights again on @p t (`tri` or its world copy) when Cycles bakes
  /// the map: a texel's steps along the baked UV map. Where Cycles shades the texel on its own
  /// triangle (shadedElsewhere), it moves that triangle's corners by the barycentric steps of
  /// the baker's triangle, whose barycentrics it reads.
  [[gnu::noinline]] BumpOffsets bumpOffsets(const ShadingTriangle& t) {
    Vec3d dPdu = t.bakeDPdu, dPdv = t.bakeDPdv;
    if (shadedElsewhere && uvSet >= 0 && uvSet < t.numUvSets) {
      triangleDerivatives(t.position, ownTriangle.get().uv[static_cast<std::size_t>(uvSet)], dPdu,
                          dPdv);
    }
    return gradient_detail::bakeBumpOffsets(t.faceNormal, dPdu, dPdv, bumpTexel);
  }
  /// `layers` = those of the material of the face of @p corner (layersByMaterial).
  [[gnu::noinline]] void selectLayersOfFace(std::uint32_t corner) {
    const std::size_t material = mesh->material(faceOfCorner(*mesh, corner));
    layers = layersByMaterial[std::min(material, layersByMaterial.size() - 1)];
  }
  /// The world scratch of `tri` (`world` non-null).
  [[gnu::noinline]] void beginWorldTriangle() {
    WorldScratch& w = worldScratch.get();
    worldTriangle(tri, *world, w.tri);
    beginSurfacePoint(w.tri, w.point);
    if (bumpTexel.x > 0) w.point.bump = bumpOffsets(w.tri);
    for (std::size_t s = 0; s < static_cast<std::size_t>(w.tri.numUvSets); ++s)
      w.preparedUv[s] = gradient_detail::prepareUvFrame(w.point.uv[s]);
  }

  /// The object's shading in world space at barycentrics @p b (`world` non-null): the guarded
  /// world normal (the unperturbed one without layers) and the unguarded one. (`point` is then
  /// the object-space point, for worldGradient.)
  [[gnu::noinline]] WorldShadedNormal shadeInWorld(const Vec3d& b, const TexelFrame& f) {
    const SurfacePoint& objectPoint = pointAt(b, f);
    WorldScratch& scratch = worldScratch.get();
    const SurfacePoint& w =
        surfacePointAt(scratch.tri, b, texelFrame(scratch.tri, b), scratch.point);
    if (layers.empty()) return {w.normal, w.normal};
    return gradient_detail::shadeLayersInWorld(layers, objectPoint, w, *world,
                                               scratch.preparedUv.data());
  }
  /// The object-space Γ of the world shading at @p b (objectSpaceGradient).
  [[gnu::noinline]] Vec3d worldGradient(const Vec3d& b, const TexelFrame& f) {
    const WorldShadedNormal shaded = shadeInWorld(b, f);
    return objectSpaceGradient(shaded, point, *world);
  }
  [[gnu::always_inline]] const SurfacePoint& pointAt(const Vec3d& b, const TexelFrame& f) {
    return surfacePointAt(tri, b, f, point);
  }

  /// Γ of a UV height layer: layerGradient(source, p) bit for bit (gradientFromUvDerivatives is
  /// prepareUvFrame + gradientFromPreparedUvFrame), with the frame prepared per triangle.
  Vec3d uvHeightGradient(const UvHeightSource& s, const SurfacePoint& p) const {
    if (s.texture == nullptr || !hasUvSet(p, s.uvSet)) return {};
    const std::size_t set = static_cast<std::size_t>(s.uvSet);
    const ScalarSample h = s.texture->sample(textureCoordinates(p.uv[set].uv, s.tiling, s.offset));
    if (gradient_detail::usesBumpNode(s.gradient, p)) [[unlikely]] {
      return withNormalMapStrength(
          gradient_detail::bumpNodeGradient(s, p.uv[set], p.normal, p.bump, h.value), p.normal,
          s.strength);
    }
    return withNormalMapStrength(
        gradient_detail::gradientFromPreparedUvFrame(preparedUv[set], p.normal,
                                                     uvDerivativesFromTexture(h, s.tiling, s.scale),
                                                     s.minFrameSine),
        p.normal, s.strength);
  }

  /// compositeGradient(layers, p) bit for bit: the same sum in the same order, with
  /// UV height layers through uvHeightGradient (no per-texel std::visit, no per-texel frame
  /// normalizations) and the mask looked up only when the layer has one (factor 1 otherwise).
  Vec3d gradient(const SurfacePoint& p) const {
    Vec3d gamma{};
    for (const Layer& layer : layers) {
      if (layer.weight == 0 || !std::isfinite(layer.weight)) continue;
      addLayerGradient(layer, p, gamma);
    }
    return isFinite(gamma) ? gamma : Vec3d{};
  }

  /// gamma += weight · mask · Γ of one layer (finite, nonzero weight) at @p p: gradient()'s step
  /// (a layer on the layers above: gamma = stackLayerGradient, with the triangle's Ng). With
  /// @p below non-null, also whether the layer makes a normal below the surface
  /// (gradient_detail::NormalBelowSurface: a normal map on the surface at weight 1, or a layer
  /// on the layers above given the normal they hand on, @p aboveNormal).
  void addLayerGradient(const Layer& layer, const SurfacePoint& p, Vec3d& gamma,
                        gradient_detail::NormalBelowSurface* below = nullptr,
                        const Vec3d* aboveNormal = nullptr) const {
    if (layer.base == LayerBase::kLayersAbove) {
      gamma = below == nullptr ? stackLayerGradient(layer, p, gamma)
                               : gradient_detail::stackLayerGradientOn(layer, p, gamma, p.normal,
                                                                       aboveNormal, below);
      return;
    }
    if (below != nullptr) *below = {};
    const double factor = layer.mask.texture == nullptr
                              ? layer.weight
                              : layer.weight * layerMask(layer.mask, p);
    if (factor == 0) return;  // masked out: the source is not sampled
    const UvHeightSource* uvHeight = std::get_if<UvHeightSource>(&layer.source);
    if (uvHeight != nullptr) {
      gamma += factor * uvHeightGradient(*uvHeight, p);
    } else if (below != nullptr) {
      gamma += factor * gradient_detail::layerGradientNoting(layer.source, p, below);
      below->found = below->found && factor == 1;
    } else {
      gamma += factor * layerGradient(layer.source, p);
    }
  }

  /// gradient(p), and in @p handed the normal the layers hand on where no Γ stands for it
  /// (gradient_detail::NormalBelowSurface: a normal map first that decodes below the surface,
  /// then the layers on the layers above while what they make stays below); empty elsewhere.
  Vec3d gradient(const SurfacePoint& p, std::optional<Vec3d>& handed) const {
    handed.reset();
    // Only a normal map first or a layer on the layers above can start a normal below the
    // surface: otherwise gradient(p).
    const auto first = std::find_if(layers.begin(), layers.end(), [](const Layer& layer) {
      return layer.weight != 0 && std::isfinite(layer.weight);
    });
    const bool stacks = std::any_of(layers.begin(), layers.end(), [](const Layer& layer) {
      return layer.base == LayerBase::kLayersAbove;
    });
    if (first == layers.end() ||
        (!stacks && !gradient_detail::mayStartBelowSurface(*first))) {
      return gradient(p);
    }
    Vec3d gamma{};
    gradient_detail::HandedNormal tracked;
    for (const Layer& layer : layers) {
      if (layer.weight == 0 || !std::isfinite(layer.weight)) continue;
      gradient_detail::NormalBelowSurface step;
      addLayerGradient(layer, p, gamma, &step, tracked.givenTo(layer));
      tracked.add(layer, step, p.normal);
    }
    handed = tracked.normal();
    return isFinite(gamma) ? gamma : Vec3d{};
  }

  /// perturbedNormal(point, layers) in object space: N' = normalize(N − Γ) (eq. 33 with the
  /// identity cofactor). Equal to resolveNormal(N, Γ) up to the sign of zero components, without
  /// its identity matrix products and its fallback normalization (computed for every texel);
  /// then Cycles' validReflectionNormal with the triangle's geometric normal, as Blender bakes.
  /// Where N̂ faces away from the triangle, what Cycles bakes there (backFacingNormal).
  /// A normal the layers hand on below the surface is guarded as it is (NormalBelowSurface).
  Vec3d perturbed(const Vec3d& b, const TexelFrame& f) {
    const SurfacePoint& p = pointAt(b, f);
    if (gradient_detail::backFacing(p.normal, tri.faceNormal)) return backFacingNormal(p);
    std::optional<Vec3d> handed;
    const Vec3d gamma = gradient(p, handed);
    return validReflectionNormal(handed ? *handed : unitOr(p.normal - gamma, p.normal),
                                 tri.faceNormal, p.normal);
  }
  /// gradient_detail::backFacingNormal with the triangle's layers and Ng (out of line: rare).
  [[gnu::noinline]] Vec3d backFacingNormal(const SurfacePoint& p) const {
    return gradient_detail::backFacingNormal(layers, p);
  }
  /// A normal map's channels of the normal (x, y, z): 0.5·(±n[axis]) + 0.5 each, by `channels`
  /// (+X+Y+Z: encodeNormal's n/2 + 0.5).
  [[gnu::always_inline]] void putEncoded(double x, double y, double z, double* out) const {
    for (std::size_t c = 0; c < 3; ++c) {
      const SwizzleAxis& s = channels[c];
      const double v = s.axis == 0 ? x : s.axis == 1 ? y : z;
      out[c] = 0.5 * ((s.negate ? -1.0 : 1.0) * v) + 0.5;
    }
  }
  static void put(const Vec3d& v, double* out) {
    out[0] = v.x;
    out[1] = v.y;
    out[2] = v.z;
  }
};

// ---------------------------------------------------------------------------------------------
// Lane-parallel shading (SampleBatch): the scalar shader's arithmetic, the same operations in the
// same order, on arrays of samples, so that the compiler computes two at a time (SSE) and the
// per-sample branches become selects. Samples that need a rare fallback (a vector that cannot be
// normalized the common way) are flagged and shaded again by the scalar shade().

using Lanes = std::array<double, SampleBatch::kMax>;
/// Per-lane flags as 64-bit integers: as wide as the doubles beside them, so that a loop that
/// sets flags vectorizes with two lanes per instruction like the arithmetic.
using LaneFlags = std::array<std::int64_t, SampleBatch::kMax>;
struct Lanes3 {
  Lanes x, y, z;
};

/// BakeShaderBase::putEncoded of lanes [0, @p n) of @p v into @p out (3 values per lane), by
/// @p channels: one loop per channel over the component it stores, so that each vectorizes.
[[gnu::always_inline]] inline void putEncodedLanes(const NormalSwizzle& channels, const Lanes3& v,
                                                   std::size_t n, double* out) {
  for (std::size_t c = 0; c < 3; ++c) {
    const SwizzleAxis& s = channels[c];
    const double* from = s.axis == 0 ? v.x.data() : s.axis == 1 ? v.y.data() : v.z.data();
    const double sign = s.negate ? -1.0 : 1.0;
    for (std::size_t i = 0; i < n; ++i) out[3 * i + c] = 0.5 * (sign * from[i]) + 0.5;
  }
}

/// x is finite (and not NaN), written so that loops over lanes vectorize. (The lane loops
/// combine conditions with & and |, not && and ||, for the same reason: no branches.)
inline bool finiteLane(double x) { return std::abs(x) <= std::numeric_limits<double>::max(); }

/// The per-texel frames of a batch (batchTexelFrames) and its slow lanes: those a lane loop
/// cannot finish the common way, shaded again by shade() (shadeSlowLanes).
struct BatchFrames {
  Lanes3 T, N, B, unitN;
  LaneFlags slow;
};

/// texelFrame() and unitNormal() of every sample: T, N, B and N̂ = N/|N|; slow[i] when N̂ needs
/// unitOr's fallback (|N|² zero, subnormal-small or not finite). Always inlined: called out of
/// line (as the compiler chose when the raster loop around it grew a little) it cost 10 % of a
/// one-thread bake.
[[gnu::always_inline]] inline void batchTexelFrames(const ShadingTriangle& t, const SampleBatch& s,
                                                    BatchFrames& f) {
  Lanes3 &T = f.T, &N = f.N, &B = f.B, &unitN = f.unitN;
  if (s.count < 1) __builtin_unreachable();  // rasterize() shades no empty batch
  LaneFlags& slow = f.slow;
  const Vec3d T0 = t.tangent[0], T1 = t.tangent[1], T2 = t.tangent[2];
  const Vec3d N0 = t.normal[0], N1 = t.normal[1], N2 = t.normal[2];
  const double s0 = t.sign[0], s1 = t.sign[1], s2 = t.sign[2];
  for (std::size_t i = 0; i < static_cast<std::size_t>(s.count); ++i) {
    const double b0 = s.b0[i], b1 = s.b1[i], b2 = s.b2[i];
    const double tx = b0 * T0.x + b1 * T1.x + b2 * T2.x;
    const double ty = b0 * T0.y + b1 * T1.y + b2 * T2.y;
    const double tz = b0 * T0.z + b1 * T1.z + b2 * T2.z;
    const double nx = b0 * N0.x + b1 * N1.x + b2 * N2.x;  // Σ bi·Ni
    const double ny = b0 * N0.y + b1 * N1.y + b2 * N2.y;
    const double nz = b0 * N0.z + b1 * N1.z + b2 * N2.z;
    const double sign = (b0 * s0 + b1 * s1 + b2 * s2) < 0 ? -1.0 : 1.0;
    T.x[i] = tx;
    T.y[i] = ty;
    T.z[i] = tz;
    N.x[i] = nx;
    N.y[i] = ny;
    N.z[i] = nz;
    B.x[i] = sign * (ny * tz - nz * ty);  // sign · N × T
    B.y[i] = sign * (nz * tx - nx * tz);
    B.z[i] = sign * (nx * ty - ny * tx);
    const double len2 = nx * nx + ny * ny + nz * nz;
    const double inv = 1 / std::sqrt(len2);
    unitN.x[i] = inv * nx;
    unitN.y[i] = inv * ny;
    unitN.z[i] = inv * nz;
    slow[i] = !((len2 > 0) & finiteLane(len2));
  }
  // A flat face's frame: N is its polygon normal (the shading normal above stays Σ bi·Ni). A
  // separate pass, so that the common loop stays as lean as it was (the select cost 12 % of a
  // one-thread bake).
  if (t.polygonFrame) {
    const Vec3d P = t.polygonNormal;
    for (std::size_t i = 0; i < static_cast<std::size_t>(s.count); ++i) {
      const double sign = (s.b0[i] * s0 + s.b1[i] * s1 + s.b2[i] * s2) < 0 ? -1.0 : 1.0;
      const double tx = T.x[i], ty = T.y[i], tz = T.z[i];
      N.x[i] = P.x;
      N.y[i] = P.y;
      N.z[i] = P.z;
      B.x[i] = sign * (P.y * tz - P.z * ty);
      B.y[i] = sign * (P.z * tx - P.x * tz);
      B.z[i] = sign * (P.x * ty - P.y * tx);
    }
  }
  if (t.flat) {  // unitNormal: the triangle's own normal
    for (std::size_t i = 0; i < static_cast<std::size_t>(s.count); ++i) {
      unitN.x[i] = t.faceNormal.x;
      unitN.y[i] = t.faceNormal.y;
      unitN.z[i] = t.faceNormal.z;
      slow[i] = false;
    }
  }
}

/// shade() of the lanes flagged slow, over what the lane loops wrote for them.
template <class Shader>
void shadeSlowLanes(Shader& shader, const SampleBatch& s, const LaneFlags& slow, double* out) {
  for (std::size_t i = 0; i < static_cast<std::size_t>(s.count); ++i)
    if (slow[i]) shader.shade({s.b0[i], s.b1[i], s.b2[i]}, s.x[i], s.y[i], out + Shader::kChannels * i);
}

/// The texture samples of UV height layer @p src (non-null texture, UV set on @p tri) at every
/// sample of @p s: the SurfacePoint's interpolated UV (moved by @p shift when given), tiled and
/// offset, through the texture's sampleMany (an image's: one dispatch on the filter per batch).
inline void batchUvHeightSamples(const ShadingTriangle& tri, const SampleBatch& s,
                                 const UvHeightSource& src,
                                 std::array<ScalarSample, SampleBatch::kMax>& h,
                                 const Vec2d* shift = nullptr) {
  const std::size_t n = static_cast<std::size_t>(s.count);
  const std::array<Vec2d, 3>& uvs = tri.uv[static_cast<std::size_t>(src.uvSet)];
  const Vec2d uv0 = uvs[0], uv1 = uvs[1], uv2 = uvs[2];
  std::array<Vec2d, SampleBatch::kMax> st;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2d uv{s.b0[i] * uv0.x + s.b1[i] * uv1.x + s.b2[i] * uv2.x,
                   s.b0[i] * uv0.y + s.b1[i] * uv1.y + s.b2[i] * uv2.y};
    st[i] = textureCoordinates(shift != nullptr ? uv + *shift : uv, src.tiling, src.offset);
  }
  src.texture->sampleMany({st.data(), n}, {h.data(), n});
}

/// Whether the batch paths take @p layer whole (batchUvHeightGradient): an unmasked UV height
/// layer of Strength 1 on the surface. Any other takes the per-sample path.
inline bool batchesWhole(const Layer& layer) {
  const UvHeightSource* uvHeight = std::get_if<UvHeightSource>(&layer.source);
  return uvHeight != nullptr && layer.mask.texture == nullptr && uvHeight->strength == 1 &&
         layer.base == LayerBase::kSurface;
}

/// batchUvHeightGradient's Γ of a layer read as the Bump node does (usesBumpNode: @p point's
/// offsets, constant over the triangle, are not empty; seen from the front, as the lanes the
/// batch keeps are): gradient_detail::bumpNodeGradient lane by lane, bit for bit, its three
/// lookups a batch each.
inline void batchBumpNodeGradient(const ShadingTriangle& tri, const SurfacePoint& point,
                                  const SampleBatch& s, const UvHeightSource& src,
                                  const Lanes3& unitN, Lanes3& layer) {
  const std::size_t n = static_cast<std::size_t>(s.count);
  const UvFrame& frame = point.uv[static_cast<std::size_t>(src.uvSet)];
  const Vec2d shiftX = gradient_detail::uvOffsetOf(frame, point.bump.dx);
  const Vec2d shiftY = gradient_detail::uvOffsetOf(frame, point.bump.dy);
  std::array<ScalarSample, SampleBatch::kMax> hc, hx, hy;
  batchUvHeightSamples(tri, s, src, hc);
  batchUvHeightSamples(tri, s, src, hx, &shiftX);
  batchUvHeightSamples(tri, s, src, hy, &shiftY);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3d gamma =
        gradient_detail::bumpNodeGradientFrom(hc[i].value, hx[i].value, hy[i].value, src.scale,
                                              {unitN.x[i], unitN.y[i], unitN.z[i]}, point.bump);
    layer.x[i] = gamma.x;
    layer.y[i] = gamma.y;
    layer.z[i] = gamma.z;
  }
}

/// The Γ of an unmasked UV height layer for every sample of @p s on triangle @p tri (whose
/// SurfacePoint fields constant over it are @p point's and whose prepared UV frames are
/// @p prepared), with the unit normals @p unitN, added as gamma += factor·Γ: what
/// BakeShaderBase::uvHeightGradient computes on the shader's triangle, and the world-space
/// evaluator (shadeLayersInWorld) on its world triangle.
inline void batchUvHeightGradient(const ShadingTriangle& tri, const SurfacePoint& point,
                                  const gradient_detail::PreparedUvFrame* prepared,
                                  const SampleBatch& s, const UvHeightSource& src, double factor,
                                  const Lanes3& unitN, Lanes3& gamma) {
  const std::size_t n = static_cast<std::size_t>(s.count);
  Lanes3 layer{};
  const std::size_t set = static_cast<std::size_t>(src.uvSet);
  const bool readable = src.texture != nullptr && hasUvSet(point, src.uvSet);
  if (readable && gradient_detail::usesBumpNode(src.gradient, point)) {
    batchBumpNodeGradient(tri, point, s, src, unitN, layer);
  } else if (readable && prepared[set].valid) {
    const gradient_detail::PreparedUvFrame& frame = prepared[set];
    std::array<ScalarSample, SampleBatch::kMax> h;
    batchUvHeightSamples(tri, s, src, h);
    // gradientFromPreparedUvFrame with dhduv = uvDerivativesFromTexture(h, tiling, scale).
    const double ku = src.scale * src.tiling.x, kv = src.scale * src.tiling.y;
    const double tolerance = gradient_detail::guardedTolerance(src.minFrameSine);
    const Vec3d ft = frame.t, fb = frame.b, tb = frame.tCrossB;
    for (std::size_t i = 0; i < n; ++i) {
      const double nx = unitN.x[i], ny = unitN.y[i], nz = unitN.z[i];
      const double det = tb.x * nx + tb.y * ny + tb.z * nz;
      const double du = ku * h[i].gradient.x / frame.lengthT;
      const double dv = kv * h[i].gradient.y / frame.lengthB;
      const double inv = 1 / det;
      const double gx = inv * (du * (fb.y * nz - fb.z * ny) + dv * (ny * ft.z - nz * ft.y));
      const double gy = inv * (du * (fb.z * nx - fb.x * nz) + dv * (nz * ft.x - nx * ft.z));
      const double gz = inv * (du * (fb.x * ny - fb.y * nx) + dv * (nx * ft.y - ny * ft.x));
      const bool keep = (std::abs(det) >= tolerance) & finiteLane(gx) & finiteLane(gy) &
                        finiteLane(gz);
      layer.x[i] = keep ? gx : 0.0;
      layer.y[i] = keep ? gy : 0.0;
      layer.z[i] = keep ? gz : 0.0;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    gamma.x[i] = gamma.x[i] + factor * layer.x[i];
    gamma.y[i] = gamma.y[i] + factor * layer.y[i];
    gamma.z[i] = gamma.z[i] + factor * layer.z[i];
  }
}

/// shader.addLayerGradient of a normal map (or a layer on the layers above) at @p p, flagging
/// @p slow where it decodes (or bumps their normal) below the surface. Out of line: inlined,
/// it kept the compiler from inlining surfacePointAt into batchGradients (1 % of a one-thread
/// bake with a triplanar layer).
[[gnu::noinline]] inline void addNormalMapGradient(const BakeShaderBase& shader, const Layer& layer,
                                                   const SurfacePoint& p, Vec3d& gamma,
                                                   std::int64_t& slow) {
  gradient_detail::NormalBelowSurface below;
  shader.addLayerGradient(layer, p, gamma, &below);
  slow = slow | below.found;
}

/// gamma = shader.gradient() of every sample's SurfacePoint (zero when not finite), bit for bit:
/// unmasked UV image heights lane-parallel (batchUvHeightGradient), any other layer sample by
/// sample through addLayerGradient, in layer order. With @p slow non-null, the lanes where a
/// normal map decodes below the surface are flagged there too (gradient(p, handed) may then
/// differ: the per-sample path shades them).
inline void batchGradients(BakeShaderBase& shader, const SampleBatch& s, const Lanes3& unitN,
                           Lanes3& gamma, LaneFlags* slow = nullptr) {
  const std::size_t n = static_cast<std::size_t>(s.count);
  for (std::size_t i = 0; i < n; ++i) gamma.x[i] = gamma.y[i] = gamma.z[i] = 0.0;
  for (const Layer& layer : shader.layers) {
    if (layer.weight == 0 || !std::isfinite(layer.weight)) continue;
    if (batchesWhole(layer)) {
      batchUvHeightGradient(shader.tri, shader.point, shader.preparedUv.data(), s,
                            std::get<UvHeightSource>(layer.source), layer.weight, unitN, gamma);
      continue;
    }
    // (Only a normal map on the surface or a layer on the layers above can start a normal
    // below it.)
    const bool noteBelow = slow != nullptr && gradient_detail::mayStartBelowSurface(layer);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3d b{s.b0[i], s.b1[i], s.b2[i]};
      Vec3d g{gamma.x[i], gamma.y[i], gamma.z[i]};
      const SurfacePoint& p = shader.pointAt(b, texelFrame(shader.tri, b));
      if (noteBelow) [[unlikely]] {
        addNormalMapGradient(shader, layer, p, g, (*slow)[i]);
      } else {
        shader.addLayerGradient(layer, p, g);
      }
      gamma.x[i] = g.x;
      gamma.y[i] = g.y;
      gamma.z[i] = g.z;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const bool finite = finiteLane(gamma.x[i]) & finiteLane(gamma.y[i]) & finiteLane(gamma.z[i]);
    gamma.x[i] = finite ? gamma.x[i] : 0.0;
    gamma.y[i] = finite ? gamma.y[i] : 0.0;
    gamma.z[i] = finite ? gamma.z[i] : 0.0;
  }
}

/// v = N̂ − Γ of every sample (batchGradients), not normalized; slow[i] also when |v|² is not a
/// normal positive number (zero, subnormal, overflowing), whose normalization takes a fallback,
/// when v fails reflectsAboveSurface (validReflectionNormal turns it: the scalar path), when
/// N̂ faces away from the triangle (backFacing: the scalar path shades it as Cycles does) and
/// when a normal map decodes below the surface (NormalBelowSurface: perturbed() takes it).
inline void batchPerturbedDirections(BakeShaderBase& shader, const SampleBatch& s, const Lanes3& unitN,
                                     Lanes3& v, LaneFlags& slow) {
  Lanes3 gamma;
  batchGradients(shader, s, unitN, gamma, &slow);
  const Vec3d ng = shader.tri.faceNormal;
  for (std::size_t i = 0; i < static_cast<std::size_t>(s.count); ++i) {
    const double vx = unitN.x[i] - gamma.x[i];
    const double vy = unitN.y[i] - gamma.y[i];
    const double vz = unitN.z[i] - gamma.z[i];
    const double len2 = vx * vx + vy * vy + vz * vz;
    v.x[i] = vx;
    v.y[i] = vy;
    v.z[i] = vz;
    // reflectsAboveSurface(v, Ng, N̂, |v|²), lane by lane.
    const double iz = unitN.x[i] * ng.x + unitN.y[i] * ng.y + unitN.z[i] * ng.z;
    const double vi = vx * unitN.x[i] + vy * unitN.y[i] + vz * unitN.z[i];
    const double vn = vx * ng.x + vy * ng.y + vz * ng.z;
    const double threshold = std::min(0.9 * iz, 0.01);
    const bool above = 2 * vi * vn - iz * len2 >= threshold * len2;
    slow[i] = slow[i] | (iz < 0) |
              !((len2 >= std::numeric_limits<double>::min()) & finiteLane(len2) & above);
  }
}

/// m·v of every lane of @p v, as Mat3's operator* computes it.
inline void batchTransform(const Mat3& m, std::size_t n, const Lanes3& v, Lanes3& out) {
  const Vec3d c0 = m.col[0], c1 = m.col[1], c2 = m.col[2];
  for (std::size_t i = 0; i < n; ++i) {
    const double x = v.x[i], y = v.y[i], z = v.z[i];
    out.x[i] = x * c0.x + y * c1.x + z * c2.x;
    out.y[i] = x * c0.y + y * c1.y + z * c2.y;
    out.z[i] = x * c0.z + y * c1.z + z * c2.z;
  }
}

/// shadeInWorld() of every sample of @p s (the shader's `world` non-null), lane-parallel: the
/// guarded world normal @p normal and the unguarded @p unguarded, both unit. Lanes it cannot
/// finish the common way are flagged in @p slow for the per-sample path: those of
/// batchTexelFrames' fallbacks on the world triangle, an N̂ − Γ that does not normalize the
/// common way, a back-facing N̂, a normal the guard turns and a normal map decoded below the
/// surface (NormalBelowSurface). Layers the batch does not take
/// whole (batchesWhole, and heights in object units) are added sample by sample
/// (addWorldLayerGradient), in layer order.
/// Out of line: the object-space paths stay as the compiler laid them out.
[[gnu::noinline]] inline void batchShadeInWorld(BakeShaderBase& shader, const SampleBatch& s,
                                                Lanes3& normal, Lanes3& unguarded,
                                                LaneFlags& slow) {
  const std::size_t n = static_cast<std::size_t>(s.count);
  BakeShaderBase::WorldScratch& w = shader.worldScratch.get();
  BatchFrames fw;
  batchTexelFrames(w.tri, s, fw);
  const Lanes3& unitN = fw.unitN;
  for (std::size_t i = 0; i < n; ++i) slow[i] = slow[i] | fw.slow[i];
  if (shader.layers.empty()) {  // the world shading normal, unbumped and unguarded
    normal = unitN;
    unguarded = unitN;
    return;
  }
  Lanes3 gamma;
  for (std::size_t i = 0; i < n; ++i) gamma.x[i] = gamma.y[i] = gamma.z[i] = 0.0;
  for (const Layer& layer : shader.layers) {
    if (layer.weight == 0 || !std::isfinite(layer.weight)) continue;
    // (A height in object units scales with the world normal: sample by sample too.)
    if (!batchesWhole(layer) || layer.objectSpaceHeight) {  // shadeLayersInWorld's step
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3d b{s.b0[i], s.b1[i], s.b2[i]};
        const SurfacePoint& objectPoint = shader.pointAt(b, texelFrame(shader.tri, b));
        const SurfacePoint& worldPoint = surfacePointAt(w.tri, b, texelFrame(w.tri, b), w.point);
        Vec3d g{gamma.x[i], gamma.y[i], gamma.z[i]};
        gradient_detail::NormalBelowSurface below;
        gradient_detail::addWorldLayerGradient(layer, objectPoint, worldPoint, *shader.world,
                                               w.preparedUv.data(), worldPoint.normal, g, &below);
        slow[i] = slow[i] | below.found;  // shadeLayersInWorld shades it from the decoded normal
        gamma.x[i] = g.x;
        gamma.y[i] = g.y;
        gamma.z[i] = g.z;
      }
      continue;
    }
    batchUvHeightGradient(w.tri, w.point, w.preparedUv.data(), s,
                          std::get<UvHeightSource>(layer.source), layer.weight, unitN, gamma);
  }
  const Vec3d ng = w.tri.faceNormal;
  for (std::size_t i = 0; i < n; ++i) {
    const double nx = unitN.x[i], ny = unitN.y[i], nz = unitN.z[i];
    const bool finite = finiteLane(gamma.x[i]) & finiteLane(gamma.y[i]) & finiteLane(gamma.z[i]);
    // unguarded = normalizeOr(N̂ − Γ, N̂) in its common case.
    const double vx = nx - (finite ? gamma.x[i] : 0.0);
    const double vy = ny - (finite ? gamma.y[i] : 0.0);
    const double vz = nz - (finite ? gamma.z[i] : 0.0);
    const double len2 = vx * vx + vy * vy + vz * vz;
    const double inv = 1 / std::sqrt(len2);
    const double ux = inv * vx, uy = inv * vy, uz = inv * vz;
    // backFacing(N̂, Ng), then reflectsAboveSurface(unguarded, Ng, N̂) of validReflectionNormal.
    const double iz = nx * ng.x + ny * ng.y + nz * ng.z;
    const double ui = ux * nx + uy * ny + uz * nz;
    const double un = ux * ng.x + uy * ng.y + uz * ng.z;
    const bool above = 2 * ui * un - iz * 1.0 >= std::min(0.9 * iz, 0.01) * 1.0;
    slow[i] = slow[i] | (iz < 0) | !((len2 > 0) & finiteLane(len2) & above);
    unguarded.x[i] = normal.x[i] = ux;
    unguarded.y[i] = normal.y[i] = uy;
    unguarded.z[i] = normal.z[i] = uz;
  }
}

/// worldGradient() of every sample of @p s (the shader's `world` non-null; @p f the frames of
/// its triangle): the object-space Γ of the unguarded world normal (objectSpaceGradient), from
/// the lane-parallel world shading.
[[gnu::noinline]] inline void batchWorldGradients(BakeShaderBase& shader, const SampleBatch& s,
                                                  BatchFrames& f, Lanes3& gamma) {
  const std::size_t n = static_cast<std::size_t>(s.count);
  Lanes3 normal, unguarded, back;
  batchShadeInWorld(shader, s, normal, unguarded, f.slow);
  batchTransform(shader.world->normalToObject, n, unguarded, back);
  // gradientFromObjectNormal(back, N̂) lane by lane (its unitAndLength scaled by the largest
  // component first), zero where it is not finite.
  const double floor = std::min(gradient_detail::guardedTolerance(kMinObjectNormalCosine), 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double ax = back.x[i], ay = back.y[i], az = back.z[i];
    const double m = std::max(std::max(std::abs(ax), std::abs(ay)), std::abs(az));
    const bool usable = (m > 0) & finiteLane(m);
    const double sx = (1 / m) * ax, sy = (1 / m) * ay, sz = (1 / m) * az;
    const double l = std::sqrt(sx * sx + sy * sy + sz * sz);
    const double vx = (1 / l) * sx, vy = (1 / l) * sy, vz = (1 / l) * sz;
    const double nx = f.unitN.x[i], ny = f.unitN.y[i], nz = f.unitN.z[i];
    const double k = vx * nx + vy * ny + vz * nz;
    const double inv = 1 / std::max(std::abs(k), floor);
    const double gx = inv * (k * nx - vx), gy = inv * (k * ny - vy), gz = inv * (k * nz - vz);
    const bool keep = usable & finiteLane(gx) & finiteLane(gy) & finiteLane(gz);
    gamma.x[i] = keep ? gx : 0.0;
    gamma.y[i] = keep ? gy : 0.0;
    gamma.z[i] = keep ? gz : 0.0;
  }
}

struct TangentNormalShader : BakeShaderBase {
  static constexpr int kChannels = 3;
  /// A positive multiple of perturbed(b, f): objectToTangent normalizes its result, and
  /// normalize(M⁻¹·normalize(v)) = normalize(M⁻¹·v) up to round-off, so N − Γ is passed on as it
  /// is (one square root and division less per texel) when its squared length is a normal
  /// positive number; otherwise (zero, underflow, overflow) perturbed()'s normalization with its
  /// fallback is kept.
  Vec3d unnormalizedPerturbed(const Vec3d& b, const TexelFrame& f) {
    const SurfacePoint& p = pointAt(b, f);
    if (gradient_detail::backFacing(p.normal, tri.faceNormal)) return backFacingNormal(p);
    std::optional<Vec3d> handed;
    const Vec3d v = p.normal - gradient(p, handed);
    if (handed) return validReflectionNormal(*handed, tri.faceNormal, p.normal);
    const double len2 = lengthSquared(v);
    if (len2 >= std::numeric_limits<double>::min() && std::isfinite(len2) &&
        reflectsAboveSurface(v, tri.faceNormal, p.normal, len2)) {
      return v;
    }
    return validReflectionNormal(normalizeOr(v, p.normal), tri.faceNormal, p.normal);
  }
  void shade(const Vec3d& b, int, int, double* out) {
    const TexelFrame f = texelFrame(tri, b);
    // In world space, Blender's baker brings the normal back to object space as a normal (M^T).
    const Vec3d normal = world != nullptr ? world->normalToObject * shadeInWorld(b, f).normal
                         : layers.empty() ? unitNormal(tri, f)
                                          : unnormalizedPerturbed(b, f);
    const Vec3d n = objectToTangent(outputFrame(b, f), normal);
    putEncoded(n.x, n.y, n.z, out);
  }

  /// shade() of every sample of @p s, lane-parallel (see batchTexelFrames).
  void shadeBatch(const SampleBatch& s, double* out) {
    BatchFrames f;
    batchTexelFrames(tri, s, f);
    if (shadedElsewhere) [[unlikely]]
      f.slow.fill(1);  // shade() takes the own frame
    if (world != nullptr) [[unlikely]]
      return shadeBatchInWorld(s, f, out);

    // The normal to express in tangent space: N̂, or N̂ − Γ (unnormalizedPerturbed).
    Lanes3 perturbedDirections;
    const Lanes3& v = layers.empty() ? f.unitN : perturbedDirections;
    if (!layers.empty()) batchPerturbedDirections(*this, s, f.unitN, perturbedDirections, f.slow);
    encodeBatch(s, f, v, out);
  }

  /// shade() in world space of every sample of @p s, frames @p f: the guarded world normal
  /// brought back as a normal (M^T), encoded in the object's frame.
  [[gnu::noinline]] void shadeBatchInWorld(const SampleBatch& s, BatchFrames& f, double* out) {
    Lanes3 normal, unguarded, v;
    batchShadeInWorld(*this, s, normal, unguarded, f.slow);
    batchTransform(world->normalToObject, static_cast<std::size_t>(s.count), normal, v);
    encodeBatch(s, f, v, out);
  }

  /// objectToTangent(f, v) of every sample, encoded (putEncoded) into @p out; then shade() of
  /// the slow lanes.
  [[gnu::always_inline]] void encodeBatch(const SampleBatch& s, BatchFrames& f, const Lanes3& v,
                                          double* out) {
    const std::size_t n = static_cast<std::size_t>(s.count);
    constexpr double kMinDet = kMinTexelFrameSine * kMinTexelFrameSine;
    Lanes3 o;  // the unit tangent-space normals
    for (std::size_t i = 0; i < n; ++i) {
      const double tx = f.T.x[i], ty = f.T.y[i], tz = f.T.z[i];
      const double nx = f.N.x[i], ny = f.N.y[i], nz = f.N.z[i];
      const double bx = f.B.x[i], by = f.B.y[i], bz = f.B.z[i];
      const double r0x = by * nz - bz * ny, r0y = bz * nx - bx * nz, r0z = bx * ny - by * nx;
      const double r1x = ny * tz - nz * ty, r1y = nz * tx - nx * tz, r1z = nx * ty - ny * tx;
      const double r2x = ty * bz - tz * by, r2y = tz * bx - tx * bz, r2z = tx * by - ty * bx;
      const double det = tx * r0x + ty * r0y + tz * r0z;
      const double lenT2 = tx * tx + ty * ty + tz * tz;
      const double lenN2 = nx * nx + ny * ny + nz * nz;
      const bool flat = !(std::abs(det) > kMinDet * lenT2 * lenN2);
      const double sd = det < 0 ? -1.0 : 1.0;
      const double vx = v.x[i], vy = v.y[i], vz = v.z[i];
      const double wx = sd * (r0x * vx + r0y * vy + r0z * vz);
      const double wy = sd * (r1x * vx + r1y * vy + r1z * vz);
      const double wz = sd * (r2x * vx + r2y * vy + r2z * vz);
      const double len2 = wx * wx + wy * wy + wz * wz;
      const double inv = 1 / std::sqrt(len2);
      f.slow[i] = f.slow[i] | (!flat & !((len2 > 0) & finiteLane(len2)));
      o.x[i] = flat ? 0.0 : inv * wx;
      o.y[i] = flat ? 0.0 : inv * wy;
      o.z[i] = flat ? 1.0 : inv * wz;
    }
    putEncodedLanes(channels, o, n, out);
    shadeSlowLanes(*this, s, f.slow, out);
  }
};

struct ObjectNormalShader : BakeShaderBase {
  static constexpr int kChannels = 3;
  void shade(const Vec3d& b, int, int, double* out) {
    const TexelFrame f = texelFrame(tri, b);
    if (world != nullptr) {  // Blender's baker brings it back as a direction (M^{-1}), measured
      const Vec3d n = shadeInWorld(b, f).normal;
      const Vec3d o = normalizeOr(world->directionToObject * n, unitNormal(tri, f));
      return putEncoded(o.x, o.y, o.z, out);
    }
    const Vec3d o = layers.empty() ? unitNormal(tri, f) : perturbed(b, f);
    putEncoded(o.x, o.y, o.z, out);
  }

  /// shade() of every sample of @p s, lane-parallel (see batchTexelFrames): N̂, or N̂ − Γ
  /// normalized as perturbed() normalizes it, encoded.
  void shadeBatch(const SampleBatch& s, double* out) {
    const std::size_t n = static_cast<std::size_t>(s.count);
    BatchFrames f;
    batchTexelFrames(tri, s, f);
    if (world != nullptr) [[unlikely]]
      return shadeBatchInWorld(s, f, out);
    Lanes3 perturbedNormals;
    const Lanes3& v = layers.empty() ? f.unitN : perturbedNormals;
    if (!layers.empty()) {
      Lanes3& w = perturbedNormals;
      batchPerturbedDirections(*this, s, f.unitN, w, f.slow);
      const Vec3d ng = tri.faceNormal;
      for (std::size_t i = 0; i < n; ++i) {  // unitOr's common case (slow covers the rest)
        const double len2 = w.x[i] * w.x[i] + w.y[i] * w.y[i] + w.z[i] * w.z[i];
        const double inv = 1 / std::sqrt(len2);
        w.x[i] = inv * w.x[i];
        w.y[i] = inv * w.y[i];
        w.z[i] = inv * w.z[i];
        // perturbed() tests the unit normal (reflectsAboveSurface): one that lies on the guard's
        // boundary (a layer on the layers above hands on a guarded normal) can pass the test
        // before normalizing and fail it after.
        const double iz = f.unitN.x[i] * ng.x + f.unitN.y[i] * ng.y + f.unitN.z[i] * ng.z;
        const double wi = w.x[i] * f.unitN.x[i] + w.y[i] * f.unitN.y[i] + w.z[i] * f.unitN.z[i];
        const double wn = w.x[i] * ng.x + w.y[i] * ng.y + w.z[i] * ng.z;
        f.slow[i] = f.slow[i] | !(2 * wi * wn - iz * 1.0 >= std::min(0.9 * iz, 0.01) * 1.0);
      }
    }
    putEncodedLanes(channels, v, n, out);
    shadeSlowLanes(*this, s, f.slow, out);
  }

  /// shade() in world space of every sample of @p s, frames @p f: the guarded world normal
  /// brought back as a direction (M^{-1}), normalized the common way of normalizeOr.
  [[gnu::noinline]] void shadeBatchInWorld(const SampleBatch& s, BatchFrames& f, double* out) {
    const std::size_t n = static_cast<std::size_t>(s.count);
    Lanes3 normal, unguarded, d;
    batchShadeInWorld(*this, s, normal, unguarded, f.slow);
    batchTransform(world->directionToObject, n, normal, d);
    for (std::size_t i = 0; i < n; ++i) {
      const double len2 = d.x[i] * d.x[i] + d.y[i] * d.y[i] + d.z[i] * d.z[i];
      const double inv = 1 / std::sqrt(len2);
      f.slow[i] = f.slow[i] | !((len2 > 0) & finiteLane(len2));
      d.x[i] = inv * d.x[i];
      d.y[i] = inv * d.y[i];
      d.z[i] = inv * d.z[i];
    }
    putEncodedLanes(channels, d, n, out);
    shadeSlowLanes(*this, s, f.slow, out);
  }
};

struct HeightShader : BakeShaderBase {
  static constexpr int kChannels = 1;
  void shade(const Vec3d& b, int, int, double* out) {
    const TexelFrame f = texelFrame(tri, b);
    out[0] = compositeHeight(layers, pointAt(b, f));
  }

  /// shade() of every sample of @p s: compositeHeight's sum in its order, with unmasked UV
  /// heights sampled for the whole batch (batchUvHeightSamples) and any other layer sample by
  /// sample.
  void shadeBatch(const SampleBatch& s, double* out) {
    const std::size_t n = static_cast<std::size_t>(s.count);
    for (std::size_t i = 0; i < n; ++i) out[i] = 0.0;
    for (const Layer& layer : layers) {
      if (layer.weight == 0 || !std::isfinite(layer.weight)) continue;
      const UvHeightSource* uvHeight = std::get_if<UvHeightSource>(&layer.source);
      if (uvHeight != nullptr && layer.mask.texture == nullptr) {
        // factor = weight · layerMask (1 without a mask); layerHeight = scale · value, or 0
        // when that is not finite (or there is no texture or UV set).
        if (uvHeight->texture == nullptr || !hasUvSet(point, uvHeight->uvSet)) {
          for (std::size_t i = 0; i < n; ++i) out[i] = out[i] + layer.weight * 0.0;  // sign of 0
          continue;
        }
        std::array<ScalarSample, SampleBatch::kMax> h;
        batchUvHeightSamples(tri, s, *uvHeight, h);
        for (std::size_t i = 0; i < n; ++i) {
          const double value = uvHeight->scale * h[i].value;
          out[i] = out[i] + layer.weight * (finiteLane(value) ? value : 0.0);
        }
        continue;
      }
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3d b{s.b0[i], s.b1[i], s.b2[i]};
        const SurfacePoint& p = pointAt(b, texelFrame(tri, b));
        const double factor = layer.weight * layerMask(layer.mask, p);
        if (factor == 0) continue;
        out[i] = out[i] + factor * layerHeight(layer.source, p);
      }
    }
    for (std::size_t i = 0; i < n; ++i) out[i] = finiteLane(out[i]) ? out[i] : 0.0;
  }
};

struct DerivativeShader : BakeShaderBase {
  static constexpr int kChannels = 2;
  void shade(const Vec3d& b, int, int, double* out) {
    const TexelFrame f = texelFrame(tri, b);
    const Vec3d gamma = world != nullptr ? worldGradient(b, f) : gradient(pointAt(b, f));
    out[0] = dot(gamma, tri.bakeDPdu);
    out[1] = dot(gamma, tri.bakeDPdv);
  }

  /// shade() of every sample of @p s, lane-parallel (batchGradients).
  void shadeBatch(const SampleBatch& s, double* out) {
    const std::size_t n = static_cast<std::size_t>(s.count);
    BatchFrames f;
    batchTexelFrames(tri, s, f);
    Lanes3 gamma;
    if (world != nullptr) [[unlikely]]
      batchWorldGradients(*this, s, f, gamma);
    else
      batchGradients(*this, s, f.unitN, gamma);
    const Vec3d du = tri.bakeDPdu, dv = tri.bakeDPdv;
    for (std::size_t i = 0; i < n; ++i) {
      out[2 * i] = gamma.x[i] * du.x + gamma.y[i] * du.y + gamma.z[i] * du.z;
      out[2 * i + 1] = gamma.x[i] * dv.x + gamma.y[i] * dv.y + gamma.z[i] * dv.z;
    }
    shadeSlowLanes(*this, s, f.slow, out);
  }
};

struct SurfaceGradientShader : BakeShaderBase {
  static constexpr int kChannels = 3;
  void shade(const Vec3d& b, int, int, double* out) {
    const TexelFrame f = texelFrame(tri, b);
    put(world != nullptr ? worldGradient(b, f) : gradient(pointAt(b, f)), out);
  }

  /// shade() of every sample of @p s, lane-parallel (batchGradients).
  void shadeBatch(const SampleBatch& s, double* out) {
    const std::size_t n = static_cast<std::size_t>(s.count);
    BatchFrames f;
    batchTexelFrames(tri, s, f);
    Lanes3 gamma;
    if (world != nullptr) [[unlikely]]
      batchWorldGradients(*this, s, f, gamma);
    else
      batchGradients(*this, s, f.unitN, gamma);
    for (std::size_t i = 0; i < n; ++i) {
      out[3 * i] = gamma.x[i];
      out[3 * i + 1] = gamma.y[i];
      out[3 * i + 2] = gamma.z[i];
    }
    shadeSlowLanes(*this, s, f.slow, out);
  }
};

struct TangentShader : BakeShaderBase {
  static constexpr int kChannels = 3;
  void shade(const Vec3d& b, int, int, double* out) {
    put(encodeNormal(normalizeOr(texelFrame(tri, b).tangent, Vec3d{})), out);
  }
};

struct BitangentShader : BakeShaderBase {
  static constexpr int kChannels = 3;
  void shade(const Vec3d& b, int, int, double* out) {
    put(encodeNormal(normalizeOr(texelFrame(tri, b).bitangent, Vec3d{})), out);
  }
};

struct MaskShader {
  static constexpr int kChannels = 1;
  void beginTriangle(std::uint32_t, const std::array<std::uint32_t, 3>&) {}
  void shade(const Vec3d&, int, int, double* out) const { out[0] = 1; }
};


}  // namespace sgbake::bake_detail
