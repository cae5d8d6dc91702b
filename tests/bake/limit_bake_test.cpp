// Baking from the exact limit surface (BakeInput::limit): object-space normals of a regular
// torus grid, whose limit is a bicubic B-spline, against the closed form; bakes of subdivided
// meshes converge to it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/subdiv/limit_surface.hpp"
#include "sgbake/subdiv/subdivide.hpp"
#include "support/bspline_torus.hpp"

namespace sgbake {
namespace {

constexpr int kNu = 8, kNv = 6, kSize = 96;

/// Worst angle (degrees) between a baked object-space normal map and the limit surface's
/// normal at each covered texel's centre; @p covered counts the texels.
double worstNormalError(const FloatImage& image, const Mesh& coarse, int& covered) {
  double worst = 0;
  covered = 0;
  for (int row = 0; row < image.height; ++row) {
    for (int x = 0; x < image.width; ++x) {
      if (image.coverage[static_cast<std::size_t>(row) * image.width + x] != 1.0f) continue;
      ++covered;
      // UVs are (i + s, j + t) / (nu, nv) on face (i, j): linear ("uv_smooth": "none").
      const Vec2d uv = bakeSampleUv(x + 0.5, image.height - row - 0.5, image.width, image.height);
      const double u = uv.x * kNu, v = uv.y * kNv;
      const int i = std::min(kNu - 1, static_cast<int>(u)), j = std::min(kNv - 1, static_cast<int>(v));
      Vec3d P, Ps, Pt;
      test::torusGridLimit(coarse, kNu, kNv, i, j, u - i, v - j, P, Ps, Pt);
      const Vec3d expected = normalizeOr(cross(Ps, Pt), Vec3d{0, 0, 1});
      const Vec3d baked{2.0 * image.at(x, row, 0) - 1, 2.0 * image.at(x, row, 1) - 1,
                        2.0 * image.at(x, row, 2) - 1};
      worst = std::max(worst, angleBetween(normalizeOr(baked, Vec3d{0, 0, 1}), expected) * 180 / kPi);
    }
  }
  return worst;
}

BakeSettings objectNormals() {
  BakeSettings settings;
  settings.map = MapKind::kObjectNormal;
  settings.width = settings.height = kSize;
  return settings;
}

/// The limit surface of the torus grid and the tessellation a limit bake walks (as the planner
/// makes them for "level": "limit").
struct LimitScene {
  Mesh coarse = test::torusGridWithUvs(kNu, kNv);
  std::optional<LimitSurface> limit;
  SurfaceParameters parameters;
  Mesh tessellation;

  explicit LimitScene(const SubdivisionOptions& options) {
    Result<LimitSurface> surface = LimitSurface::create(coarse, options);
    EXPECT_TRUE(surface) << surface.error().message;
    if (surface) limit = std::move(*surface);
    Result<Mesh> mesh = subdivideMesh(coarse, options, &parameters);
    EXPECT_TRUE(mesh) << mesh.error().message;
    if (mesh) tessellation = std::move(*mesh);
  }
  bool ok() const { return limit.has_value() && tessellation.numFaces() > 0; }
  BakeInput input(const CornerTangents* tangents = nullptr) const {
    return {&tessellation, tangents, {}, &*limit, &parameters};
  }
};

TEST(LimitBake, ObjectNormalsAreTheLimitSurfaceNormals) {
  const LimitScene scene({2, SubdivisionUvSmooth::kNone});
  ASSERT_TRUE(scene.ok());
  const Mesh& coarse = scene.coarse;
  Result<FloatImage> baked = bakeMap(scene.input(), objectNormals());
  ASSERT_TRUE(baked) << baked.error().message;
  int covered = 0;
  const double limitError = worstNormalError(*baked, coarse, covered);
  EXPECT_EQ(covered, kSize * kSize);  // the UVs tile [0,1]²
  EXPECT_LT(limitError, 1e-4);        // float pixels; the surface is exact
  std::printf("limit surface: worst %.2e deg\n", limitError);

  // Bakes of the subdivided meshes (interpolated vertex normals) approach it, level by level.
  double previous = 180;
  for (int level = 1; level <= 4; ++level) {
    Result<Mesh> fine = subdivideMesh(coarse, {level, SubdivisionUvSmooth::kNone});
    ASSERT_TRUE(fine) << fine.error().message;
    Result<FloatImage> mesh = bakeMap({&*fine, nullptr, {}}, objectNormals());
    ASSERT_TRUE(mesh) << mesh.error().message;
    const double error = worstNormalError(*mesh, coarse, covered);
    EXPECT_LT(error, previous) << "level " << level;
    EXPECT_GT(error, 100 * limitError) << "level " << level;
    std::printf("subdivided to level %d: worst %.2e deg\n", level, error);
    previous = error;
  }
}

TEST(LimitBake, TangentSpaceBakeIsFlatWithoutLayersAndThreadsGiveTheSameBits) {
  const LimitScene scene({3, SubdivisionUvSmooth::kKeepBoundaries});
  ASSERT_TRUE(scene.ok());
  Result<CornerTangents> tangents = computeTangents(scene.tessellation.view(0));
  ASSERT_TRUE(tangents);
  BakeSettings settings = objectNormals();
  settings.map = MapKind::kTangentNormal;
  settings.threads = 1;
  const BakeInput input = scene.input(&*tangents);
  Result<FloatImage> one = bakeMap(input, settings);
  settings.threads = 2;
  Result<FloatImage> two = bakeMap(input, settings);
  ASSERT_TRUE(one && two);
  EXPECT_TRUE(one->pixels == two->pixels);
  // No layers: the surface's own normal is (0, 0, 1) in its own tangent space.
  for (std::size_t t = 0; t < one->coverage.size(); ++t) {
    if (one->coverage[t] == 0) continue;
    EXPECT_NEAR(one->pixels[3 * t], 0.5, 1e-6);
    EXPECT_NEAR(one->pixels[3 * t + 1], 0.5, 1e-6);
    EXPECT_NEAR(one->pixels[3 * t + 2], 1.0, 1e-6);
  }
  // A mesh that is not the tessellation is refused.
  const Mesh other = test::torusGridWithUvs(kNu, kNv);
  Result<FloatImage> refused =
      bakeMap({&other, nullptr, {}, &*scene.limit, &scene.parameters}, objectNormals());
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("not a tessellation of the limit surface"),
            std::string::npos);
}

}  // namespace
}  // namespace sgbake
