// Numerical stability of whole bakes: every map of a bumped torus is the same at any object
// scale from 1e-6 to 1e6 (the unit vectors exactly so, heights and derivatives in proportion),
// and meshes full of degenerate faces, or bumps far too strong or too faint, bake to finite
// values and unit normals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "bake_test_util.hpp"
#include "sgbake/bake/bake.hpp"
#include "sgbake/frames/tangents.hpp"
#include "support/parametric_mesh.hpp"

namespace sgbake {
namespace {

constexpr MapKind kAllMaps[] = {MapKind::kTangentNormal, MapKind::kObjectNormal,
                                MapKind::kHeight,        MapKind::kDerivative,
                                MapKind::kSurfaceGradient, MapKind::kTangent,
                                MapKind::kBitangent,     MapKind::kMask};

/// How a map's values change when the object is scaled by s (with heights in object units
/// scaled by s too): unit vectors and Γ (height per length) not at all, heights and ∂h/∂u, ∂h/∂v
/// (object units per UV unit) by s.
bool scalesWithObject(MapKind map) { return map == MapKind::kHeight || map == MapKind::kDerivative; }

/// Whether the map's RGB is an encoded unit vector (n/2 + 0.5).
bool isEncodedUnitVector(MapKind map) {
  return map == MapKind::kTangentNormal || map == MapKind::kObjectNormal ||
         map == MapKind::kTangent || map == MapKind::kBitangent;
}

Mesh scaled(Mesh mesh, float s) {
  for (Vec3f& p : mesh.positions) p = {p.x * s, p.y * s, p.z * s};
  return mesh;
}

Result<FloatImage> bake(const Mesh& mesh, MapKind map, double heightScale, int size, int samples,
                        const ScalarTexture& height) {
  Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  if (!tangents) return tangents.error();
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, heightScale}, 1.0, {}}};
  BakeSettings settings;
  settings.map = map;
  settings.width = settings.height = size;
  settings.samples = samples;
  return bakeMap({&mesh, &*tangents, layers}, settings);
}

/// Checks that every value is finite and, for unit-vector maps, that covered texels decode to
/// unit length (one sample per texel: averaging would shorten them). Returns the texels checked.
int expectFiniteAndUnit(const FloatImage& image, MapKind map, bool unitLength, const char* what) {
  int covered = 0;
  for (std::size_t t = 0; t < image.coverage.size(); ++t) {
    const float coverage = image.coverage[t];
    EXPECT_TRUE(coverage >= 0.0f && coverage <= 1.0f) << what << " texel " << t;
    double length2 = 0;
    for (int c = 0; c < image.channels; ++c) {
      const float v = image.pixels[t * static_cast<std::size_t>(image.channels) + static_cast<std::size_t>(c)];
      EXPECT_TRUE(std::isfinite(v)) << what << " " << mapKindName(map) << " texel " << t;
      if (c < 3) length2 += (2.0 * v - 1) * (2.0 * v - 1);
    }
    if (coverage == 0) continue;
    ++covered;
    if (unitLength && isEncodedUnitVector(map)) {
      EXPECT_NEAR(std::sqrt(length2), 1.0, 1e-5) << what << " " << mapKindName(map) << " texel " << t;
    }
  }
  return covered;
}

TEST(Stability, EveryMapIsTheSameAtAnyObjectScale) {
  // A torus (curved everywhere, a UV seam) with a sine height layer whose scale is in object
  // units: scaling the object by s and the heights by s leaves the bumped surface's shape, so
  // its normals, frames and Γ, unchanged.
  const Mesh unit = test::gridMesh(test::torus, 24, 16, [](double s, double t) {
    return Vec2d{0.02 + 0.96 * s, 0.02 + 0.96 * t};
  });
  const test::SineHeight height(1.0, 4);
  constexpr double kHeightScale = 0.004;
  constexpr int kSize = 64;
  for (const MapKind map : kAllMaps) {
    Result<FloatImage> reference = bake(unit, map, kHeightScale, kSize, 1, height);
    ASSERT_TRUE(reference) << reference.error().message;
    double worst = 0;
    for (const float s : {1e-6f, 1e-3f, 1e3f, 1e6f}) {
      const Mesh mesh = scaled(unit, s);
      Result<FloatImage> image = bake(mesh, map, kHeightScale * s, kSize, 1, height);
      ASSERT_TRUE(image) << image.error().message;
      ASSERT_EQ(image->coverage, reference->coverage) << "scale " << s;
      const double divide = scalesWithObject(map) ? s : 1.0;
      double largest = 1e-30;
      for (const float v : reference->pixels) largest = std::max(largest, std::abs(double(v)));
      for (std::size_t i = 0; i < image->pixels.size(); ++i) {
        const double difference =
            std::abs(image->pixels[i] / divide - reference->pixels[i]) / largest;
        worst = std::max(worst, difference);
      }
    }
    // Float rounding of the scaled positions and heights only (measured: ≤ 4e-6 of the map's
    // largest value; without the height scaled with the object, 0.3 and more).
    EXPECT_LT(worst, 2e-5) << mapKindName(map);
    std::printf("%-17s worst difference over scales 1e-6 … 1e6: %.2e of its largest value\n",
                std::string(mapKindName(map)).c_str(), worst);
  }
}

TEST(Stability, TheScaleTestCanFail) {
  // The same comparison with the heights left at their unit-scale size: the bumps are then
  // 1000 times too strong or weak, and the normal maps must differ.
  const Mesh unit = test::gridMesh(test::torus, 24, 16);
  const test::SineHeight height(1.0, 4);
  Result<FloatImage> reference = bake(unit, MapKind::kTangentNormal, 0.004, 32, 1, height);
  Result<FloatImage> wrong = bake(scaled(unit, 1e3f), MapKind::kTangentNormal, 0.004, 32, 1, height);
  ASSERT_TRUE(reference && wrong);
  double worst = 0;
  for (std::size_t i = 0; i < wrong->pixels.size(); ++i)
    worst = std::max(worst, std::abs(double(wrong->pixels[i]) - reference->pixels[i]));
  EXPECT_GT(worst, 0.01);  // 500 times the tolerance above
}

TEST(Stability, DegenerateFacesBakeToFiniteValuesAndUnitNormals) {
  // One mesh with every kind of bad face next to good ones: a zero-area triangle (collinear
  // corners), a face whose UVs collapse to a point, a UV sliver 1e-7 wide, two faces sharing
  // the same positions (duplicate vertices), a quad with a reflex corner, a face with a
  // zero-length normal and one with an inverted UV winding.
  const std::vector<Vec3f> p{{0, 0, 0},     {1, 0, 0},   {2, 0, 0},     {0, 1, 0},
                             {1, 1, 0.2f},  {2, 1, 0},   {0.5f, 0.5f, 0}, {1, 1, 0.2f},
                             {1.5f, 0.2f, 0}, {0, 2, 0}, {1, 2, 0.1f},  {2, 2, 0}};
  const std::vector<std::vector<std::uint32_t>> faces{
      {0, 1, 2},        // collinear: zero area
      {0, 1, 4, 3},     // UVs collapsed to a point
      {1, 2, 5, 4},     // UV sliver
      {3, 4, 10, 9},    // a good quad
      {3, 7, 10},       // vertex 7 duplicates vertex 4
      {4, 8, 5, 11},    // reflex corner at 8
      {4, 5, 11, 10},   // zero-length normal at one corner
      {9, 10, 11}};     // inverted UV winding
  std::vector<Vec2f> uvs{{0.1f, 0.1f}, {0.5f, 0.1f}, {0.9f, 0.1f},                      // 0
                         {0.3f, 0.3f}, {0.3f, 0.3f}, {0.3f, 0.3f}, {0.3f, 0.3f},        // 1
                         {0.5f, 0.2f}, {0.5f + 1e-7f, 0.2f}, {0.5f + 1e-7f, 0.8f}, {0.5f, 0.8f},  // 2
                         {0.1f, 0.5f}, {0.4f, 0.5f}, {0.4f, 0.9f}, {0.1f, 0.9f},        // 3
                         {0.1f, 0.5f}, {0.4f, 0.5f}, {0.1f, 0.9f},                      // 4
                         {0.6f, 0.3f}, {0.75f, 0.45f}, {0.9f, 0.3f}, {0.9f, 0.6f},      // 5
                         {0.6f, 0.6f}, {0.9f, 0.6f}, {0.9f, 0.9f}, {0.6f, 0.9f},        // 6
                         {0.9f, 0.95f}, {0.6f, 0.95f}, {0.75f, 0.99f}};                 // 7
  std::vector<Vec3f> normals(uvs.size(), Vec3f{0, 0, 1});
  normals[22] = Vec3f{0, 0, 0};
  const Mesh mesh = test::polygonMesh(p, faces, uvs, {0, 0, 1}, normals);
  const test::SineHeight height(1.0, 3);
  for (const MapKind map : kAllMaps) {
    for (const int samples : {1, 3}) {
      for (const double heightScale : {0.01, 1e9, 1e-30}) {
        Result<FloatImage> image = bake(mesh, map, heightScale, 48, samples, height);
        ASSERT_TRUE(image) << image.error().message;
        const int covered = expectFiniteAndUnit(*image, map, samples == 1, "degenerate mesh");
        EXPECT_GT(covered, 300) << mapKindName(map);
      }
    }
  }
}

}  // namespace
}  // namespace sgbake
