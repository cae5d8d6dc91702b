// The texel raster: Blender's looptris, texel centres and row order, the edge rule (every sample
// of a watertight UV region claimed exactly once), supersampled coverage, UDIM tiles, threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "bake/raster.hpp"
#include "bake_test_util.hpp"
#include "support/parametric_mesh.hpp"
#include "sgbake/bake/bake.hpp"
#include "sgbake/frames/tangents.hpp"

namespace sgbake {
namespace {

using Tri = std::array<std::uint32_t, 3>;

Mesh quadMesh(std::vector<Vec3f> p) {
  return test::polygonMesh(p, {{0, 1, 2, 3}}, {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
}

Result<FloatImage> bakeMask(const Mesh& mesh, int w, int h, int samples = 1, int tile = 1001) {
  BakeSettings s;
  s.map = MapKind::kMask;
  s.width = w;
  s.height = h;
  s.samples = samples;
  s.udimTile = tile;
  return bakeMap({&mesh, nullptr, {}}, s);
}

// --- looptris (verified against Blender 3.4.1's Mesh.calc_loop_triangles) -------------------

TEST(LoopTriangles, ConvexQuadSplitsOnDiagonal02) {
  const auto t = loopTriangles(quadMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}));
  EXPECT_EQ(t, (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}}));
}

TEST(LoopTriangles, QuadReflexAtCorner1Or3FlipsToDiagonal13) {
  EXPECT_EQ(loopTriangles(quadMesh({{0, 0, 0}, {0.3f, 0.6f, 0}, {1, 1, 0}, {0, 1, 0}})),
            (std::vector<Tri>{{0, 1, 3}, {1, 2, 3}}));
  EXPECT_EQ(loopTriangles(quadMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0.6f, 0.3f, 0}})),
            (std::vector<Tri>{{0, 1, 3}, {1, 2, 3}}));
  // Bow-tie and a twisted non-planar quad, as Blender.
  EXPECT_EQ(loopTriangles(quadMesh({{0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}})),
            (std::vector<Tri>{{0, 1, 3}, {1, 2, 3}}));
  EXPECT_EQ(loopTriangles(quadMesh({{0, 0, 0}, {1, 0, 1.5f}, {1, 1, 0}, {0, 1, 1.5f}})),
            (std::vector<Tri>{{0, 1, 3}, {1, 2, 3}}));
}

// Suzanne's concave quad 162 (its positions and UVs, the UVs stretched to fill the image): the
// baker's fast test flips it to the 1–3 diagonal, Cycles' test with the polygon normal keeps
// 0–2, and Cycles shades the baker's triangle k on its own triangle k (measured on flat
// Suzanne: all 48 texels of quads 162 and 163 show the 0–2 triangles' normals).
TEST(LoopTriangles, CyclesShadesANearTieQuadOnItsOtherSplit) {
  const std::vector<Vec3f> p{{0.1015625f, -0.7421875f, -0.1484375f},
                             {0.125f, -0.75f, -0.2265625f},
                             {0.1640625f, -0.7109375f, -0.2421875f},
                             {0.125f, -0.8125f, -0.1015625f}};
  const std::vector<Vec2f> suzanneUv{{0.544281006f, 0.193366006f},
                                     {0.548362017f, 0.173559994f},
                                     {0.561572015f, 0.167778999f},
                                     {0.55311799f, 0.209599003f}};
  std::vector<Vec2f> uv;
  for (const Vec2f t : suzanneUv) uv.push_back({(t.x - 0.54f) / 0.025f, (t.y - 0.16f) / 0.055f});
  Mesh mesh = test::polygonMesh(p, {{0, 1, 2, 3}}, uv);
  mesh.faceFlat = {1};
  const std::vector<Tri> baker = loopTriangles(mesh);
  ASSERT_EQ(baker, (std::vector<Tri>{{0, 1, 3}, {1, 2, 3}}));
  const std::vector<Tri> cycles{{0, 1, 2}, {0, 2, 3}};
  EXPECT_EQ(bake_detail::cyclesShadingTriangles(mesh, baker), cycles);
  // A quad both tests flip, and one neither flips: shaded on the baker's own triangles.
  const Mesh concave = quadMesh({{0, 0, 0}, {0.3f, 0.6f, 0}, {1, 1, 0}, {0, 1, 0}});
  EXPECT_TRUE(bake_detail::cyclesShadingTriangles(concave, loopTriangles(concave)).empty());
  const Mesh square = quadMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  EXPECT_TRUE(bake_detail::cyclesShadingTriangles(square, loopTriangles(square)).empty());

  // A flat face's object-space normal is the normal of the triangle Cycles shades.
  BakeSettings s;
  s.map = MapKind::kObjectNormal;
  s.width = s.height = 32;
  const Result<FloatImage> image = bakeMap({&mesh, nullptr, {}}, s);
  ASSERT_TRUE(image.ok()) << image.error().message;
  const auto normalOf = [&](const Tri& t) {
    return normalizeOr(cross(cast<double>(p[t[1]] - p[t[0]]), cast<double>(p[t[2]] - p[t[0]])),
                       Vec3d{});
  };
  int covered = 0, other = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      if (test::coverageUp(*image, x, y) != 1.0f) continue;
      ++covered;
      const Vec2d q = bakeSampleUv(x + 0.5, y + 0.5, 32, 32);
      // The baker's triangle k holding the sample.
      std::size_t k = 0;
      for (std::size_t t = 0; t < 2; ++t) {
        const Vec2d a = cast<double>(uv[baker[t][0]]), b = cast<double>(uv[baker[t][1]]),
                    c = cast<double>(uv[baker[t][2]]);
        const double area = (b - a).x * (c - a).y - (b - a).y * (c - a).x;
        const double l1 = ((q - a).x * (c - a).y - (q - a).y * (c - a).x) / area;
        const double l2 = ((b - a).x * (q - a).y - (b - a).y * (q - a).x) / area;
        if (l1 >= 0 && l2 >= 0 && l1 + l2 <= 1) k = t;
      }
      const Vec3d expected = normalOf(cycles[k]);
      const Vec3d got = 2.0 * test::pixelUp(*image, x, y) - Vec3d{1, 1, 1};
      EXPECT_LT(length(got - expected), 1e-5) << x << "," << y;
      other += length(expected - normalOf(baker[k])) > 0.5;
    }
  }
  EXPECT_GT(covered, 100);
  EXPECT_EQ(other, covered) << "every triangle of the other split has another normal here";
}

TEST(LoopTriangles, ReflexAt0Or2AndTiesKeepDiagonal02) {
  const std::vector<Tri> keep{{0, 1, 2}, {0, 2, 3}};
  EXPECT_EQ(loopTriangles(quadMesh({{0.7f, 0.7f, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}})), keep);
  EXPECT_EQ(loopTriangles(quadMesh({{0, 0, 0}, {1, 0, 0}, {0.4f, 0.4f, 0}, {0, 1, 0}})), keep);
  EXPECT_EQ(loopTriangles(quadMesh({{0, 0, 0}, {0.5f, 0.5f, 0}, {1, 1, 0}, {0, 1, 0}})), keep);
  EXPECT_EQ(loopTriangles(quadMesh({{0, 0, 0}, {1, 0, 0}, {0, 0, 0}, {0, 1, 0}})), keep);
}

TEST(LoopTriangles, TrianglesAndNgons) {
  const Mesh mesh = test::polygonMesh(
      {{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {1, 2, 0}, {0, 1, 0}, {3, 3, 0}},
      {{0, 1, 2, 3, 4}, {1, 5, 2}}, std::vector<Vec2f>(8, Vec2f{0, 0}));
  const auto t = loopTriangles(mesh);
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[3], (Tri{5, 6, 7}));
  for (int i = 0; i < 3; ++i)
    for (const std::uint32_t c : t[static_cast<std::size_t>(i)]) EXPECT_LT(c, 5u);
}

// --- coverage and the edge rule --------------------------------------------------------------

TEST(Raster, SquareSplitInTwoCoversEveryTexelExactlyOnce) {
  // The diagonal passes exactly through texel centres when W == H: the tie rule must give each
  // to exactly one triangle (coverage 2 would mean a double count, 0 a gap).
  const Mesh mesh = test::uvPlaneMesh({{{0, 0}, {1, 0}, {1, 1}, {0, 1}}});
  for (const auto& [w, h, n] : std::vector<std::array<int, 3>>{{64, 64, 1}, {37, 23, 1}, {16, 16, 3}, {9, 9, 4}}) {
    const Result<FloatImage> mask = bakeMask(mesh, w, h, n);
    ASSERT_TRUE(mask.ok()) << mask.error().message;
    for (std::size_t i = 0; i < mask->coverage.size(); ++i) {
      ASSERT_EQ(mask->coverage[i], 1.0f) << w << "x" << h << " N=" << n << " texel " << i;
      ASSERT_EQ(mask->pixels[i], 1.0f);
    }
  }
}

TEST(Raster, FansAndJitteredGridsCoverExactlyOnce) {
  // A square as a fan of 4 triangles around its centre (a vertex on a texel centre), and a grid of
  // quads with jittered interior UVs: samples on shared edges and vertices are claimed once.
  const Mesh fan = test::uvPlaneMesh({{{0, 0}, {1, 0}, {0.5f, 0.5f}},
                                      {{1, 0}, {1, 1}, {0.5f, 0.5f}},
                                      {{1, 1}, {0, 1}, {0.5f, 0.5f}},
                                      {{0, 1}, {0, 0}, {0.5f, 0.5f}}});
  for (const int w : {8, 9, 32}) {
    const Result<FloatImage> mask = bakeMask(fan, w, w, w == 8 ? 2 : 1);
    ASSERT_TRUE(mask.ok());
    for (const float c : mask->coverage) ASSERT_EQ(c, 1.0f) << w;
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
  const int n = 6;
  std::vector<std::vector<Vec2f>> grid(n + 1, std::vector<Vec2f>(n + 1));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const bool border = i == 0 || j == 0 || i == n || j == n;
      grid[j][i] = {(float(i) + (border ? 0.0f : jitter(rng))) / float(n),
                    (float(j) + (border ? 0.0f : jitter(rng))) / float(n)};
    }
  // Pixel-aligned interior vertices too: every other one snapped to a texel centre of a 48² bake.
  for (int j = 1; j < n; j += 2)
    for (int i = 1; i < n; i += 2) grid[j][i] = {(8.0f * float(i) + 0.5f) / 48, (8.0f * float(j) + 0.5f) / 48};
  std::vector<std::vector<Vec2f>> faces;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) faces.push_back({grid[j][i], grid[j][i + 1], grid[j + 1][i + 1], grid[j + 1][i]});
  const Mesh jittered = test::uvPlaneMesh(faces);
  for (const int samples : {1, 3}) {
    const Result<FloatImage> mask = bakeMask(jittered, 48, 48, samples);
    ASSERT_TRUE(mask.ok());
    for (const float c : mask->coverage) ASSERT_EQ(c, 1.0f) << "samples " << samples;
  }
}

TEST(Raster, TexelCentresAndRowOrder) {
  // A quad covering exactly u < 1/2: columns x < W/2 (centres (x + 0.5)/W < 1/2), every row.
  for (const int w : {8, 7, 33}) {
    const Mesh left = test::uvPlaneMesh({{{0, 0}, {0.5f, 0}, {0.5f, 1}, {0, 1}}});
    const Result<FloatImage> mask = bakeMask(left, w, 5);
    ASSERT_TRUE(mask.ok());
    for (int row = 0; row < 5; ++row)
      for (int x = 0; x < w; ++x)
        EXPECT_EQ(mask->coverage[static_cast<std::size_t>(row) * w + x], (x + 0.5) / w < 0.5 ? 1.0f : 0.0f)
            << "W=" << w << " x=" << x;
  }
  // A quad covering v < 1/2 covers the bottom rows, i.e. the *last* rows of the image.
  const Mesh bottom = test::uvPlaneMesh({{{0, 0}, {1, 0}, {1, 0.5f}, {0, 0.5f}}});
  const Result<FloatImage> mask = bakeMask(bottom, 4, 6);
  ASSERT_TRUE(mask.ok());
  for (int row = 0; row < 6; ++row)
    for (int x = 0; x < 4; ++x)
      EXPECT_EQ(mask->coverage[static_cast<std::size_t>(row) * 4 + x], row >= 3 ? 1.0f : 0.0f) << row;
}

TEST(Raster, EdgeThroughTexelCentresGoesToTheNudgedSide) {
  // Two quads meeting at u = 4.5/8, the centre of column 4. Blender nudges samples by
  // +(0.001, 0.002) texels, so column 4 belongs to the right quad; together they cover it once.
  const float m = 4.5f / 8;
  const Mesh left = test::uvPlaneMesh({{{0, 0}, {m, 0}, {m, 1}, {0, 1}}});
  const Mesh right = test::uvPlaneMesh({{{m, 0}, {1, 0}, {1, 1}, {m, 1}}});
  const Result<FloatImage> a = bakeMask(left, 8, 3), b = bakeMask(right, 8, 3);
  ASSERT_TRUE(a.ok() && b.ok());
  for (int x = 0; x < 8; ++x) {
    EXPECT_EQ(a->coverage[static_cast<std::size_t>(x)], x < 4 ? 1.0f : 0.0f) << x;
    EXPECT_EQ(b->coverage[static_cast<std::size_t>(x)], x >= 4 ? 1.0f : 0.0f) << x;
  }
  // Horizontal edge through row centres: the upper quad (nudge +y) takes the row.
  const float mv = 2.5f / 6;
  const Mesh low = test::uvPlaneMesh({{{0, 0}, {1, 0}, {1, mv}, {0, mv}}});
  const Result<FloatImage> c = bakeMask(low, 2, 6);
  ASSERT_TRUE(c.ok());
  for (int y = 0; y < 6; ++y) EXPECT_EQ(test::coverageUp(*c, 0, y), y < 2 ? 1.0f : 0.0f) << y;
}

TEST(Raster, TexelsNextToAnEdgeGoWhereTheNudgedSampleIs) {
  // Blender samples texel (x, y) at (x + 0.501, y + 0.502) texels, not at its centre: an edge
  // 0.0005 texel right of column 4's centre gives the column to the right quad, one 0.0015
  // texel right leaves it to the left quad. Likewise in y with a nudge of 0.002.
  for (const double offset : {0.0005, 0.0015}) {
    const float m = static_cast<float>((4.5 + offset) / 8);
    const Mesh left = test::uvPlaneMesh({{{0, 0}, {m, 0}, {m, 1}, {0, 1}}});
    const Mesh right = test::uvPlaneMesh({{{m, 0}, {1, 0}, {1, 1}, {m, 1}}});
    const Result<FloatImage> a = bakeMask(left, 8, 3), b = bakeMask(right, 8, 3);
    ASSERT_TRUE(a.ok() && b.ok());
    const int firstRight = offset < kBakeSampleNudge.x ? 4 : 5;
    for (int x = 0; x < 8; ++x) {
      EXPECT_EQ(a->coverage[static_cast<std::size_t>(x)], x < firstRight ? 1.0f : 0.0f)
          << offset << " " << x;
      EXPECT_EQ(b->coverage[static_cast<std::size_t>(x)], x >= firstRight ? 1.0f : 0.0f)
          << offset << " " << x;
    }
  }
  for (const double offset : {0.0015, 0.0025}) {
    const float mv = static_cast<float>((2.5 + offset) / 6);
    const Mesh low = test::uvPlaneMesh({{{0, 0}, {1, 0}, {1, mv}, {0, mv}}});
    const Result<FloatImage> c = bakeMask(low, 2, 6);
    ASSERT_TRUE(c.ok());
    const int rowsBelow = offset < kBakeSampleNudge.y ? 2 : 3;
    for (int y = 0; y < 6; ++y)
      EXPECT_EQ(test::coverageUp(*c, 0, y), y < rowsBelow ? 1.0f : 0.0f) << offset << " " << y;
  }
}

TEST(Raster, MirroredAndDegenerateUvTriangles) {
  // Clockwise UVs (a mirrored island) cover like counter-clockwise ones; zero-area UV triangles
  // cover nothing.
  const Mesh cw = test::uvPlaneMesh({{{0, 0}, {0, 1}, {1, 1}, {1, 0}}});
  const Result<FloatImage> mask = bakeMask(cw, 16, 16);
  ASSERT_TRUE(mask.ok());
  for (const float c : mask->coverage) ASSERT_EQ(c, 1.0f);
  // A triangle far larger than the tile covers all of it.
  const Mesh huge = test::uvPlaneMesh({{{-1000, -1000}, {3000, -1000}, {-1000, 3000}}});
  const Result<FloatImage> all = bakeMask(huge, 16, 16, 2);
  ASSERT_TRUE(all.ok());
  for (const float c : all->coverage) ASSERT_EQ(c, 1.0f);
  const Mesh flat = test::uvPlaneMesh({{{0, 0}, {1, 1}, {0.5f, 0.5f}}});
  const Result<FloatImage> none = bakeMask(flat, 16, 16);
  ASSERT_TRUE(none.ok());
  for (const float c : none->coverage) ASSERT_EQ(c, 0.0f);
}

TEST(Raster, OverlappingUvsTakeTheLastTriangleAtEverySample) {
  // Two quads with the same UVs, facing +Z and tilted 45° about X. Blender 3.4's Cycles bake of
  // this mesh (NORMAL, object space, 16², checked by hand) gives the second quad's normal at
  // every texel: the last triangle to cover a pixel owns it. sgbake does the same at one
  // sample per texel and, sample by sample, with supersampling: a texel's samples are counted
  // once (coverage 1, not 2) and all come from the second quad.
  const float h = 0.5f;
  const std::vector<Vec3f> positions{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                     {0, 0, h}, {1, 0, h}, {1, 1, 1 + h}, {0, 1, 1 + h}};
  const std::vector<Vec2f> square{{0.25f, 0.25f}, {0.75f, 0.25f}, {0.75f, 0.75f}, {0.25f, 0.75f}};
  std::vector<Vec2f> uvs = square;
  uvs.insert(uvs.end(), square.begin(), square.end());
  const float r = static_cast<float>(std::sqrt(0.5));
  std::vector<Vec3f> normals(4, Vec3f{0, 0, 1});
  normals.insert(normals.end(), 4, Vec3f{0, -r, r});
  const Mesh mesh = test::polygonMesh(positions, {{0, 1, 2, 3}, {4, 5, 6, 7}}, uvs, {0, 0, 1}, normals);
  for (const int samples : {1, 3}) {
    BakeSettings settings;
    settings.map = MapKind::kObjectNormal;
    settings.width = settings.height = 16;
    settings.samples = samples;
    Result<FloatImage> image = bakeMap({&mesh, nullptr, {}}, settings);
    ASSERT_TRUE(image) << image.error().message;
    int covered = 0;
    for (std::size_t t = 0; t < image->coverage.size(); ++t) {
      const float coverage = image->coverage[t];
      ASSERT_LE(coverage, 1.0f) << "samples " << samples << " texel " << t;
      if (coverage == 0) continue;
      ++covered;
      EXPECT_NEAR(image->pixels[3 * t], 0.5, 1e-6);
      EXPECT_NEAR(image->pixels[3 * t + 1], 0.5 - 0.5 * r, 1e-6) << "samples " << samples;
      EXPECT_NEAR(image->pixels[3 * t + 2], 0.5 + 0.5 * r, 1e-6) << "samples " << samples;
    }
    EXPECT_EQ(covered, 8 * 8);
  }
}

TEST(Raster, SupersampledCoverageIsTheFractionOfSamples) {
  // Edge at u = 1.5/4: in column 1 the samples at x + 1/8 and x + 3/8 are inside, x + 5/8, 7/8
  // outside: coverage 8/16 with 4×4 samples; the mask equals the coverage.
  const float m = 1.5f / 4;
  const Mesh left = test::uvPlaneMesh({{{0, 0}, {m, 0}, {m, 1}, {0, 1}}});
  const Result<FloatImage> mask = bakeMask(left, 4, 2, 4);
  ASSERT_TRUE(mask.ok());
  for (int row = 0; row < 2; ++row) {
    const float* c = mask->coverage.data() + row * 4;
    EXPECT_EQ(c[0], 1.0f);
    EXPECT_EQ(c[1], 0.5f);
    EXPECT_EQ(c[2], 0.0f);
    EXPECT_EQ(c[3], 0.0f);
    EXPECT_EQ(mask->pixels[static_cast<std::size_t>(row) * 4 + 1], 0.5f);
  }
}

// --- UDIM ------------------------------------------------------------------------------------

TEST(Udim, TilesAreReportedAndEachBakeSeesOnlyItsTile) {
  const Mesh mesh = test::uvPlaneMesh({{{0.25f, 0.25f}, {0.75f, 0.25f}, {0.75f, 0.75f}, {0.25f, 0.75f}},
                                       {{1.25f, 0.25f}, {1.75f, 0.25f}, {1.75f, 0.5f}, {1.25f, 0.5f}}});
  EXPECT_EQ(udimTiles(mesh, 0), (std::vector<int>{1001, 1002}));
  EXPECT_TRUE(udimTiles(mesh, 1).empty());

  const Result<FloatImage> t1 = bakeMask(mesh, 8, 8, 1, 1001);
  const Result<FloatImage> t2 = bakeMask(mesh, 8, 8, 1, 1002);
  const Result<FloatImage> t3 = bakeMask(mesh, 8, 8, 1, 1003);
  ASSERT_TRUE(t1.ok() && t2.ok() && t3.ok());
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      const bool inX = x >= 2 && x < 6;
      EXPECT_EQ(test::coverageUp(*t1, x, y), inX && y >= 2 && y < 6 ? 1.0f : 0.0f);
      EXPECT_EQ(test::coverageUp(*t2, x, y), inX && y >= 2 && y < 4 ? 1.0f : 0.0f);
      EXPECT_EQ(test::coverageUp(*t3, x, y), 0.0f);
    }
  }
}

TEST(Udim, RowsOfTilesBordersAndOutOfRange) {
  // A quad in tile 1011 (v ∈ [1, 2)), a triangle that only touches tile 1003's border, and
  // geometry at negative u (no tile).
  const Mesh mesh = test::uvPlaneMesh({{{0.1f, 1.1f}, {0.9f, 1.1f}, {0.9f, 1.9f}, {0.1f, 1.9f}},
                                       {{2.2f, 0.2f}, {3.0f, 0.5f}, {2.2f, 0.8f}},
                                       {{-0.5f, 0.2f}, {-0.1f, 0.2f}, {-0.1f, 0.6f}}});
  std::size_t outside = 99;
  EXPECT_EQ(udimTiles(mesh, 0, &outside), (std::vector<int>{1003, 1011}));
  EXPECT_EQ(outside, 1u) << "the triangle at negative u";
  const Result<FloatImage> t = bakeMask(mesh, 10, 10, 1, 1011);
  ASSERT_TRUE(t.ok());
  EXPECT_EQ(test::coverageUp(*t, 5, 5), 1.0f);
  EXPECT_EQ(test::coverageUp(*t, 0, 0), 0.0f);
  // A triangle spanning two tiles is baked, clipped, into both.
  const Mesh spanning = test::uvPlaneMesh({{{0.5f, 0.1f}, {1.5f, 0.1f}, {1.0f, 0.9f}}});
  EXPECT_EQ(udimTiles(spanning, 0, &outside), (std::vector<int>{1001, 1002}));
  EXPECT_EQ(outside, 0u);
  const Result<FloatImage> a = bakeMask(spanning, 16, 16, 1, 1001), b = bakeMask(spanning, 16, 16, 1, 1002);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(test::coverageUp(*a, 15, 4), 1.0f);
  EXPECT_EQ(test::coverageUp(*b, 0, 4), 1.0f);
}

// --- threads ---------------------------------------------------------------------------------

TEST(Raster, OneAndManyThreadsGiveIdenticalBits) {
  const Mesh mesh = test::gridMesh(test::torus, 24, 12);
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const test::SineHeight height(0.01, 3);
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, 1.0}, 1.0, {}}};
  for (const MapKind kind : {MapKind::kTangentNormal, MapKind::kHeight, MapKind::kDerivative}) {
    BakeSettings s;
    s.map = kind;
    s.width = 203;
    s.height = 97;
    s.samples = 2;
    FloatImage reference;
    for (const int threads : {1, 2, 3, 0}) {
      s.threads = threads;
      Result<FloatImage> image = bakeMap({&mesh, &*tangents, layers}, s);
      ASSERT_TRUE(image.ok()) << image.error().message;
      if (threads == 1) {
        reference = std::move(*image);
        continue;
      }
      ASSERT_EQ(image->pixels.size(), reference.pixels.size());
      EXPECT_EQ(std::memcmp(image->pixels.data(), reference.pixels.data(), reference.pixels.size() * sizeof(float)), 0)
          << mapKindName(kind) << " threads " << threads;
      EXPECT_EQ(image->coverage, reference.coverage);
    }
  }
}

TEST(Raster, RowSpansKeepEverySampleTheExactTestAccepts) {
  // rowSpan only narrows the texels to test; every sample inside the triangle (by the exact
  // edge functions) must lie in its row's span, for fat, thin, mirrored and nearly horizontal
  // triangles and 1 to 3 samples per axis, while the spans skip most of the bounding box of a
  // thin diagonal sliver.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-5.0, 70.0);
  std::size_t tested = 0, spanTexels = 0, boxTexels = 0;
  for (int t = 0; t < 400; ++t) {
    std::array<Vec2d, 3> p{Vec2d{coordinate(rng), coordinate(rng)},
                           Vec2d{coordinate(rng), coordinate(rng)},
                           Vec2d{coordinate(rng), coordinate(rng)}};
    if (t % 4 == 1) p[2] = p[0] + 1e-7 * (p[1] - p[0]) + Vec2d{0, 1e-9};  // sliver
    if (t % 4 == 2) p[1].y = p[0].y + 1e-12;                              // nearly horizontal
    if (t % 4 == 3) p = {Vec2d{0.3, 0.2}, Vec2d{63.7, 61.9}, Vec2d{1.1 + 0.01 * t, 0.4}};
    bake_detail::RasterTriangle tri;
    if (!bake_detail::setupRasterTriangle(p, 64, 64, tri)) continue;
    for (const int n : {1, 3}) {
      const bake_detail::SampleOffsets offsets(n);
      for (int y = tri.y0; y <= tri.y1; ++y) {
        int first = 0, last = -1;
        bake_detail::rowSpan(tri, y, offsets, first, last);
        ASSERT_GE(first, tri.x0);
        ASSERT_LE(last, tri.x1);
        if (t % 4 == 3 && n == 1) {
          spanTexels += static_cast<std::size_t>(std::max(0, last - first + 1));
          boxTexels += static_cast<std::size_t>(tri.x1 - tri.x0 + 1);
        }
        for (int x = tri.x0; x <= tri.x1; ++x) {
          for (const double oy : offsets.y) {
            for (const double ox : offsets.x) {
              const double px = x + ox, py = y + oy;
              bool inside = true;
              for (const bake_detail::EdgeFunction& e : tri.edge) inside = inside && e.inside(e(px, py));
              if (!inside) continue;
              ++tested;
              ASSERT_TRUE(x >= first && x <= last)
                  << "triangle " << t << ", sample (" << px << ", " << py << ") outside the span ["
                  << first << ", " << last << "]";
            }
          }
        }
      }
    }
  }
  EXPECT_GT(tested, 10000u);
  EXPECT_LT(spanTexels * 4, boxTexels);  // the slivers' spans are a small part of their boxes
}

}  // namespace
}  // namespace sgbake
