// Layers and their composite (seed 001 eq. 34-35): Γ = Σ weight · mask · Γ_i, linearity in the
// heights, masks and weights that skip sampling, invalid layers as values, and every source kind
// dispatched to its kernel.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <vector>

#include "gradient/bump_node.hpp"
#include "gradient/stacking.hpp"
#include "gradient/valid_reflection.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/layers.hpp"
#include "support/analytic_textures.hpp"
#include "support/surface_points.hpp"

namespace sgbake {
namespace {

using test::AnalyticHeight;
using test::maxAbsDiff;
using test::samplePoint;

/// α·h1 + β·h2 as one texture (for the linearity test).
class SumTexture final : public ScalarTexture {
 public:
  SumTexture(double alpha, const ScalarTexture& h1, double beta, const ScalarTexture& h2)
      : alpha_(alpha), beta_(beta), h1_(h1), h2_(h2) {}
  ScalarSample sample(Vec2d st) const override {
    const ScalarSample a = h1_.sample(st), b = h2_.sample(st);
    return {alpha_ * a.value + beta_ * b.value, alpha_ * a.gradient + beta_ * b.gradient};
  }

 private:
  double alpha_, beta_;
  const ScalarTexture &h1_, &h2_;
};

class ConstantTexture final : public ScalarTexture {
 public:
  explicit ConstantTexture(double v) : v_(v) {}
  ScalarSample sample(Vec2d) const override { return {v_, {0, 0}}; }

 private:
  double v_;
};

/// A tangent-space map whose texel varies with (s, t) and stays above the horizon.
class WavyNormalTexture final : public VectorTexture {
 public:
  Vec3d sample(Vec2d st) const override {
    ++count;
    const Vec3d n =
        normalizeOr(Vec3d{0.4 * std::sin(5 * st.x), 0.3 * std::cos(3 * st.y), 1}, Vec3d{});
    return 0.5 * n + Vec3d{0.5, 0.5, 0.5};
  }
  mutable std::atomic<int> count{0};
};

TEST(Composite, IsTheWeightedMaskedSumOfTheSourceGradients) {
  AnalyticHeight h1(0.5, -0.2, 0.1), h2(0, 0.3, 0.2);
  WavyNormalTexture ts;
  ConstantTexture mask(0.25);
  const UvHeightSource a{&h1, 0, 0.7, {2, 2}, {0.1, 0}};
  const TangentNormalSource b{&ts, 1, {}};
  TriplanarSource c;
  c.height = &h2;
  c.options.scale = 0.3;
  const std::vector<Layer> layers{{a, 1.5, {}}, {b, -0.5, {&mask, 1}}, {c, 2.0, {}}};
  std::mt19937_64 rng(31);
  for (int i = 0; i < 200; ++i) {
    const SurfacePoint p = samplePoint(rng);
    const Vec3d expected =
        1.5 * layerGradient(a, p) + (-0.5 * 0.25) * layerGradient(b, p) + 2.0 * layerGradient(c, p);
    EXPECT_LT(maxAbsDiff(compositeGradient(layers, p), expected), 1e-14);
    EXPECT_LT(maxAbsDiff(perturbedNormal(p, layers), resolveNormal(p.normal, expected)), 1e-14);
  }
}

// Eq. 35: Γ(α h1 + β h2) = α Γ(h1) + β Γ(h2), for UV heights, planar and triplanar projections.
TEST(Composite, IsLinearInTheHeights) {
  AnalyticHeight h1(0.5, -0.2, 0.1), h2(-0.1, 0.3, 0.25);
  const double alpha = 0.7, beta = -1.3;
  SumTexture sum(alpha, h1, beta, h2);
  std::mt19937_64 rng(32);
  for (int i = 0; i < 200; ++i) {
    const SurfacePoint p = samplePoint(rng);
    const auto check = [&](auto make) {
      const std::vector<Layer> separate{{make(&h1), alpha, {}}, {make(&h2), beta, {}}};
      const std::vector<Layer> combined{{make(&sum), 1.0, {}}};
      EXPECT_LT(maxAbsDiff(compositeGradient(separate, p), compositeGradient(combined, p)), 1e-13);
    };
    check([i](const ScalarTexture* t) {
      return UvHeightSource{t, i % 2, 0.8, {1.5, 0.5}, {0, 0}};
    });
    check([](const ScalarTexture* t) {
      PlanarSource s;
      s.height = t;
      s.mapping.axis = ProjectionAxis::kY;
      return s;
    });
    check([](const ScalarTexture* t) {
      TriplanarSource s;
      s.height = t;
      s.options.sharpness = 2;
      return s;
    });
  }
}

// Eq. 34: the weight is the height scale.
TEST(Composite, WeightScalesLikeTheHeightScale) {
  AnalyticHeight h(0.5, -0.2, 0.1);
  std::mt19937_64 rng(33);
  const SurfacePoint p = samplePoint(rng);
  const std::vector<Layer> weighted{{UvHeightSource{&h, 0, 1.0}, 2.5, {}}};
  const std::vector<Layer> scaled{{UvHeightSource{&h, 0, 2.5}, 1.0, {}}};
  EXPECT_LT(maxAbsDiff(compositeGradient(weighted, p), compositeGradient(scaled, p)), 1e-15);
}

TEST(Composite, ZeroWeightsAndZeroMasksDoNotSample) {
  AnalyticHeight h(0.5, -0.2, 0.1);
  ConstantTexture zero(0), negative(-3), big(7), half(0.5);
  std::mt19937_64 rng(34);
  const SurfacePoint p = samplePoint(rng);
  const UvHeightSource src{&h, 0, 1.0};
  EXPECT_EQ(compositeGradient(std::vector<Layer>{{src, 0.0, {}}}, p), Vec3d{});
  EXPECT_EQ(compositeGradient(std::vector<Layer>{{src, 1.0, {&zero, 0}}}, p), Vec3d{});
  EXPECT_EQ(compositeGradient(std::vector<Layer>{{src, 1.0, {&negative, 0}}}, p), Vec3d{});  // → 0
  EXPECT_EQ(compositeGradient(std::vector<Layer>{{src, std::nan(""), {}}}, p), Vec3d{});
  EXPECT_EQ(h.count, 0);
  const Vec3d full = layerGradient(src, p);
  EXPECT_EQ(h.count, 1);
  EXPECT_EQ(compositeGradient(std::vector<Layer>{{src, 1.0, {&big, 1}}}, p), full);  // clamped to 1
  EXPECT_LT(
      maxAbsDiff(compositeGradient(std::vector<Layer>{{src, 1.0, {&half, 0}}}, p), 0.5 * full),
      1e-16);
  EXPECT_EQ(compositeGradient(std::vector<Layer>{{src, 1.0, {&half, 3}}}, p), Vec3d{});  // no set 3
  EXPECT_EQ(compositeGradient({}, p), Vec3d{});
  EXPECT_LT(maxAbsDiff(perturbedNormal(p, {}), p.normal), 1e-15);
}

// A height layer on the layers above is Cycles' Bump node with its Normal input linked to the
// node before it (svm_node_set_bump): with screen differentials ∂P/∂x, ∂P/∂y in the plane of
// Ng and the height's differences along them, R_x = ∂P/∂y × n₁, R_y = n₁ × ∂P/∂x,
// det = ⟨∂P/∂x, R_x⟩, n₂ = normalize(|det| n₁ − sign(det) (Δh_x R_x + Δh_y R_y)) and the
// Strength blend normalize(s n₂ + (1 − s) n₁). A linear height makes the differences exact, so
// the composite must give n₂ to round-off for any choice of the two differentials; adding the
// bump's gradient to the normal map's instead is off by far more.
TEST(Composite, ALayerOnTheLayersAboveIsCyclesBumpOnTheirNormal) {
  std::mt19937_64 rng(5);
  AnalyticHeight ramp(0.8, -0.5, 0);  // linear
  WavyNormalTexture ts;
  std::uniform_real_distribution<double> u(-1, 1);
  double largestSumError = 0;
  for (int trial = 0; trial < 50; ++trial) {
    SurfacePoint p = samplePoint(rng);
    const Vec3d ng = p.normal;  // the plane of ∂P/∂u, ∂P/∂v
    // A smooth normal up to ~14° off the face's.
    p.normal = normalizeOr(ng + 0.15 * Vec3d{u(rng), u(rng), u(rng)}, ng);
    p.geometricNormal = ng;
    p.tangent = normalizeOr(p.tangent - dot(p.tangent, p.normal) * p.normal, Vec3d{1, 0, 0});
    const double scale = 0.05 + 0.1 * (u(rng) + 1), weight = 1 + 0.5 * u(rng);
    const double strength = trial % 3 == 0 ? 1.0 : 0.5 + 0.4 * u(rng);
    const TangentNormalSource map{&ts, 1, {}};
    Layer bump{UvHeightSource{&ramp, 0, scale}, weight, {}};
    std::get<UvHeightSource>(bump.source).strength = strength;
    bump.base = LayerBase::kLayersAbove;
    const std::vector<Layer> layers{Layer{map, 1.0, {}}, bump};

    // Cycles: the normal the Normal Map node hands on, and the Bump node on it.
    const Vec3d n1 = normalizeOr(p.normal - layerGradient(map, p), p.normal);
    const Vec2d dx{0.01 * (1 + u(rng)), 0.004 * u(rng)}, dy{0.003 * u(rng), 0.01 * (1 + u(rng))};
    const Vec3d dPdx = dx.x * p.uv[0].dPdu + dx.y * p.uv[0].dPdv;
    const Vec3d dPdy = dy.x * p.uv[0].dPdu + dy.y * p.uv[0].dPdv;
    const double hx = weight * scale * (0.8 * dx.x - 0.5 * dx.y);  // the ramp's differences
    const double hy = weight * scale * (0.8 * dy.x - 0.5 * dy.y);
    const Vec3d rx = cross(dPdy, n1), ry = cross(n1, dPdx);
    const double det = dot(dPdx, rx);
    const Vec3d bumped =
        normalizeOr(std::abs(det) * n1 - (det < 0 ? -1.0 : 1.0) * (hx * rx + hy * ry), n1);
    const Vec3d expected = normalizeOr(strength * bumped + (1 - strength) * n1, n1);

    // Cycles' guard (validReflectionNormal) leaves both alone here: what is compared is the bump.
    ASSERT_TRUE(gradient_detail::reflectsAboveSurface(n1, ng, p.normal)) << trial;
    ASSERT_TRUE(gradient_detail::reflectsAboveSurface(expected, ng, p.normal)) << trial;
    const Vec3d ours = resolveNormal(p.normal, compositeGradient(layers, p));
    EXPECT_LT(length(ours - expected), 1e-12) << "trial " << trial;
    Layer added = bump;
    added.base = LayerBase::kSurface;
    const std::vector<Layer> sum{Layer{map, 1.0, {}}, added};
    largestSumError = std::max(
        largestSumError, length(resolveNormal(p.normal, compositeGradient(sum, p)) - expected));
  }
  EXPECT_GT(largestSumError, 1e-2);
}

// On nothing (no layers above, or all masked out) a layer on the layers above is the same bump
// as on the surface; a normal map cannot be one (its node has no Normal input).
TEST(Composite, ALayerOnNothingIsOnTheSurfaceAndNormalMapsCannotBeOnTop) {
  std::mt19937_64 rng(9);
  AnalyticHeight h(0.5, -0.2, 0.1);
  for (int trial = 0; trial < 20; ++trial) {
    const SurfacePoint p = samplePoint(rng);
    // (A weight scales the height of a layer on the layers above, before its Strength blend,
    // and the Γ of one on the surface, after it: the two agree when either is 1.)
    const bool blend = trial % 2 == 0;
    Layer onTop{UvHeightSource{&h, 0, 0.3}, blend ? 1.0 : 0.7, {}};
    std::get<UvHeightSource>(onTop.source).strength = blend ? 0.75 : 1.0;
    const std::vector<Layer> surface{onTop};
    onTop.base = LayerBase::kLayersAbove;
    const std::vector<Layer> above{onTop};
    EXPECT_LT(length(resolveNormal(p.normal, compositeGradient(above, p)) -
                     resolveNormal(p.normal, compositeGradient(surface, p))),
              1e-12)
        << trial;
  }
  WavyNormalTexture ts;
  Layer map{TangentNormalSource{&ts, 0, {}}, 1.0, {}};
  map.base = LayerBase::kLayersAbove;
  const Status refused = validateLayers(std::vector<Layer>{map}, 1);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("layer 0"), std::string::npos) << refused.error().message;
  EXPECT_NE(refused.error().message.find("only a height"), std::string::npos);
}

TEST(Layers, InvalidLayersContributeNothingAndAreReported) {
  AnalyticHeight h(0.5, -0.2, 0.1);
  WavyNormalTexture ts;
  std::mt19937_64 rng(35);
  const SurfacePoint p = samplePoint(rng);
  EXPECT_EQ(layerGradient(UvHeightSource{}, p), Vec3d{});
  EXPECT_EQ(layerGradient(UvHeightSource{&h, 2}, p), Vec3d{});  // the point has sets 0 and 1
  EXPECT_EQ(layerGradient(TangentNormalSource{}, p), Vec3d{});
  EXPECT_EQ(layerGradient(ObjectNormalSource{}, p), Vec3d{});
  EXPECT_EQ(layerGradient(VolumeSource{}, p), Vec3d{});
  TriplanarSource wrongTexture;
  wrongTexture.kind = ProjectedKind::kTangentNormal;
  wrongTexture.height = &h;  // a height texture for a normal-map kind
  EXPECT_EQ(layerGradient(wrongTexture, p), Vec3d{});

  const std::vector<Layer> good{{UvHeightSource{&h, 1}, 1, {}},
                                {TangentNormalSource{&ts, 0, {}}, 1, {}}};
  EXPECT_TRUE(validateLayers(good, 2).ok());

  auto message = [](const std::vector<Layer>& layers, int sets) {
    const Status s = validateLayers(layers, sets);
    EXPECT_FALSE(s.ok());
    return s.ok() ? std::string() : s.error().message;
  };
  EXPECT_EQ(message({{UvHeightSource{&h, 1}, 1, {}}}, 1),
            "layer 0 (UV height map): UV set 1 does not exist (the mesh has 1 usable)");
  EXPECT_EQ(message({good[0], {TangentNormalSource{}, 1, {}}}, 2),
            "layer 1 (tangent-space normal map): no texture");
  EXPECT_EQ(message({{wrongTexture, 1, {}}}, 1),
            "layer 0 (triplanar projection): no normal-map texture");
  EXPECT_EQ(message({{UvHeightSource{&h, 0}, std::nan(""), {}}}, 1),
            "layer 0 (UV height map): weight is not finite");
  EXPECT_EQ(message({{UvHeightSource{&h, 0, 1, {std::nan(""), 1}}, 1, {}}}, 1),
            "layer 0 (UV height map): tiling is not finite");
  EXPECT_EQ(message({{VolumeSource{}, 1, {}}}, 0), "layer 0 (height volume): no volume");
  EXPECT_EQ(message({{UvHeightSource{&h, 0}, 1, {&h, 5}}}, 1),
            "layer 0 (UV height map): mask: UV set 5 does not exist (the mesh has 1 usable)");
  EXPECT_EQ(h.count, 0);  // validation never samples
}

// A tangent-space map on UV set 1 equals the same map on UV set 0 when the two sets are
// identical and the MikkTSpace frame of set 0 is the UV-derivative frame.
TEST(Layers, TangentNormalOnASecondIdenticalUvSetEqualsTheFirst) {
  WavyNormalTexture ts;
  std::mt19937_64 rng(36);
  for (int i = 0; i < 200; ++i) {
    SurfacePoint p = samplePoint(rng);
    p.uv[1] = p.uv[0];
    TangentNormalSource first{&ts, 0, {}}, second{&ts, 1, {}};
    first.options.tiling = second.options.tiling = {3, 2};
    const Vec3d a = layerGradient(first, p);   // MikkTSpace frame
    const Vec3d b = layerGradient(second, p);  // UV-derivative frame of set 1
    EXPECT_LT(maxAbsDiff(a, b), 1e-14);
    EXPECT_GT(length(a), 0.0);
  }
}

TEST(Layers, VolumeSourceProjectsTheVolumeGradient) {
  auto sine = DirectionalSine::create({0.2, 1.5, {1, 2, 3}, 0.3});
  ASSERT_TRUE(sine.ok());
  std::mt19937_64 rng(37);
  for (int i = 0; i < 100; ++i) {
    const SurfacePoint p = samplePoint(rng);
    const Vec3d g = sine->analyticGradient(p.position);
    const Vec3d expected = 0.5 * (g - dot(g, p.normal) * p.normal);
    const Vec3d analytic =
        layerGradient(VolumeSource{&*sine, GradientScheme::kAnalytic, 0, 0.5}, p);
    EXPECT_LT(maxAbsDiff(analytic, expected), 1e-15);
    const Vec3d central =
        layerGradient(VolumeSource{&*sine, GradientScheme::kCentral, defaultStep(4), 0.5}, p);
    EXPECT_LT(maxAbsDiff(central, expected), 1e-8);
  }
}

// Heights read at positions take Blender's Bump Strength as UV heights do: the bumped normal
// blended with N (withNormalMapStrength), on the surface and on the layers above alike; a normal
// kind's is its scale, and the field is not read.
TEST(Layers, HeightsReadAtPositionsTakeTheBumpStrength) {
  auto sine = DirectionalSine::create({0.2, 1.5, {1, 2, 3}, 0.3});
  ASSERT_TRUE(sine.ok());
  const AnalyticHeight heights(0.3, -0.2, 0.05);
  WavyNormalTexture wavy;
  TriplanarSource box;
  box.height = &heights;
  box.options.projection = TriplanarProjection::kBox;
  box.options.boxBlend = 0.3;
  box.options.scale = 0.2;
  PlanarSource planar;
  planar.height = &heights;
  planar.scale = 0.3;
  const std::vector<LayerSource> sources{VolumeSource{&*sine, GradientScheme::kAnalytic, 0, 0.5},
                                         planar, box};
  std::mt19937_64 rng(71);
  for (int i = 0; i < 30; ++i) {
    SurfacePoint p = samplePoint(rng);
    p.geometricNormal = p.normal;
    for (const LayerSource& full : sources) {
      LayerSource half = full;
      std::visit(
          [](auto& s) {
            if constexpr (requires { s.strength; }) s.strength = 0.5;
          },
          half);
      EXPECT_EQ(gradient_detail::bumpStrength(half), 0.5);
      const Vec3d gamma = layerGradient(full, p);
      EXPECT_GT(length(gamma), 0);
      EXPECT_LT(maxAbsDiff(layerGradient(half, p), withNormalMapStrength(gamma, p.normal, 0.5)),
                1e-15);
      // On the layers above (here: none), the same blend of normals.
      Layer above{half, 1.0, {}};
      above.base = LayerBase::kLayersAbove;
      EXPECT_LT(maxAbsDiff(resolveNormal(p.normal, compositeGradient(std::vector{above}, p)),
                           resolveNormal(p.normal, layerGradient(half, p))),
                1e-12);
    }
  }
  TriplanarSource normals;
  normals.kind = ProjectedKind::kObjectNormal;
  normals.normals = &wavy;
  normals.strength = 0.5;  // not a normal kind's: its scale is
  EXPECT_EQ(gradient_detail::bumpStrength(normals), 1);
}

// On a triangle whose shading normal N leans from its geometric normal Ng, a height defined in
// space takes its slopes along the triangle's plane, as Cycles' Bump node does (and as eq. 31
// does for UV heights): Γ ⊥ N with ⟨Γ, a⟩ = ⟨∇h, a⟩ for every a ⊥ Ng. Where N = Ng it is the
// plain projection.
TEST(Layers, HeightsInSpaceTakeTheirSlopesAlongTheTrianglesPlane) {
  auto sine = DirectionalSine::create({0.2, 1.5, {1, 2, 3}, 0.3});
  ASSERT_TRUE(sine.ok());
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 100; ++i) {
    SurfacePoint p = samplePoint(rng);
    const Vec3d ng = p.normal;  // samplePoint's N is its frame's geometric normal
    p.geometricNormal = ng;
    const VolumeSource volume{&*sine, GradientScheme::kAnalytic, 0, 0.5};
    const Vec3d plain = layerGradient(volume, p);
    const Vec3d g = 0.5 * sine->analyticGradient(p.position);
    EXPECT_LT(maxAbsDiff(plain, g - dot(g, ng) * ng), 1e-15);
    // Lean N by up to ~60 degrees.
    p.normal = normalizeOr(ng + Vec3d{u(rng), u(rng), u(rng)}, ng);
    if (dot(p.normal, ng) < 0.3) continue;
    const Vec3d gamma = layerGradient(volume, p);
    EXPECT_NEAR(dot(gamma, p.normal), 0, 1e-14);
    Vec3d a, b;
    gradient_detail::cyclesOrthonormals(ng, a, b);  // two directions in the triangle's plane
    EXPECT_NEAR(dot(gamma, a), dot(g, a), 1e-14);
    EXPECT_NEAR(dot(gamma, b), dot(g, b), 1e-14);
  }
}

// Seen from behind (backFacingNormal), Cycles bumps −N: a UV height's slopes, read through the
// flipped ∂P/∂u, ∂P/∂v, flip with it, so its bump is the front one flipped; a height read at
// positions keeps its slopes, so its Γ enters negated.
TEST(Layers, BehindAPointHeightsReadAtPositionsKeepTheirSlopes) {
  auto sine = DirectionalSine::create({0.2, 1.5, {1, 2, 3}, 0.3});
  ASSERT_TRUE(sine.ok());
  const AnalyticHeight heights(0.3, -0.2, 0.05);
  std::mt19937_64 rng(43);
  for (int i = 0; i < 50; ++i) {
    SurfacePoint p = samplePoint(rng);
    const Vec3d ng = -p.normal;  // N faces away from its triangle
    p.geometricNormal = ng;
    const Layer volume{VolumeSource{&*sine, GradientScheme::kAnalytic, 0, 0.5}, 1.0, {}};
    const Layer uv{UvHeightSource{&heights, 0, 0.5}, 1.0, {}};
    const Vec3d volumeGamma = layerGradient(volume.source, p);
    const Vec3d uvGamma = layerGradient(uv.source, p);
    const std::vector<Layer> volumes{volume}, uvs{uv};
    EXPECT_LT(maxAbsDiff(gradient_detail::backFacingNormal(volumes, p),
                         gradient_detail::backFacingGuarded(p.normal, -volumeGamma, ng)),
              1e-15);
    EXPECT_LT(maxAbsDiff(gradient_detail::backFacingNormal(uvs, p),
                         gradient_detail::backFacingGuarded(p.normal, uvGamma, ng)),
              1e-15);
    EXPECT_TRUE(gradient_detail::readsHeightsAtPosition(volume.source));
    EXPECT_FALSE(gradient_detail::readsHeightsAtPosition(uv.source));
  }
}

TEST(Layers, PlanarAndObjectSpaceSourcesDispatchToTheirKernels) {
  AnalyticHeight h(0.5, -0.2, 0.1);
  WavyNormalTexture ts;
  std::mt19937_64 rng(38);
  const SurfacePoint p = samplePoint(rng);
  PlanarSource planar;
  planar.kind = ProjectedKind::kTangentNormal;
  planar.normals = &ts;
  planar.mapping = {ProjectionAxis::kX, {2, 1}, {0, 0.5}};
  planar.scale = 0.5;
  EXPECT_EQ(layerGradient(planar, p), planarTangentNormalGradient(ts, planar.mapping, 0.5, p));
  const ObjectNormalSource os{&ts, 1, {2, 2}, {0, 0}, 0.5};
  const Vec2d st = textureCoordinates(p.uv[1].uv, {2, 2}, {0, 0});
  EXPECT_EQ(
      layerGradient(os, p),
      withNormalMapStrength(gradientFromObjectNormal(decodeNormalTexel(ts.sample(st)), p.normal),
                            p.normal, 0.5));
}

// No NaN from any layer kind at random points with extreme parameters (1e±8 scales, tilings and
// weights, grazing normals, degenerate frames).
// A normal map whose texels Blender's Box projection reads (TangentNormalSource::projection,
// ObjectNormalSource::projection: an Image Texture with Projection Box before a Normal Map node)
// decodes the blended colour exactly as the same map read through a UV set decodes a texel of
// that colour: Strength, frames and guards are the normal map's, and the colour is blended
// before it is decoded.
TEST(Layers, AProjectedNormalMapDecodesTheColourReadAsAUvTexel) {
  class Colour final : public VectorTexture {
   public:
    Vec3d colour;
    Vec3d sample(Vec2d) const override { return colour; }
  };
  WavyNormalTexture wavy;
  TriplanarOptions box;
  box.projection = TriplanarProjection::kBox;
  box.boxBlend = 0.4;
  box.tiling = {1.5, 0.5};
  box.coordinates = CoordinateMapping::fromMappingNode({0.1, 0.2, 0}, {0.3, 0, 0.2}, {1, 2, 1});
  std::mt19937_64 rng(61);
  int blended = 0;
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (int i = 0; i < 60; ++i) {
    // samplePoint's normals are near z: turned, to face every side of the box.
    SurfacePoint p = samplePoint(rng);
    const Mat3 r =
        CoordinateMapping::fromMappingNode({}, {angle(rng), angle(rng), 0}, {1, 1, 1}).linear;
    p.normal = r * p.normal;
    p.tangent = r * p.tangent;
    for (UvFrame& frame : p.uv) {
      frame.dPdu = r * frame.dPdu;
      frame.dPdv = r * frame.dPdv;
    }
    Colour same;
    same.colour = projectedTexel(wavy, box, p);
    blended += triplanarPlanes(box, p.normal).count > 1;
    TangentNormalSource tangentBox{&wavy, 1, {}};
    tangentBox.options.strength = 0.7;
    tangentBox.projection = box;
    TangentNormalSource tangentUv{&same, 1, {}};
    tangentUv.options.strength = 0.7;
    EXPECT_EQ(layerGradient(tangentBox, p), layerGradient(tangentUv, p)) << i;
    ObjectNormalSource objectBox{&wavy};
    objectBox.strength = 1.3;
    objectBox.projection = box;
    ObjectNormalSource objectUv{&same};
    objectUv.strength = 1.3;
    EXPECT_EQ(layerGradient(objectBox, p), layerGradient(objectUv, p)) << i;
    EXPECT_GT(length(layerGradient(objectBox, p)), 0) << i;
    // An object-space map read by the projection needs no UV set; a tangent-space one its frame.
    SurfacePoint bare = p;
    bare.numUvSets = 0;
    EXPECT_EQ(layerGradient(objectBox, bare), layerGradient(objectBox, p)) << i;
    EXPECT_EQ(layerGradient(tangentBox, bare), Vec3d{}) << i;
  }
  EXPECT_GT(blended, 10);  // points where the Box blends planes were among them
  // A blend that cancels (the colour (0.5, 0.5, 0.5) decodes to the zero vector) bumps nothing.
  Colour grey;
  grey.colour = {0.5, 0.5, 0.5};
  SurfacePoint p = samplePoint(rng);
  TangentNormalSource greyTangent{&grey, 0, {}};
  greyTangent.projection = box;
  ObjectNormalSource greyObject{&grey};
  greyObject.projection = box;
  for (const LayerSource& source : std::vector<LayerSource>{greyTangent, greyObject}) {
    const Vec3d gamma = layerGradient(source, p);
    EXPECT_TRUE(isFinite(gamma));
    EXPECT_LT(length(gamma), 1e-12);
  }
  // Blender's Flat projection reads the (x, y) plane of the mapped coordinates, whatever the
  // normal; sgbake's own blend is no read of Blender's.
  TriplanarOptions flat = box;
  flat.projection = TriplanarProjection::kFlat;
  for (int i = 0; i < 10; ++i) {
    const SurfacePoint q = samplePoint(rng);
    const Vec3d at = flat.coordinates.apply(q.position);
    EXPECT_EQ(projectedTexel(wavy, flat, q),
              wavy.sample(Vec2d{flat.tiling.x * at.x, flat.tiling.y * at.y} + flat.offset));
    // Its Sphere and Tube projections wrap the image around z, whatever the normal too.
    TriplanarOptions sphere = flat, tube = flat;
    sphere.projection = TriplanarProjection::kSphere;
    tube.projection = TriplanarProjection::kTube;
    const Vec2d su = sphereCoordinates(at), tu = tubeCoordinates(at);
    EXPECT_EQ(projectedTexel(wavy, sphere, q),
              wavy.sample(Vec2d{flat.tiling.x * su.x, flat.tiling.y * su.y} + flat.offset));
    EXPECT_EQ(projectedTexel(wavy, tube, q),
              wavy.sample(Vec2d{flat.tiling.x * tu.x, flat.tiling.y * tu.y} + flat.offset));
  }
  TangentNormalSource blendedRead{&wavy, 0, {}};
  blendedRead.projection = box;
  blendedRead.projection->projection = TriplanarProjection::kBlended;
  const Status status = validateLayers(std::vector<Layer>{{blendedRead, 1.0, {}}}, 2);
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().message,
            "layer 0 (tangent-space normal map): its projected read must be one of Blender's "
            "projections (Box, Flat, Sphere, Tube)");
}

TEST(Layers, NoNanForExtremeParameters) {
  AnalyticHeight h(0.5, -0.2, 0.1);
  WavyNormalTexture ts;
  auto sine = DirectionalSine::create({0.2, 1.5, {1, 2, 3}, 0.3});
  ASSERT_TRUE(sine.ok());
  std::mt19937_64 rng(39);
  const double scales[] = {1e-8, 1, 1e8};
  for (const double s : scales) {
    for (const double t : scales) {
      for (const ProjectedKind kind :
           {ProjectedKind::kHeight, ProjectedKind::kTangentNormal, ProjectedKind::kObjectNormal}) {
        TriplanarSource tri;
        tri.kind = kind;
        tri.height = &h;
        tri.normals = &ts;
        tri.options.scale = s;
        tri.options.tiling = {t, t};
        // Normal maps read by Blender's Box projection (Blend 1: the planes blended widely).
        TriplanarOptions box;
        box.projection = TriplanarProjection::kBox;
        box.boxBlend = 1;
        box.tiling = {t, t};
        TangentNormalSource tangentBox{
            &ts, 1, {NormalMapGreen::kOpenGL, TangentFrameChoice::kAuto, s, {t, t}}};
        tangentBox.projection = box;
        ObjectNormalSource objectBox{&ts, 0, {t, t}, {0, 0}, s};
        objectBox.projection = box;
        VolumeSource weak{&*sine, GradientScheme::kAnalytic, 0, s};
        weak.strength = 1 / s;  // a Bump Strength far out of range either way
        const std::vector<Layer> layers{
            {UvHeightSource{&h, 0, s, {t, t}}, s, {}},
            {TangentNormalSource{
                 &ts, 1, {NormalMapGreen::kDirectX, TangentFrameChoice::kAuto, s, {t, t}}},
             1,
             {}},
            {ObjectNormalSource{&ts, 0, {t, t}, {0, 0}, s}, 1, {}},
            {VolumeSource{&*sine, GradientScheme::kTetrahedral, 1e-3 * t, s}, 1, {}},
            {tri, 1 / s, {}},
            {tangentBox, 1, {}},
            {objectBox, 1, {}},
            {weak, 1, {}}};
        for (int i = 0; i < 50; ++i) {
          SurfacePoint p = samplePoint(rng);
          if (i % 5 == 0) p.uv[0].dPdv = p.uv[0].dPdu;  // degenerate UV frame
          if (i % 5 == 1) p.normal = normalizeOr(Vec3d{1, 1e-9, 0}, Vec3d{});  // grazing axes
          if (i % 5 == 2) p.tangent = {};  // zero MikkTSpace tangent
          p.position = t * p.position;
          const Vec3d gamma = compositeGradient(layers, p);
          ASSERT_TRUE(isFinite(gamma)) << s << " " << t << " " << i;
          const Vec3d n = perturbedNormal(p, layers, cofactor(Mat3::diagonal({s, 1, 1 / t})));
          ASSERT_TRUE(isFinite(n));
          EXPECT_NEAR(length(n), 1.0, 1e-12);
        }
      }
    }
  }
}

}  // namespace
}  // namespace sgbake
