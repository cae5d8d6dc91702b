#include "sgbake/gradient/layers.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>
#include <variant>

#include "gradient/bump_node.hpp"
#include "gradient/prepared_uv_frame.hpp"
#include "gradient/stacking.hpp"
#include "gradient/valid_reflection.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/world_shading.hpp"

namespace sgbake {
namespace {

bool hasUvSet(const SurfacePoint& point, int uvSet) {
  return uvSet >= 0 && uvSet < point.numUvSets && uvSet < kMaxUvSets;
}

const UvFrame& uvFrame(const SurfacePoint& point, int uvSet) {
  return point.uv[static_cast<std::size_t>(uvSet)];
}

/// Γ of a UV height map before its Strength.
Vec3d unblendedGradient(const UvHeightSource& s, const SurfacePoint& point) {
  if (s.texture == nullptr || !hasUvSet(point, s.uvSet)) return {};
  const UvFrame& frame = uvFrame(point, s.uvSet);
  const ScalarSample h = s.texture->sample(textureCoordinates(frame.uv, s.tiling, s.offset));
  if (gradient_detail::usesBumpNode(s.gradient, point))
    return gradient_detail::bumpNodeGradient(s, frame, point.normal, point.bump, h.value);
  return gradientFromUvDerivatives(frame, point.normal,
                                   uvDerivativesFromTexture(h, s.tiling, s.scale), s.minFrameSine);
}

/// The evaluate(source, point) functions give the Γ of a source before its Bump Strength
/// (gradient_detail::unblendedLayerGradient).
Vec3d evaluate(const UvHeightSource& s, const SurfacePoint& point) {
  return unblendedGradient(s, point);
}

/// A normal map's texels: through its UV set, or by its projection, whose planes are picked by
/// @p planesNormal when given (else point.seenNormal()).
template <class Source>
Vec3d normalTexel(const Source& s, const SurfacePoint& point, Vec2d tiling, Vec2d offset,
                  const Vec3d* planesNormal) {
  if (!s.projection)
    return s.texture->sample(textureCoordinates(uvFrame(point, s.uvSet).uv, tiling, offset));
  return projectedTexel(*s.texture, *s.projection, point.position,
                        planesNormal != nullptr ? *planesNormal : point.seenNormal());
}

Vec3d evaluate(const TangentNormalSource& s, const SurfacePoint& point,
               gradient_detail::NormalBelowSurface* below = nullptr,
               const Vec3d* planesNormal = nullptr) {
  if (s.texture == nullptr || !hasUvSet(point, s.projection ? s.frameUvSet() : s.uvSet)) return {};
  const Vec3d n = decodeNormalTexel(
      normalTexel(s, point, s.options.tiling, s.options.offset, planesNormal), s.options.green);
  if (below != nullptr && isFinite(n) &&
      !(n.z >= std::min(gradient_detail::guardedTolerance(s.options.minNormalZ), 1.0) *
                   std::sqrt(lengthSquared(n)))) {
    // slopesFromTangentNormal clamps z here: the decoded normal itself (none at n = 0).
    const Vec3d decoded = decodeTangentNormal(n, point, s.frameUvSet(), s.options);
    if (lengthSquared(decoded) > 0)
      *below = {true, normalizeOr(decoded, point.normal), s.options.strength};
  }
  return gradientFromTangentNormal(n, point, s.frameUvSet(), s.options);
}

Vec3d evaluate(const ObjectNormalSource& s, const SurfacePoint& point,
               gradient_detail::NormalBelowSurface* below = nullptr,
               const Vec3d* planesNormal = nullptr) {
  if (s.texture == nullptr || (!s.projection && !hasUvSet(point, s.uvSet))) return {};
  const Vec3d n = decodeNormalTexel(normalTexel(s, point, s.tiling, s.offset, planesNormal));
  if (below != nullptr) {
    const Vec3d unit = normalizeOr(n, Vec3d{});
    if (gradient_detail::belowSurface(unit, point.normal, s.minCosine))
      *below = {true, unit, s.strength};
  }
  const Vec3d gamma = gradientFromObjectNormal(n, point.normal, s.minCosine);
  return withNormalMapStrength(isFinite(gamma) ? gamma : Vec3d{}, point.normal, s.strength);
}

/// The Γ of a height read at positions as the Bump node makes it (object space).
template <class Source>
Vec3d bumpNodeInObjectSpace(const Source& s, const SurfacePoint& point) {
  return gradient_detail::positionBumpNodeGradient(s, point.position, point.seenNormal(),
                                                   point.normal, point.bump,
                                                   [](const Vec3d& w) { return w; });
}

Vec3d evaluate(const VolumeSource& s, const SurfacePoint& point) {
  if (s.volume == nullptr) return {};
  if (gradient_detail::usesBumpNode(s.gradient, point)) return bumpNodeInObjectSpace(s, point);
  const Vec3d gradient = volumeGradient(*s.volume, point.position, s.scheme, s.step);
  const Vec3d gamma =
      s.scale * projectOntoTangentPlaneAlong(gradient, point.normal, point.geometricNormal);
  return isFinite(gamma) ? gamma : Vec3d{};
}

Vec3d evaluate(const PlanarSource& s, const SurfacePoint& point) {
  switch (s.kind) {
    case ProjectedKind::kHeight:
      if (s.height == nullptr) return {};
      if (gradient_detail::usesBumpNode(s.gradient, point)) return bumpNodeInObjectSpace(s, point);
      return planarHeightGradient(*s.height, s.mapping, s.scale, point, s.coordinates);
    case ProjectedKind::kTangentNormal:
      return s.normals ? planarTangentNormalGradient(*s.normals, s.mapping, s.scale, point,
                                                     s.normal, s.coordinates)
                       : Vec3d{};
    case ProjectedKind::kObjectNormal:
      return s.normals ? planarObjectNormalGradient(*s.normals, s.mapping, s.scale, point, s.normal,
                                                    s.coordinates)
                       : Vec3d{};
  }
  return {};
}

Vec3d evaluate(const TriplanarSource& s, const SurfacePoint& point) {
  switch (s.kind) {
    case ProjectedKind::kHeight:
      if (s.height == nullptr) return {};
      if (gradient_detail::usesBumpNode(s.gradient, point)) return bumpNodeInObjectSpace(s, point);
      return triplanarHeightGradient(*s.height, s.options, point);
    case ProjectedKind::kTangentNormal:
      return s.normals ? triplanarTangentNormalGradient(*s.normals, s.options, point) : Vec3d{};
    case ProjectedKind::kObjectNormal:
      return s.normals ? triplanarObjectNormalGradient(*s.normals, s.options, point) : Vec3d{};
  }
  return {};
}

/// A source's Bump Strength (gradient_detail::bumpStrength): heights' own, 1 for normal maps.
double strengthOf(const UvHeightSource& s) { return s.strength; }
double strengthOf(const VolumeSource& s) { return s.strength; }
double strengthOf(const PlanarSource& s) {
  return s.kind == ProjectedKind::kHeight ? s.strength : 1.0;
}
double strengthOf(const TriplanarSource& s) {
  return s.kind == ProjectedKind::kHeight ? s.strength : 1.0;
}
double strengthOf(const TangentNormalSource&) { return 1; }
double strengthOf(const ObjectNormalSource&) { return 1; }

// --- validation ------------------------------------------------------------------------------

/// What is wrong with one layer, or an empty string.
class LayerChecker {
 public:
  explicit LayerChecker(int numUvSets) : numUvSets_(std::min(numUvSets, kMaxUvSets)) {}

  std::string operator()(const UvHeightSource& s) const {
    return first({present(s.texture, "texture"), uvSet(s.uvSet), finite(s.scale, "scale"),
                  finite(s.tiling, "tiling"), finite(s.offset, "offset")});
  }
  std::string operator()(const TangentNormalSource& s) const {
    return first({present(s.texture, "texture"), s.projection ? std::string() : uvSet(s.uvSet),
                  uvSet(s.frameUvSet()), finite(s.options.strength, "strength"),
                  finite(s.options.tiling, "tiling"), finite(s.options.offset, "offset"),
                  projectedRead(s.projection)});
  }
  std::string operator()(const ObjectNormalSource& s) const {
    return first({present(s.texture, "texture"), s.projection ? std::string() : uvSet(s.uvSet),
                  finite(s.strength, "strength"), finite(s.tiling, "tiling"),
                  finite(s.offset, "offset"), projectedRead(s.projection)});
  }
  std::string operator()(const VolumeSource& s) const {
    return first({present(s.volume, "volume"), finite(s.scale, "scale"),
                  s.scheme == GradientScheme::kAnalytic ? std::string() : finite(s.step, "step")});
  }
  std::string operator()(const PlanarSource& s) const {
    return first({projected(s.kind, s.height, s.normals), finite(s.scale, "scale"),
                  finite(s.mapping.tiling, "tiling"), finite(s.mapping.offset, "offset")});
  }
  std::string operator()(const TriplanarSource& s) const {
    return first({projected(s.kind, s.height, s.normals), finite(s.options.scale, "scale"),
                  finite(s.options.tiling, "tiling"), finite(s.options.offset, "offset"),
                  finite(s.options.sharpness, "sharpness"),
                  finite(s.options.minWeight, "minimum weight")});
  }
  std::string mask(const LayerMask& m) const {
    if (m.texture == nullptr) return {};
    const std::string problem =
        first({uvSet(m.uvSet), finite(m.tiling, "tiling"), finite(m.offset, "offset")});
    return problem.empty() ? problem : "mask: " + problem;
  }

 private:
  static std::string first(std::initializer_list<std::string> problems) {
    for (const std::string& p : problems)
      if (!p.empty()) return p;
    return {};
  }
  template <class T>
  static std::string present(const T* p, const char* what) {
    return p ? std::string() : std::string("no ") + what;
  }
  static std::string finite(double x, const char* what) {
    return std::isfinite(x) ? std::string() : std::string(what) + " is not finite";
  }
  static std::string finite(Vec2d x, const char* what) {
    return isFinite(x) ? std::string() : std::string(what) + " is not finite";
  }
  /// A normal map's projected read.
  static std::string projectedRead(const std::optional<TriplanarOptions>& options) {
    if (!options) return {};
    if (options->projection == TriplanarProjection::kBlended)
      return "its projected read must be one of Blender's projections (Box, Flat, Sphere, Tube)";
    return first({finite(options->tiling, "tiling"), finite(options->offset, "offset"),
                  finite(options->boxBlend, "Box blend")});
  }
  std::string uvSet(int set) const {
    if (set >= 0 && set < numUvSets_) return {};
    return "UV set " + std::to_string(set) + " does not exist (the mesh has " +
           std::to_string(numUvSets_) + " usable)";
  }
  static std::string projected(ProjectedKind kind, const ScalarTexture* height,
                               const VectorTexture* normals) {
    return kind == ProjectedKind::kHeight ? present(height, "height texture")
                                          : present(normals, "normal-map texture");
  }

  int numUvSets_;
};

/// Whether @p source is a height (a Bump node's input) rather than a normal map.
bool bumpsHeights(const LayerSource& source) {
  if (const auto* planar = std::get_if<PlanarSource>(&source))
    return planar->kind == ProjectedKind::kHeight;
  if (const auto* triplanar = std::get_if<TriplanarSource>(&source))
    return triplanar->kind == ProjectedKind::kHeight;
  return std::holds_alternative<UvHeightSource>(source) ||
         std::holds_alternative<VolumeSource>(source);
}

const char* kindName(const LayerSource& source) {
  constexpr const char* kNames[] = {"UV height map",           "tangent-space normal map",
                                    "object-space normal map", "height volume",
                                    "planar projection",       "triplanar projection"};
  return kNames[source.index()];
}

}  // namespace

std::vector<Layer> layersOfMaterial(std::span<const Layer> layers, std::uint32_t material) {
  std::vector<Layer> chosen;
  for (const Layer& layer : layers) {
    if (layer.material < 0 || static_cast<std::uint32_t>(layer.material) == material)
      chosen.push_back(layer);
  }
  return chosen;
}

std::vector<std::vector<Layer>> layersByMaterial(std::span<const Layer> layers) {
  int highest = -1;
  for (const Layer& layer : layers) highest = std::max(highest, layer.material);
  std::vector<std::vector<Layer>> byMaterial;
  if (highest < 0) return byMaterial;
  for (int m = 0; m <= highest + 1; ++m)
    byMaterial.push_back(layersOfMaterial(layers, static_cast<std::uint32_t>(m)));
  return byMaterial;
}

Vec3d layerGradient(const LayerSource& source, const SurfacePoint& point) {
  return std::visit(
      [&](const auto& s) {
        return withNormalMapStrength(evaluate(s, point), point.normal, strengthOf(s));
      },
      source);
}

namespace gradient_detail {

double bumpStrength(const LayerSource& source) {
  return std::visit([](const auto& s) { return strengthOf(s); }, source);
}

Vec3d unblendedLayerGradient(const LayerSource& source, const SurfacePoint& point) {
  return std::visit([&](const auto& s) { return evaluate(s, point); }, source);
}

Vec3d layerGradientNoting(const TangentNormalSource& source, const SurfacePoint& point,
                          NormalBelowSurface* below, const Vec3d* planesNormal) {
  if (below != nullptr) *below = {};
  return evaluate(source, point, below, planesNormal);
}

Vec3d layerGradientNoting(const ObjectNormalSource& source, const SurfacePoint& point,
                          NormalBelowSurface* below, const Vec3d* planesNormal) {
  if (below != nullptr) *below = {};
  return evaluate(source, point, below, planesNormal);
}

Vec3d layerGradientNoting(const LayerSource& source, const SurfacePoint& point,
                          NormalBelowSurface* below) {
  if (const auto* tangent = std::get_if<TangentNormalSource>(&source))
    return layerGradientNoting(*tangent, point, below);
  if (const auto* object = std::get_if<ObjectNormalSource>(&source))
    return layerGradientNoting(*object, point, below);
  if (below != nullptr) *below = {};
  return layerGradient(source, point);
}

Vec3d stackLayerGradientOn(const Layer& layer, const SurfacePoint& point, const Vec3d& gammaAbove,
                           const Vec3d& incoming, const Vec3d* aboveNormal,
                           NormalBelowSurface* below) {
  if (below != nullptr) *below = {};
  const double factor = layer.weight * layerMask(layer.mask, point);
  if (factor == 0) {  // masked out: the source is not sampled
    noteHandedOn(below, aboveNormal);
    return gammaAbove;
  }
  const double strength = bumpStrength(layer.source);
  if (!(strength > 0)) {  // Blender clamps Strength at 0 (and NaN is no bump)
    noteHandedOn(below, aboveNormal);
    return gammaAbove;
  }
  const Vec3d gamma = factor * unblendedLayerGradient(layer.source, point);
  return stackGradientNoting(gamma, strength, point.normal, point.planeNormal(), gammaAbove,
                             incoming, aboveNormal, below);
}

Vec3d stackGradientNoting(const Vec3d& gamma, double strength, const Vec3d& n, const Vec3d& ng,
                          const Vec3d& gammaAbove, const Vec3d& incoming, const Vec3d* aboveNormal,
                          NormalBelowSurface* below) {
  if (below != nullptr) *below = {};
  if (!(strength > 0)) {  // Blender clamps Strength at 0 (and NaN is no bump)
    noteHandedOn(below, aboveNormal);
    return gammaAbove;
  }
  Vec3d bumped = n;
  const Vec3d result = stackGradient(gamma, strength, n, ng, gammaAbove, incoming, aboveNormal,
                                     below != nullptr ? &bumped : nullptr);
  // Below the surface whether it was given a normal there or bumped one above it that far
  // (Cycles' closure keeps a normal far below as it is; the Γ would drop the bump).
  if (below != nullptr && belowSurface(bumped, n)) *below = {true, bumped, 1};
  return result;
}

}  // namespace gradient_detail

double layerMask(const LayerMask& mask, const SurfacePoint& point) {
  if (mask.texture == nullptr) return 1;
  if (!hasUvSet(point, mask.uvSet)) return 0;
  const double m =
      mask.texture
          ->sample(textureCoordinates(uvFrame(point, mask.uvSet).uv, mask.tiling, mask.offset))
          .value;
  return m > 0 ? std::min(m, 1.0) : 0.0;  // NaN → 0
}

namespace {

/// stackLayerGradient with the guards seeing @p incoming.
Vec3d stackLayerGradientSeen(const Layer& layer, const SurfacePoint& point, const Vec3d& gammaAbove,
                             const Vec3d& incoming) {
  return gradient_detail::stackLayerGradientOn(layer, point, gammaAbove, incoming, nullptr,
                                               nullptr);
}

/// compositeGradient, its stacked layers' guards seeing the incoming direction N, or −N at a
/// back-facing point (backFacingNormal).
Vec3d compositeSeen(std::span<const Layer> layers, const SurfacePoint& point, bool back) {
  const Vec3d incoming = back ? -point.normal : point.normal;
  Vec3d gamma{};
  Layer scratch;
  for (const Layer& given : layers) {
    if (given.weight == 0 || !std::isfinite(given.weight)) continue;
    const Layer& layer = back ? gradient_detail::seenFromBehind(given, scratch) : given;
    if (layer.base == LayerBase::kLayersAbove) {
      gamma = stackLayerGradientSeen(layer, point, gamma, incoming);
      continue;
    }
    const double factor = layer.weight * layerMask(layer.mask, point);
    if (factor == 0) continue;  // masked out: the source is not sampled
    gamma += factor * layerGradient(layer.source, point);
  }
  return isFinite(gamma) ? gamma : Vec3d{};  // overflow of absurd weights/scales: unperturbed
}

}  // namespace

Vec3d compositeGradient(std::span<const Layer> layers, const SurfacePoint& point) {
  return compositeSeen(layers, point, false);
}

Vec3d stackLayerGradient(const Layer& layer, const SurfacePoint& point, const Vec3d& gammaAbove) {
  return stackLayerGradientSeen(layer, point, gammaAbove, point.normal);
}

namespace gradient_detail {

bool readsHeightsAtPosition(const LayerSource& source) {
  if (std::holds_alternative<VolumeSource>(source)) return true;
  if (const auto* planar = std::get_if<PlanarSource>(&source))
    return planar->kind == ProjectedKind::kHeight;
  if (const auto* triplanar = std::get_if<TriplanarSource>(&source))
    return triplanar->kind == ProjectedKind::kHeight;
  return false;
}

const Layer& seenFromBehind(const Layer& layer, Layer& scratch) {
  if (!readsHeightsAtPosition(layer.source)) return layer;
  scratch = withHeightsScaled(layer, -1);
  return scratch;
}

Vec3d backFacingNormal(std::span<const Layer> layers, const SurfacePoint& point) {
  return backFacingGuarded(point.normal, compositeSeen(layers, seenFromBehind(point), true),
                           point.planeNormal());
}

Vec3d stackGradient(const Vec3d& gamma, double strength, const Vec3d& n, const Vec3d& ng,
                    const Vec3d& gammaAbove, const Vec3d& incoming, const Vec3d* aboveNormal,
                    Vec3d* bumpedOut) {
  if (!isFinite(gamma) || !isFinite(gammaAbove)) return gammaAbove;
  // The normal the layers above hand on, unguarded: in Blender 3.4 the Normal Map and Bump
  // nodes hand on what they make, and only the closure guards (a stretched chain's p99 off
  // Cycles: 3.3° tangent, 6.0° object when this normal was guarded too).
  const Vec3d above = aboveNormal != nullptr ? *aboveNormal : normalizeOr(n - gammaAbove, n);
  // The same derivatives along the plane of Ng, perpendicular to that normal.
  const double across = dot(ng, above);
  const Vec3d sigma = std::abs(across) > 0 ? gamma - (dot(gamma, above) / across) * ng : gamma;
  Vec3d bumped = normalizeOr(above - sigma, above);
  if (strength != 1) bumped = normalizeOr(strength * bumped + (1 - strength) * above, above);
  // The closure's guard, which the normal must pass to be a Γ for the layers after it.
  bumped = validReflectionNormal(bumped, ng, incoming);
  if (bumpedOut != nullptr) *bumpedOut = bumped;
  // The Γ that resolves to it: N − Γ = n₂ / ⟨n₂, N⟩.
  const double height = dot(bumped, n);
  if (!(height > 0)) return gammaAbove;  // only when the guard had nothing to turn to
  const Vec3d result = n - (1 / height) * bumped;
  return isFinite(result) ? result : gammaAbove;
}

}  // namespace gradient_detail

Vec3d perturbedNormal(const SurfacePoint& point, std::span<const Layer> layers,
                      const Mat3& objectScaleCofactor) {
  return resolveNormal(point.normal, compositeGradient(layers, point), objectScaleCofactor);
}

Status validateLayers(std::span<const Layer> layers, int numUvSets) {
  const LayerChecker checker(numUvSets);
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const Layer& layer = layers[i];
    std::string problem = std::visit(checker, layer.source);
    if (problem.empty() && !std::isfinite(layer.weight)) problem = "weight is not finite";
    if (problem.empty() && layer.base == LayerBase::kLayersAbove && !bumpsHeights(layer.source)) {
      problem =
          "only a height can bump the normal of the layers above (a normal map has no "
          "normal to start from)";
    }
    if (problem.empty() && layer.objectSpaceHeight && !bumpsHeights(layer.source))
      problem = "only a height is measured in object units (a normal map has no height)";
    if (problem.empty()) problem = checker.mask(layer.mask);
    if (!problem.empty()) {
      return Error::badInput("layer " + std::to_string(i) + " (" + kindName(layer.source) +
                             "): " + problem);
    }
  }
  return Ok{};
}

}  // namespace sgbake
