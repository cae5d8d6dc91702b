#include "sgbake/gradient/projection.hpp"

#include <algorithm>
#include <cmath>

#include "gradient/triplanar_sum.hpp"
#include "sgbake/core/math.hpp"

namespace sgbake {
namespace {

constexpr std::array<ProjectionAxis, 3> kAxes{ProjectionAxis::kX, ProjectionAxis::kY,
                                              ProjectionAxis::kZ};

constexpr std::size_t index(ProjectionAxis axis) { return static_cast<std::size_t>(axis); }

/// Slopes (∂h/∂s, ∂h/∂t) per texture unit of a tangent-space texel read in a plane's frame.
Vec2d planeSlopes(const VectorTexture& texture, Vec2d st, const ProjectedNormalOptions& options) {
  return slopesFromTangentNormal(decodeNormalTexel(texture.sample(st), options.green),
                                 options.minNormalZ);
}

/// Γ as computed, or 0 when it overflowed (absurd scales) or met a NaN input.
Vec3d finiteOrZero(Vec3d gamma) { return isFinite(gamma) ? gamma : Vec3d{}; }

}  // namespace

CoordinateMapping CoordinateMapping::fromMappingNode(Vec3d location, Vec3d rotation, Vec3d scale,
                                                     MappingType type) {
  const auto turn = [](double angle, int axis) {
    const double c = std::cos(angle), s = std::sin(angle);
    Mat3 r;
    const std::size_t i = static_cast<std::size_t>((axis + 1) % 3),
                      j = static_cast<std::size_t>((axis + 2) % 3);
    r.col[i][i] = c;
    r.col[i][j] = s;
    r.col[j][i] = -s;
    r.col[j][j] = c;
    return r;
  };
  const Mat3 r = turn(rotation.z, 2) * turn(rotation.y, 1) * turn(rotation.x, 0);
  CoordinateMapping m;
  switch (type) {
    case MappingType::kPoint:
    case MappingType::kVector:
      m.linear = r * Mat3::diagonal(scale);
      m.translation = type == MappingType::kPoint ? location : Vec3d{};
      break;
    case MappingType::kTexture: {
      // Cycles' safe_divide: a zero scale gives 0, not infinity.
      const auto inverse = [](double s) { return s != 0 ? 1 / s : 0.0; };
      m.linear =
          Mat3::diagonal({inverse(scale.x), inverse(scale.y), inverse(scale.z)}) * transpose(r);
      m.translation = -(m.linear * location);
      break;
    }
  }
  m.identity = (type == MappingType::kVector || location == Vec3d{}) && rotation == Vec3d{} &&
               scale == Vec3d{1, 1, 1};
  return m;
}

CoordinateMapping CoordinateMapping::affine(const Mat3& linear, Vec3d translation) {
  CoordinateMapping m;
  m.linear = linear;
  m.translation = translation;
  const Mat3 one = Mat3::identity();
  m.identity = translation == Vec3d{} && linear.col[0] == one.col[0] &&
               linear.col[1] == one.col[1] && linear.col[2] == one.col[2];
  return m;
}

CoordinateMapping CoordinateMapping::after(const CoordinateMapping& first) const {
  if (identity) return first;
  if (first.identity) return *this;
  return affine(linear * first.linear, linear * first.translation + translation);
}

PlaneAxes planeAxes(ProjectionAxis axis) { return planeAxes(PlanarMapping{axis}); }

namespace {

/// The object axes (0 = x, 1 = y, 2 = z) a plane's s and t grow along, by layout.
struct PlaneIndices {
  std::size_t s, t;
};
PlaneIndices planeIndices(const PlanarMapping& mapping) {
  constexpr PlaneIndices kCyclic[3] = {{1, 2}, {2, 0}, {0, 1}};  // X (y, z), Y (z, x), Z (x, y)
  constexpr PlaneIndices kBox[3] = {{1, 2}, {0, 2}, {1, 0}};     // X (y, z), Y (x, z), Z (y, x)
  return (mapping.layout == PlaneLayout::kBox ? kBox : kCyclic)[index(mapping.axis)];
}

/// Cycles' remap of the [0, 1] box to [−1, 1] before its Sphere and Tube projections.
Vec3d remapSquare(Vec3d mapped) { return 2.0 * (mapped - Vec3d{0.5, 0.5, 0.5}); }

/// u of the Sphere and Tube projections: the angle about z from −y, as a fraction of a turn.
double wrappedU(Vec3d c) { return 0.5 - std::atan2(c.x, c.y) / (2 * kPi); }

}  // namespace

Vec2d sphereCoordinates(Vec3d mapped) {
  const Vec3d c = remapSquare(mapped);
  const double r = length(c);
  if (!(r > 0)) return {0, 0};
  const double u = c.x == 0 && c.y == 0 ? 0.0 : wrappedU(c);
  return {u, 1 - std::acos(std::clamp(c.z / r, -1.0, 1.0)) / kPi};
}

Vec2d tubeCoordinates(Vec3d mapped) {
  const Vec3d c = remapSquare(mapped);
  if (c.x == 0 && c.y == 0) return {0, 0};
  return {wrappedU(c), 0.5 * (c.z + 1)};
}

CoordinateGradients wrappedCoordinateGradients(Vec3d mapped, PlaneLayout layout) {
  // d/dP' = 2 d/dc. u = ½ − atan2(x, y)/2π: ∇_c u = (−y, x, 0) / (2π ρ²), ρ² = x² + y².
  const Vec3d c = remapSquare(mapped);
  const double rho2 = c.x * c.x + c.y * c.y;
  CoordinateGradients g;
  if (layout == PlaneLayout::kTube) g.t = {0, 0, 1};  // v = (z + 1)/2
  if (!(rho2 > 0) || !std::isfinite(rho2)) return g;
  g.s = (1 / (kPi * rho2)) * Vec3d{-c.y, c.x, 0};
  if (layout == PlaneLayout::kSphere) {
    // v = 1 − acos(z / r)/π: ∇_c v = (−x z / ρ, −y z / ρ, ρ) / (π r²).
    const double rho = std::sqrt(rho2), r2 = rho2 + c.z * c.z;
    g.t = (2 / (kPi * r2)) * Vec3d{-c.x * c.z / rho, -c.y * c.z / rho, rho};
  }
  return g;
}

PlanarMapping singleLookupMapping(TriplanarProjection projection, Vec2d tiling, Vec2d offset) {
  PlanarMapping mapping{ProjectionAxis::kZ, tiling, offset};
  if (projection == TriplanarProjection::kSphere) mapping.layout = PlaneLayout::kSphere;
  if (projection == TriplanarProjection::kTube) mapping.layout = PlaneLayout::kTube;
  return mapping;
}

PlaneAxes planeAxes(const PlanarMapping& mapping) {
  if (isWrapped(mapping.layout)) return {};
  const PlaneIndices i = planeIndices(mapping);
  PlaneAxes a;
  a.s[i.s] = mapping.mirrored ? -1 : 1;
  a.t[i.t] = 1;
  a.n = cross(a.s, a.t);
  return a;
}

Vec2d planeCoordinates(Vec3d position, ProjectionAxis axis) {
  return planeCoordinates(position, PlanarMapping{axis});
}

Vec2d planeCoordinates(Vec3d position, const PlanarMapping& mapping) {
  if (mapping.layout == PlaneLayout::kSphere) return sphereCoordinates(position);
  if (mapping.layout == PlaneLayout::kTube) return tubeCoordinates(position);
  // A mirrored plane's first coordinate is 1 − s (Cycles' Box), not −s.
  const PlaneIndices i = planeIndices(mapping);
  const double s = position[i.s];
  return {mapping.mirrored ? 1 - s : s, position[i.t]};
}

Vec2d planarTextureCoordinates(Vec3d position, const PlanarMapping& mapping) {
  return textureCoordinates(planeCoordinates(position, mapping), mapping.tiling, mapping.offset);
}

Vec3d projectedVolumeGradient(Vec2d dhdst, const PlanarMapping& mapping, Vec3d mapped,
                              double scale) {
  if (!isWrapped(mapping.layout)) return planeVolumeGradient(dhdst, mapping, scale);
  const CoordinateGradients g = wrappedCoordinateGradients(mapped, mapping.layout);
  return scale * (mapping.tiling.x * dhdst.x * g.s + mapping.tiling.y * dhdst.y * g.t);
}

Vec3d planeVolumeGradient(Vec2d dhdst, const PlanarMapping& mapping, double scale) {
  if (isWrapped(mapping.layout)) return {};  // no fixed axes: projectedVolumeGradient
  const PlaneIndices i = planeIndices(mapping);
  Vec3d g{};
  const double alongS = scale * mapping.tiling.x * dhdst.x;
  g[i.s] = mapping.mirrored ? -alongS : alongS;
  g[i.t] = scale * mapping.tiling.y * dhdst.y;
  return g;
}

Vec3d planarHeightGradient(const ScalarTexture& texture, const PlanarMapping& mapping, double scale,
                           const SurfacePoint& point, const CoordinateMapping& coordinates) {
  const Vec3d mapped = coordinates.apply(point.position);
  const ScalarSample h = texture.sample(planarTextureCoordinates(mapped, mapping));
  return finiteOrZero(projectOntoTangentPlaneAlong(
      coordinates.pullBack(projectedVolumeGradient(h.gradient, mapping, mapped, scale)),
      point.normal, point.geometricNormal));
}

Vec3d planarTangentNormalGradient(const VectorTexture& texture, const PlanarMapping& mapping,
                                  double strength, const SurfacePoint& point,
                                  const ProjectedNormalOptions& options,
                                  const CoordinateMapping& coordinates) {
  const Vec3d mapped = coordinates.apply(point.position);
  const Vec2d slopes = planeSlopes(texture, planarTextureCoordinates(mapped, mapping), options);
  return finiteOrZero(projectOntoTangentPlane(
      coordinates.pullBack(projectedVolumeGradient(slopes, mapping, mapped, strength)),
      point.normal));
}

Vec3d planarObjectNormalGradient(const VectorTexture& texture, const PlanarMapping& mapping,
                                 double strength, const SurfacePoint& point,
                                 const ProjectedNormalOptions& options,
                                 const CoordinateMapping& coordinates) {
  const Vec3d n = decodeNormalTexel(
      texture.sample(planarTextureCoordinates(coordinates.apply(point.position), mapping)));
  return finiteOrZero(strength * gradientFromObjectNormal(n, point.normal, options.minCosine));
}

TriplanarWeights triplanarWeights(Vec3d normal, double sharpness, double minWeight) {
  TriplanarWeights result;
  if (!isFinite(normal)) return result;
  const Vec3d a{std::abs(normal.x), std::abs(normal.y), std::abs(normal.z)};
  const double largest = std::max({a.x, a.y, a.z});
  if (!(largest > 0)) return result;
  const double exponent = sharpness > 0 ? sharpness : 0.0;  // NaN → 0
  const double threshold = std::clamp(minWeight > 0 ? minWeight : 0.0, 0.0, 1.0 / 3.0);

  // Ratios to the largest component: the dominant plane gets exactly 1, nothing overflows, and
  // the sum lies in [1, 3], so the division below is safe.
  std::array<double, 3> w{};
  double sum = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    w[i] = std::pow(a[i] / largest, exponent);
    sum += w[i];
  }
  double kept = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    w[i] /= sum;
    if (w[i] < threshold) w[i] = 0;
    kept += w[i];
  }
  for (std::size_t i = 0; i < 3; ++i) {
    result.w[i] = w[i] / kept;  // kept ≥ the dominant weight ≥ 1/3
    if (result.w[i] > 0) ++result.active;
  }
  return result;
}

bool boxPlaneMirrored(ProjectionAxis axis, Vec3d seenNormal) {
  switch (axis) {
    case ProjectionAxis::kX:
      return seenNormal.x < 0;
    case ProjectionAxis::kY:
      return seenNormal.y > 0;
    case ProjectionAxis::kZ:
      break;
  }
  return seenNormal.z > 0;
}

TriplanarWeights boxProjectionWeights(Vec3d normal, double blend) {
  TriplanarWeights result;
  if (!isFinite(normal)) return result;
  const double total = std::abs(normal.x) + std::abs(normal.y) + std::abs(normal.z);
  if (!(total > 0) || !std::isfinite(total)) return result;
  // a: N's place in the triangle whose corners are the three planes (barycentric).
  const std::array<double, 3> a{std::abs(normal.x) / total, std::abs(normal.y) / total,
                                std::abs(normal.z) / total};
  const double b = blend > 0 ? std::min(blend, 1.0) : 0.0;  // NaN → 0
  const double limit = 0.5 * (1 + b);
  std::array<double, 3>& w = result.w;

  // A plane alone, where it outweighs both others by more than the limit.
  const auto alone = [&](std::size_t i, std::size_t j, std::size_t k) {
    return a[i] > limit * (a[i] + a[j]) && a[i] > limit * (a[i] + a[k]);
  };
  // Planes i and j, where plane k lies below the band it would blend in.
  const auto pair = [&](std::size_t i, std::size_t j, std::size_t k) {
    if (!(a[k] < (1 - limit) * (a[i] + a[j]))) return false;
    w[i] = std::clamp((a[i] / (a[i] + a[j]) - 0.5 * (1 - b)) / b, 0.0, 1.0);
    w[j] = 1 - w[i];
    return true;
  };
  if (alone(0, 1, 2)) {
    w[0] = 1;
  } else if (alone(1, 0, 2)) {
    w[1] = 1;
  } else if (alone(2, 0, 1)) {
    w[2] = 1;
  } else if (b > 0) {
    if (!pair(0, 1, 2) && !pair(1, 2, 0) && !pair(0, 2, 1)) {
      for (std::size_t i = 0; i < 3; ++i)
        w[i] = ((2 - limit) * a[i] + (limit - 1)) / (2 * limit - 1);
    }
  } else {
    w[0] = 1;  // blend 0 and no plane ahead: the tie goes to X, as in Cycles
  }
  for (double& weight : w) {
    if (!(weight > 0)) weight = 0;  // not sampled (Cycles samples only positive weights)
    if (weight > 0) ++result.active;
  }
  return result;
}

TriplanarPlanes triplanarPlanes(const TriplanarOptions& options, Vec3d seenNormal) {
  TriplanarPlanes planes;
  if (isSingleLookup(options.projection)) {
    planes.plane[0] = {singleLookupMapping(options.projection, options.tiling, options.offset),
                       1.0};
    planes.count = 1;
    return planes;
  }
  const bool box = options.projection == TriplanarProjection::kBox;
  const TriplanarWeights weights =
      box ? boxProjectionWeights(seenNormal, options.boxBlend)
          : triplanarWeights(seenNormal, options.sharpness, options.minWeight);
  for (const ProjectionAxis axis : kAxes) {
    const double w = weights.w[index(axis)];
    if (w == 0) continue;
    PlanarMapping mapping{axis, options.tiling, options.offset};
    if (box) {
      mapping.layout = PlaneLayout::kBox;
      mapping.mirrored = boxPlaneMirrored(axis, seenNormal);
    }
    planes.plane[static_cast<std::size_t>(planes.count++)] = {mapping, w};
  }
  return planes;
}

namespace {

/// gradient_detail::sumOverPlanes at @p point of plane(mapping, P', st, w · scale): the loop
/// the three triplanar kinds share.
template <class PlaneTerm>
Vec3d sumOverPlanes(const TriplanarOptions& options, const SurfacePoint& point,
                    const PlaneTerm& plane) {
  return gradient_detail::sumOverPlanes<Vec3d>(
      options, point.position, point.seenNormal(),
      [&](const PlanarMapping& mapping, Vec3d mapped, Vec2d st, double weight) {
        return plane(mapping, mapped, st, weight * options.scale);
      });
}

}  // namespace

Vec3d triplanarHeightGradient(const ScalarTexture& texture, const TriplanarOptions& options,
                              const SurfacePoint& point) {
  const Vec3d volumeGradient = sumOverPlanes(
      options, point,
      [&](const PlanarMapping& mapping, Vec3d mapped, Vec2d st, double weightedScale) {
        return projectedVolumeGradient(texture.sample(st).gradient, mapping, mapped, weightedScale);
      });
  return finiteOrZero(projectOntoTangentPlaneAlong(options.coordinates.pullBack(volumeGradient),
                                                   point.normal, point.geometricNormal));
}

Vec3d triplanarTangentNormalGradient(const VectorTexture& texture, const TriplanarOptions& options,
                                     const SurfacePoint& point) {
  const Vec3d volumeGradient = sumOverPlanes(
      options, point,
      [&](const PlanarMapping& mapping, Vec3d mapped, Vec2d st, double weightedScale) {
        return projectedVolumeGradient(planeSlopes(texture, st, options.normal), mapping, mapped,
                                       weightedScale);
      });
  return finiteOrZero(
      projectOntoTangentPlane(options.coordinates.pullBack(volumeGradient), point.normal));
}

Vec3d projectedTexel(const VectorTexture& texture, const TriplanarOptions& options,
                     const SurfacePoint& point) {
  return projectedTexel(texture, options, point.position, point.seenNormal());
}

Vec3d projectedTexel(const VectorTexture& texture, const TriplanarOptions& options, Vec3d position,
                     Vec3d seenNormal) {
  return gradient_detail::sumOverPlanes<Vec3d>(
      options, position, seenNormal, [&](const PlanarMapping&, Vec3d, Vec2d st, double weight) {
        return weight * texture.sample(st);
      });
}

Vec3d triplanarObjectNormalGradient(const VectorTexture& texture, const TriplanarOptions& options,
                                    const SurfacePoint& point) {
  if (options.projection == TriplanarProjection::kBox) {
    // Cycles blends the texels' colours and a Normal Map node decodes the blend: one normal.
    const Vec3d blend = decodeNormalTexel(projectedTexel(texture, options, point));
    return finiteOrZero(options.scale *
                        gradientFromObjectNormal(blend, point.normal, options.normal.minCosine));
  }
  return finiteOrZero(sumOverPlanes(
      options, point, [&](const PlanarMapping&, Vec3d, Vec2d st, double weightedScale) {
        const Vec3d n = decodeNormalTexel(texture.sample(st));
        return weightedScale * gradientFromObjectNormal(n, point.normal, options.normal.minCosine);
      }));
}

}  // namespace sgbake
