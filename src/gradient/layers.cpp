#include "sgbake/gradient/layers.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>

#include "sgbake/core/math.hpp"

namespace sgbake {
namespace {

bool hasUvSet(const SurfacePoint& point, int uvSet) {
  return uvSet >= 0 && uvSet < point.numUvSets && uvSet < kMaxUvSets;
}

const UvFrame& uvFrame(const SurfacePoint& point, int uvSet) {
  return point.uv[static_cast<std::size_t>(uvSet)];
}

Vec3d evaluate(const UvHeightSource& s, const SurfacePoint& point) {
  if (s.texture == nullptr || !hasUvSet(point, s.uvSet)) return {};
  const UvFrame& frame = uvFrame(point, s.uvSet);
  const ScalarSample h = s.texture->sample(textureCoordinates(frame.uv, s.tiling, s.offset));
  return withNormalMapStrength(
      gradientFromUvDerivatives(frame, point.normal, uvDerivativesFromTexture(h, s.tiling, s.scale),
                                s.minFrameSine),
      point.normal, s.strength);
}

Vec3d evaluate(const TangentNormalSource& s, const SurfacePoint& point) {
  if (s.texture == nullptr || !hasUvSet(point, s.uvSet)) return {};
  const Vec2d st =
      textureCoordinates(uvFrame(point, s.uvSet).uv, s.options.tiling, s.options.offset);
  const Vec3d n = decodeNormalTexel(s.texture->sample(st), s.options.green);
  return gradientFromTangentNormal(n, point, s.uvSet, s.options);
}

Vec3d evaluate(const ObjectNormalSource& s, const SurfacePoint& point) {
  if (s.texture == nullptr || !hasUvSet(point, s.uvSet)) return {};
  const Vec2d st = textureCoordinates(uvFrame(point, s.uvSet).uv, s.tiling, s.offset);
  const Vec3d gamma =
      gradientFromObjectNormal(decodeNormalTexel(s.texture->sample(st)), point.normal, s.minCosine);
  return withNormalMapStrength(isFinite(gamma) ? gamma : Vec3d{}, point.normal, s.strength);
}

Vec3d evaluate(const VolumeSource& s, const SurfacePoint& point) {
  if (s.volume == nullptr) return {};
  const Vec3d gradient = volumeGradient(*s.volume, point.position, s.scheme, s.step);
  const Vec3d gamma = s.scale * projectOntoTangentPlane(gradient, point.normal);
  return isFinite(gamma) ? gamma : Vec3d{};
}

Vec3d evaluate(const PlanarSource& s, const SurfacePoint& point) {
  switch (s.kind) {
    case ProjectedKind::kHeight:
      return s.height ? planarHeightGradient(*s.height, s.mapping, s.scale, point) : Vec3d{};
    case ProjectedKind::kTangentNormal:
      return s.normals
                 ? planarTangentNormalGradient(*s.normals, s.mapping, s.scale, point, s.normal)
                 : Vec3d{};
    case ProjectedKind::kObjectNormal:
      return s.normals ? planarObjectNormalGradient(*s.normals, s.mapping, s.scale, point, s.normal)
                       : Vec3d{};
  }
  return {};
}

Vec3d evaluate(const TriplanarSource& s, const SurfacePoint& point) {
  switch (s.kind) {
    case ProjectedKind::kHeight:
      return s.height ? triplanarHeightGradient(*s.height, s.options, point) : Vec3d{};
    case ProjectedKind::kTangentNormal:
      return s.normals ? triplanarTangentNormalGradient(*s.normals, s.options, point) : Vec3d{};
    case ProjectedKind::kObjectNormal:
      return s.normals ? triplanarObjectNormalGradient(*s.normals, s.options, point) : Vec3d{};
  }
  return {};
}

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
    return first({present(s.texture, "texture"), uvSet(s.uvSet),
                  finite(s.options.strength, "strength"), finite(s.options.tiling, "tiling"),
                  finite(s.options.offset, "offset")});
  }
  std::string operator()(const ObjectNormalSource& s) const {
    return first({present(s.texture, "texture"), uvSet(s.uvSet), finite(s.strength, "strength"),
                  finite(s.tiling, "tiling"), finite(s.offset, "offset")});
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

const char* kindName(const LayerSource& source) {
  constexpr const char* kNames[] = {"UV height map",           "tangent-space normal map",
                                    "object-space normal map", "height volume",
                                    "planar projection",       "triplanar projection"};
  return kNames[source.index()];
}

}  // namespace

Vec3d layerGradient(const LayerSource& source, const SurfacePoint& point) {
  return std::visit([&](const auto& s) { return evaluate(s, point); }, source);
}

double layerMask(const LayerMask& mask, const SurfacePoint& point) {
  if (mask.texture == nullptr) return 1;
  if (!hasUvSet(point, mask.uvSet)) return 0;
  const double m =
      mask.texture
          ->sample(textureCoordinates(uvFrame(point, mask.uvSet).uv, mask.tiling, mask.offset))
          .value;
  return m > 0 ? std::min(m, 1.0) : 0.0;  // NaN → 0
}

Vec3d compositeGradient(std::span<const Layer> layers, const SurfacePoint& point) {
  Vec3d gamma{};
  for (const Layer& layer : layers) {
    if (layer.weight == 0 || !std::isfinite(layer.weight)) continue;
    const double factor = layer.weight * layerMask(layer.mask, point);
    if (factor == 0) continue;  // masked out: the source is not sampled
    gamma += factor * layerGradient(layer.source, point);
  }
  return isFinite(gamma) ? gamma : Vec3d{};  // overflow of absurd weights/scales: unperturbed
}

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
    if (problem.empty()) problem = checker.mask(layer.mask);
    if (!problem.empty()) {
      return Error::badInput("layer " + std::to_string(i) + " (" + kindName(layer.source) +
                             "): " + problem);
    }
  }
  return Ok{};
}

}  // namespace sgbake
