/// @file world_shading.hpp
/// @brief Layers on an object the world sees through a transform: how Cycles shades such an
/// object, and how Blender's baker brings the result back to object space.
///
/// The surface-gradient framework composites in object space and maps the result with the
/// cofactor of the object's transform (seed 000 eq. 33): a height then stretches with the object.
/// Cycles does not. A Bump node's Distance is a world distance, its finite difference is taken
/// on the world-space surface, and the guard on bumped normals (validReflectionNormal) works in
/// world space. The two agree for a rotation and a uniform scale s once heights are divided by
/// s, and differ by direction for any other transform (a cube scaled 3 × 1 × 0.4 and never
/// applied bumps 2.6 × more along x than an object-space bake would).
///
/// What Blender 3.4's Cycles bake does with an object transform M (linear part; the
/// translation changes nothing here), measured against bakes of a UV sphere scaled (2, 1, 0.5)
/// and turned (BlenderBakeOracle cases stretch_*):
///  - the shading normal is interpolated from the corner normals each carried to world space
///    as a normal and normalized, normalize(M^{-T} n_i), and the geometric normal is the world
///    triangle's: an unbumped object-space bake through M^{-1} matched these to 0.002° (median),
///    against 0.09° (p99 3.2°) for the object-space normal carried over as a whole;
///  - a height's surface gradient is taken on the world surface: UV height maps from the world
///    triangle's ∂P/∂u, ∂P/∂v; heights defined on object-space positions (volumes, planar and
///    triplanar projections) as P_w(M^{-T} σ_o), the world gradient projected on the tangent
///    plane;
///  - a normal map is decoded in object space and carried to world space as a normal,
///    normalize(M^{-T} n_o); its Strength then blends in world space;
///  - the guard runs on the world normal, with the world Ng;
///  - the baker brings the world normal back to object space as a normal (M^T n) for tangent-
///    space maps, but as a direction (M^{-1} n, normalized) for object-space maps.
/// shadeLayersInWorld computes the first four; the bake's shaders do the last.
#pragma once

#include <optional>
#include <span>

#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/surface_gradient.hpp"
#include "sgbake/gradient/surface_point.hpp"

namespace sgbake {

/// @brief An object's placement in the world: p_world = linear · p + translation (Blender's
/// Object.matrix_world).
struct ObjectTransform {
  Mat3 linear = Mat3::identity();
  Vec3d translation{};

  /// Whether it changes no normal and no height: the identity linear part (any translation).
  bool shadesAsObjectSpace() const;
  /// @brief s when the linear part is a rotation (or a mirror) times a uniform scale s, to
  /// within @p tolerance (relative; Blender's float matrices are orthogonal to ~1e-7), else
  /// nothing. Such an object shades in world space exactly as in object space with every
  /// height divided by s (the normals carried there and back are the object's own, and the
  /// guard does not change under a rotation or a mirror): withHeightsScaled. Not heights
  /// differenced as the Bump node does: Cycles lays its offsets along its orthonormals of the
  /// world Ng, which do not turn with the object.
  std::optional<double> uniformScale(double tolerance = 1e-6) const;
  /// @brief The uniform scale s by which the object shades as object space (heights divided by
  /// s), or nothing when it shades in world space: uniformScale(), unless a layer's heights are
  /// differenced as the Bump node does (@p readsBumpOffsets). The baker and the planner's
  /// --explain decide by this one rule.
  std::optional<double> objectSpaceScale(bool readsBumpOffsets) const {
    return readsBumpOffsets ? std::nullopt : uniformScale();
  }
};

/// @brief The ObjectTransform of a matrix_world given row by row (Blender's Object.matrix_world):
/// @p rowMajor holds @p rows rows of @p columns finite numbers, 4 × 4, 3 × 4 (without the last
/// row) or 3 × 3 (the linear part alone). Bad input, with a message to follow the name of what
/// was read: a 4 × 4 whose last row is not 0 0 0 1 ("row 3 must be [0, 0, 0, 1] (an affine
/// transform), not [...]"), or a singular linear part ("is singular (...)").
Result<ObjectTransform> objectTransformFromRows(std::span<const double> rowMajor, int rows,
                                                int columns);

/// @brief @p layer with its height (UV height maps, volumes, height projections) multiplied by
/// @p factor; normal maps unchanged.
Layer withHeightsScaled(Layer layer, double factor);

/// @brief The matrices shading under an ObjectTransform uses, computed once.
struct WorldSpace {
  Mat3 toWorld;            ///< M, points and directions object → world
  Mat3 normalToWorld;      ///< M^{-T}, normals object → world (up to length)
  Mat3 normalToObject;     ///< M^T, normals world → object (up to length)
  Mat3 directionToObject;  ///< M^{-1}, directions world → object
  Vec3d translation{};

  /// @brief The matrices of @p transform; kBadInput when its linear part is singular or not
  /// finite (no normal can be carried through it).
  static Result<WorldSpace> of(const ObjectTransform& transform);
};

/// @brief @p point as the world sees it through @p space: the position moved, the normal carried
/// as a normal (normalized), ∂P/∂u and ∂P/∂v as directions; UVs and tangent frames kept (what
/// shadeLayersInWorld's worldPoint needs where there is no triangle, e.g. at a corner).
SurfacePoint worldSurfacePoint(const SurfacePoint& point, const WorldSpace& space);

/// @brief What shadeLayersInWorld computes at one point.
struct WorldShadedNormal {
  /// The perturbed world normal after Cycles' guard (unit): what the baker converts back.
  Vec3d normal{0, 0, 1};
  /// The same before the guard (unit): what objectSpaceGradient reads.
  Vec3d unguarded{0, 0, 1};
};

/// @brief The Γ in object space that resolves (N − Γ, normalized) to @p shaded's unguarded
/// normal brought back to object space as a normal (M^T): the surface-gradient and derivative
/// maps' value, consistent with the tangent-space map where the guard does not act. Zero when
/// not finite.
/// @param[in] objectPoint the point shadeLayersInWorld shaded, in object space
Vec3d objectSpaceGradient(const WorldShadedNormal& shaded, const SurfacePoint& objectPoint,
                          const WorldSpace& space);

/// @brief The layers at a point of an object shaded in world space (see the file comment).
///
/// @param[in] objectPoint the point in object space (normal-map layers decode there; volumes and
///            projections read its position and normal)
/// @param[in] worldPoint  the same point in world space: unit normal interpolated from the
///            world corner normals, world ∂P/∂u, ∂P/∂v (UV height layers are evaluated there),
///            and the world triangle's unit normal as its geometricNormal (the guard's Ng, and
///            the plane a layer on the layers above bumps along; N where it is zero)
/// Layers are skipped, weighted, masked and stacked (LayerBase::kLayersAbove) as
/// compositeGradient does, with every layer's Γ taken in world space and summed there.
WorldShadedNormal shadeLayersInWorld(std::span<const Layer> layers, const SurfacePoint& objectPoint,
                                     const SurfacePoint& worldPoint, const WorldSpace& space);

}  // namespace sgbake
