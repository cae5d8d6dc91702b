#include "sgbake/gradient/world_shading.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <type_traits>
#include <variant>

#include "gradient/bump_node.hpp"
#include "gradient/prepared_uv_frame.hpp"
#include "gradient/stacking.hpp"
#include "gradient/valid_reflection.hpp"
#include "gradient/world_shading_detail.hpp"
#include "sgbake/core/math.hpp"

namespace sgbake {
namespace {

using gradient_detail::PreparedUvFrame;

bool isFinite(const Mat3& m) {
  return sgbake::isFinite(m.col[0]) && sgbake::isFinite(m.col[1]) && sgbake::isFinite(m.col[2]);
}

/// A layer's Γ in world space before its Strength, and that Strength (1: none, or one the
/// source applies itself).
struct WorldGradient {
  Vec3d gamma;
  double strength = 1;
  /// A normal map's decoded world normal lies at or below the tangent plane (gamma stands for
  /// its mirror image): then `decoded` is that normal, unit.
  bool belowSurface = false;
  Vec3d decoded{};
};

/// Carries world normals and heights' gradients for one point.
class WorldLayerEvaluator {
 public:
  WorldLayerEvaluator(const SurfacePoint& objectPoint, const SurfacePoint& worldPoint,
                      const WorldSpace& space, const gradient_detail::PreparedUvFrame* prepared)
      : object_(objectPoint), world_(worldPoint), space_(space), prepared_(prepared) {}

  /// Eq. 31 on the world triangle; Strength blends in world space (withNormalMapStrength).
  WorldGradient operator()(const UvHeightSource& s) const {
    if (s.texture == nullptr || s.uvSet < 0 || s.uvSet >= world_.numUvSets ||
        s.uvSet >= kMaxUvSets) {
      return {Vec3d{}, s.strength};
    }
    const std::size_t set = static_cast<std::size_t>(s.uvSet);
    const ScalarSample h =
        s.texture->sample(textureCoordinates(world_.uv[set].uv, s.tiling, s.offset));
    if (gradient_detail::usesBumpNode(s.gradient, world_)) {
      return {
          gradient_detail::bumpNodeGradient(s, world_.uv[set], world_.normal, world_.bump, h.value),
          s.strength};
    }
    const gradient_detail::PreparedUvFrame frame =
        prepared_ != nullptr ? prepared_[set] : gradient_detail::prepareUvFrame(world_.uv[set]);
    return {
        gradient_detail::gradientFromPreparedUvFrame(
            frame, world_.normal, uvDerivativesFromTexture(h, s.tiling, s.scale), s.minFrameSine),
        s.strength};
  }
  WorldGradient operator()(const TangentNormalSource& s) const {
    TangentNormalSource unblended = s;
    unblended.options.strength = 1;
    return decodedNormal(objectNormal(unblended), s.options.strength);
  }
  WorldGradient operator()(const ObjectNormalSource& s) const {
    ObjectNormalSource unblended = s;
    unblended.strength = 1;
    return decodedNormal(objectNormal(unblended), s.strength);
  }
  /// Heights read at positions: their Strength blends in world space too.
  WorldGradient operator()(const VolumeSource& s) const {
    if (s.volume != nullptr && gradient_detail::usesBumpNode(s.gradient, world_))
      return {bumpNodeInWorld(s, object_), s.strength};
    return {heightGradient(gradient_detail::unblendedLayerGradient(s, object_)), s.strength};
  }
  WorldGradient operator()(const PlanarSource& s) const { return projected(s, object_); }
  /// Cycles picks a triplanar's planes (weights, Box mirrors) by the world normal it shades
  /// with, taken back to object space (M^T n). Its world normals are the corner normals carried
  /// to world space and normalized before they are interpolated, so on a stretched object that
  /// is not the object's interpolated normal: with it, a stretched sphere's Box bump was off by
  /// p99 0.30 deg (0.0023 deg with this one). Γ does not depend on the object normal otherwise
  /// (heightGradient re-projects along Ng in world space), and an object-space normal's blend is
  /// taken relative to it.
  WorldGradient operator()(const TriplanarSource& s) const {
    SurfacePoint planes = object_;
    planes.normal = planesNormal();
    return projected(s, planes);
  }

 private:
  /// A height's object-space surface gradient σ as the world one: M^{-T} σ projected onto the
  /// world tangent plane along the world Ng (projectOntoTangentPlaneAlong), as σ was in object
  /// space: the slopes along the triangle are the same, w.r.t. world distances. (σ differs
  /// from ∇h by a multiple of Ng, which M^{-T} keeps along Ng and the projection removes.)
  Vec3d heightGradient(const Vec3d& sigma) const {
    return projectOntoTangentPlaneAlong(space_.normalToWorld * sigma, world_.normal,
                                        world_.geometricNormal);
  }
  /// A normal map's decoded object-space normal (Strength 1): N − Γ_o, or the decoded normal
  /// itself where it lies below the object's surface and Γ_o cannot stand for it.
  /// A projected map's planes are picked by the world normal taken back to object space, as a
  /// triplanar's (above); it decodes with the object's own normal and frames.
  template <class Source>
  Vec3d objectNormal(const Source& s) const {
    gradient_detail::NormalBelowSurface below;
    const Vec3d seen = object_.bump.behind ? -planesNormal() : planesNormal();
    const Vec3d gamma = gradient_detail::layerGradientNoting(s, object_, &below, &seen);
    return below.found ? below.decoded : object_.normal - gamma;
  }
  /// The world normal Cycles shades with, taken back to object space (M^T n), unit.
  Vec3d planesNormal() const {
    return normalizeOr(space_.normalToObject * world_.normal, object_.normal);
  }
  /// The Γ of a normal map's object-space normal @p objectNormal, carried to world space as a
  /// normal (and that normal when the Γ cannot stand for it).
  WorldGradient decodedNormal(const Vec3d& objectNormal, double strength = 1) const {
    const Vec3d n = space_.normalToWorld * objectNormal;
    WorldGradient g{finiteOrZero(gradientFromObjectNormal(n, world_.normal)), strength};
    const Vec3d unit = normalizeOr(n, Vec3d{});
    if (gradient_detail::belowSurface(unit, world_.normal)) {
      g.belowSurface = true;
      g.decoded = unit;
    }
    return g;
  }
  /// The Γ of a height read at (object) positions as the Bump node makes it in world space: its
  /// world offsets carried into object space (M⁻¹), the node's geometry the world's; triplanar
  /// planes those of @p object's seen normal.
  template <class Source>
  Vec3d bumpNodeInWorld(const Source& s, const SurfacePoint& object) const {
    return gradient_detail::positionBumpNodeGradient(
        s, object.position, object.seenNormal(), world_.normal, world_.bump,
        [this](const Vec3d& w) { return space_.directionToObject * w; });
  }
  /// A planar or triplanar projection evaluated at @p object (object_, or it with the normal
  /// the planes are picked by).
  template <class Source>
  WorldGradient projected(const Source& s, const SurfacePoint& object) const {
    if (s.kind == ProjectedKind::kHeight && s.height != nullptr &&
        gradient_detail::usesBumpNode(s.gradient, world_)) {
      return {bumpNodeInWorld(s, object), s.strength};
    }
    const Vec3d gamma = gradient_detail::unblendedLayerGradient(s, object);
    return s.kind == ProjectedKind::kHeight ? WorldGradient{heightGradient(gamma), s.strength}
                                            : decodedNormal(object.normal - gamma);
  }
  static Vec3d finiteOrZero(const Vec3d& v) { return sgbake::isFinite(v) ? v : Vec3d{}; }

  const SurfacePoint& object_;
  const SurfacePoint& world_;
  const WorldSpace& space_;
  const gradient_detail::PreparedUvFrame* prepared_;  ///< per UV set of world_, or null
};

}  // namespace

bool ObjectTransform::shadesAsObjectSpace() const {
  const Mat3 identity = Mat3::identity();
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (linear(r, c) != identity(r, c)) return false;
  return true;
}

Result<ObjectTransform> objectTransformFromRows(std::span<const double> rowMajor, int rows,
                                                int columns) {
  const auto at = [&](int r, int c) {
    return rowMajor[static_cast<std::size_t>(r) * static_cast<std::size_t>(columns) +
                    static_cast<std::size_t>(c)];
  };
  if (rows == 4 && (at(3, 0) != 0 || at(3, 1) != 0 || at(3, 2) != 0 || at(3, 3) != 1)) {
    std::ostringstream row;
    row << "[" << at(3, 0) << ", " << at(3, 1) << ", " << at(3, 2) << ", " << at(3, 3) << "]";
    return Error::badInput("row 3 must be [0, 0, 0, 1] (an affine transform), not " + row.str());
  }
  ObjectTransform transform;
  transform.linear =
      Mat3::fromColumns({at(0, 0), at(1, 0), at(2, 0)}, {at(0, 1), at(1, 1), at(2, 1)},
                        {at(0, 2), at(1, 2), at(2, 2)});
  if (columns == 4) transform.translation = {at(0, 3), at(1, 3), at(2, 3)};
  if (determinant(transform.linear) == 0) {
    return Error::badInput(
        "is singular (its 3 x 3 part has determinant 0): no normal can be carried through it");
  }
  if (!WorldSpace::of(transform)) {
    return Error::badInput("is too close to singular: its normals overflow");
  }
  return transform;
}

std::optional<double> ObjectTransform::uniformScale(double tolerance) const {
  // MᵀM = s²·I for M = s·Q, Q orthogonal.
  const Mat3 gram = transpose(linear) * linear;
  const double s2 = (gram(0, 0) + gram(1, 1) + gram(2, 2)) / 3;
  if (!(s2 > 0) || !std::isfinite(s2)) return std::nullopt;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const double expected = r == c ? s2 : 0.0;
      if (!(std::abs(gram(r, c) - expected) <= tolerance * s2)) return std::nullopt;
    }
  }
  return std::sqrt(s2);
}

Layer withHeightsScaled(Layer layer, double factor) {
  std::visit(
      [factor](auto& source) {
        using Source = std::decay_t<decltype(source)>;
        if constexpr (std::is_same_v<Source, UvHeightSource> ||
                      std::is_same_v<Source, VolumeSource>) {
          source.scale *= factor;
        } else if constexpr (std::is_same_v<Source, PlanarSource>) {
          if (source.kind == ProjectedKind::kHeight) source.scale *= factor;
        } else if constexpr (std::is_same_v<Source, TriplanarSource>) {
          if (source.kind == ProjectedKind::kHeight) source.options.scale *= factor;
        }
      },
      layer.source);
  return layer;
}

Result<WorldSpace> WorldSpace::of(const ObjectTransform& transform) {
  const Mat3& m = transform.linear;
  const double det = determinant(m);
  if (!isFinite(m) || !sgbake::isFinite(transform.translation) || !std::isfinite(det) || det == 0) {
    return Error::badInput("the object transform is singular or not finite");
  }
  // cof(M) = det(M)·M^{-T}: M^{-T} = cof(M)/det, M^{-1} = cof(M)^T/det.
  const Mat3 cof = cofactor(m);
  const double inv = 1 / det;
  const Mat3 normalToWorld =
      Mat3::fromColumns(inv * cof.col[0], inv * cof.col[1], inv * cof.col[2]);
  WorldSpace space;
  space.toWorld = m;
  space.normalToWorld = normalToWorld;
  space.normalToObject = transpose(m);
  space.directionToObject = transpose(normalToWorld);
  space.translation = transform.translation;
  if (!isFinite(space.normalToWorld)) {
    return Error::badInput("the object transform is too close to singular");
  }
  return space;
}

WorldShadedNormal shadeLayersInWorld(std::span<const Layer> layers, const SurfacePoint& objectPoint,
                                     const SurfacePoint& worldPoint, const WorldSpace& space) {
  return gradient_detail::shadeLayersInWorld(layers, objectPoint, worldPoint, space, nullptr);
}

namespace gradient_detail {

WorldShadedNormal shadeLayersInWorld(std::span<const Layer> layers, const SurfacePoint& objectPoint,
                                     const SurfacePoint& worldPoint, const WorldSpace& space,
                                     const PreparedUvFrame* preparedWorldUv) {
  const Vec3d& n = worldPoint.normal;
  const Vec3d& ng = worldPoint.planeNormal();
  // The layers' Γ seen from the front, or as backFacingNormal sums it at a back-facing point.
  // From the front, also the normal the layers hand on when it lies below the surface, where
  // no Γ stands for it (NormalBelowSurface): a normal map first, then the layers on it.
  HandedNormal handed;
  auto composite = [&](bool back) {
    const Vec3d incoming = back ? -n : n;
    const std::optional<SurfacePoint> behind =
        back ? std::optional<SurfacePoint>(seenFromBehind(worldPoint)) : std::nullopt;
    const std::optional<SurfacePoint> objectBehind =
        back ? std::optional<SurfacePoint>(seenFromBehind(objectPoint)) : std::nullopt;
    Vec3d gamma{};
    Layer scratch;
    for (const Layer& layer : layers) {
      if (layer.weight == 0 || !std::isfinite(layer.weight)) continue;
      if (back) {
        addWorldLayerGradient(seenFromBehind(layer, scratch), *objectBehind, *behind, space,
                              preparedWorldUv, incoming, gamma);
        continue;
      }
      NormalBelowSurface step;
      addWorldLayerGradient(layer, objectPoint, worldPoint, space, preparedWorldUv, incoming, gamma,
                            &step, handed.givenTo(layer));
      handed.add(layer, step, n);
    }
    return isFinite(gamma) ? gamma : Vec3d{};  // overflow of absurd weights/scales: unperturbed
  };

  WorldShadedNormal result;
  result.unguarded = normalizeOr(n - composite(false), n);
  // Cycles' closure guards that normal as it is, below the surface too (a normal far below
  // passes the guard; one nearer the plane is turned up on its own side of Ng).
  if (handed.normal()) result.unguarded = *handed.normal();
  if (layers.empty()) {
    result.normal = n;
  } else if (backFacing(n, ng)) {  // backFacingNormal, in world space
    result.normal = backFacingGuarded(n, composite(true), ng);
  } else {
    result.normal = validReflectionNormal(result.unguarded, ng, n);
  }
  return result;
}

void addWorldLayerGradient(const Layer& layer, const SurfacePoint& objectPoint,
                           const SurfacePoint& worldPoint, const WorldSpace& space,
                           const PreparedUvFrame* preparedWorldUv, const Vec3d& incoming,
                           Vec3d& gamma, NormalBelowSurface* below, const Vec3d* aboveNormal) {
  if (below != nullptr) *below = {};
  double factor = layer.weight * layerMask(layer.mask, objectPoint);
  // A height in object units along the normal (a Displacement node in Object space): |Mᵀn|
  // times it in the world.
  if (layer.objectSpaceHeight) factor *= length(space.normalToObject * worldPoint.normal);
  if (factor == 0) {  // masked out: the source is not sampled
    if (layer.base == LayerBase::kLayersAbove) noteHandedOn(below, aboveNormal);
    return;
  }
  const Vec3d& n = worldPoint.normal;
  const WorldGradient g = std::visit(
      WorldLayerEvaluator(objectPoint, worldPoint, space, preparedWorldUv), layer.source);
  if (below != nullptr && g.belowSurface && factor == 1 && layer.base == LayerBase::kSurface)
    *below = {true, g.decoded, g.strength};
  if (layer.base == LayerBase::kLayersAbove) {
    gamma = stackGradientNoting(factor * g.gamma, g.strength, n, worldPoint.planeNormal(), gamma,
                                incoming, aboveNormal, below);
    return;
  }
  gamma += factor * withNormalMapStrength(g.gamma, n, g.strength);
}

}  // namespace gradient_detail

SurfacePoint worldSurfacePoint(const SurfacePoint& point, const WorldSpace& space) {
  SurfacePoint world = point;
  world.position = space.toWorld * point.position + space.translation;
  world.normal = normalizeOr(space.normalToWorld * point.normal, point.normal);
  world.geometricNormal = normalizeOr(space.normalToWorld * point.geometricNormal, Vec3d{});
  for (std::size_t set = 0; set < static_cast<std::size_t>(point.numUvSets); ++set) {
    world.uv[set].dPdu = space.toWorld * point.uv[set].dPdu;
    world.uv[set].dPdv = space.toWorld * point.uv[set].dPdv;
  }
  return world;
}

Vec3d objectSpaceGradient(const WorldShadedNormal& shaded, const SurfacePoint& objectPoint,
                          const WorldSpace& space) {
  const Vec3d gamma =
      gradientFromObjectNormal(space.normalToObject * shaded.unguarded, objectPoint.normal);
  return isFinite(gamma) ? gamma : Vec3d{};
}

}  // namespace sgbake
