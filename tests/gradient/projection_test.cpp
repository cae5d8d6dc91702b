// Planar (seed 001 eq. 39-44) and triplanar (eq. 45-50, seed 003) projections: orientation
// conventions, equality with the UV-mapped bake and with planar mapping (eq. 50), the closed-form
// projected volume gradient, the blend weights and their skip threshold (counted samples), and
// finiteness at grazing normals and extreme scales.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/projection.hpp"
#include "support/analytic_textures.hpp"

namespace sgbake {
namespace {

using test::maxAbsDiff;

/// h(s, t) = A sin(2π s + φ) cos(2π t) + c·s, exact derivatives; counts its samples.
class SineTexture final : public ScalarTexture {
 public:
  ScalarSample sample(Vec2d st) const override {
    ++count;
    last = st;
    const double w = 2 * kPi;
    return {0.3 * std::sin(w * st.x + 0.4) * std::cos(w * st.y) + 0.1 * st.x,
            {0.3 * w * std::cos(w * st.x + 0.4) * std::cos(w * st.y) + 0.1,
             -0.3 * w * std::sin(w * st.x + 0.4) * std::sin(w * st.y)}};
  }
  mutable std::atomic<int> count{0};
  mutable Vec2d last{};
};

/// The tangent-space normal map of a height texture: channels = n/2 + 1/2 with
/// n = normalize(−∂h/∂s, −∂h/∂t, 1) (green flipped for DirectX). Counts its samples.
class HeightNormalTexture final : public VectorTexture {
 public:
  explicit HeightNormalTexture(const ScalarTexture& height,
                               NormalMapGreen green = NormalMapGreen::kOpenGL)
      : height_(height), green_(green) {}
  Vec3d sample(Vec2d st) const override {
    ++count;
    const Vec2d g = height_.sample(st).gradient;
    Vec3d n = normalizeOr(Vec3d{-g.x, -g.y, 1}, Vec3d{0, 0, 1});
    if (green_ == NormalMapGreen::kDirectX) n.y = -n.y;
    return 0.5 * n + Vec3d{0.5, 0.5, 0.5};
  }
  mutable std::atomic<int> count{0};

 private:
  const ScalarTexture& height_;
  NormalMapGreen green_;
};

/// An object-space normal map whose normal varies with (s, t); counts its samples.
class ObjectNormalTexture final : public VectorTexture {
 public:
  Vec3d sample(Vec2d st) const override {
    ++count;
    const Vec3d n = normalizeOr(
        Vec3d{std::sin(3 * st.x), std::cos(2 * st.y), 0.5 + 0.3 * std::sin(st.x + st.y)},
        Vec3d{0, 0, 1});
    return 0.5 * n + Vec3d{0.5, 0.5, 0.5};
  }
  mutable std::atomic<int> count{0};
};

SurfacePoint pointAt(Vec3d position, Vec3d normal) {
  SurfacePoint p;
  p.position = position;
  p.normal = normalizeOr(normal, Vec3d{0, 0, 1});
  return p;
}

constexpr ProjectionAxis kAxes[] = {ProjectionAxis::kX, ProjectionAxis::kY, ProjectionAxis::kZ};

/// The tangential part of the gradient of @p height (a function of object position) at @p p,
/// by central differences: the reference Γ of a height defined in space.
template <class Height>
Vec3d projectedCentralGradient(const Height& height, const SurfacePoint& p) {
  const double e = 1e-6;
  Vec3d grad{};
  for (std::size_t k = 0; k < 3; ++k) {
    Vec3d d{};
    d[k] = e;
    grad[k] = (height(p.position + d) - height(p.position - d)) / (2 * e);
  }
  return grad - dot(grad, p.normal) * p.normal;
}

// ---------------------------------------------------------------------------------------------
// orientation

TEST(Planar, PlanesAreCyclicAndRightHanded) {
  for (const ProjectionAxis axis : kAxes) {
    const PlaneAxes a = planeAxes(axis);
    EXPECT_EQ(cross(a.s, a.t), a.n);
    const Vec3d p{1, 2, 3};
    const Vec2d st = planeCoordinates(p, axis);
    EXPECT_EQ(st.x, dot(p, a.s));
    EXPECT_EQ(st.y, dot(p, a.t));
  }
  EXPECT_EQ(planeCoordinates({1, 2, 3}, ProjectionAxis::kZ), Vec2d(1, 2));  // (x, y)
  EXPECT_EQ(planeCoordinates({1, 2, 3}, ProjectionAxis::kX), Vec2d(2, 3));  // (y, z)
  EXPECT_EQ(planeCoordinates({1, 2, 3}, ProjectionAxis::kY), Vec2d(3, 1));  // (z, x)
}

TEST(Triplanar, ZPlaneIsTexturedAtXYTimesTiling) {
  SineTexture tex;
  TriplanarOptions o;
  o.tiling = {2, 3};
  o.offset = {0.25, -0.5};
  triplanarHeightGradient(tex, o, pointAt({0.5, 0.75, 9}, {0, 0, 1}));
  EXPECT_EQ(tex.count, 1);
  EXPECT_EQ(tex.last, Vec2d(2 * 0.5 + 0.25, 3 * 0.75 - 0.5));
  triplanarHeightGradient(tex, o, pointAt({0.5, 0.75, 9}, {-1, 0, 0}));  // X plane: (y, z)
  EXPECT_EQ(tex.last, Vec2d(2 * 0.75 + 0.25, 3 * 9 - 0.5));
  triplanarHeightGradient(tex, o, pointAt({0.5, 0.75, 9}, {0, 1, 0}));  // Y plane: (z, x)
  EXPECT_EQ(tex.last, Vec2d(2 * 9 + 0.25, 3 * 0.5 - 0.5));
}

// ---------------------------------------------------------------------------------------------
// planar

// On a tilted plane z = αx + βy parametrized by (u, v) = (x, y), the planar Z projection and the
// UV-mapped bake (eq. 31 with ∂P/∂u = (1, 0, α), ∂P/∂v = (0, 1, β)) are the same Γ; likewise for
// the X and Y planes with the coordinates permuted.
TEST(Planar, HeightEqualsTheUvMappedBakeWhenUvIsThePlaneCoordinates) {
  SineTexture tex;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  for (const ProjectionAxis axis : kAxes) {
    const PlaneAxes a = planeAxes(axis);
    for (int i = 0; i < 500; ++i) {
      const double alpha = u(rng), beta = u(rng);
      const Vec2d st{u(rng), u(rng)};
      const Vec3d position = st.x * a.s + st.y * a.t + (alpha * st.x + beta * st.y) * a.n;
      const Vec3d dPdu = a.s + alpha * a.n, dPdv = a.t + beta * a.n;
      Vec3d normal = normalizeOr(cross(dPdu, dPdv), Vec3d{});
      if (i % 2) normal = -normal;  // the back side: same Γ
      const PlanarMapping mapping{axis, {1.5, -2}, {0.1, 0.3}};
      const SurfacePoint p = pointAt(position, normal);
      const Vec3d planar = planarHeightGradient(tex, mapping, 0.7, p);
      const ScalarSample h = tex.sample(textureCoordinates(st, mapping.tiling, mapping.offset));
      const Vec3d uvMapped = gradientFromUvDerivatives(
          {st, dPdu, dPdv}, normal, uvDerivativesFromTexture(h, mapping.tiling, 0.7));
      worst = std::max(worst, maxAbsDiff(planar, uvMapped));
    }
  }
  EXPECT_LT(worst, 1e-13);
}

// Eq. 44 written out: Γ = [[1 − n_x², −n_x n_y], [−n_x n_y, 1 − n_y²], [−n_x n_z, −n_y n_z]] γ.
TEST(Planar, HeightOnTheZPlaneIsEquation44) {
  SineTexture tex;
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 500; ++i) {
    const SurfacePoint p = pointAt({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
    const PlanarMapping mapping{ProjectionAxis::kZ, {1, 1}, {0, 0}};
    const Vec2d g = tex.sample(planeCoordinates(p.position, ProjectionAxis::kZ)).gradient;
    const Vec3d n = p.normal;
    const Vec3d expected{(1 - n.x * n.x) * g.x - n.x * n.y * g.y,
                         -n.x * n.y * g.x + (1 - n.y * n.y) * g.y,
                         -n.x * n.z * g.x - n.y * n.z * g.y};
    EXPECT_LT(maxAbsDiff(planarHeightGradient(tex, mapping, 1, p), expected), 1e-13);
  }
}

// A tangent-space map that is the normal map of a height bakes exactly like the height, in both
// green conventions, on every plane.
TEST(Planar, TangentNormalMapOfAHeightEqualsTheHeight) {
  SineTexture tex;
  HeightNormalTexture gl(tex), dx(tex, NormalMapGreen::kDirectX);
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  for (const ProjectionAxis axis : kAxes) {
    for (int i = 0; i < 300; ++i) {
      const SurfacePoint p = pointAt({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
      const PlanarMapping mapping{axis, {0.5, 1.5}, {0.2, 0.1}};
      const Vec3d height = planarHeightGradient(tex, mapping, 0.8, p);
      const Vec3d fromGl = planarTangentNormalGradient(gl, mapping, 0.8, p);
      const Vec3d fromDx =
          planarTangentNormalGradient(dx, mapping, 0.8, p, {NormalMapGreen::kDirectX});
      worst = std::max({worst, maxAbsDiff(height, fromGl), maxAbsDiff(height, fromDx)});
    }
  }
  EXPECT_LT(worst, 1e-12);
}

// A sine height on the plane z = 0 by planar projection: the closed-form normal.
TEST(Planar, SineHeightOnThePlaneGivesTheClosedFormNormal) {
  SineTexture tex;
  const PlanarMapping mapping{ProjectionAxis::kZ, {2, 0.5}, {0.1, 0.2}};
  for (int i = 0; i < 100; ++i) {
    const Vec3d position{0.037 * i - 1, 0.021 * i, 0};
    const Vec2d g = tex.sample(planarTextureCoordinates(position, mapping)).gradient;
    const Vec3d expected = normalizeOr(Vec3d{-0.4 * 2 * g.x, -0.4 * 0.5 * g.y, 1}, Vec3d{});
    const Vec3d normal = resolveNormal(
        {0, 0, 1}, planarHeightGradient(tex, mapping, 0.4, pointAt(position, {0, 0, 1})));
    EXPECT_LT(maxAbsDiff(normal, expected), 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------
// triplanar weights

TEST(TriplanarWeights, AreNormalizedPowersOfTheNormal) {
  const Vec3d n = normalizeOr(Vec3d{0.3, -0.5, 0.8}, Vec3d{});
  const TriplanarWeights w = triplanarWeights(n, 2, 0);
  const double sum = n.x * n.x + n.y * n.y + n.z * n.z;
  EXPECT_NEAR(w.w[0], n.x * n.x / sum, 1e-15);
  EXPECT_NEAR(w.w[1], n.y * n.y / sum, 1e-15);
  EXPECT_NEAR(w.w[2], n.z * n.z / sum, 1e-15);
  EXPECT_EQ(w.active, 3);
  const TriplanarWeights equal = triplanarWeights(n, 0, 0);
  for (double x : equal.w) EXPECT_NEAR(x, 1.0 / 3, 1e-15);
}

TEST(TriplanarWeights, SkipPlanesBelowTheThresholdAndRenormalize) {
  // n = (1, 0.1, 0): w_y = 1e-4 / (1 + 1e-4) < 1e-3 with sharpness 4.
  const TriplanarWeights w = triplanarWeights(normalizeOr(Vec3d{1, 0.1, 0}, Vec3d{}), 4, 1e-3);
  EXPECT_EQ(w.active, 1);
  EXPECT_EQ(w.w[0], 1.0);
  EXPECT_EQ(w.w[1], 0.0);
  // ... but it is kept with a lower threshold.
  EXPECT_EQ(triplanarWeights(normalizeOr(Vec3d{1, 0.1, 0}, Vec3d{}), 4, 1e-5).active, 2);
}

TEST(TriplanarWeights, NeverUnderflowOrDivideByZero) {
  for (const double sharpness : {0.0, 1.0, 4.0, 1e3, 1e8, 1e300, -5.0, std::nan("")}) {
    for (const Vec3d n : {Vec3d{0.6, 0.8, 0}, Vec3d{1, 1, 1}, Vec3d{1e-300, 0, 0}, Vec3d{0, 0, -1},
                          Vec3d{0.5, 0.5, 0.7071}}) {
      const TriplanarWeights w = triplanarWeights(n, sharpness, 1e-3);
      ASSERT_GE(w.active, 1);
      double sum = 0;
      for (double x : w.w) {
        ASSERT_TRUE(std::isfinite(x));
        EXPECT_GE(x, 0);
        sum += x;
      }
      EXPECT_NEAR(sum, 1.0, 1e-15);
    }
  }
  EXPECT_EQ(triplanarWeights({0, 0, 0}).active, 0);
  EXPECT_EQ(triplanarWeights({std::nan(""), 0, 1}).active, 0);
}

// ---------------------------------------------------------------------------------------------
// triplanar

// Eq. 50: with N along an axis only that plane contributes and triplanar is planar mapping.
TEST(Triplanar, NormalAlongAnAxisEqualsPlanarMapping) {
  SineTexture tex;
  HeightNormalTexture tsTex(tex);
  ObjectNormalTexture osTex;
  TriplanarOptions o;
  o.tiling = {1.5, 0.5};
  o.offset = {0.3, 0.1};
  o.scale = 0.6;
  std::mt19937_64 rng(24);
  std::uniform_real_distribution<double> u(-2, 2);
  for (const ProjectionAxis axis : kAxes) {
    for (const double side : {1.0, -1.0}) {
      for (int i = 0; i < 50; ++i) {
        const SurfacePoint p = pointAt({u(rng), u(rng), u(rng)}, side * planeAxes(axis).n);
        const PlanarMapping m{axis, o.tiling, o.offset};
        EXPECT_EQ(triplanarHeightGradient(tex, o, p), planarHeightGradient(tex, m, o.scale, p));
        EXPECT_EQ(triplanarTangentNormalGradient(tsTex, o, p),
                  planarTangentNormalGradient(tsTex, m, o.scale, p));
        EXPECT_EQ(triplanarObjectNormalGradient(osTex, o, p),
                  planarObjectNormalGradient(osTex, m, o.scale, p));
      }
    }
  }
}

// With N along +Z (or −Z) and UV = (x, y), triplanar equals the UV-mapped bake of the same
// texture, for heights, tangent-space maps (UV-derivative frame) and object-space maps.
TEST(Triplanar, NormalAlongAnAxisEqualsTheUvMappedBake) {
  SineTexture tex;
  HeightNormalTexture tsTex(tex);
  ObjectNormalTexture osTex;
  TriplanarOptions o;
  o.tiling = {2, 3};
  o.offset = {0.1, 0.2};
  std::mt19937_64 rng(25);
  std::uniform_real_distribution<double> u(-2, 2);
  double worst = 0;
  for (const double side : {1.0, -1.0}) {
    for (int i = 0; i < 200; ++i) {
      SurfacePoint p = pointAt({u(rng), u(rng), u(rng)}, {0, 0, side});
      p.numUvSets = 1;
      p.uv[0] = {{p.position.x, p.position.y}, {1, 0, 0}, {0, 1, 0}};
      const Vec2d st = textureCoordinates(p.uv[0].uv, o.tiling, o.offset);
      const Vec3d uvHeight = gradientFromUvDerivatives(
          p.uv[0], p.normal, uvDerivativesFromTexture(tex.sample(st), o.tiling, o.scale));
      // A projection's tangent-space map is a height's slopes under tiling (seed 003's
      // derivative form), which a UV normal layer is not (it repeats, as in Blender): the UV
      // layer's texel with its slopes scaled by the tiling.
      TangentNormalOptions ts;
      ts.frame = TangentFrameChoice::kUvDerivatives;
      const Vec3d texel = decodeNormalTexel(tsTex.sample(st));
      const Vec3d uvTangent = gradientFromTangentNormal(
          Vec3d{o.tiling.x * texel.x, o.tiling.y * texel.y, texel.z}, p, 0, ts);
      const Vec3d uvObject =
          gradientFromObjectNormal(decodeNormalTexel(osTex.sample(st)), p.normal);
      worst = std::max({worst, maxAbsDiff(triplanarHeightGradient(tex, o, p), uvHeight),
                        maxAbsDiff(triplanarTangentNormalGradient(tsTex, o, p), uvTangent),
                        maxAbsDiff(triplanarObjectNormalGradient(osTex, o, p), uvObject)});
    }
  }
  EXPECT_LT(worst, 1e-13);
}

// The volume-gradient formulation: Γ is the tangential part of the gradient of the blended
// volume H(P) = Σ w_i · scale · h(tiling ∘ plane_i(P) + offset) with the weights frozen (eq. 48),
// checked against central differences of H.
TEST(Triplanar, HeightIsTheProjectedGradientOfTheBlendedVolume) {
  SineTexture tex;
  TriplanarOptions o;
  o.tiling = {1.3, 0.7};
  o.offset = {0.2, -0.1};
  o.scale = 0.5;
  o.sharpness = 2;
  std::mt19937_64 rng(26);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const SurfacePoint p = pointAt({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
    const TriplanarWeights w = triplanarWeights(p.normal, o.sharpness, o.minWeight);
    auto volume = [&](Vec3d q) {
      double h = 0;
      for (const ProjectionAxis axis : kAxes) {
        const PlanarMapping m{axis, o.tiling, o.offset};
        h += w.w[static_cast<std::size_t>(axis)] * o.scale *
             tex.sample(planarTextureCoordinates(q, m)).value;
      }
      return h;
    };
    EXPECT_LT(maxAbsDiff(triplanarHeightGradient(tex, o, p), projectedCentralGradient(volume, p)),
              1e-8);
  }
}

// Eq. 45: object-space triplanar is the weighted blend of the per-plane eq. 38 gradients.
TEST(Triplanar, ObjectNormalsBlendPerPlaneGradients) {
  ObjectNormalTexture tex;
  TriplanarOptions o;
  o.sharpness = 1;
  const SurfacePoint p = pointAt({0.3, -0.2, 0.5}, {0.4, 0.5, 0.6});
  const TriplanarWeights w = triplanarWeights(p.normal, o.sharpness, o.minWeight);
  Vec3d expected{};
  for (const ProjectionAxis axis : kAxes) {
    const PlanarMapping m{axis, o.tiling, o.offset};
    expected += w.w[static_cast<std::size_t>(axis)] * planarObjectNormalGradient(tex, m, 1, p);
  }
  EXPECT_LT(maxAbsDiff(triplanarObjectNormalGradient(tex, o, p), expected), 1e-15);
}

// Planes below the weight threshold are not sampled: 1, 2 or 3 samples per point.
TEST(Triplanar, PlanesBelowTheThresholdAreNotSampled) {
  struct Case {
    Vec3d normal;
    int samples;
  };
  const Case cases[] = {{{1, 0, 0}, 1}, {{0, -1, 0}, 1},
                        {{0, 0, 1}, 1}, {{1, 0.1, 0}, 1},  // w_y ≈ 1e-4 < 1e-3
                        {{1, 1, 0}, 2}, {{0, 0.6, -0.8}, 2},
                        {{1, 1, 1}, 3}, {{1, 0.3, 0.3}, 3}};  // w = 0.0081/1.0162 ≈ 8e-3 ≥ 1e-3
  for (const Case& c : cases) {
    SineTexture height;
    HeightNormalTexture ts(height);
    ObjectNormalTexture os;
    const SurfacePoint p = pointAt({0.1, 0.2, 0.3}, c.normal);
    const TriplanarOptions o;
    triplanarHeightGradient(height, o, p);
    EXPECT_EQ(height.count, c.samples) << c.normal.x << " " << c.normal.y << " " << c.normal.z;
    triplanarTangentNormalGradient(ts, o, p);
    EXPECT_EQ(ts.count, c.samples);
    triplanarObjectNormalGradient(os, o, p);
    EXPECT_EQ(os.count, c.samples);
  }
}

// Grazing and diagonal normals, extreme tiling and scale: finite, and the resolved normal unit.
TEST(Triplanar, GrazingNormalsAndExtremeScalesAreFinite) {
  SineTexture tex;
  HeightNormalTexture ts(tex);
  ObjectNormalTexture os;
  std::mt19937_64 rng(27);
  std::uniform_real_distribution<double> u(-1, 1);
  const double scales[] = {1e-8, 1e-3, 1, 1e3, 1e8};
  int n = 0;
  for (const double tiling : scales) {
    for (const double scale : scales) {
      for (int i = 0; i < 40; ++i) {
        Vec3d normal{u(rng), u(rng), u(rng)};
        if (i % 4 == 0) normal = {1, 1, 1};
        if (i % 4 == 1) normal = {1, 1e-9, 0};
        if (i % 4 == 2) normal = {0.70710678, 0.70710678, 1e-12};
        const SurfacePoint p = pointAt({u(rng) * scale, u(rng), u(rng) / scale}, normal);
        TriplanarOptions o;
        o.tiling = {tiling, 1 / tiling};
        o.scale = scale;
        o.sharpness = i % 3 == 0 ? 1e6 : 4;
        for (const Vec3d gamma :
             {triplanarHeightGradient(tex, o, p), triplanarTangentNormalGradient(ts, o, p),
              triplanarObjectNormalGradient(os, o, p)}) {
          ASSERT_TRUE(isFinite(gamma));
          const Vec3d resolved = resolveNormal(p.normal, gamma);
          ASSERT_TRUE(isFinite(resolved));
          EXPECT_NEAR(length(resolved), 1.0, 1e-12);
          ++n;
        }
      }
    }
  }
  EXPECT_EQ(n, 5 * 5 * 40 * 3);
}

// ---------------------------------------------------------------------------------------------
// Blender's Box projection
// ---------------------------------------------------------------------------------------------

/// The texture coordinates Cycles' Box projection reads plane @p axis at, for object position
/// @p q and the normal it shades with @p n, written out from Blender's rule (not from
/// planeAxes): X (±y, z), Y (±x, z), Z (±y, x), mirrored as 1 − s on −X, +Y, +Z.
Vec2d boxCoordinates(Vec3d q, ProjectionAxis axis, Vec3d n) {
  switch (axis) {
    case ProjectionAxis::kX:
      return {n.x < 0 ? 1 - q.y : q.y, q.z};
    case ProjectionAxis::kY:
      return {n.y > 0 ? 1 - q.x : q.x, q.z};
    case ProjectionAxis::kZ:
      break;
  }
  return {n.z > 0 ? 1 - q.y : q.y, q.x};
}

TEST(BoxProjection, WeightsAtHandComputedNormals) {
  // a = |N| / Σ|N| = (0.6, 0.3, 0.1), blend 0.4 (limit 0.7): no plane alone (0.6 ≤ 0.7·0.9),
  // Z below the band (0.1 < 0.3·0.9): X and Y blend, w_x = (0.6/0.9 − 0.3)/0.4 = 11/12.
  const TriplanarWeights xy = boxProjectionWeights({-0.6, 0.3, 0.1}, 0.4);
  EXPECT_NEAR(xy.w[0], 11.0 / 12, 1e-15);
  EXPECT_NEAR(xy.w[1], 1.0 / 12, 1e-15);
  EXPECT_EQ(xy.w[2], 0);
  EXPECT_EQ(xy.active, 2);
  // (1, 1, 1): all three, ((2 − L)/3 + L − 1)/(2L − 1) = 1/3 at any blend.
  for (const double blend : {0.1, 0.5, 1.0}) {
    const TriplanarWeights all = boxProjectionWeights({1, -1, 1}, blend);
    for (const double w : all.w) EXPECT_NEAR(w, 1.0 / 3, 1e-15) << blend;
    EXPECT_EQ(all.active, 3);
  }
  // Within the limit of an axis: that plane alone.
  const TriplanarWeights z = boxProjectionWeights({0.1, -0.2, -0.9}, 0.3);
  EXPECT_EQ(z.w[2], 1);
  EXPECT_EQ(z.active, 1);
  // Blend 0: the largest component alone; on a tie no plane is ahead and X takes it (Cycles).
  EXPECT_EQ(boxProjectionWeights({0.3, -0.5, 0.4}, 0).w[1], 1);
  EXPECT_EQ(boxProjectionWeights({0, 0.7, 0.7}, 0).w[0], 1);
  EXPECT_EQ(boxProjectionWeights({0, 0, 0}, 0.2).active, 0);
  EXPECT_EQ(boxProjectionWeights({std::nan(""), 0, 1}, 0.2).active, 0);
}

// The seven zones meet without jumps (blend > 0), the weights are a partition of unity, and
// permuting N's components permutes them (away from Cycles' tie-breaking order).
TEST(BoxProjection, WeightsAreContinuousSymmetricAndSumToOne) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1, 1);
  const double blends[] = {0.05, 0.2, 0.5, 0.9, 1.0};
  double worstJump = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3d n{u(rng), u(rng), u(rng)};
    const double blend = blends[static_cast<std::size_t>(i) % 5];
    const TriplanarWeights w = boxProjectionWeights(n, blend);
    double sum = 0;
    for (const double wi : w.w) {
      EXPECT_GE(wi, 0);
      EXPECT_LE(wi, 1);
      sum += wi;
    }
    EXPECT_NEAR(sum, 1, 1e-12);
    const Vec3d near = n + 1e-9 * Vec3d{u(rng), u(rng), u(rng)};
    const TriplanarWeights v = boxProjectionWeights(near, blend);
    for (std::size_t k = 0; k < 3; ++k) worstJump = std::max(worstJump, std::abs(w.w[k] - v.w[k]));
    const TriplanarWeights turned = boxProjectionWeights({n.y, n.z, n.x}, blend);
    EXPECT_NEAR(turned.w[0], w.w[1], 1e-12);
    EXPECT_NEAR(turned.w[1], w.w[2], 1e-12);
    EXPECT_NEAR(turned.w[2], w.w[0], 1e-12);
  }
  // A step of 1e-9 in N moves a weight by at most ~1e-9 / blend: no zone's formula jumps.
  EXPECT_LT(worstJump, 1e-6);
}

// Each plane reads Blender's coordinates, mirrored on the sides Cycles mirrors, by the normal it
// shades with: seen from behind (−N), the other side's mirror.
TEST(BoxProjection, PlanesReadBlendersMirroredCoordinates) {
  TriplanarOptions o;
  o.projection = TriplanarProjection::kBox;
  o.tiling = {2, 3};
  o.offset = {0.25, -0.5};
  const Vec3d q{0.3, -0.2, 0.7};
  const Vec3d normals[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const bool behind : {false, true}) {
    for (const Vec3d& n : normals) {
      SineTexture tex;
      SurfacePoint p = pointAt(q, n);
      p.bump.behind = behind;
      triplanarHeightGradient(tex, o, p);
      ASSERT_EQ(tex.count, 1);
      const ProjectionAxis axis = std::abs(n.x) > 0   ? ProjectionAxis::kX
                                  : std::abs(n.y) > 0 ? ProjectionAxis::kY
                                                      : ProjectionAxis::kZ;
      const Vec2d st = boxCoordinates(q, axis, behind ? -n : n);
      EXPECT_NEAR(tex.last.x, o.tiling.x * st.x + o.offset.x, 1e-15) << n.x << n.y << n.z;
      EXPECT_NEAR(tex.last.y, o.tiling.y * st.y + o.offset.y, 1e-15) << n.x << n.y << n.z;
    }
  }
}

// Γ of a Box-projected height is the tangential part of the gradient of the blended volume
// Σ w_i · scale · h(tiling ∘ boxCoordinates_i(P) + offset), weights and mirrors frozen at the
// point, checked against central differences of that volume; front and behind.
TEST(BoxProjection, HeightIsTheProjectedGradientOfTheBlendedVolume) {
  SineTexture tex;
  TriplanarOptions o;
  o.projection = TriplanarProjection::kBox;
  o.boxBlend = 0.6;
  o.tiling = {1.3, 0.7};
  o.offset = {0.2, -0.1};
  o.scale = 0.5;
  std::mt19937_64 rng(32);
  std::uniform_real_distribution<double> u(-1, 1);
  int blended = 0;
  for (int i = 0; i < 400; ++i) {
    SurfacePoint p = pointAt({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
    p.bump.behind = i % 2 == 1;
    const Vec3d seen = p.bump.behind ? -p.normal : p.normal;
    const TriplanarWeights w = boxProjectionWeights(seen, o.boxBlend);
    if (w.active > 1) ++blended;
    auto volume = [&](Vec3d x) {
      double h = 0;
      for (const ProjectionAxis axis : kAxes) {
        const Vec2d st = boxCoordinates(x, axis, seen);
        h += w.w[static_cast<std::size_t>(axis)] * o.scale *
             tex.sample({o.tiling.x * st.x + o.offset.x, o.tiling.y * st.y + o.offset.y}).value;
      }
      return h;
    };
    EXPECT_LT(maxAbsDiff(triplanarHeightGradient(tex, o, p), projectedCentralGradient(volume, p)),
              1e-8);
  }
  EXPECT_GT(blended, 100);  // the blend zones are exercised, not only single planes
}

// Box-projected object-space normals blend as Cycles blends texels: one decoded normal
// Σ w_i n_i, which the layer resolves to (not the blend of each plane's surface gradient).
TEST(BoxProjection, ObjectNormalsBlendTexelsThenDecode) {
  ObjectNormalTexture tex;
  TriplanarOptions o;
  o.projection = TriplanarProjection::kBox;
  o.boxBlend = 0.8;
  const SurfacePoint p = pointAt({0.3, -0.2, 0.5}, {0.5, -0.55, 0.6});
  const TriplanarWeights w = boxProjectionWeights(p.normal, o.boxBlend);
  ASSERT_EQ(w.active, 3);
  Vec3d blend{};
  for (const ProjectionAxis axis : kAxes) {
    const Vec2d st = boxCoordinates(p.position, axis, p.normal);
    blend += w.w[static_cast<std::size_t>(axis)] * (2 * tex.sample(st) - Vec3d{1, 1, 1});
  }
  const Vec3d resolved = resolveNormal(p.normal, triplanarObjectNormalGradient(tex, o, p));
  EXPECT_LT(maxAbsDiff(resolved, normalizeOr(blend, Vec3d{})), 1e-14);
}

// Blender's Mapping node (Point): scale, then the XYZ Euler rotation (x first), then location.
TEST(CoordinateMapping, IsBlendersMappingNode) {
  const double q = kPi / 2;
  const CoordinateMapping turn = CoordinateMapping::fromMappingNode({}, {q, 0, q}, {1, 1, 1});
  EXPECT_LT(maxAbsDiff(turn.apply({0, 1, 0}), Vec3d{0, 0, 1}), 1e-15);  // z first: (−1, 0, 0)
  const CoordinateMapping scaled =
      CoordinateMapping::fromMappingNode({0.5, -1, 2}, {0, 0, q}, {2, 1, 1});
  EXPECT_LT(maxAbsDiff(scaled.apply({1, 0, 0}), Vec3d{0.5, 1, 2}), 1e-15);
  EXPECT_TRUE(CoordinateMapping::fromMappingNode({}, {}, {1, 1, 1}).identity);
  EXPECT_FALSE(scaled.identity);
  // An affine map first (another object's coordinates, the texture space), then the node.
  const CoordinateMapping first =
      CoordinateMapping::affine(Mat3::fromColumns({0, 2, 0}, {1, 0, 0}, {0, 0, -1}), {1, 2, 3});
  const Vec3d p{0.3, -0.7, 1.1};
  EXPECT_LT(maxAbsDiff(scaled.after(first).apply(p), scaled.apply(first.apply(p))), 1e-15);
  EXPECT_EQ(maxAbsDiff(CoordinateMapping{}.after(first).apply(p), first.apply(p)), 0);
  EXPECT_TRUE(CoordinateMapping::affine(Mat3::identity(), {}).identity);
}

// The node's other types: Texture undoes Point (Cycles' mapping_texture), and divides by a zero
// scale as Cycles' safe_divide does (to 0); Vector is Point without the location.
TEST(CoordinateMapping, TextureUndoesPointAndVectorDropsTheLocation) {
  const Vec3d location{0.5, -1, 2}, rotation{0.4, -0.3, 1.2}, scale{2, 0.5, 1.5};
  const CoordinateMapping point = CoordinateMapping::fromMappingNode(location, rotation, scale);
  const CoordinateMapping texture =
      CoordinateMapping::fromMappingNode(location, rotation, scale, MappingType::kTexture);
  const CoordinateMapping vector =
      CoordinateMapping::fromMappingNode(location, rotation, scale, MappingType::kVector);
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int i = 0; i < 20; ++i) {
    const Vec3d p{u(rng), u(rng), u(rng)};
    EXPECT_LT(maxAbsDiff(texture.apply(point.apply(p)), p), 1e-14);
    EXPECT_LT(maxAbsDiff(point.apply(texture.apply(p)), p), 1e-14);
    EXPECT_LT(maxAbsDiff(vector.apply(p), point.apply(p) - location), 1e-15);
  }
  const CoordinateMapping flat =
      CoordinateMapping::fromMappingNode({1, 2, 3}, {}, {2, 0, 4}, MappingType::kTexture);
  EXPECT_LT(maxAbsDiff(flat.apply({5, 7, 11}), Vec3d{2, 0, 2}), 1e-15);
  EXPECT_TRUE(
      CoordinateMapping::fromMappingNode({1, 2, 3}, {}, {1, 1, 1}, MappingType::kVector).identity);
  EXPECT_FALSE(
      CoordinateMapping::fromMappingNode({1, 2, 3}, {}, {1, 1, 1}, MappingType::kTexture).identity);
}

// With a mapping, Γ is still the projected gradient of the height the planes read at P', checked
// by central differences through planarTextureCoordinates, for planar and Box projections.
TEST(CoordinateMapping, SlopesAreThoseOfTheMappedCoordinates) {
  SineTexture tex;
  const CoordinateMapping m =
      CoordinateMapping::fromMappingNode({0.3, -0.2, 0.1}, {0.4, 0.2, 0.7}, {1.5, 0.8, 1.2});
  std::mt19937_64 rng(33);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 100; ++i) {
    const SurfacePoint p = pointAt({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
    const PlanarMapping planar{kAxes[i % 3], {1.3, 0.7}, {0.2, -0.1}};
    TriplanarOptions box;
    box.projection = TriplanarProjection::kBox;
    box.boxBlend = 0.5;
    box.coordinates = m;
    const TriplanarPlanes planes = triplanarPlanes(box, p.normal);
    const auto planarHeight = [&](Vec3d x) {
      return 0.5 * tex.sample(planarTextureCoordinates(m.apply(x), planar)).value;
    };
    const auto boxHeight = [&](Vec3d x) {
      double h = 0;
      for (const WeightedPlane& plane : planes)
        h += plane.weight * tex.sample(planarTextureCoordinates(m.apply(x), plane.mapping)).value;
      return h;
    };
    EXPECT_LT(maxAbsDiff(planarHeightGradient(tex, planar, 0.5, p, m),
                         projectedCentralGradient(planarHeight, p)),
              1e-8);
    EXPECT_LT(
        maxAbsDiff(triplanarHeightGradient(tex, box, p), projectedCentralGradient(boxHeight, p)),
        1e-8);
  }
}

// ---------------------------------------------------------------------------------------------
// Blender's Sphere and Tube projections

/// P' whose Cycles remap 2 · (P' − ½) is @p c.
Vec3d mappedOf(Vec3d c) { return 0.5 * c + Vec3d{0.5, 0.5, 0.5}; }

// u turns about z from the seam at −y (0) through +x (¼), +y (½), −x (¾); the Sphere's v is the
// latitude from the south pole (0) to the north (1), the Tube's the height from c_z = −1 to 1.
// On the z axis and at the centre they are what Cycles returns there.
TEST(WrappedProjection, CoordinatesAtHandComputedPoints) {
  struct Case {
    Vec3d c;
    Vec2d sphere, tube;
  };
  const Case cases[] = {
      {{1, 0, 0}, {0.25, 0.5}, {0.25, 0.5}},
      {{0, 2, 0}, {0.5, 0.5}, {0.5, 0.5}},
      {{-1, 0, 0}, {0.75, 0.5}, {0.75, 0.5}},
      {{0, -1, 0}, {0.0, 0.5}, {0.0, 0.5}},  // atan2(+0, −1) = π: the seam's u = 0 side
      {{1, 0, 1}, {0.25, 0.75}, {0.25, 1.0}},
      {{0, 1, -std::sqrt(3.0)}, {0.5, 1.0 / 6.0}, {0.5, 0.5 * (1 - std::sqrt(3.0))}},
      {{0, 0, 1}, {0.0, 1.0}, {0.0, 0.0}},  // the axis: u = 0; the Tube gives (0, 0)
      {{0, 0, -0.5}, {0.0, 0.0}, {0.0, 0.0}},
      {{0, 0, 0}, {0.0, 0.0}, {0.0, 0.0}},  // the centre
  };
  for (const Case& k : cases) {
    EXPECT_LT(maxAbsDiff(sphereCoordinates(mappedOf(k.c)), k.sphere), 1e-15) << k.c.x << k.c.y;
    EXPECT_LT(maxAbsDiff(tubeCoordinates(mappedOf(k.c)), k.tube), 1e-15) << k.c.x << k.c.y;
  }
  // Just past the seam, on the −x side, u is just below 1.
  EXPECT_NEAR(sphereCoordinates(mappedOf({-1e-9, -1, 0})).x, 1.0, 1e-9);
  // The single lookups: Flat is the Z plane, Sphere and Tube these.
  const Vec3d p{0.3, 0.9, -0.2};
  EXPECT_EQ(planarTextureCoordinates(p, singleLookupMapping(TriplanarProjection::kFlat)),
            (Vec2d{0.3, 0.9}));
  EXPECT_EQ(planarTextureCoordinates(p, singleLookupMapping(TriplanarProjection::kSphere)),
            sphereCoordinates(p));
  EXPECT_EQ(planarTextureCoordinates(
                p, singleLookupMapping(TriplanarProjection::kTube, {2, 3}, {0.5, 0.25})),
            (Vec2d{2 * tubeCoordinates(p).x + 0.5, 3 * tubeCoordinates(p).y + 0.25}));
}

TEST(WrappedProjection, CoordinateGradientsAreTheDerivatives) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  int tested = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3d x{u(rng), u(rng), u(rng)};
    const Vec3d c = 2.0 * (x - Vec3d{0.5, 0.5, 0.5});
    const double su = sphereCoordinates(x).x;
    // Away from the axis, where u is not differentiable, and from the seam, where it jumps.
    if (c.x * c.x + c.y * c.y < 0.01 || su < 0.01 || su > 0.99) continue;
    ++tested;
    for (const PlaneLayout layout : {PlaneLayout::kSphere, PlaneLayout::kTube}) {
      const auto uv = [&](Vec3d y) {
        return layout == PlaneLayout::kSphere ? sphereCoordinates(y) : tubeCoordinates(y);
      };
      const CoordinateGradients g = wrappedCoordinateGradients(x, layout);
      const double e = 1e-6;
      for (std::size_t k = 0; k < 3; ++k) {
        Vec3d d{};
        d[k] = e;
        const Vec2d central = (1 / (2 * e)) * (uv(x + d) - uv(x - d));
        EXPECT_NEAR(g.s[k], central.x, 1e-7 * (1 + std::abs(central.x)));
        EXPECT_NEAR(g.t[k], central.y, 1e-7 * (1 + std::abs(central.y)));
      }
    }
  }
  EXPECT_GT(tested, 300);
}

// A height read through the Sphere or Tube projection (after a Mapping node): Γ is the
// tangential gradient of the height it reads, as planar and triplanar layers' is; the
// triplanar kernel with a single-lookup projection gives the same; projectedTexel reads there.
TEST(WrappedProjection, HeightIsTheProjectedGradientOfTheWrappedHeight) {
  SineTexture tex;
  const CoordinateMapping m =
      CoordinateMapping::fromMappingNode({0.5, 0.45, 0.55}, {0.3, -0.2, 0.4}, {0.6, 0.4, 0.5});
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1, 1);
  int tested = 0;
  for (int i = 0; i < 400; ++i) {
    const SurfacePoint p = pointAt({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
    const Vec3d c = 2.0 * (m.apply(p.position) - Vec3d{0.5, 0.5, 0.5});
    const double su = sphereCoordinates(m.apply(p.position)).x;
    if (c.x * c.x + c.y * c.y < 0.01 || su < 0.01 || su > 0.99) continue;
    ++tested;
    for (const TriplanarProjection projection :
         {TriplanarProjection::kSphere, TriplanarProjection::kTube}) {
      const PlanarMapping lookup = singleLookupMapping(projection, {1.3, 0.7}, {0.2, -0.1});
      const auto height = [&](Vec3d x) {
        return 0.5 * tex.sample(planarTextureCoordinates(m.apply(x), lookup)).value;
      };
      const Vec3d reference = projectedCentralGradient(height, p);
      EXPECT_LT(maxAbsDiff(planarHeightGradient(tex, lookup, 0.5, p, m), reference),
                1e-7 * (1 + length(reference)));
      TriplanarOptions o;
      o.projection = projection;
      o.tiling = lookup.tiling;
      o.offset = lookup.offset;
      o.scale = 0.5;
      o.coordinates = m;
      EXPECT_EQ(triplanarHeightGradient(tex, o, p), planarHeightGradient(tex, lookup, 0.5, p, m));
      HeightNormalTexture normals(tex);
      EXPECT_EQ(projectedTexel(normals, o, p),
                normals.sample(planarTextureCoordinates(m.apply(p.position), lookup)));
    }
  }
  EXPECT_GT(tested, 300);
}

// On the z axis u has no derivative: the slopes along v alone, finite; at the centre, none.
TEST(WrappedProjection, OnTheAxisTheSlopesAreFinite) {
  SineTexture tex;
  for (const Vec3d c : {Vec3d{0, 0, 0.7}, Vec3d{0, 0, -0.3}, Vec3d{0, 0, 0}}) {
    for (const TriplanarProjection projection :
         {TriplanarProjection::kSphere, TriplanarProjection::kTube}) {
      const SurfacePoint p = pointAt(mappedOf(c), {0.3, 0.4, 0.8});
      const Vec3d gamma = planarHeightGradient(tex, singleLookupMapping(projection), 1, p);
      EXPECT_TRUE(isFinite(gamma));
      const CoordinateGradients g = wrappedCoordinateGradients(mappedOf(c), PlaneLayout::kSphere);
      EXPECT_EQ(g.s, Vec3d{});
      EXPECT_EQ(g.t, Vec3d{});
      // The Tube's v grows along z everywhere: 2 · ½ per unit of P'.
      EXPECT_EQ(wrappedCoordinateGradients(mappedOf(c), PlaneLayout::kTube).t, (Vec3d{0, 0, 1}));
    }
  }
}

}  // namespace
}  // namespace sgbake
