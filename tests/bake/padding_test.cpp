// Edge padding: Blender's Extend margin grows ring by ring in the L1 metric with IMB_filter_extend's
// 2/1 weights; push-pull fills every hole and keeps covered texels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <random>

#include "bake_test_util.hpp"
#include "sgbake/bake/bake.hpp"

namespace sgbake {
namespace {

constexpr float kHole = std::numeric_limits<float>::quiet_NaN();

/// W×H×C image of holes (NaN, coverage 0).
FloatImage holes(int w, int h, int c) {
  FloatImage image;
  image.width = w;
  image.height = h;
  image.channels = c;
  image.pixels.assign(static_cast<std::size_t>(w) * h * c, kHole);
  image.coverage.assign(static_cast<std::size_t>(w) * h, 0.0f);
  return image;
}

void cover(FloatImage& image, int x, int row, std::initializer_list<float> value, float coverage = 1) {
  int c = 0;
  for (const float v : value) image.at(x, row, c++) = v;
  image.coverage[static_cast<std::size_t>(row) * image.width + x] = coverage;
}

bool isHole(const FloatImage& image, int x, int row) { return std::isnan(image.at(x, row, 0)); }

TEST(ExtendMargin, GrowsOneL1RingPerPass) {
  // A 3×2 island; after margin k exactly the texels within L1 distance k of it are written.
  for (int margin = 0; margin <= 5; ++margin) {
    FloatImage image = holes(20, 17, 2);
    for (int row = 7; row < 9; ++row)
      for (int x = 8; x < 11; ++x) cover(image, x, row, {0.25f, -3.0f});
    const std::vector<float> coverage = image.coverage;
    extendMargin(image, margin);
    EXPECT_EQ(image.coverage, coverage);  // coverage stays geometric
    for (int row = 0; row < 17; ++row) {
      for (int x = 0; x < 20; ++x) {
        const int dx = x < 8 ? 8 - x : (x > 10 ? x - 10 : 0);
        const int dr = row < 7 ? 7 - row : (row > 8 ? row - 8 : 0);
        const bool within = dx + dr <= margin;
        ASSERT_EQ(!isHole(image, x, row), within) << "margin " << margin << " at " << x << "," << row;
        if (within) {  // averages of equal values
          EXPECT_EQ(image.at(x, row, 0), 0.25f);
          EXPECT_EQ(image.at(x, row, 1), -3.0f);
        }
      }
    }
  }
}

TEST(ExtendMargin, WeightsEdgeNeighboursTwiceAsMuchAsDiagonalOnes) {
  // a = 3 at (1, 1), b = 9 at (3, 0) (x, row). One pass:
  FloatImage image = holes(5, 3, 1);
  cover(image, 1, 1, {3.0f});
  cover(image, 3, 0, {9.0f});
  extendMargin(image, 1);
  EXPECT_FLOAT_EQ(image.at(2, 1, 0), (2 * 3.0f + 9.0f) / 3);  // a beside (2), b diagonal (1)
  EXPECT_FLOAT_EQ(image.at(2, 0, 0), (2 * 9.0f + 3.0f) / 3);  // b beside (2), a diagonal (1)
  EXPECT_FLOAT_EQ(image.at(0, 1, 0), 3.0f);
  EXPECT_FLOAT_EQ(image.at(1, 0, 0), 3.0f);
  EXPECT_FLOAT_EQ(image.at(1, 2, 0), 3.0f);
  EXPECT_FLOAT_EQ(image.at(4, 0, 0), 9.0f);
  EXPECT_FLOAT_EQ(image.at(3, 1, 0), 9.0f);
  // A diagonal neighbour alone does not fill a texel (Blender requires an edge neighbour).
  EXPECT_TRUE(isHole(image, 0, 0));
  EXPECT_TRUE(isHole(image, 0, 2));
  EXPECT_TRUE(isHole(image, 2, 2));
  // The second pass reads the first ring: (0, 0) now has edge neighbours (1, 0) and (0, 1).
  extendMargin(image, 1);  // covered set is still {a, b}: the same first ring again
  EXPECT_TRUE(isHole(image, 0, 0));
  FloatImage twice = holes(5, 3, 1);
  cover(twice, 1, 1, {3.0f});
  cover(twice, 3, 0, {9.0f});
  extendMargin(twice, 2);
  EXPECT_FLOAT_EQ(twice.at(0, 0, 0), 3.0f);  // (1,0) and (0,1) both 3, (1,1) diagonal 3
  EXPECT_FLOAT_EQ(twice.at(2, 2, 0), (2 * 3.0f + 2 * 5.0f + 3.0f + 9.0f) / 6);
}

TEST(ExtendMargin, ThreadsGiveIdenticalBits) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(0, 1);
  FloatImage image = holes(300, 211, 3);
  for (int k = 0; k < 400; ++k)
    cover(image, static_cast<int>(rng() % 300), static_cast<int>(rng() % 211), {value(rng), value(rng), value(rng)});
  FloatImage a = image, b = image;
  extendMargin(a, 7, 1);
  extendMargin(b, 7, 2);
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)), 0);
}

TEST(ExtendMargin, StripsFromTheirHaloAloneEqualTheWholeImage) {
  // extendMarginRows pads a strip from `margin` rows either side of it; every strip, near the
  // image's edges or not, must equal those rows of the whole image's padding bit for bit.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> value(0, 1);
  FloatImage image = holes(97, 130, 3);
  for (int k = 0; k < 60; ++k) {  // small islands, a few texels each, with gaps between
    const int x0 = static_cast<int>(rng() % 95), r0 = static_cast<int>(rng() % 128);
    for (int r = r0; r < r0 + 2; ++r)
      for (int x = x0; x < x0 + 3; ++x) cover(image, x, r, {value(rng), value(rng), value(rng)});
  }
  for (const int margin : {1, 4, 9}) {
    FloatImage whole = image;
    extendMargin(whole, margin);
    FloatImage window;  // reused from strip to strip, as the baker does
    for (const int rows : {1, 7, 33}) {
      for (int begin = 0; begin < image.height; begin += rows) {
        const int end = std::min(image.height, begin + rows);
        const int first = extendMarginRows(image, margin, begin, end, window);
        ASSERT_EQ(window.width, image.width);
        ASSERT_GE(window.height, first + end - begin);
        const std::size_t rowValues = static_cast<std::size_t>(image.width) * 3;
        ASSERT_EQ(std::memcmp(window.pixels.data() + static_cast<std::size_t>(first) * rowValues,
                              whole.pixels.data() + static_cast<std::size_t>(begin) * rowValues,
                              static_cast<std::size_t>(end - begin) * rowValues * sizeof(float)),
                  0)
            << "margin " << margin << ", rows " << begin << " to " << end;
      }
    }
  }
  // The test can fail: a strip padded without its halo differs from the whole image.
  FloatImage whole = image;
  extendMargin(whole, 9);
  FloatImage window;
  const int first = extendMarginRows(image, 0, 40, 50, window);
  extendMargin(window, 9);
  EXPECT_NE(std::memcmp(window.pixels.data() + static_cast<std::size_t>(first) * 97 * 3,
                        whole.pixels.data() + std::size_t{40} * 97 * 3, std::size_t{10} * 97 * 3 * sizeof(float)),
            0);
}

TEST(ExtendMargin, BandsPaddedInPlaceInARingEqualTheWholeImage) {
  // What the CLI does: bands of rows arrive top first in a ring of band + 2·margin rows; after
  // each, the rows at least `margin` above the unbaked part are padded in place, with the rows
  // above them already padded the same way. Every row must end up as the whole image's padding.
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> value(-1, 1);
  FloatImage image = holes(53, 211, 3);
  for (int k = 0; k < 40; ++k) {
    const int x0 = static_cast<int>(rng() % 51), r0 = static_cast<int>(rng() % 209);
    for (int r = r0; r < r0 + 2; ++r)
      for (int x = x0; x < x0 + 2; ++x) cover(image, x, r, {value(rng), value(rng), value(rng)});
  }
  const std::size_t rowValues = 53 * 3;
  for (const int margin : {1, 6, 15}) {
    for (const int band : {8, 40}) {
      FloatImage whole = image;
      extendMargin(whole, margin);
      const int ringRows = band + 2 * margin;
      std::vector<float> pixels(static_cast<std::size_t>(ringRows) * rowValues);
      std::vector<float> coverage(static_cast<std::size_t>(ringRows) * 53);
      int written = 0, previousEnd = 0;
      for (int end = std::min(211, band); previousEnd < 211; end = std::min(211, end + band)) {
        for (int r = previousEnd; r < end; ++r) {  // the new band, as baked
          std::copy_n(image.pixels.begin() + static_cast<std::ptrdiff_t>(r * rowValues), rowValues,
                      pixels.begin() + static_cast<std::ptrdiff_t>((r % ringRows) * rowValues));
          std::copy_n(image.coverage.begin() + r * 53, 53, coverage.begin() + (r % ringRows) * 53);
        }
        const MutableImageRows rows{53, 211, 3, std::max(0, previousEnd - 2 * margin), end, ringRows,
                                    pixels.data(), coverage.data()};
        previousEnd = end;
        const int ready = end == 211 ? 211 : end - margin;
        if (ready <= written) continue;
        extendMarginRowsInPlace(rows, margin, written, ready);
        for (int r = written; r < ready; ++r) {
          ASSERT_EQ(std::memcmp(rows.pixelRow(r), whole.pixels.data() + static_cast<std::size_t>(r) * rowValues,
                                rowValues * sizeof(float)),
                    0)
              << "margin " << margin << ", band " << band << ", row " << r;
        }
        written = ready;
      }
      EXPECT_EQ(written, 211);
    }
  }
  // A view that holds a strip's halo pads it as the whole image; one that lacks part of the
  // halo leaves every row as it was.
  FloatImage whole = image;
  extendMargin(whole, 15);
  FloatImage strip = image;
  MutableImageRows rows = MutableImageRows::of(strip);
  rows.begin = 100;
  rows.end = 140;
  extendMarginRowsInPlace(rows, 15, 115, 125);  // needs rows 100 to 140: held
  EXPECT_EQ(std::memcmp(strip.pixels.data() + 115 * rowValues, whole.pixels.data() + 115 * rowValues,
                        10 * rowValues * sizeof(float)),
            0);
  FloatImage untouched = image;
  MutableImageRows partial = MutableImageRows::of(untouched);
  partial.begin = 110;  // rows 100 to 110 missing
  partial.end = 140;
  extendMarginRowsInPlace(partial, 15, 115, 125);
  EXPECT_EQ(std::memcmp(untouched.pixels.data(), image.pixels.data(), image.pixels.size() * sizeof(float)), 0);
}

TEST(ExtendMargin, StripsReadFromARingOfRowsEqualTheWholeImage) {
  // The baker keeps only a ring of rows (bakeMapRows): file row r in slot r % ringRows, with
  // the rows a strip reads wrapping around the ring's end. The padded strip must not depend on
  // where its rows sit.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(0, 1);
  FloatImage image = holes(41, 90, 2);
  for (int k = 0; k < 30; ++k) {
    const int x0 = static_cast<int>(rng() % 40), r0 = static_cast<int>(rng() % 89);
    cover(image, x0, r0, {value(rng), value(rng)});
  }
  const int margin = 3, ringRows = 17;
  FloatImage whole = image;
  extendMargin(whole, margin);
  const std::size_t rowValues = 41 * 2;
  std::vector<float> pixels(ringRows * rowValues, -1.0f), coverage(ringRows * 41, -1.0f);
  FloatImage window;
  int checked = 0;
  for (int begin = 0; begin + 5 <= 90; begin += 5) {
    const int end = begin + 5;
    const int from = std::max(0, begin - margin), to = std::min(90, end + margin);
    for (int r = from; r < to; ++r) {  // the rows the strip needs, at their ring slots
      std::copy_n(image.pixels.begin() + r * 82, 82, pixels.begin() + (r % ringRows) * 82);
      std::copy_n(image.coverage.begin() + r * 41, 41, coverage.begin() + (r % ringRows) * 41);
    }
    const ImageRows rows{41, 90, 2, from, to, ringRows, pixels.data(), coverage.data()};
    const int first = extendMarginRows(rows, margin, begin, end, window);
    ASSERT_EQ(window.height, to - from);
    EXPECT_EQ(std::memcmp(window.pixels.data() + static_cast<std::size_t>(first) * rowValues,
                          whole.pixels.data() + static_cast<std::size_t>(begin) * rowValues,
                          5 * rowValues * sizeof(float)),
              0)
        << "rows " << begin << " to " << end;
    checked += to / ringRows != from / ringRows ? 1 : 0;  // strips whose rows wrap
  }
  EXPECT_GE(checked, 4);
  // Rows the view does not hold give an empty window, not a read outside the ring.
  const ImageRows partial{41, 90, 2, 10, 20, ringRows, pixels.data(), coverage.data()};
  extendMarginRows(partial, margin, 10, 20, window);
  EXPECT_EQ(window.height, 0);
}

TEST(PushPullFill, FillsEveryHoleAndKeepsCoveredTexels) {
  for (const auto& [w, h] : std::vector<std::array<int, 2>>{{64, 64}, {37, 19}, {1, 9}, {129, 3}}) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> value(-1, 2);
    FloatImage image = holes(w, h, 3);
    for (int k = 0; k < std::max(1, w * h / 50); ++k)
      cover(image, static_cast<int>(rng() % w), static_cast<int>(rng() % h), {value(rng), value(rng), value(rng)},
            k % 3 == 0 ? 0.5f : 1.0f);
    const FloatImage before = image;
    float lo = INFINITY, hi = -INFINITY;
    for (std::size_t i = 0; i < before.coverage.size(); ++i)
      if (before.coverage[i] > 0)
        for (int c = 0; c < 3; ++c) {
          lo = std::min(lo, before.pixels[3 * i + c]);
          hi = std::max(hi, before.pixels[3 * i + c]);
        }
    pushPullFill(image, 2);
    FloatImage serial = before;
    pushPullFill(serial, 1);
    EXPECT_EQ(std::memcmp(image.pixels.data(), serial.pixels.data(), image.pixels.size() * sizeof(float)), 0);
    EXPECT_EQ(image.coverage, before.coverage);
    for (std::size_t i = 0; i < image.coverage.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        const float v = image.pixels[3 * i + c];
        ASSERT_FALSE(std::isnan(v)) << w << "x" << h << " texel " << i;
        if (before.coverage[i] > 0) {
          ASSERT_EQ(std::memcmp(&v, &before.pixels[3 * i + c], sizeof(float)), 0);
        } else {  // a convex combination of the sources
          EXPECT_GE(v, lo - 1e-6f);
          EXPECT_LE(v, hi + 1e-6f);
        }
      }
    }
  }
}

TEST(PushPullFill, ConstantSourcesGiveAConstantFillAndNoSourcesChangeNothing) {
  FloatImage image = holes(50, 30, 1);
  cover(image, 3, 4, {0.75f});
  cover(image, 40, 20, {0.75f});
  pushPullFill(image);
  for (const float v : image.pixels) EXPECT_FLOAT_EQ(v, 0.75f);
  FloatImage empty = holes(8, 8, 2);
  pushPullFill(empty);
  for (const float v : empty.pixels) EXPECT_TRUE(std::isnan(v));
}

TEST(Padding, InvalidImagesAreIgnored) {
  FloatImage bad;
  bad.width = 4;
  bad.height = 4;
  bad.channels = 3;
  bad.pixels.assign(5, 0.0f);  // wrong size: nothing happens, nothing crashes
  extendMargin(bad, 3);
  pushPullFill(bad);
  EXPECT_EQ(bad.pixels.size(), 5u);
}

}  // namespace
}  // namespace sgbake

namespace sgbake {
namespace {

// Adjacent Faces margin: two unit squares side by side in 3D (x ∈ [0, 2], y ∈ [0, 1]) whose UV
// islands lie apart, the second turned by 90° (or mirrored). Each covered texel holds the 3D
// point (x, y) it shows; a margin texel across the shared edge must hold the point the surface
// continues to there, which the other island shows.
struct SeamScene {
  Mesh mesh;
  FloatImage image;
  bool mirrored = false;
};

constexpr int kSeamSize = 100;  // 0.2 UV = 20 texels: island edges lie between texel centres

Vec2d islandA(Vec2d uv) { return {(uv.x - 0.2) / 0.2, (uv.y - 0.2) / 0.2}; }
Vec2d islandB(Vec2d uv, bool mirrored) {
  // Turned: uv = (0.7, 0.6) + 0.2·(−b, a); mirrored: uv = (0.5, 0.6) + 0.2·(b, a); (a, b) = (x − 1,
  // y).
  const double a = (uv.y - 0.6) / 0.2;
  const double b = mirrored ? (uv.x - 0.5) / 0.2 : -(uv.x - 0.7) / 0.2;
  return {1 + a, b};
}

SeamScene seamScene(bool mirrored, int size = kSeamSize, float uShiftB = 0) {
  SeamScene s;
  s.mirrored = mirrored;
  const std::vector<Vec3f> positions{{0, 0, 0}, {1, 0, 0}, {1, 1, 0},
                                     {0, 1, 0}, {2, 0, 0}, {2, 1, 0}};
  auto uvB = [&](float x, float y) {
    const float a = x - 1, b = y;
    return mirrored ? Vec2f{uShiftB + 0.5f + 0.2f * b, 0.6f + 0.2f * a}
                    : Vec2f{uShiftB + 0.7f - 0.2f * b, 0.6f + 0.2f * a};
  };
  const std::vector<Vec2f> uvs{{0.2f, 0.2f}, {0.4f, 0.2f}, {0.4f, 0.4f}, {0.2f, 0.4f},
                               uvB(1, 0),    uvB(2, 0),    uvB(2, 1),    uvB(1, 1)};
  s.mesh = test::polygonMesh(positions, {{0, 1, 2, 3}, {1, 4, 5, 2}}, uvs);
  s.image = holes(size, size, 2);
  for (int row = 0; row < size; ++row) {
    for (int x = 0; x < size; ++x) {
      const Vec2d uv{(x + 0.5) / size, 1 - (row + 0.5) / size};
      const bool inA = uv.x > 0.2 && uv.x < 0.4 && uv.y > 0.2 && uv.y < 0.4;
      const bool inB = uv.x > 0.5 && uv.x < 0.7 && uv.y > 0.6 && uv.y < 0.8;
      if (!inA && !inB) continue;
      const Vec2d p = inA ? islandA(uv) : islandB(uv, mirrored);
      cover(s.image, x, row, {static_cast<float>(p.x), static_cast<float>(p.y)});
    }
  }
  return s;
}

TEST(AdjacentFacesMargin, ContinuesTheSurfaceAcrossASeam) {
  for (const bool mirrored : {false, true}) {
    SeamScene s = seamScene(mirrored);
    const std::vector<float> before = s.image.pixels;
    adjacentFacesMargin(s.image, s.mesh, 0, kFirstUdimTile, 1, 4);
    int checked = 0;
    for (int row = 0; row < kSeamSize; ++row) {
      for (int x = 0; x < kSeamSize; ++x) {
        const Vec2d uv{(x + 0.5) / kSeamSize, 1 - (row + 0.5) / kSeamSize};
        std::optional<Vec2d> expected;
        // Right of A, off the edge's ends: the surface continues into B.
        if (uv.x > 0.4 && uv.x < 0.45 && uv.y > 0.22 && uv.y < 0.38) expected = islandA(uv);
        // Beyond B's side on the shared edge (its bottom, v = 0.6): back into A.
        if (uv.y < 0.6 && uv.y > 0.55 && uv.x > 0.52 && uv.x < 0.68)
          expected = islandB(uv, mirrored);
        if (!expected) continue;
        ASSERT_FALSE(isHole(s.image, x, row))
            << "mirrored " << mirrored << " texel " << x << "," << row;
        EXPECT_NEAR(s.image.at(x, row, 0), expected->x, 1e-5)
            << "mirrored " << mirrored << " " << x << "," << row;
        EXPECT_NEAR(s.image.at(x, row, 1), expected->y, 1e-5)
            << "mirrored " << mirrored << " " << x << "," << row;
        ++checked;
      }
    }
    EXPECT_EQ(checked, 2 * 5 * 16);  // 5 columns beyond A (margin 4 reaches 5), 5 rows below B
    for (std::size_t i = 0; i < before.size(); ++i) {  // covered texels keep their values
      if (s.image.coverage[i / 2] > 0) {
        ASSERT_EQ(s.image.pixels[i], before[i]);
      }
    }
  }
}

TEST(AdjacentFacesMargin, ReachesOneTexelBeyondTheMarginAsBlenderDoes) {
  // Blender 3.4 writes margin + 1 texel rows beyond a straight island edge with Adjacent Faces
  // (9 for margin 8), one more than its Extend margin.
  for (const int margin : {1, 3, 8}) {
    SeamScene s = seamScene(false);
    adjacentFacesMargin(s.image, s.mesh, 0, kFirstUdimTile, 1, margin);
    const int row = kSeamSize - 30;  // v = 0.295: across A's middle
    int written = 0;
    for (int x = 40; x < 50; ++x) written += isHole(s.image, x, row) ? 0 : 1;
    EXPECT_EQ(written, margin + 1) << "margin " << margin;
  }
}

TEST(AdjacentFacesMargin, ABoundaryEdgeRepeatsTheNearestPointOfTheFace) {
  // Left of A the mesh ends: the margin holds the face's value at the edge's nearest point,
  // which for a texel beside the island is the edge texel of the same row.
  SeamScene s = seamScene(false);
  adjacentFacesMargin(s.image, s.mesh, 0, kFirstUdimTile, 1, 4);
  for (int row = kSeamSize - 38; row < kSeamSize - 22; ++row) {
    for (int x = 15; x < 20; ++x) {
      ASSERT_FALSE(isHole(s.image, x, row));
      EXPECT_FLOAT_EQ(s.image.at(x, row, 0), s.image.at(20, row, 0));
      EXPECT_FLOAT_EQ(s.image.at(x, row, 1), s.image.at(20, row, 1));
    }
  }
}

TEST(AdjacentFacesMargin, WhereTheSeamLeadsOutOfTheTileTheFaceIsExtended) {
  // B in UDIM tile 1002: beyond A's shared edge the surface continues in another image, so
  // the margin repeats A's value at its outline's nearest point, as at a boundary.
  SeamScene s = seamScene(false, kSeamSize, 1.0f);
  adjacentFacesMargin(s.image, s.mesh, 0, kFirstUdimTile, 1, 4);
  for (int row = kSeamSize - 38; row < kSeamSize - 22; ++row) {
    for (int x = 40; x < 45; ++x) {
      ASSERT_FALSE(isHole(s.image, x, row)) << x << "," << row;
      EXPECT_FLOAT_EQ(s.image.at(x, row, 0), s.image.at(39, row, 0));
      EXPECT_FLOAT_EQ(s.image.at(x, row, 1), s.image.at(39, row, 1));
    }
  }
}

TEST(AdjacentFacesMargin, ThreadsGiveIdenticalBits) {
  // 500 rows: several blocks of the distance transform and of the face raster.
  SeamScene a = seamScene(true, 500), b = seamScene(true, 500);
  adjacentFacesMargin(a.image, a.mesh, 0, kFirstUdimTile, 1, 6, 1);
  adjacentFacesMargin(b.image, b.mesh, 0, kFirstUdimTile, 1, 6, 2);
  EXPECT_EQ(0, std::memcmp(a.image.pixels.data(), b.image.pixels.data(),
                           a.image.pixels.size() * sizeof(float)));
}

}  // namespace
}  // namespace sgbake
