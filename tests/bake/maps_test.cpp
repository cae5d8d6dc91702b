// The map kinds against closed forms: a flat plane, a linear height field (constant exact
// answer), and Blender's per-texel frame (T, N, sign interpolated; inverse, not transpose) on a
// hand-built triangle with hand-made tangents.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <span>
#include <vector>

#include "bake/texel_frame.hpp"
#include "bake_test_util.hpp"
#include "sgbake/bake/bake.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/corners.hpp"
#include "sgbake/gradient/volume.hpp"
#include "support/analytic_textures.hpp"
#include "support/parametric_mesh.hpp"

namespace sgbake {
namespace {

constexpr double kFloatTol = 2e-6;  // values are stored as float

Vec3d encode(Vec3d n) { return {0.5 * n.x + 0.5, 0.5 * n.y + 0.5, 0.5 * n.z + 0.5}; }

void expectNear(Vec3d a, Vec3d b, double tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

/// A plane P = (Lx·u, Ly·v, 0) over UV [0.1, 0.9]², as a grid of quads (UV = grid parameter).
Mesh scaledPlane(double lx, double ly) {
  return test::gridMesh(
      [&](double s, double t) {
        const double u = 0.1 + 0.8 * s, v = 0.1 + 0.8 * t;
        return test::SurfacePoint{{lx * u, ly * v, 0}, {0, 0, 1}, {lx, 0, 0}, {0, ly, 0}};
      },
      4, 3, [](double s, double t) { return Vec2d{0.1 + 0.8 * s, 0.1 + 0.8 * t}; });
}

/// Calls check(x, y, at) for every fully covered texel of @p image (x right, y up; `at` names
/// it for messages); returns how many there were.
template <class Check>
int forEachCoveredTexel(const FloatImage& image, const Check& check) {
  int covered = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (test::coverageUp(image, x, y) != 1.0f) continue;
      ++covered;
      check(x, y, std::to_string(x) + "," + std::to_string(y));
    }
  }
  return covered;
}

Result<FloatImage> bake(const Mesh& mesh, const CornerTangents* tangents, std::span<const Layer> layers,
                        MapKind kind, int size = 32, int samples = 1) {
  BakeSettings s;
  s.map = kind;
  s.width = size;
  s.height = size;
  s.samples = samples;
  return bakeMap({&mesh, tangents, layers}, s);
}

TEST(Maps, NamesChannelsAndTangentNeeds) {
  for (const MapKind k : {MapKind::kTangentNormal, MapKind::kObjectNormal, MapKind::kHeight, MapKind::kDerivative,
                          MapKind::kSurfaceGradient, MapKind::kTangent, MapKind::kBitangent, MapKind::kMask}) {
    const Result<MapKind> parsed = parseMapKind(mapKindName(k));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, k);
  }
  EXPECT_EQ(mapChannels(MapKind::kDerivative), 2);
  EXPECT_EQ(mapChannels(MapKind::kHeight), 1);
  EXPECT_EQ(mapChannels(MapKind::kObjectNormal), 3);
  EXPECT_TRUE(mapNeedsTangents(MapKind::kTangentNormal));
  EXPECT_FALSE(mapNeedsTangents(MapKind::kObjectNormal));
  const Result<MapKind> bad = parseMapKind("normal");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("'normal'"), std::string::npos);
  EXPECT_NE(bad.error().message.find("tangent-normal"), std::string::npos);
}

TEST(Maps, FlatPlaneWithoutLayersBakesTheFlatNormal) {
  const Mesh mesh = scaledPlane(2, 3);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  for (const MapKind kind : {MapKind::kTangentNormal, MapKind::kObjectNormal}) {
    const Result<FloatImage> image = bake(mesh, &*tangents, {}, kind);
    ASSERT_TRUE(image.ok()) << image.error().message;
    int covered = 0;
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        const Vec2d uv = bakeSampleUv(x + 0.5, y + 0.5, 32, 32);
        const double u = uv.x, v = uv.y;
        const bool inside = u > 0.1 && u < 0.9 && v > 0.1 && v < 0.9;
        ASSERT_EQ(test::coverageUp(*image, x, y), inside ? 1.0f : 0.0f);
        const Vec3d c = test::pixelUp(*image, x, y);
        if (inside) {
          ++covered;
          EXPECT_EQ(c.x, 0.5) << mapKindName(kind) << " " << x << "," << y;
          EXPECT_EQ(c.y, 0.5) << mapKindName(kind) << " " << x << "," << y;
          EXPECT_EQ(c.z, 1.0) << mapKindName(kind) << " " << x << "," << y;
        } else {
          const Vec3d background = kind == MapKind::kTangentNormal ? Vec3d{0.5, 0.5, 1.0} : Vec3d{0, 0, 0};
          EXPECT_EQ(c, background);
        }
      }
    }
    EXPECT_EQ(covered, 26 * 26);
  }
}

TEST(Maps, AFlatNonPlanarQuadShowsEachTrianglesNormal) {
  // Blender 3.4 (Cycles' Ng) bakes a flat-shaded quad whose corners are not coplanar with the
  // normal of each of its two triangles (0-1-2 and 0-2-3), not the polygon's; smooth, with the
  // same corner normals, it is their interpolation.
  const std::vector<Vec3f> positions{{0, 0, 0}, {1, 0, 0.4f}, {1, 1, 0}, {0, 1, 0.1f}};
  const std::vector<Vec2f> uvs{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const Vec3d polygon = normalizeOr(Vec3d{-0.1467348, 0.1467348, 0.9782320}, {});
  Mesh mesh = test::polygonMesh(positions, {{0, 1, 2, 3}}, uvs, cast<float>(polygon));
  const Vec3d first = normalizeOr(cross(Vec3d{1, 0, 0.4}, Vec3d{1, 1, 0}), {});
  const Vec3d second = normalizeOr(cross(Vec3d{1, 1, 0}, Vec3d{0, 1, 0.1}), {});
  for (const auto& [flagged, autoSmooth] :
       {std::pair{true, false}, std::pair{false, false}, std::pair{true, true}}) {
    // With Blender's Auto Smooth on, Cycles shades flat faces with their corner normals too.
    const bool flat = flagged && !autoSmooth;
    mesh.faceFlat = {static_cast<std::uint8_t>(flagged ? 1 : 0)};
    mesh.autoSmooth = autoSmooth;
    const Result<FloatImage> image = bake(mesh, nullptr, {}, MapKind::kObjectNormal, 16);
    ASSERT_TRUE(image.ok()) << image.error().message;
    // Texel (12, 3) lies in 0-1-2, (3, 12) in 0-2-3 (y up).
    expectNear(test::pixelUp(*image, 12, 3), encode(flat ? first : polygon), 1e-6, "first");
    expectNear(test::pixelUp(*image, 3, 12), encode(flat ? second : polygon), 1e-6, "second");
  }
}

TEST(Maps, BackFacingTexelsBakeWhatCyclesShadesFromBehind) {
  // A plane z = 0 (Ng = +z) whose corner normals all lean past it, N = (0.8, 0, −0.6): every
  // texel is back-facing (⟨N, Ng⟩ < 0). Cycles shades it from behind, and the bumped normal it
  // bakes is the front one, normalize(N − Γ), negated (BlenderBakeOracle sphere_backfacing);
  // derivative maps keep the front Γ. Without layers the unbumped N is baked as it is.
  const Vec3d n{0.8, 0, -0.6};
  Mesh mesh = test::uvPlaneMesh({{{0, 0}, {1, 0}, {1, 1}, {0, 1}}});
  mesh.cornerNormals.assign(mesh.cornerVertex.size(), cast<float>(n));
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const double a = 0.3, b = -0.2, scale = 0.5;
  const test::LinearHeight height(a, b);
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, scale}, 1.0, {}}};
  // Γ ⊥ N with ⟨Γ, ∂P/∂u⟩ = ∂h/∂u, ⟨Γ, ∂P/∂v⟩ = ∂h/∂v (∂P/∂u = x̂, ∂P/∂v = ŷ): eq. 31.
  const Vec3d t{1, 0, 0}, bt{0, 1, 0};
  const Vec3d gamma =
      (1 / dot(cross(t, bt), n)) * (scale * a * cross(bt, n) + scale * b * cross(n, t));
  const Vec3d front = normalizeOr(n - gamma, Vec3d{});
  // Cycles' guard, with the incoming direction and Ng it sees from behind, leaves it alone here.
  const Vec3d incoming = -n, ng{0, 0, 1};
  ASSERT_GE(2 * dot(front, incoming) * dot(front, ng) - dot(incoming, ng),
            std::min(0.9 * dot(incoming, ng), 0.01));

  const auto on = bake(mesh, &*tangents, layers, MapKind::kObjectNormal, 16);
  const auto tn = bake(mesh, &*tangents, layers, MapKind::kTangentNormal, 16);
  const auto dv = bake(mesh, &*tangents, layers, MapKind::kDerivative, 16);
  const auto plain = bake(mesh, &*tangents, {}, MapKind::kObjectNormal, 16);
  ASSERT_TRUE(on.ok() && tn.ok() && dv.ok() && plain.ok());
  const int covered = forEachCoveredTexel(*on, [&](int x, int y, const std::string& at) {
    expectNear(test::pixelUp(*on, x, y), encode(-front), kFloatTol, "object-normal " + at);
    expectNear(test::pixelUp(*plain, x, y), encode(n), kFloatTol, "unbumped " + at);
    // In the tangent frame (T ⊥ N, N): the reversed normal points into the surface.
    EXPECT_LT(2 * test::pixelUp(*tn, x, y).z - 1, -0.9) << at;
    EXPECT_NEAR(dv->at(x, 15 - y, 0), scale * a, 1e-6) << at;
    EXPECT_NEAR(dv->at(x, 15 - y, 1), scale * b, 1e-6) << at;
  });
  EXPECT_EQ(covered, 256);
}

TEST(Maps, LinearHeightOnAPlaneBakesTheAnalyticConstant) {
  // h = scale·(a·u + b·v) on P = (Lx u, Ly v, 0): Γ = scale·(a/Lx, b/Ly, 0), N' = normalize(−Γ +
  // ẑ), MikkTSpace frame of the plane = (x̂, ŷ, ẑ), so the tangent-space normal is N' itself. The
  // Bump node's forward differences are exact on a linear height: the same maps.
  const double lx = 2, ly = 0.5, a = 0.3, b = -0.2, scale = 0.7;
  const Mesh mesh = scaledPlane(lx, ly);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const test::LinearHeight height(a, b);
  const Vec3d gamma{scale * a / lx, scale * b / ly, 0};
  const Vec3d perturbed = normalizeOr(Vec3d{-gamma.x, -gamma.y, 1}, Vec3d{});

  for (const auto& [samples, differences] :
       {std::pair{1, HeightGradient::kAnalytic}, std::pair{3, HeightGradient::kAnalytic},
        std::pair{1, HeightGradient::kBumpNode}, std::pair{3, HeightGradient::kBumpNode}}) {
    UvHeightSource source{&height, 0, scale};
    source.gradient = differences;
    const std::vector<Layer> layers{Layer{source, 1.0, {}}};
    const auto tn = bake(mesh, &*tangents, layers, MapKind::kTangentNormal, 32, samples);
    const auto on = bake(mesh, &*tangents, layers, MapKind::kObjectNormal, 32, samples);
    const auto sg = bake(mesh, &*tangents, layers, MapKind::kSurfaceGradient, 32, samples);
    const auto dv = bake(mesh, &*tangents, layers, MapKind::kDerivative, 32, samples);
    const auto ht = bake(mesh, &*tangents, layers, MapKind::kHeight, 32, samples);
    ASSERT_TRUE(tn.ok() && on.ok() && sg.ok() && dv.ok() && ht.ok());
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        if (test::coverageUp(*tn, x, y) != 1.0f) continue;
        const std::string at = std::to_string(x) + "," + std::to_string(y);
        expectNear(test::pixelUp(*tn, x, y), encode(perturbed), kFloatTol, "tangent-normal " + at);
        expectNear(test::pixelUp(*on, x, y), encode(perturbed), kFloatTol, "object-normal " + at);
        expectNear(test::pixelUp(*sg, x, y), gamma, 1e-6, "surface gradient " + at);
        const int row = 31 - y;
        EXPECT_NEAR(dv->at(x, row, 0), scale * a, 1e-6) << at;
        EXPECT_NEAR(dv->at(x, row, 1), scale * b, 1e-6) << at;
        if (samples == 1) {  // the mean of a linear function over the samples is its centre value
          const Vec2d uv = bakeSampleUv(x + 0.5, y + 0.5, 32, 32);
          const double u = uv.x, v = uv.y;
          EXPECT_NEAR(ht->at(x, row, 0), scale * (a * u + b * v), 1e-6) << at;
        }
      }
    }
  }
}

// The same plane on an object turned and scaled (sx, sy, sz) = (2, 0.5, 1.5), shaded in world
// space as Cycles shades it (BakeInput::transform): the world slope along x is a/(sx·Lx), the
// world normal normalize(−Γ_w + ẑ) turned, and the baker brings it back as a normal (M^T) for
// the tangent-space map, ∝ (−scale·a/Lx, −scale·b/Ly, sz): only the scale across the plane
// matters, as a Bump node's Distance is measured along the world normal. The object-space map
// takes M^{-1} instead, as Blender's baker does. Heights are unchanged; a translation alone
// changes nothing, bit for bit.
TEST(Maps, LinearHeightOnATransformedPlaneIsBumpedInWorldSpace) {
  const double lx = 2, ly = 0.5, a = 0.3, b = -0.2, scale = 0.7;
  const double sx = 2, sy = 0.5, sz = 1.5;
  const Mesh mesh = scaledPlane(lx, ly);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const test::LinearHeight height(a, b);
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, scale}, 1.0, {}}};
  const double c = std::cos(0.6), s = std::sin(0.6);
  const Mat3 turn = Mat3::fromColumns({c, s, 0}, {0, 0, 1}, {s, -c, 0});  // a proper rotation
  const ObjectTransform transform{turn * Mat3::diagonal({sx, sy, sz}), {3, -1, 2}};
  const ObjectTransform moved{Mat3::identity(), {3, -1, 2}};

  const Vec3d tangentNormal = normalizeOr(Vec3d{-scale * a / lx, -scale * b / ly, sz}, Vec3d{});
  const Vec3d objectNormal =
      normalizeOr(Vec3d{-scale * a / (sx * sx * lx), -scale * b / (sy * sy * ly), 1 / sz}, Vec3d{});
  const Vec3d gamma{scale * a / (lx * sz), scale * b / (ly * sz), 0};
  // A 32² bake of `baked` (the ramp by default) under transform t.
  const auto bakeWith = [&](const ObjectTransform* t, MapKind kind,
                            std::span<const Layer> baked = {}) {
    BakeInput input{&mesh, &*tangents, baked.empty() ? std::span<const Layer>(layers) : baked};
    input.transform = t;
    BakeSettings settings;
    settings.map = kind;
    settings.width = settings.height = 32;
    Result<FloatImage> image = bakeMap(input, settings);
    EXPECT_TRUE(image.ok()) << image.error().message;
    return image.ok() ? std::move(*image) : FloatImage{};
  };
  const auto maxDifference = [](const FloatImage& x, const FloatImage& y) {
    EXPECT_EQ(x.pixels.size(), y.pixels.size());
    float worst = 0;
    for (std::size_t i = 0; i < std::min(x.pixels.size(), y.pixels.size()); ++i)
      worst = std::max(worst, std::abs(x.pixels[i] - y.pixels[i]));
    return worst;
  };
  const FloatImage tn = bakeWith(&transform, MapKind::kTangentNormal);
  const FloatImage on = bakeWith(&transform, MapKind::kObjectNormal);
  const FloatImage sg = bakeWith(&transform, MapKind::kSurfaceGradient);
  const FloatImage dv = bakeWith(&transform, MapKind::kDerivative);
  int covered = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      if (test::coverageUp(tn, x, y) != 1.0f) continue;
      ++covered;
      const std::string at = std::to_string(x) + "," + std::to_string(y);
      expectNear(test::pixelUp(tn, x, y), encode(tangentNormal), kFloatTol, "tangent-normal " + at);
      expectNear(test::pixelUp(on, x, y), encode(objectNormal), kFloatTol, "object-normal " + at);
      expectNear(test::pixelUp(sg, x, y), gamma, 1e-6, "surface gradient " + at);
      EXPECT_NEAR(dv.at(x, 31 - y, 0), scale * a / sz, 1e-6) << at;
      EXPECT_NEAR(dv.at(x, 31 - y, 1), scale * b / sz, 1e-6) << at;
    }
  }
  EXPECT_GT(covered, 300);
  for (const MapKind kind : {MapKind::kHeight, MapKind::kTangent, MapKind::kMask}) {
    EXPECT_EQ(bakeWith(&transform, kind).pixels, bakeWith(nullptr, kind).pixels)
        << mapKindName(kind);
  }
  for (const MapKind kind : {MapKind::kTangentNormal, MapKind::kObjectNormal}) {
    EXPECT_EQ(bakeWith(&moved, kind).pixels, bakeWith(nullptr, kind).pixels) << mapKindName(kind);
  }
  // A rotation with a uniform scale 2 (shaded as object space with heights halved, on the
  // lane-parallel paths): the world bump is half as steep in both maps; heights unchanged.
  const ObjectTransform similar{turn * Mat3::diagonal({2, 2, 2}), {}};
  ASSERT_TRUE(similar.uniformScale().has_value());
  const Vec3d halved = normalizeOr(Vec3d{-scale * a / (2 * lx), -scale * b / (2 * ly), 1}, {});
  const FloatImage tnSimilar = bakeWith(&similar, MapKind::kTangentNormal);
  const FloatImage onSimilar = bakeWith(&similar, MapKind::kObjectNormal);
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      if (test::coverageUp(tnSimilar, x, y) != 1.0f) continue;
      expectNear(test::pixelUp(tnSimilar, x, y), encode(halved), kFloatTol, "similar tangent");
      expectNear(test::pixelUp(onSimilar, x, y), encode(halved), kFloatTol, "similar object");
    }
  }
  EXPECT_EQ(bakeWith(&similar, MapKind::kHeight).pixels,
            bakeWith(nullptr, MapKind::kHeight).pixels);
  // Heights in object units along the normal (a Displacement node in Object space): sz times
  // as high in the world on the stretched plane (|Mᵀn| = sz), s = 2 times on the similar one,
  // where they bake as without the transform.
  {
    std::vector<Layer> objectUnits = layers;
    objectUnits[0].objectSpaceHeight = true;
    const std::vector<Layer> worldUnits{withHeightsScaled(layers[0], sz)};
    const MapKind tangentMap = MapKind::kTangentNormal;
    const FloatImage object = bakeWith(&transform, tangentMap, objectUnits);
    EXPECT_LT(maxDifference(object, bakeWith(&transform, tangentMap, worldUnits)), 1e-6f);
    EXPECT_GT(maxDifference(object, bakeWith(&transform, tangentMap)), 1e-2f);
    EXPECT_EQ(bakeWith(&similar, tangentMap, objectUnits).pixels,
              bakeWith(nullptr, tangentMap).pixels);
  }
  // Heights differenced as the Bump node does, on that rotation: Cycles lays the offsets along
  // its orthonormals of the world Ng, which do not turn with the object, so the rotation shades
  // as the world path does (which a stretch by 1e-4 takes, changing the bump by as little), not
  // as object space: on a curved height the two sets of differences part by 4e-3 here.
  {
    const test::AnalyticHeight wavy(0.1, -0.2, 0.05);
    Layer differenced{UvHeightSource{&wavy, 0, scale}, 1.0, {}};
    std::get<UvHeightSource>(differenced.source).gradient = HeightGradient::kBumpNode;
    const std::vector<Layer> bumpNode{differenced};
    const ObjectTransform stretched{similar.linear * Mat3::diagonal({1, 1, 1 + 1e-4}), {}};
    ASSERT_FALSE(stretched.uniformScale().has_value());
    const MapKind tangentMap = MapKind::kTangentNormal;
    const FloatImage turned = bakeWith(&similar, tangentMap, bumpNode);
    EXPECT_LT(maxDifference(turned, bakeWith(&stretched, tangentMap, bumpNode)), 1e-4f);
    // (the bump is the halved one: not the unturned bake)
    EXPECT_GT(maxDifference(turned, bakeWith(nullptr, tangentMap, bumpNode)), 1e-3f);
  }
  const ObjectTransform singular{Mat3::diagonal({1, 1, 0}), {}};
  BakeInput bad{&mesh, &*tangents, layers};
  bad.transform = &singular;
  const Result<FloatImage> refused = bakeMap(bad, {});
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("singular"), std::string::npos) << refused.error().message;
}

// A layer of one material bumps that material's faces only, as a multi-material object's Bump
// node bumps its material's faces: the plane's quads alternately of materials 0 and 1, the
// ramp on material 1: its faces bake the analytic bump, the others the flat normal; the height
// map too holds material 1's height only.
TEST(Maps, ALayerOfOneMaterialBumpsItsFacesOnly) {
  const double lx = 2, ly = 0.5, a = 0.3, b = -0.2, scale = 0.7;
  Mesh mesh = scaledPlane(lx, ly);
  mesh.faceMaterial.resize(mesh.numFaces());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) mesh.faceMaterial[f] = f % 2 == 0 ? 1 : 0;
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const test::LinearHeight height(a, b);
  Layer ramp{UvHeightSource{&height, 0, scale}, 1.0, {}};
  ramp.material = 1;
  const std::vector<Layer> layers{ramp};
  const Vec3d bumped = normalizeOr(Vec3d{-scale * a / lx, -scale * b / ly, 1}, Vec3d{});
  const auto tn = bake(mesh, &*tangents, layers, MapKind::kTangentNormal);
  const auto ht = bake(mesh, &*tangents, layers, MapKind::kHeight);
  ASSERT_TRUE(tn.ok() && ht.ok());
  // Which face covers a texel centre: the grid's quads are 4 x 3 over UV [0.1, 0.9]².
  const auto faceAt = [](double u, double v) {
    const int i = std::min(3, static_cast<int>((u - 0.1) / 0.8 * 4));
    const int j = std::min(2, static_cast<int>((v - 0.1) / 0.8 * 3));
    return static_cast<std::size_t>(j * 4 + i);
  };
  int onOne = 0, onZero = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      if (test::coverageUp(*tn, x, y) != 1.0f) continue;
      const Vec2d uv = bakeSampleUv(x + 0.5, y + 0.5, 32, 32);
      const double u = uv.x, v = uv.y;
      // Texels within half a texel of a quad's edge could belong to either neighbour.
      const double gu = (u - 0.1) / 0.8 * 4, gv = (v - 0.1) / 0.8 * 3;
      if (std::abs(gu - std::round(gu)) < 0.1 || std::abs(gv - std::round(gv)) < 0.1) continue;
      const bool one = mesh.material(faceAt(u, v)) == 1;
      const std::string at = std::to_string(x) + "," + std::to_string(y);
      expectNear(test::pixelUp(*tn, x, y), encode(one ? bumped : Vec3d{0, 0, 1}), kFloatTol,
                 (one ? "material 1 " : "material 0 ") + at);
      EXPECT_NEAR(ht->at(x, 31 - y, 0), one ? scale * (a * u + b * v) : 0.0, 1e-6) << at;
      ++(one ? onOne : onZero);
    }
  }
  EXPECT_GT(onOne, 100);
  EXPECT_GT(onZero, 100);
}

// Cycles bends a bumped normal whose reflection of the incoming direction (at a bake, the
// shading normal: ẑ on this plane) would go below the surface: on a flat plane no normal leans
// more than acos(0.01)/2 = 44.71° from ẑ. A steep linear height (60°) bakes that tilt, in the
// same azimuth, while the surface-gradient and derivative maps keep the height's own slope.
TEST(Maps, SteepBumpsAreBentToCyclesValidReflection) {
  const Mesh mesh = scaledPlane(1, 1);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const double slope = std::tan(60 * kPi / 180);
  const test::LinearHeight height(0.6, 0.8);  // gradient direction (0.6, 0.8), |∇h| = 1
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, slope}, 1.0, {}}};
  const double tilt = std::acos(0.01) / 2;
  const Vec3d bent{-0.6 * std::sin(tilt), -0.8 * std::sin(tilt), std::cos(tilt)};
  const auto on = bake(mesh, &*tangents, layers, MapKind::kObjectNormal, 16, 1);
  const auto tn = bake(mesh, &*tangents, layers, MapKind::kTangentNormal, 16, 1);
  const auto sg = bake(mesh, &*tangents, layers, MapKind::kSurfaceGradient, 16, 1);
  ASSERT_TRUE(on.ok() && tn.ok() && sg.ok());
  const int covered = forEachCoveredTexel(*on, [&](int x, int y, const std::string& at) {
    expectNear(test::pixelUp(*on, x, y), encode(bent), kFloatTol, "object-normal " + at);
    expectNear(test::pixelUp(*tn, x, y), encode(bent), kFloatTol, "tangent-normal " + at);
    expectNear(test::pixelUp(*sg, x, y), Vec3d{0.6 * slope, 0.8 * slope, 0}, 1e-6,
               "surface gradient " + at);
  });
  EXPECT_GT(covered, 100);
}

// validReflectionNormal against Cycles' guard written in its angle form: the tilts from Ng
// whose reflection of I rises by t are (φ ± acos(t/√a))/2; Cycles' squared equation sees each
// folded into [0°, 90°] (the same cos²θ), keeps those with 1e-5 < cos²θ ≤ 1 + 1e-5, and of two
// takes the lower reflection when both rise by 1e-5, else the higher. Random normals (some below
// the surface) and incoming directions, a third of these within 0.7° of the tangent plane, where
// the nearest tilt that reaches t may lie beyond 89.82° and Cycles takes the other root.
TEST(Maps, ValidReflectionNormalIsCyclesGuard) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto unit = [](const Vec3d& v) { return (1 / std::sqrt(lengthSquared(v))) * v; };
  const double eps = gradient_detail::kGuardEpsilon,
               top = gradient_detail::kGuardCosine2Max;
  int bent = 0, otherRoot = 0;
  for (int i = 0; i < 6000; ++i) {
    const Vec3d ng = unit({u(rng), u(rng), u(rng)});
    Vec3d incoming = unit(ng + 0.6 * Vec3d{u(rng), u(rng), u(rng)});
    if (i % 3 == 0) {  // within 0.7° of the tangent plane, in front
      const Vec3d along = unit(incoming - dot(incoming, ng) * ng);
      const double iz = 0.012 * (0.5 + 0.5 * u(rng));
      incoming = std::sqrt(1 - iz * iz) * along + iz * ng;
    }
    const Vec3d n = unit(ng + 2.0 * Vec3d{u(rng), u(rng), u(rng)});
    const Vec3d out = bake_detail::validReflectionNormal(n, ng, incoming);
    if (bake_detail::reflectsAboveSurface(n, ng, incoming)) {
      EXPECT_EQ(out, n);
      continue;
    }
    const double t = std::min(0.9 * dot(ng, incoming), 0.01);
    const Vec3d x = unit(n - dot(n, ng) * ng);
    const double ix = dot(incoming, x), iz = dot(incoming, ng), sa = std::hypot(ix, iz);
    const double phi = std::atan2(ix, iz), h = std::acos(t / sa);
    double theta[2], cos2[2], rise[2];
    for (int k = 0; k < 2; ++k) {
      const double c = std::abs(std::cos(0.5 * (phi + (k == 0 ? -h : h))));
      theta[k] = std::acos(std::min(c, 1.0));
      cos2[k] = c * c;
      rise[k] = sa * std::cos(2 * theta[k] - phi);
    }
    if (cos2[0] < cos2[1]) {  // Cycles' first root is the larger cos²θ
      std::swap(theta[0], theta[1]);
      std::swap(cos2[0], cos2[1]);
      std::swap(rise[0], rise[1]);
    }
    const auto near = [](double a, double b) { return std::abs(a - b) < 1e-9; };
    if (near(cos2[0], eps) || near(cos2[1], eps) || near(rise[0], eps) || near(rise[1], eps) ||
        near(rise[0], rise[1])) {
      continue;  // decided by rounding
    }
    const bool valid0 = cos2[0] > eps && cos2[0] <= top, valid1 = cos2[1] > eps && cos2[1] <= top;
    Vec3d expected = ng;
    if (valid0 || valid1) {
      int k = valid0 ? 0 : 1;
      if (valid0 && valid1) {
        k = (rise[0] >= eps && rise[1] >= eps) ? (rise[0] < rise[1] ? 0 : 1)
                                                : (rise[0] > rise[1] ? 0 : 1);
      }
      expected = std::sin(theta[k]) * x + std::cos(theta[k]) * ng;
      // The root the nearest tilt would give is not this one.
      const double nearest = std::atan2(std::sqrt(lengthSquared(n - dot(n, ng) * ng)),
                                        dot(n, ng)) > phi / 2 ? 0.5 * (phi + h) : 0.5 * (phi - h);
      otherRoot += std::abs(nearest - theta[k]) > 0.1;
    }
    ++bent;
    EXPECT_LT(test::maxAbsDiff(out, expected), 1e-9) << i;
    EXPECT_NEAR(lengthSquared(out), 1.0, 1e-12) << i;
    EXPECT_NEAR(dot(out, cross(n, ng)), 0.0, 1e-12) << i;  // in the plane of n and Ng
  }
  EXPECT_GT(bent, 1000);
  EXPECT_GT(otherRoot, 20);
}

// I within 0.06° of the tangent plane (⟨Ng, I⟩ = 0.001) and a bumped normal almost opposite Ng,
// as at the back-facing sphere's texels where the custom normal meets its triangle edge-on: the
// nearest tilt whose reflection rises by t is 89.94° from Ng, past Cycles' 89.82° (cos²θ ≤ 1e-5),
// so Cycles returns its other root, 0.003° from Ng.
TEST(Maps, ValidReflectionNormalDropsARootBeyondCyclesBound) {
  const double deg = std::acos(-1.0) / 180;
  const Vec3d ng{0, 0, 1};
  const double iz = 0.001;
  const Vec3d incoming{std::sqrt(1 - iz * iz), 0, iz};
  const Vec3d n{std::sin(179.6 * deg), 0, std::cos(179.6 * deg)};
  ASSERT_FALSE(bake_detail::reflectsAboveSurface(n, ng, incoming));
  const Vec3d out = bake_detail::validReflectionNormal(n, ng, incoming);
  const double phi = std::atan2(incoming.x, iz), h = std::acos(0.9 * iz);
  const double theta = 0.5 * (h - phi);  // 0.0029°
  EXPECT_NEAR(theta / deg, 0.0029, 1e-4);
  EXPECT_LT(test::maxAbsDiff(out, Vec3d{std::sin(theta), 0, std::cos(theta)}), 1e-12);
}

/// A quad with curved normals and UVs that are no parallelogram (its MikkTSpace frames differ
/// from its two loop triangles'), and the same two triangles as faces of their own.
struct CurvedQuad {
  Mesh quad, triangles;
  std::vector<std::array<std::uint32_t, 3>> split;  ///< loopTriangles(quad)
};

CurvedQuad curvedQuad() {
  const std::vector<Vec3f> positions{{0, 0, 0}, {1, 0, 0.1f}, {1.1f, 1, 0.3f}, {0, 0.9f, 0}};
  const std::vector<Vec2f> uvs{{0.1f, 0.1f}, {0.8f, 0.15f}, {0.9f, 0.9f}, {0.05f, 0.7f}};
  std::vector<Vec3f> normals{
      {0, 0, 1}, {-0.2f, 0, 0.98f}, {-0.3f, -0.3f, 0.905f}, {0, -0.1f, 0.995f}};
  for (Vec3f& v : normals) v = cast<float>(normalizeOr(cast<double>(v), Vec3d{0, 0, 1}));
  CurvedQuad c;
  c.quad = test::polygonMesh(positions, {{0, 1, 2, 3}}, uvs, {}, normals);
  c.split = loopTriangles(c.quad);
  std::vector<std::vector<std::uint32_t>> faces;
  std::vector<Vec2f> splitUvs;
  std::vector<Vec3f> splitNormals;
  for (const auto& t : c.split) {
    faces.push_back(
        {c.quad.cornerVertex[t[0]], c.quad.cornerVertex[t[1]], c.quad.cornerVertex[t[2]]});
    for (const std::uint32_t corner : t) {
      splitUvs.push_back(c.quad.uvSets[0].uvs[corner]);
      splitNormals.push_back(c.quad.cornerNormals[corner]);
    }
  }
  c.triangles = test::polygonMesh(positions, faces, splitUvs, {}, splitNormals);
  return c;
}

// Cycles' Normal Map node decodes with MikkTSpace of the triangulated mesh. On a quad with
// curved normals and UVs that are no parallelogram, those tangents differ from the quad's, and
// a tangent-space layer with BakeInput::triangleTangents bakes exactly as the same two
// triangles given as faces of their own do.
TEST(Maps, TangentSpaceLayersDecodeWithTheLoopTrianglesTangents) {
  const CurvedQuad curved = curvedQuad();
  const Mesh& quad = curved.quad;
  const Mesh& triangles = curved.triangles;
  const std::vector<std::array<std::uint32_t, 3>>& split = curved.split;
  ASSERT_EQ(split.size(), 2u);

  const Result<CornerTangents> quadTangents = computeTangents(quad.view(0));
  const Result<CornerTangents> loopTangents = computeLoopTriangleTangents(quad);
  const Result<CornerTangents> splitTangents = computeTangents(triangles.view(0));
  ASSERT_TRUE(quadTangents.ok() && loopTangents.ok() && splitTangents.ok());
  EXPECT_EQ(loopTangents->tangent, splitTangents->tangent);
  EXPECT_EQ(loopTangents->sign, splitTangents->sign);
  double largest = 0;  // how far the quad's frames are from the triangles' (same corners)
  for (std::size_t k = 0; k < 6; ++k) {
    const std::uint32_t c = split[k / 3][k % 3];
    largest = std::max(largest, std::sqrt(lengthSquared(cast<double>(quadTangents->tangent[c] -
                                                                     loopTangents->tangent[k]))));
  }
  EXPECT_GT(largest, 1e-3);

  const test::ConstantColour texel(Vec3d{0.75, 0.35, 0.8});  // a tilted tangent-space normal
  TangentNormalSource source;
  source.texture = &texel;
  const std::vector<Layer> layers{Layer{source, 1.0, {}}};
  BakeSettings settings;
  settings.map = MapKind::kObjectNormal;
  settings.width = settings.height = 32;
  BakeInput withLoop{&quad, &*quadTangents, layers};
  withLoop.triangleTangents[0] = &*loopTangents;
  const Result<FloatImage> ours = bakeMap(withLoop, settings);
  const Result<FloatImage> faces2 = bakeMap({&triangles, &*splitTangents, layers}, settings);
  const Result<FloatImage> polygon = bakeMap({&quad, &*quadTangents, layers}, settings);
  ASSERT_TRUE(ours.ok() && faces2.ok() && polygon.ok());
  EXPECT_EQ(ours->pixels, faces2->pixels);
  EXPECT_NE(ours->pixels, polygon->pixels);
  // A wrong number of frames is refused.
  const CornerTangents shortList{{Vec3f{1, 0, 0}}, {1}};
  withLoop.triangleTangents[0] = &shortList;
  EXPECT_FALSE(bakeMap(withLoop, settings).ok());
}

// The corner table decodes tangent-space layers as the bake does: with
// CornerOptions::layerTangents from loopTriangleFramesAtCorners, each corner of the quad gets the
// perturbed normal the same corner gets in the two triangles given as faces of their own, and
// not the one of the quad's MikkTSpace frame (which stays the table's tangent column).
TEST(Maps, CornerTableDecodesWithTheLoopTrianglesTangents) {
  const CurvedQuad curved = curvedQuad();
  const Mesh& quad = curved.quad;
  const Mesh& triangles = curved.triangles;
  const std::vector<std::array<std::uint32_t, 3>>& split = curved.split;

  const Result<CornerTangents> loop = computeLoopTriangleTangents(quad);
  ASSERT_TRUE(loop.ok());
  const CornerTangents atCorners = loopTriangleFramesAtCorners(quad, *loop);
  ASSERT_EQ(atCorners.tangent.size(), quad.numCorners());

  const test::ConstantColour texel(Vec3d{0.75, 0.35, 0.8});
  TangentNormalSource source;
  source.texture = &texel;
  const std::vector<Layer> layers{Layer{source, 1.0, {}}};
  CornerOptions options;
  options.layerTangents[0] = &atCorners;
  const auto ours = evaluateCorners(quad, layers, options);
  const auto polygon = evaluateCorners(quad, layers);
  const auto reference = evaluateCorners(triangles, layers);
  ASSERT_TRUE(ours.ok() && polygon.ok() && reference.ok());
  double largest = 0;  // how far the quad's own frames would put the normals
  std::vector<bool> seen(quad.numCorners(), false);
  for (std::size_t k = 0; k < 3 * split.size(); ++k) {
    const std::uint32_t c = split[k / 3][k % 3];
    if (seen[c]) continue;
    seen[c] = true;
    expectNear((*ours)[c].perturbed, (*reference)[k].perturbed, 1e-12,
               "corner " + std::to_string(c));
    EXPECT_EQ((*ours)[c].tangent, (*polygon)[c].tangent) << c;
    largest = std::max(largest, length((*ours)[c].perturbed - (*polygon)[c].perturbed));
  }
  EXPECT_EQ(std::count(seen.begin(), seen.end(), true), 4);
  EXPECT_GT(largest, 1e-3);
}

// A tangent-space layer on UV set 1 decodes in MikkTSpace of that set (as Cycles does for the
// UV map a Normal Map node names): the same as the mesh with that set first, and not the
// per-point UV-derivative frame it used without.
TEST(Maps, TangentSpaceLayersOnAnotherUvSetDecodeInItsOwnFrames) {
  const std::vector<Vec3f> positions{{0, 0, 0}, {1, 0, 0.1f}, {1.1f, 1, 0.3f}, {0, 0.9f, 0}};
  const std::vector<Vec2f> first{{0.1f, 0.1f}, {0.9f, 0.1f}, {0.9f, 0.9f}, {0.1f, 0.9f}};
  const std::vector<Vec2f> second{{0.2f, 0.1f}, {0.8f, 0.15f}, {0.9f, 0.9f}, {0.05f, 0.7f}};
  std::vector<Vec3f> normals{
      {0, 0, 1}, {-0.2f, 0, 0.98f}, {-0.3f, -0.3f, 0.905f}, {0, -0.1f, 0.995f}};
  for (Vec3f& v : normals) v = cast<float>(normalizeOr(cast<double>(v), Vec3d{0, 0, 1}));
  Mesh twoSets = test::polygonMesh(positions, {{0, 1, 2, 3}}, first, {}, normals);
  twoSets.uvSets.push_back({"second", second});
  Mesh swapped = twoSets;
  std::swap(swapped.uvSets[0], swapped.uvSets[1]);

  const test::ConstantColour texel(Vec3d{0.75, 0.35, 0.8});
  const auto layerOn = [&texel](int uvSet) {
    TangentNormalSource source;
    source.texture = &texel;
    source.uvSet = uvSet;
    return std::vector<Layer>{Layer{source, 1.0, {}}};
  };
  BakeSettings settings;
  settings.map = MapKind::kObjectNormal;
  settings.width = settings.height = 32;
  settings.uvSet = 1;  // placed by the second set in both (swapped: its set 0) ...
  const Result<CornerTangents> onSecond = computeLoopTriangleTangents(twoSets, 1);
  const Result<CornerTangents> swappedFirst = computeLoopTriangleTangents(swapped, 0);
  ASSERT_TRUE(onSecond.ok() && swappedFirst.ok());
  EXPECT_EQ(onSecond->tangent, swappedFirst->tangent);
  const std::vector<Layer> layers1 = layerOn(1), layers0 = layerOn(0);
  BakeInput ours{&twoSets, nullptr, layers1};
  ours.triangleTangents[1] = &*onSecond;
  BakeInput reference{&swapped, nullptr, layers0};
  reference.triangleTangents[0] = &*swappedFirst;
  const Result<FloatImage> a = bakeMap(ours, settings);
  settings.uvSet = 0;  // ... which is set 0 of the swapped mesh
  const Result<FloatImage> b = bakeMap(reference, settings);
  settings.uvSet = 1;
  const Result<FloatImage> derivativeFrame = bakeMap({&twoSets, nullptr, layers1}, settings);
  ASSERT_TRUE(a.ok() && b.ok() && derivativeFrame.ok());
  EXPECT_EQ(a->pixels, b->pixels);
  EXPECT_NE(a->pixels, derivativeFrame->pixels);
  EXPECT_FALSE(computeLoopTriangleTangents(twoSets, 2).ok());

  // Looked up on set 1 and decoded in set 0's frames (a Normal Map node whose UV Map is not
  // its image's): the constant texel bakes as on set 0 alone, not as on set 1.
  const Result<CornerTangents> onFirst = computeLoopTriangleTangents(twoSets, 0);
  ASSERT_TRUE(onFirst.ok());
  std::vector<Layer> split = layerOn(1);
  std::get<TangentNormalSource>(split[0].source).tangentUvSet = 0;
  BakeInput splitInput{&twoSets, nullptr, split};
  splitInput.triangleTangents[0] = &*onFirst;
  BakeInput firstInput{&twoSets, nullptr, layers0};
  firstInput.triangleTangents[0] = &*onFirst;
  const Result<FloatImage> splitBake = bakeMap(splitInput, settings);
  const Result<FloatImage> firstBake = bakeMap(firstInput, settings);
  ASSERT_TRUE(splitBake.ok() && firstBake.ok());
  EXPECT_EQ(splitBake->pixels, firstBake->pixels);
  EXPECT_NE(splitBake->pixels, a->pixels);
  std::get<TangentNormalSource>(split[0].source).tangentUvSet = 2;  // a set the mesh lacks
  splitInput.layers = split;
  EXPECT_FALSE(bakeMap(splitInput, settings).ok());
}

// Heights differenced as the Bump node does (HeightGradient::kBumpNode) are a first-order
// estimate half a texel wide: on a curved height the bake differs from the exact one, by about
// a quarter as much when the bake is four times larger; and the per-sample path it takes gives
// the analytic layer's bits when the layer asks for exact slopes.
TEST(Maps, BumpNodeSlopesConvergeToTheExactOnesAsTheBakeGrows) {
  const Mesh mesh = scaledPlane(2, 0.5);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const test::SineHeight height(0.02, 2);
  UvHeightSource exact{&height, 0, 1.0};
  UvHeightSource differenced = exact;
  differenced.gradient = HeightGradient::kBumpNode;
  const std::vector<Layer> exactLayers{Layer{exact, 1.0, {}}};
  const std::vector<Layer> bumpLayers{Layer{differenced, 1.0, {}}};
  // Largest angle between the two bakes' normals, degrees.
  const auto largestGap = [&](int size) {
    const auto a = bake(mesh, &*tangents, exactLayers, MapKind::kTangentNormal, size);
    const auto b = bake(mesh, &*tangents, bumpLayers, MapKind::kTangentNormal, size);
    EXPECT_TRUE(a.ok() && b.ok());
    double gap = 0;
    forEachCoveredTexel(*a, [&](int x, int y, const std::string&) {
      const Vec3d na = normalizeOr(2.0 * test::pixelUp(*a, x, y) - Vec3d{1, 1, 1}, Vec3d{});
      const Vec3d nb = normalizeOr(2.0 * test::pixelUp(*b, x, y) - Vec3d{1, 1, 1}, Vec3d{});
      gap = std::max(gap, std::acos(std::clamp(dot(na, nb), -1.0, 1.0)) * 180 / kPi);
    });
    return gap;
  };
  const double at64 = largestGap(64), at256 = largestGap(256);
  EXPECT_GT(at64, 0.5);  // visibly not the exact slopes at 64²
  EXPECT_LT(at256, at64 / 3);
  EXPECT_GT(at256, at64 / 6);  // first order: a quarter
}

// A height layer's strength is Blender's Bump Strength: the bumped normal blended with the
// unbumped one, normalize(N + s·(n' − N)), not a scaled height; the height map keeps the
// height, and strength 1 is the plain bump, bit for bit.
TEST(Maps, HeightStrengthBlendsNormalsAsTheBumpNodeDoes) {
  const Mesh mesh = scaledPlane(1, 1);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const test::LinearHeight height(0.6, -0.3);
  const double scale = 0.8;
  const Vec3d bumped = normalizeOr(Vec3d{-0.6 * scale, 0.3 * scale, 1}, Vec3d{});
  for (const double strength : {1.0, 0.5, 1.5}) {
    UvHeightSource source{&height, 0, scale};
    source.strength = strength;
    const std::vector<Layer> layers{Layer{source, 1.0, {}}};
    const Vec3d z{0, 0, 1};
    const Vec3d expected = normalizeOr(z + strength * (bumped - z), z);
    const auto on = bake(mesh, &*tangents, layers, MapKind::kObjectNormal, 16, 1);
    const auto tn = bake(mesh, &*tangents, layers, MapKind::kTangentNormal, 16, 1);
    const auto ht = bake(mesh, &*tangents, layers, MapKind::kHeight, 16, 1);
    ASSERT_TRUE(on.ok() && tn.ok() && ht.ok());
    int covered = 0;
    for (int y = 0; y < 16; ++y) {
      for (int x = 0; x < 16; ++x) {
        if (test::coverageUp(*on, x, y) != 1.0f) continue;
        ++covered;
        const std::string at =
            std::to_string(strength) + " " + std::to_string(x) + "," + std::to_string(y);
        expectNear(test::pixelUp(*on, x, y), encode(expected), kFloatTol, "object-normal " + at);
        expectNear(test::pixelUp(*tn, x, y), encode(expected), kFloatTol, "tangent-normal " + at);
        const Vec2d uv = bakeSampleUv(x + 0.5, y + 0.5, 16, 16);
        const double u = uv.x, v = uv.y;
        EXPECT_NEAR(ht->at(x, 15 - y, 0), scale * (0.6 * u - 0.3 * v), 1e-6) << at;
      }
    }
    EXPECT_GT(covered, 50);
  }
}

TEST(Maps, HeightSumsWeightedMaskedHeightLayers) {
  // On the plane P = (2u, 0.5v, 0): a volume sine along x, a planar (Z) linear height map and a
  // triplanar one (only the Z plane is active for N = ẑ), weighted, one of them masked by 0.5;
  // a tangent-space normal-map layer adds no height.
  const Mesh mesh = scaledPlane(2, 0.5);
  const Result<DirectionalSine> sine = DirectionalSine::create({0.1, 0.75, {1, 0, 0}, 0.3});
  ASSERT_TRUE(sine.ok());
  const test::LinearHeight planar(0.4, -0.3);
  const test::ConstantColour tilted(Vec3d{0.7, 0.5, 0.9});
  PlanarSource planarSource;
  planarSource.height = &planar;
  planarSource.mapping.tiling = {2, 3};
  planarSource.scale = 0.2;
  TriplanarSource triplanar;
  triplanar.height = &planar;
  triplanar.options.scale = 0.05;
  TangentNormalSource normalMap;
  normalMap.texture = &tilted;
  class HalfMask final : public ScalarTexture {
   public:
    ScalarSample sample(Vec2d) const override { return {0.5, {0, 0}}; }
  } mask;
  const std::vector<Layer> layers{
      Layer{VolumeSource{&*sine, GradientScheme::kAnalytic, 0, 2.0}, 1.5, {}},
      Layer{planarSource, -1.0, LayerMask{&mask, 0}},
      Layer{triplanar, 1.0, {}},
      Layer{normalMap, 1.0, {}},
  };
  const auto ht = bake(mesh, nullptr, layers, MapKind::kHeight, 32);
  ASSERT_TRUE(ht.ok()) << ht.error().message;
  int checked = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      if (test::coverageUp(*ht, x, y) != 1.0f) continue;
      const Vec2d uv = bakeSampleUv(x + 0.5, y + 0.5, 32, 32);
      const double u = uv.x, v = uv.y;
      const Vec3d p{2 * u, 0.5 * v, 0};
      const double volume = 2.0 * 0.1 * std::sin(2 * kPi * 0.75 * p.x + 0.3);
      const double planarH = 0.2 * (0.4 * 2 * p.x - 0.3 * 3 * p.y);
      const double triplanarH = 0.05 * (0.4 * p.x - 0.3 * p.y);
      EXPECT_NEAR(ht->at(x, 31 - y, 0), 1.5 * volume - 0.5 * planarH + triplanarH, 1e-6) << x << "," << y;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 26 * 26);
}

TEST(Maps, DirectXGreenFlipsG) {
  const Mesh mesh = scaledPlane(1, 1);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const test::LinearHeight height(0.2, 0.4);
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, 1.0}, 1.0, {}}};
  BakeSettings s;
  s.width = s.height = 16;
  const Result<FloatImage> gl = bakeMap({&mesh, &*tangents, layers}, s);
  s.green = NormalMapGreen::kDirectX;
  const Result<FloatImage> dx = bakeMap({&mesh, &*tangents, layers}, s);
  ASSERT_TRUE(gl.ok() && dx.ok());
  for (std::size_t i = 0; i < gl->coverage.size(); ++i) {
    EXPECT_EQ(dx->pixels[3 * i], gl->pixels[3 * i]);
    EXPECT_FLOAT_EQ(dx->pixels[3 * i + 1], 1.0f - gl->pixels[3 * i + 1]);
    EXPECT_EQ(dx->pixels[3 * i + 2], gl->pixels[3 * i + 2]);
  }
}

TEST(NormalSwizzle, ParsesSignedAxesAndBlendersNamesAndWritesThemBack) {
  const Result<NormalSwizzle> dx = parseNormalSwizzle("+x -Y, +z");
  ASSERT_TRUE(dx.ok()) << dx.error().message;
  EXPECT_EQ(normalSwizzleName(*dx), "+X-Y+Z");
  const Result<NormalSwizzle> blender = parseNormalSwizzle("NEG_Z,pos_x,NEG_Y");
  ASSERT_TRUE(blender.ok()) << blender.error().message;
  EXPECT_EQ(normalSwizzleName(*blender), "-Z+X-Y");
  EXPECT_EQ(normalSwizzleName(kIdentitySwizzle), "+X+Y+Z");
  for (const char* bad : {"", "+X+Y", "+X+Y+Z+X", "X+Y+Z", "+W+Y+Z", "+X+Y+", "POS_X,NEG_Q,+Z"}) {
    const Result<NormalSwizzle> parsed = parseNormalSwizzle(bad);
    ASSERT_FALSE(parsed.ok()) << bad;
    EXPECT_EQ(parsed.error().code, ErrorCode::kBadInput);
    EXPECT_NE(parsed.error().message.find(std::string("'") + bad + "'"), std::string::npos)
        << parsed.error().message;
  }
}

// Blender's bake Swizzle: channel c of a swizzled map is ±(the normal's component axis), as
// the unswizzled map encodes it; uncovered texels of a tangent-space map are the flat normal
// swizzled. In both spaces, and with a DirectX green negating G after the swizzle.
TEST(Maps, SwizzleStoresSignedComponentsOfTheNormal) {
  const Mesh mesh = scaledPlane(1, 1);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const test::LinearHeight height(0.2, 0.4);
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, 1.0}, 1.0, {}}};
  const NormalSwizzle swizzle = {{{2, true}, {0, false}, {1, true}}};  // -Z+X-Y
  for (const MapKind map : {MapKind::kTangentNormal, MapKind::kObjectNormal}) {
    for (const NormalMapGreen green : {NormalMapGreen::kOpenGL, NormalMapGreen::kDirectX}) {
      if (map == MapKind::kObjectNormal && green == NormalMapGreen::kDirectX) continue;
      SCOPED_TRACE(std::string(mapKindName(map)) +
                   (green == NormalMapGreen::kDirectX ? ", DirectX" : ""));
      BakeSettings s;
      s.map = map;
      s.width = s.height = 16;
      const Result<FloatImage> plain = bakeMap({&mesh, &*tangents, layers}, s);
      s.swizzle = swizzle;
      s.green = green;
      const Result<FloatImage> swizzled = bakeMap({&mesh, &*tangents, layers}, s);
      ASSERT_TRUE(plain.ok() && swizzled.ok());
      int covered = 0, outside = 0;
      for (std::size_t i = 0; i < plain->coverage.size(); ++i) {
        const bool in = plain->coverage[i] > 0;
        covered += in;
        outside += !in && map == MapKind::kTangentNormal;
        const Vec3d n = in ? 2.0 * Vec3d{plain->pixels[3 * i], plain->pixels[3 * i + 1],
                                         plain->pixels[3 * i + 2]} -
                                 Vec3d{1, 1, 1}
                           : Vec3d{0, 0, 1};
        if (!in && map == MapKind::kObjectNormal) continue;  // (black)
        const double g = green == NormalMapGreen::kDirectX ? -1 : 1;
        const Vec3d expected{-n.z, g * n.x, -n.y};
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(swizzled->pixels[3 * i + static_cast<std::size_t>(c)],
                      0.5 * expected[static_cast<std::size_t>(c)] + 0.5, 1e-6)
              << "texel " << i << " channel " << c;
        }
      }
      EXPECT_GT(covered, 100);
      if (map == MapKind::kTangentNormal) {
        EXPECT_GT(outside, 0);
      }
    }
  }
}

// --- Blender's per-texel frame on a hand-built triangle --------------------------------------

struct HandTriangle {
  Mesh mesh;
  CornerTangents tangents;
  std::array<Vec2d, 3> uv;
  std::array<Vec3d, 3> normal, tangent;
  std::array<double, 3> sign;
};

HandTriangle handTriangle() {
  HandTriangle h;
  h.uv = {Vec2d{0.05, 0.05}, Vec2d{0.95, 0.1}, Vec2d{0.2, 0.9}};
  h.normal = {normalizeOr(Vec3d{0, 0, 1}, Vec3d{}), normalizeOr(Vec3d{0.3, 0, 1}, Vec3d{}),
              normalizeOr(Vec3d{0, -0.4, 1}, Vec3d{})};
  // Unit tangents, deliberately not orthogonal to the normals, and a sign change inside.
  h.tangent = {normalizeOr(Vec3d{1, 0, 0.2}, Vec3d{}), normalizeOr(Vec3d{1, 0.2, 0.1}, Vec3d{}),
               normalizeOr(Vec3d{0.8, -0.3, 0.3}, Vec3d{})};
  h.sign = {1, 1, -1};
  std::vector<Vec3f> normals;
  for (int i = 0; i < 3; ++i) {
    normals.push_back(cast<float>(h.normal[i]));
    h.normal[i] = cast<double>(normals.back());  // what the baker reads
    h.tangents.tangent.push_back(cast<float>(h.tangent[i]));
    h.tangent[i] = cast<double>(h.tangents.tangent.back());
    h.tangents.sign.push_back(static_cast<float>(h.sign[i]));
  }
  h.mesh = test::polygonMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0.2f}}, {{0, 1, 2}},
                             {cast<float>(h.uv[0]), cast<float>(h.uv[1]), cast<float>(h.uv[2])},
                             {0, 0, 1}, normals);
  for (int i = 0; i < 3; ++i) h.uv[i] = cast<double>(h.mesh.uvSets[0].uvs[i]);
  return h;
}

/// Barycentrics of (u, v) in the UV triangle, by Cramer's rule.
Vec3d barycentrics(const std::array<Vec2d, 3>& t, double u, double v) {
  const double d = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
  const double b1 = ((u - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (v - t[0].y)) / d;
  const double b2 = ((t[1].x - t[0].x) * (v - t[0].y) - (u - t[0].x) * (t[1].y - t[0].y)) / d;
  return {1 - b1 - b2, b1, b2};
}

/// x with M x = n for M = [T B N], by Gaussian elimination with partial pivoting (independent of
/// the baker's adjugate formula).
Vec3d solve(Vec3d T, Vec3d B, Vec3d N, Vec3d n) {
  double m[3][4] = {{T.x, B.x, N.x, n.x}, {T.y, B.y, N.y, n.y}, {T.z, B.z, N.z, n.z}};
  for (int c = 0; c < 3; ++c) {
    int p = c;
    for (int r = c + 1; r < 3; ++r)
      if (std::abs(m[r][c]) > std::abs(m[p][c])) p = r;
    for (int k = 0; k < 4; ++k) std::swap(m[c][k], m[p][k]);
    for (int r = 0; r < 3; ++r) {
      if (r == c) continue;
      const double f = m[r][c] / m[c][c];
      for (int k = 0; k < 4; ++k) m[r][k] -= f * m[c][k];
    }
  }
  return {m[0][3] / m[0][0], m[1][3] / m[1][1], m[2][3] / m[2][2]};
}

TEST(Maps, PerTexelFrameMatchesTheClosedForm) {
  const HandTriangle h = handTriangle();
  // A constant object-space normal map: the perturbed normal is exactly its (unit) value.
  const Vec3d objectNormal = normalizeOr(Vec3d{0.25, -0.15, 1}, Vec3d{});
  const test::ConstantColour map(encode(objectNormal));
  const std::vector<Layer> layers{Layer{ObjectNormalSource{&map, 0}, 1.0, {}}};

  const int size = 48;
  const auto tangentMap = bake(h.mesh, &h.tangents, {}, MapKind::kTangent, size);
  const auto bitangentMap = bake(h.mesh, &h.tangents, {}, MapKind::kBitangent, size);
  const auto normalMap = bake(h.mesh, &h.tangents, {}, MapKind::kObjectNormal, size);
  const auto tsMap = bake(h.mesh, &h.tangents, layers, MapKind::kTangentNormal, size);
  ASSERT_TRUE(tangentMap.ok() && bitangentMap.ok() && normalMap.ok() && tsMap.ok());

  int covered = 0, negative = 0;
  double transposeError = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const Vec2d uv = bakeSampleUv(x + 0.5, y + 0.5, size, size);
      const Vec3d b = barycentrics(h.uv, uv.x, uv.y);
      const bool inside = b.x > 1e-9 && b.y > 1e-9 && b.z > 1e-9;
      const bool outside = b.x < -1e-9 || b.y < -1e-9 || b.z < -1e-9;
      if (!inside && !outside) continue;  // on an edge: either is right
      ASSERT_EQ(test::coverageUp(*tangentMap, x, y), inside ? 1.0f : 0.0f) << x << "," << y;
      if (!inside) continue;
      ++covered;
      const Vec3d T = b.x * h.tangent[0] + b.y * h.tangent[1] + b.z * h.tangent[2];
      const Vec3d N = b.x * h.normal[0] + b.y * h.normal[1] + b.z * h.normal[2];
      const double s = b.x * h.sign[0] + b.y * h.sign[1] + b.z * h.sign[2];
      negative += s < 0;
      const Vec3d B = (s < 0 ? -1.0 : 1.0) * cross(N, T);
      const std::string at = std::to_string(x) + "," + std::to_string(y);
      expectNear(test::pixelUp(*tangentMap, x, y), encode(normalizeOr(T, Vec3d{})), kFloatTol, "T " + at);
      expectNear(test::pixelUp(*bitangentMap, x, y), encode(normalizeOr(B, Vec3d{})), kFloatTol, "B " + at);
      expectNear(test::pixelUp(*normalMap, x, y), encode(normalizeOr(N, Vec3d{})), kFloatTol, "N " + at);
      const Vec3d ts = normalizeOr(solve(T, B, N, objectNormal), Vec3d{});
      expectNear(test::pixelUp(*tsMap, x, y), encode(ts), kFloatTol, "tangent-space " + at);
      // The transpose would be wrong here (T is not orthogonal to N): make sure the test can tell.
      const Vec3d transposed = normalizeOr(Vec3d{dot(T, objectNormal), dot(B, objectNormal), dot(N, objectNormal)}, Vec3d{});
      transposeError = std::max(transposeError, length(transposed - ts));
    }
  }
  EXPECT_GT(covered, 500);
  EXPECT_GT(negative, 20);  // the interpolated sign flips inside the triangle
  EXPECT_GT(transposeError, 1e-2);
}

TEST(Maps, SupersampledNormalsAreTheMeanOfEncodedSamples) {
  // With 2×2 samples the tangent map of the hand triangle is the mean of the four encoded
  // sample values (box filter, not renormalized), where all four samples are inside.
  const HandTriangle h = handTriangle();
  const int size = 24;
  const auto map = bake(h.mesh, &h.tangents, {}, MapKind::kTangent, size, 2);
  ASSERT_TRUE(map.ok());
  int checked = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      Vec3d sum{};
      bool all = true;
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
          const Vec2d uv = bakeSampleUv(x + (i + 0.5) / 2, y + (j + 0.5) / 2, size, size);
          const Vec3d b = barycentrics(h.uv, uv.x, uv.y);
          all = all && b.x > 1e-9 && b.y > 1e-9 && b.z > 1e-9;
          sum += encode(normalizeOr(b.x * h.tangent[0] + b.y * h.tangent[1] + b.z * h.tangent[2], Vec3d{}));
        }
      if (!all) continue;
      ++checked;
      ASSERT_EQ(test::coverageUp(*map, x, y), 1.0f);
      expectNear(test::pixelUp(*map, x, y), 0.25 * sum, kFloatTol, std::to_string(x) + "," + std::to_string(y));
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(Maps, BandByBandRowsEqualTheWholeImageAndStayReadableForTheirHalo) {
  // bakeMapRows bakes bands from the top down into a ring of reused rows. Every row a call may
  // read (the new band and keepRows rows above it) must hold bakeMap's values bit for bit: a
  // reused slot left uncleared, or a band overwriting the kept rows, shows here.
  const HandTriangle h = handTriangle();
  for (const MapKind map : {MapKind::kTangentNormal, MapKind::kTangent, MapKind::kMask}) {
    for (const int samples : {1, 2}) {
      BakeSettings s;
      s.map = map;
      s.width = 37;
      s.height = 603;  // three bands, the first of them shorter (603 is not a multiple of 8)
      s.samples = samples;
      const Result<FloatImage> plain = bakeMap({&h.mesh, &h.tangents, {}}, s);
      ASSERT_TRUE(plain.ok());
      for (const int keep : {0, 5, 40, 1000}) {
        const std::string what = std::string(mapKindName(map)) + ", samples " +
                                 std::to_string(samples) + ", keep " + std::to_string(keep);
        std::vector<int> ends;
        int rowsChecked = 0;
        const Status done = bakeMapRows({&h.mesh, &h.tangents, {}}, s, keep, [&](const ImageRows& rows) {
          const int previousEnd = ends.empty() ? 0 : ends.back();
          EXPECT_EQ(rows.begin, std::max(0, previousEnd - keep)) << what;
          EXPECT_GT(rows.end, previousEnd) << what;
          EXPECT_LE(rows.end - previousEnd, kBakeBandRows) << what;
          ends.push_back(rows.end);
          const std::size_t rowValues = rows.rowValues();
          for (int r = rows.begin; r < rows.end; ++r, ++rowsChecked) {
            EXPECT_EQ(std::memcmp(rows.pixelRow(r), plain->pixels.data() + static_cast<std::size_t>(r) * rowValues,
                                  rowValues * sizeof(float)),
                      0)
                << what << ", row " << r;
            EXPECT_EQ(std::memcmp(rows.coverageRow(r), plain->coverage.data() + static_cast<std::size_t>(r) * 37,
                                  37 * sizeof(float)),
                      0)
                << what << ", row " << r;
          }
          return Status{Ok{}};
        });
        ASSERT_TRUE(done.ok()) << what;
        ASSERT_EQ(ends.size(), 3u) << what;
        EXPECT_EQ(ends.back(), 603) << what;
        EXPECT_GE(rowsChecked, 603) << what;
      }
    }
  }
}

TEST(Maps, BandByBandStopsAtTheSinksError) {
  const HandTriangle h = handTriangle();
  BakeSettings s;
  s.map = MapKind::kTangent;
  s.width = 16;
  s.height = 600;
  int calls = 0;
  const Status done = bakeMapRows({&h.mesh, &h.tangents, {}}, s, 0, [&](const ImageRows&) {
    ++calls;
    return Status{Error::internal("disk full")};
  });
  ASSERT_FALSE(done.ok());
  EXPECT_EQ(done.error().message, "disk full");
  EXPECT_EQ(calls, 1);
  // Settings are checked as bakeMap checks them, before any band.
  s.width = 0;
  const Status bad = bakeMapRows({&h.mesh, &h.tangents, {}}, s, 0, [&](const ImageRows&) {
    ++calls;
    return Status{Ok{}};
  });
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kBadInput);
  EXPECT_EQ(calls, 1);
}

TEST(Maps, ProgressReportsEveryBandAndGivesTheSameBitsAndStopsWhenAsked) {
  const HandTriangle h = handTriangle();
  BakeSettings s;
  s.map = MapKind::kTangentNormal;
  s.width = 29;
  s.height = 603;  // three bands
  s.samples = 2;
  const Result<FloatImage> plain = bakeMap({&h.mesh, &h.tangents, {}}, s);
  ASSERT_TRUE(plain.ok());
  std::vector<int> reported;
  const Result<FloatImage> tracked =
      bakeMap({&h.mesh, &h.tangents, {}}, s, [&](int rowsDone, int rows) {
        EXPECT_EQ(rows, 603);
        reported.push_back(rowsDone);
        return true;
      });
  ASSERT_TRUE(tracked.ok());
  EXPECT_EQ(tracked->pixels, plain->pixels);
  EXPECT_EQ(tracked->coverage, plain->coverage);
  ASSERT_EQ(reported.size(), 3u);
  EXPECT_TRUE(std::is_sorted(reported.begin(), reported.end()));
  EXPECT_EQ(reported.back(), 603);

  int calls = 0;
  const Result<FloatImage> stopped =
      bakeMap({&h.mesh, &h.tangents, {}}, s, [&](int, int) { return ++calls < 1; });
  ASSERT_FALSE(stopped.ok());
  EXPECT_EQ(stopped.error().code, ErrorCode::kCancelled);
  EXPECT_EQ(calls, 1);
}

TEST(Maps, BadInputIsAnErrorValue) {
  const Mesh mesh = scaledPlane(1, 1);
  BakeSettings s;
  s.width = s.height = 8;
  EXPECT_FALSE(bakeMap({nullptr, nullptr, {}}, s).ok());
  const Result<FloatImage> noTangents = bakeMap({&mesh, nullptr, {}}, s);
  ASSERT_FALSE(noTangents.ok());
  EXPECT_EQ(noTangents.error().code, ErrorCode::kBadInput);
  EXPECT_NE(noTangents.error().message.find("tangent"), std::string::npos);
  s.map = MapKind::kObjectNormal;
  EXPECT_TRUE(bakeMap({&mesh, nullptr, {}}, s).ok());
  auto expectBad = [&](BakeSettings bad) {
    const Result<FloatImage> r = bakeMap({&mesh, nullptr, {}}, bad);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kBadInput) << r.error().message;
  };
  BakeSettings t = s;
  t.uvSet = 1;
  expectBad(t);
  t = s;
  t.samples = 0;
  expectBad(t);
  t = s;
  t.samples = kMaxBakeSamples + 1;
  expectBad(t);
  t = s;
  t.udimTile = 1000;
  expectBad(t);
  t = s;
  t.width = 0;
  expectBad(t);
  t = s;
  t.threads = -1;
  expectBad(t);
  CornerTangents wrong;
  wrong.tangent.resize(3);
  wrong.sign.resize(3);
  EXPECT_FALSE(bakeMap({&mesh, &wrong, {}}, s).ok());
  const std::vector<Layer> badLayer{Layer{UvHeightSource{nullptr, 0, 1.0}, 1.0, {}}};
  EXPECT_FALSE(bakeMap({&mesh, nullptr, badLayer}, s).ok());
}

}  // namespace
}  // namespace sgbake
