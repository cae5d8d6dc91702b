// Shading in world space through an object transform (world_shading.hpp): analytic references
// on a plane, the similarity case against object space with heights divided by the scale,
// normal maps carried as normals, and transforms that cannot be used.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gradient/valid_reflection.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/volume.hpp"
#include "sgbake/gradient/world_shading.hpp"
#include "support/analytic_textures.hpp"
#include "support/surface_points.hpp"

namespace sgbake {
namespace {

using test::AnalyticHeight;
using test::ConstantNormalTexture;
using test::maxAbsDiff;
using test::samplePoint;

/// h = slope · s (a ramp along the first texture coordinate).
class RampTexture final : public ScalarTexture {
 public:
  explicit RampTexture(double slope) : slope_(slope) {}
  ScalarSample sample(Vec2d st) const override { return {slope_ * st.x, {slope_, 0}}; }

 private:
  double slope_;
};

/// A tangent-space map whose normals lean a little (no guard acts on them).
class GentleNormalTexture final : public VectorTexture {
 public:
  Vec3d sample(Vec2d st) const override {
    const Vec3d n = normalizeOr(Vec3d{0.2 * std::sin(3 * st.x), 0.15 * std::cos(2 * st.y), 1}, {});
    return 0.5 * n + Vec3d{0.5, 0.5, 0.5};
  }
};

Mat3 rotation(double yaw, double pitch) {
  const double cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch);
  const Mat3 z = Mat3::fromColumns({cy, sy, 0}, {-sy, cy, 0}, {0, 0, 1});
  const Mat3 x = Mat3::fromColumns({1, 0, 0}, {0, cp, sp}, {0, -sp, cp});
  return z * x;
}

WorldSpace spaceOf(const Mat3& m) {
  const Result<WorldSpace> space = WorldSpace::of({m, {0.5, -2, 3}});
  EXPECT_TRUE(space.ok());
  return space.ok() ? *space : WorldSpace{};
}

// A ramp h = a·u on the plane z = 0 with ∂P/∂u = x̂, of an object scaled (2, 1, 0.5): in world
// space the ramp rises a over 2 units of x, so the world normal is (−a/2, 0, 1)/…; carried back
// to object space as a normal (M^T) it is (−a, 0, 0.5)/…, i.e. Γ = (2a, 0, 0): twice the
// object-space slope, not the cofactor's (seed 000 eq. 33) half.
TEST(WorldShading, RampOnAStretchedPlaneFollowsTheWorldSlope) {
  const double a = 0.3;
  RampTexture ramp(a);
  const WorldSpace space = spaceOf(Mat3::diagonal({2, 1, 0.5}));
  SurfacePoint object;
  object.numUvSets = 1;
  object.uv[0] = {{0.25, 0.5}, {1, 0, 0}, {0, 1, 0}};
  const SurfacePoint world = worldSurfacePoint(object, space);
  const std::vector<Layer> layers{{UvHeightSource{&ramp, 0, 1.0}, 1.0, {}}};
  const WorldShadedNormal shaded = shadeLayersInWorld(layers, object, world, space);
  EXPECT_LT(maxAbsDiff(objectSpaceGradient(shaded, object, space), Vec3d{2 * a, 0, 0}), 1e-15);
  EXPECT_LT(maxAbsDiff(shaded.normal, normalizeOr(Vec3d{-a / 2, 0, 1}, {})), 1e-15);
  // The framework's object-space composite would give a here, and the cofactor a/4 in world.
  EXPECT_GT(std::abs(objectSpaceGradient(shaded, object, space).x - a), 0.2);
}

// A rotation times a uniform scale s changes nothing but the unit of height: the world shading
// brought back to object space is the object-space composite with heights divided by s.
TEST(WorldShading, ASimilarityIsObjectSpaceWithHeightsDividedByTheScale) {
  AnalyticHeight h(0.5, -0.2, 0.1);
  std::mt19937_64 rng(71);
  for (const double s : {0.25, 1.0, 3.0}) {
    const WorldSpace space = spaceOf(rotation(0.7, -0.4) * Mat3::diagonal({s, s, s}));
    for (int i = 0; i < 100; ++i) {
      const SurfacePoint object = samplePoint(rng);
      const SurfacePoint world = worldSurfacePoint(object, space);
      const std::vector<Layer> inWorld{{UvHeightSource{&h, 0, 0.2}, 1.0, {}}};
      const std::vector<Layer> inObject{{UvHeightSource{&h, 0, 0.2 / s}, 1.0, {}}};
      const WorldShadedNormal shaded = shadeLayersInWorld(inWorld, object, world, space);
      EXPECT_LT(maxAbsDiff(objectSpaceGradient(shaded, object, space),
                           compositeGradient(inObject, object)),
                1e-12);
      // The guard (here Ng = N) is the same in both spaces for a similarity.
      const Vec3d guarded = gradient_detail::validReflectionNormal(
          perturbedNormal(object, inObject), object.normal, object.normal);
      EXPECT_LT(maxAbsDiff(normalizeOr(space.normalToObject * shaded.normal, {}), guarded), 1e-12);
    }
  }
}

// Cycles decodes a normal map in object space and carries it to world space as a normal; the
// baker's way back (M^T) undoes that: with no guard acting, any transform gives the
// object-space result, which is what Blender's tangent-space bake of a normal map shows.
TEST(WorldShading, ANormalMapComesBackUnchangedThroughAnyTransform) {
  GentleNormalTexture map;
  std::mt19937_64 rng(72);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 100; ++i) {
    Mat3 m = rotation(3 * u(rng), u(rng)) * Mat3::diagonal({2 + u(rng), 1, 0.6 + 0.3 * u(rng)});
    m.col[1] += 0.3 * u(rng) * m.col[0];  // a shear as well
    const WorldSpace space = spaceOf(m);
    const SurfacePoint object = samplePoint(rng);
    const SurfacePoint world = worldSurfacePoint(object, space);
    const std::vector<Layer> layers{{TangentNormalSource{&map, 0, {}}, 1.0, {}}};
    const WorldShadedNormal shaded = shadeLayersInWorld(layers, object, world, space);
    EXPECT_LT(maxAbsDiff(normalizeOr(space.normalToObject * shaded.normal, {}),
                         perturbedNormal(object, layers)),
              1e-12);
    EXPECT_LT(
        maxAbsDiff(objectSpaceGradient(shaded, object, space), compositeGradient(layers, object)),
        1e-12);
  }
}

// Strength blends in world space, as Cycles' Normal Map and Bump nodes do after the transform.
TEST(WorldShading, StrengthBlendsTheWorldNormals) {
  RampTexture ramp(0.4);
  const WorldSpace space = spaceOf(Mat3::diagonal({3, 1, 0.4}));
  SurfacePoint object;
  object.numUvSets = 1;
  object.uv[0] = {{0.1, 0.2}, {0.8, 0.1, 0}, {-0.1, 1.1, 0}};
  const SurfacePoint world = worldSurfacePoint(object, space);
  UvHeightSource full{&ramp, 0, 1.0};
  UvHeightSource half = full;
  half.strength = 0.5;
  const Vec3d n = world.normal;
  const Vec3d bumped =
      shadeLayersInWorld(std::vector<Layer>{{full, 1.0, {}}}, object, world, space).normal;
  const Vec3d blended =
      shadeLayersInWorld(std::vector<Layer>{{half, 1.0, {}}}, object, world, space).normal;
  EXPECT_LT(maxAbsDiff(blended, normalizeOr(0.5 * bumped + 0.5 * n, {})), 1e-15);
  // A height read at positions (a volume) blends in world space too.
  auto sine = DirectionalSine::create({0.2, 1.5, {1, 2, 3}, 0.3});
  ASSERT_TRUE(sine.ok());
  VolumeSource volume{&*sine, GradientScheme::kAnalytic, 0, 0.5};
  const Vec3d volumeBumped =
      shadeLayersInWorld(std::vector<Layer>{{volume, 1.0, {}}}, object, world, space).normal;
  volume.strength = 0.5;
  const Vec3d volumeBlended =
      shadeLayersInWorld(std::vector<Layer>{{volume, 1.0, {}}}, object, world, space).normal;
  ASSERT_GT(length(volumeBumped - n), 1e-3);
  EXPECT_LT(maxAbsDiff(volumeBlended, normalizeOr(0.5 * volumeBumped + 0.5 * n, {})), 1e-15);
}

// A shear can carry an object normal 60° from N below the world's tangent plane. No Γ stands
// for such a normal (N − Γ resolves to its mirror image above the plane); Cycles' guard sees
// the decoded normal itself. Its test reflects I about the normal's line, so a normal far
// enough below passes it and is baked below the surface; one nearer the plane is turned up on
// its own side.
TEST(WorldShading, ANormalMapDecodedBelowTheSurfaceIsGuardedAsItIs) {
  // M^{-T} maps (x, y, z) to (x, y, z − 2x): N = ẑ stays, v = (sin 60°, 0, cos 60°) goes below.
  const WorldSpace space = spaceOf(Mat3::fromColumns({1, 0, 0}, {0, 1, 0}, {2, 0, 1}));
  const Vec3d v{std::sin(kPi / 3), 0, std::cos(kPi / 3)};
  ConstantNormalTexture map(v);
  SurfacePoint object;
  object.numUvSets = 1;
  object.uv[0] = {{0.25, 0.5}, {1, 0, 0}, {0, 1, 0}};
  const SurfacePoint world = worldSurfacePoint(object, space);
  const Vec3d n = world.normal, decoded = normalizeOr(space.normalToWorld * v, {});
  ASSERT_LT(maxAbsDiff(n, Vec3d{0, 0, 1}), 1e-15);
  ASSERT_LT(dot(decoded, n), -0.8);
  for (const double strength : {1.0, 0.6}) {
    ObjectNormalSource source{&map, 0};
    source.strength = strength;
    const std::vector<Layer> layers{{source, 1.0, {}}};
    const WorldShadedNormal shaded = shadeLayersInWorld(layers, object, world, space);
    const Vec3d unguarded = strength == 1 ? decoded : normalizeOr(n + strength * (decoded - n), {});
    EXPECT_LT(maxAbsDiff(shaded.unguarded, unguarded), 1e-15) << strength;
    EXPECT_LT(maxAbsDiff(shaded.normal, gradient_detail::validReflectionNormal(unguarded, n, n)),
              1e-15)
        << strength;
  }
  // Strength 1: 35° below the plane, its reflection of I rises: kept (the mirror image the Γ
  // resolves to lies 35° above it).
  const std::vector<Layer> alone{{ObjectNormalSource{&map, 0}, 1.0, {}}};
  EXPECT_LT(maxAbsDiff(shadeLayersInWorld(alone, object, world, space).normal, decoded), 1e-15);
  // Strength 0.6: 5° below, turned up to the guard's 44.7° from N, towards +x.
  ObjectNormalSource weak{&map, 0};
  weak.strength = 0.6;
  const Vec3d turned =
      shadeLayersInWorld(std::vector<Layer>{{weak, 1.0, {}}}, object, world, space).normal;
  EXPECT_NEAR(std::acos(turned.z), std::acos(0.01) / 2, 1e-12);
  EXPECT_GT(turned.x, 0.7);
}

// A Bump node on such a normal map bumps the decoded normal itself (Cycles' nodes hand on what
// they make; only the closure guards): a flat height leaves the map's result as it is, a
// gentle one moves it a little, not over to the mirror image 35° above the plane.
TEST(WorldShading, AHeightOnANormalMapDecodedBelowTheSurfaceBumpsThatNormal) {
  const WorldSpace space = spaceOf(Mat3::fromColumns({1, 0, 0}, {0, 1, 0}, {2, 0, 1}));
  ConstantNormalTexture map(Vec3d{std::sin(kPi / 3), 0, std::cos(kPi / 3)});
  SurfacePoint object;
  object.numUvSets = 1;
  object.uv[0] = {{0.25, 0.5}, {1, 0, 0}, {0, 1, 0}};
  const SurfacePoint world = worldSurfacePoint(object, space);
  const Vec3d alone = shadeLayersInWorld(std::vector<Layer>{{ObjectNormalSource{&map, 0}, 1.0, {}}},
                                         object, world, space)
                          .normal;
  ASSERT_LT(alone.z, -0.8);  // kept below the surface (see the test above)
  for (const double slope : {0.0, 0.02}) {
    RampTexture ramp(slope);
    Layer bump{UvHeightSource{&ramp, 0, 1.0}, 1.0, {}};
    bump.base = LayerBase::kLayersAbove;
    const std::vector<Layer> chain{{ObjectNormalSource{&map, 0}, 1.0, {}}, bump};
    const Vec3d bumped = shadeLayersInWorld(chain, object, world, space).normal;
    const double degrees = std::acos(std::min(1.0, dot(bumped, alone))) * 180 / kPi;
    EXPECT_LT(degrees, slope == 0 ? 1e-6 : 3.0) << slope;
    EXPECT_GT(degrees, slope == 0 ? -1.0 : 0.1) << slope;
  }
}

// Where the world normal points behind the world triangle, Cycles shades from behind and bakes
// the front normal reversed (gradient_detail::backFacingNormal); in front, and for the Γ the
// derivative maps read, nothing changes. The ramp of the stretched plane, with N leaning past
// the plane: a small slope, so that no guard acts, either side.
TEST(WorldShading, BackFacingPointsBakeTheFrontNormalReversed) {
  RampTexture ramp(0.05);
  const WorldSpace space = spaceOf(Mat3::diagonal({2, 1, 0.5}));
  const std::vector<Layer> layers{{UvHeightSource{&ramp, 0, 1.0}, 1.0, {}}};
  const Vec3d ng = normalizeOr(space.normalToWorld * Vec3d{0, 0, 1}, {});
  for (const double lean : {0.3, 2.0}) {  // radians from Ng: in front, then behind
    SurfacePoint object;
    object.normal = Vec3d{std::sin(lean), 0, std::cos(lean)};
    object.geometricNormal = Vec3d{0, 0, 1};
    object.numUvSets = 1;
    object.uv[0] = {{0.25, 0.5}, {1, 0, 0}, {0, 1, 0}};
    const SurfacePoint world = worldSurfacePoint(object, space);
    ASSERT_LT(maxAbsDiff(world.geometricNormal, ng), 1e-15);  // carried to world as a normal
    const bool back = dot(world.normal, ng) < 0;
    EXPECT_EQ(back, lean > 1.6) << lean;
    const WorldShadedNormal shaded = shadeLayersInWorld(layers, object, world, space);
    const Vec3d expected = back ? -shaded.unguarded : shaded.unguarded;
    EXPECT_LT(maxAbsDiff(shaded.normal, expected), 1e-15) << lean;
    // The unguarded normal is the front one either way: N − Γ with the world ramp's Γ ⊥ N.
    EXPECT_GT(dot(shaded.unguarded, world.normal), 0.99) << lean;
  }
}

TEST(WorldShading, SingularOrNonFiniteTransformsAreRejected) {
  EXPECT_FALSE(WorldSpace::of({Mat3::diagonal({1, 0, 1}), {}}).ok());
  EXPECT_FALSE(WorldSpace::of({Mat3::diagonal({1, NAN, 1}), {}}).ok());
  EXPECT_FALSE(WorldSpace::of({Mat3::identity(), {0, INFINITY, 0}}).ok());
  EXPECT_FALSE(WorldSpace::of({Mat3::diagonal({1e-200, 1e-200, 1e-200}), {}}).ok());
  EXPECT_TRUE(WorldSpace::of({Mat3::diagonal({-1, 1, 1}), {}}).ok());  // a mirror is fine
  const ObjectTransform moved{Mat3::identity(), {1, 2, 3}};
  const ObjectTransform mirrored{Mat3::diagonal({1, 1, -1}), {}};
  EXPECT_TRUE(moved.shadesAsObjectSpace());
  EXPECT_FALSE(mirrored.shadesAsObjectSpace());
}

}  // namespace
}  // namespace sgbake
