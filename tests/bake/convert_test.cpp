// Object <-> tangent conversion: converting an object-space bake gives the tangent-space bake of
// the same layers (and back), texels outside the islands keep the input, threads do not matter.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "bake_test_util.hpp"
#include "support/bspline_torus.hpp"
#include "support/parametric_mesh.hpp"
#include "sgbake/bake/bake.hpp"
#include "sgbake/bake/convert.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/subdiv/limit_surface.hpp"

namespace sgbake {
namespace {

/// Converted values go through one extra float encode/decode: a few float ulps of 1.
constexpr double kRoundTripTol = 2e-6;

struct Baked {
  Mesh mesh;
  CornerTangents tangents;
  FloatImage objectSpace, tangentSpace;
};

/// A sphere and a torus (curved, seams, mirrored sign-free UVs) with a sine height layer.
Baked bakeBoth(const test::Surface& surface, int size, int samples) {
  Baked b;
  b.mesh = test::gridMesh(surface, 24, 16, [](double s, double t) { return Vec2d{0.02 + 0.96 * s, 0.02 + 0.96 * t}; });
  Result<CornerTangents> tangents = computeTangents(b.mesh.view(0));
  EXPECT_TRUE(tangents.ok());
  b.tangents = std::move(*tangents);
  static const test::SineHeight height(0.004, 5);
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, 1.0}, 1.0, {}}};
  BakeSettings s;
  s.width = s.height = size;
  s.samples = samples;
  s.map = MapKind::kObjectNormal;
  Result<FloatImage> o = bakeMap({&b.mesh, &b.tangents, layers}, s);
  s.map = MapKind::kTangentNormal;
  Result<FloatImage> t = bakeMap({&b.mesh, &b.tangents, layers}, s);
  EXPECT_TRUE(o.ok() && t.ok());
  b.objectSpace = std::move(*o);
  b.tangentSpace = std::move(*t);
  return b;
}

double maxDifference(const FloatImage& a, const FloatImage& b, int& compared) {
  double worst = 0;
  compared = 0;
  for (std::size_t i = 0; i < a.coverage.size(); ++i) {
    if (a.coverage[i] != 1.0f) continue;
    ++compared;
    for (std::size_t c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(double(a.pixels[3 * i + c]) - double(b.pixels[3 * i + c])));
  }
  return worst;
}

TEST(Convert, ObjectToTangentOfAnObjectBakeIsTheTangentBakeAndBack) {
  for (const auto& surface : {test::Surface(test::sphere), test::Surface(test::torus)}) {
    const Baked b = bakeBoth(surface, 96, 1);
    ConvertSettings cs;
    const Result<FloatImage> toTangent =
        convertNormalMap(b.mesh, b.tangents, b.objectSpace, NormalSpace::kObject, NormalSpace::kTangent, cs);
    const Result<FloatImage> toObject =
        convertNormalMap(b.mesh, b.tangents, b.tangentSpace, NormalSpace::kTangent, NormalSpace::kObject, cs);
    ASSERT_TRUE(toTangent.ok() && toObject.ok());
    EXPECT_EQ(toTangent->coverage, b.tangentSpace.coverage);
    int compared = 0;
    EXPECT_LT(maxDifference(*toTangent, b.tangentSpace, compared), kRoundTripTol);
    EXPECT_GT(compared, 4000);
    EXPECT_LT(maxDifference(*toObject, b.objectSpace, compared), kRoundTripTol);
    // Round trip tangent → object → tangent.
    const Result<FloatImage> back =
        convertNormalMap(b.mesh, b.tangents, *toObject, NormalSpace::kObject, NormalSpace::kTangent, cs);
    ASSERT_TRUE(back.ok());
    EXPECT_LT(maxDifference(*back, b.tangentSpace, compared), kRoundTripTol);
    // The conversion is not the identity: the two bakes differ a lot.
    EXPECT_GT(maxDifference(b.objectSpace, b.tangentSpace, compared), 0.3);
  }
}

TEST(Convert, OnTheLimitSurfaceAnObjectBakeBecomesTheLimitTangentBake) {
  // A regular torus grid (its limit is a bicubic B-spline) with a sine height layer, baked from
  // the limit surface in both spaces: converting with the limit surface's frames (settings.limit)
  // turns one bake into the other, as on meshes.
  const Mesh coarse = test::torusGridWithUvs(8, 6);
  Result<LimitTessellation> limit =
      tessellateLimitSurface(coarse, {0, SubdivisionUvSmooth::kNone});
  ASSERT_TRUE(limit) << limit.error().message;
  Result<CornerTangents> tangents = computeTangents(limit->mesh.view(0));
  ASSERT_TRUE(tangents);
  static const test::SineHeight height(0.004, 5);
  const std::vector<Layer> layers{Layer{UvHeightSource{&height, 0, 1.0}, 1.0, {}}};
  const BakeInput input{&limit->mesh, &*tangents, layers, &limit->surface, &limit->parameters};
  BakeSettings s;
  s.width = s.height = 96;
  s.map = MapKind::kObjectNormal;
  Result<FloatImage> objectSpace = bakeMap(input, s);
  s.map = MapKind::kTangentNormal;
  Result<FloatImage> tangentSpace = bakeMap(input, s);
  ASSERT_TRUE(objectSpace && tangentSpace);

  ConvertSettings cs;
  cs.limit = &limit->surface;
  cs.limitParameters = &limit->parameters;
  const Result<FloatImage> toTangent = convertNormalMap(
      limit->mesh, *tangents, *objectSpace, NormalSpace::kObject, NormalSpace::kTangent, cs);
  const Result<FloatImage> toObject = convertNormalMap(
      limit->mesh, *tangents, *tangentSpace, NormalSpace::kTangent, NormalSpace::kObject, cs);
  ASSERT_TRUE(toTangent && toObject) << (toTangent ? toObject.error() : toTangent.error()).message;
  EXPECT_EQ(toTangent->coverage, tangentSpace->coverage);
  int compared = 0;
  EXPECT_LT(maxDifference(*toTangent, *tangentSpace, compared), kRoundTripTol);
  EXPECT_EQ(compared, 96 * 96);  // the UVs tile [0,1]²
  EXPECT_LT(maxDifference(*toObject, *objectSpace, compared), kRoundTripTol);

  // The tessellation's own MikkTSpace frames are not the limit surface's: without
  // settings.limit the same conversion misses the limit bake.
  cs.limit = nullptr;
  cs.limitParameters = nullptr;
  const Result<FloatImage> meshFrames = convertNormalMap(
      limit->mesh, *tangents, *objectSpace, NormalSpace::kObject, NormalSpace::kTangent, cs);
  ASSERT_TRUE(meshFrames);
  EXPECT_GT(maxDifference(*meshFrames, *tangentSpace, compared), 100 * kRoundTripTol);

  // A mesh that is not the tessellation is refused.
  cs.limit = &limit->surface;
  cs.limitParameters = &limit->parameters;
  const Result<CornerTangents> coarseTangents = computeTangents(coarse.view(0));
  ASSERT_TRUE(coarseTangents);
  const Result<FloatImage> refused = convertNormalMap(
      coarse, *coarseTangents, *objectSpace, NormalSpace::kObject, NormalSpace::kTangent, cs);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("not a tessellation of the limit surface"),
            std::string::npos);
}

TEST(Convert, SupersampledConversionMatchesTheSupersampledBake) {
  // A texel's input colour is converted with the frame at each sample and the results averaged;
  // compared against a 2×2 bake of the same layers. The two differ only by how much the frame and
  // the bumps vary inside a texel (a torus: no poles, where the bumps' slope is unbounded).
  const Baked b = bakeBoth(test::torus, 64, 2);
  ConvertSettings cs;
  cs.samples = 2;
  const Result<FloatImage> toTangent =
      convertNormalMap(b.mesh, b.tangents, b.objectSpace, NormalSpace::kObject, NormalSpace::kTangent, cs);
  ASSERT_TRUE(toTangent.ok());
  EXPECT_EQ(toTangent->coverage, b.tangentSpace.coverage);
  int compared = 0;
  EXPECT_LT(maxDifference(*toTangent, b.tangentSpace, compared), 0.05);
}

TEST(Convert, TexelsOutsideIslandsAndExtraChannelsKeepTheInput) {
  const Mesh mesh = test::uvPlaneMesh({{{0.25f, 0.25f}, {0.75f, 0.25f}, {0.75f, 0.75f}, {0.25f, 0.75f}}});
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  FloatImage input;
  input.width = 16;
  input.height = 12;
  input.channels = 4;
  for (int i = 0; i < 16 * 12 * 4; ++i) input.pixels.push_back(0.001f * static_cast<float>(i % 997));
  input.coverage.assign(16 * 12, 0.0f);
  for (const NormalMapGreen green : {NormalMapGreen::kOpenGL, NormalMapGreen::kDirectX}) {
    ConvertSettings cs;
    cs.green = green;
    const Result<FloatImage> out =
        convertNormalMap(mesh, *tangents, input, NormalSpace::kObject, NormalSpace::kTangent, cs);
    ASSERT_TRUE(out.ok()) << out.error().message;
    ASSERT_EQ(out->channels, 4);
    int covered = 0;
    for (int row = 0; row < 12; ++row) {
      for (int x = 0; x < 16; ++x) {
        const std::size_t i = static_cast<std::size_t>(row) * 16 + x;
        EXPECT_EQ(out->pixels[4 * i + 3], input.pixels[4 * i + 3]);  // alpha copied
        if (out->coverage[i] == 0) {
          for (int c = 0; c < 3; ++c) EXPECT_EQ(out->pixels[4 * i + c], input.pixels[4 * i + c]);
        } else {
          ++covered;
          // A flat plane with frame (x̂, ±ŷ, ẑ): the converted colour is the input normalized.
          const Vec3d n = normalizeOr(Vec3d{2.0 * input.pixels[4 * i] - 1, 2.0 * input.pixels[4 * i + 1] - 1,
                                            2.0 * input.pixels[4 * i + 2] - 1},
                                      Vec3d{0, 0, 1});
          const double g = green == NormalMapGreen::kDirectX ? -n.y : n.y;
          EXPECT_NEAR(out->pixels[4 * i], 0.5 * n.x + 0.5, 2e-6);
          EXPECT_NEAR(out->pixels[4 * i + 1], 0.5 * g + 0.5, 2e-6);
          EXPECT_NEAR(out->pixels[4 * i + 2], 0.5 * n.z + 0.5, 2e-6);
        }
      }
    }
    EXPECT_EQ(covered, 8 * 6);
  }
}

// Swizzled channels (Blender's bake Swizzle) on either side: the input is read in its order,
// the output written in its own, and a DirectX green negates the G channel of the
// tangent-space side after its swizzle; a swizzle naming an axis twice cannot be read back.
TEST(Convert, SwizzledChannelsAreReadAndWrittenInTheirOrder) {
  const Mesh mesh =
      test::uvPlaneMesh({{{0.25f, 0.25f}, {0.75f, 0.25f}, {0.75f, 0.75f}, {0.25f, 0.75f}}});
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  const NormalSwizzle in = {{{1, true}, {2, false}, {0, false}}};  // -Y+Z+X
  const NormalSwizzle out = {{{2, true}, {0, false}, {1, true}}};  // -Z+X-Y
  FloatImage input;
  input.width = 16;
  input.height = 12;
  input.channels = 3;
  input.coverage.assign(16 * 12, 0.0f);
  std::vector<Vec3d> normals;  // what each texel stands for
  for (int i = 0; i < 16 * 12; ++i) {
    const Vec3d n = normalizeOr(Vec3d{0.3 * std::sin(i), 0.4 * std::cos(3.0 * i), 1.0}, Vec3d{});
    normals.push_back(n);
    for (const SwizzleAxis& s : in) {
      const double v = n[static_cast<std::size_t>(s.axis)];
      input.pixels.push_back(static_cast<float>(0.5 * (s.negate ? -v : v) + 0.5));
    }
  }
  for (const NormalMapGreen green : {NormalMapGreen::kOpenGL, NormalMapGreen::kDirectX}) {
    for (const NormalSpace from : {NormalSpace::kObject, NormalSpace::kTangent}) {
      const NormalSpace to =
          from == NormalSpace::kObject ? NormalSpace::kTangent : NormalSpace::kObject;
      SCOPED_TRACE(std::string(normalSpaceName(from)) +
                   (green == NormalMapGreen::kDirectX ? ", DirectX" : ""));
      ConvertSettings cs;
      cs.green = green;
      cs.inputSwizzle = in;
      cs.outputSwizzle = out;
      const Result<FloatImage> converted = convertNormalMap(mesh, *tangents, input, from, to, cs);
      ASSERT_TRUE(converted.ok()) << converted.error().message;
      int covered = 0;
      for (std::size_t i = 0; i < normals.size(); ++i) {
        if (converted->coverage[i] == 0) {
          for (std::size_t c = 0; c < 3; ++c)
            EXPECT_EQ(converted->pixels[3 * i + c], input.pixels[3 * i + c]);
          continue;
        }
        ++covered;
        // The plane's frame is (x̂, ŷ, ẑ): the normal is the same in both spaces. A DirectX
        // green reads the input's G negated (from tangent space: the component in[1] stands
        // for comes out negated) or writes the output's G negated (to tangent space).
        const bool dx = green == NormalMapGreen::kDirectX;
        Vec3d n = normals[i];
        if (dx && from == NormalSpace::kTangent) {
          n[static_cast<std::size_t>(in[1].axis)] = -n[static_cast<std::size_t>(in[1].axis)];
        }
        for (std::size_t c = 0; c < 3; ++c) {
          const double v = n[static_cast<std::size_t>(out[c].axis)];
          const bool negate = out[c].negate != (dx && to == NormalSpace::kTangent && c == 1);
          EXPECT_NEAR(converted->pixels[3 * i + c], 0.5 * (negate ? -v : v) + 0.5, 2e-6)
              << "texel " << i << " channel " << c;
        }
      }
      EXPECT_EQ(covered, 8 * 6);
    }
  }
  ConvertSettings twice;
  twice.inputSwizzle = {{{0, false}, {0, true}, {2, false}}};
  const Result<FloatImage> refused =
      convertNormalMap(mesh, *tangents, input, NormalSpace::kObject, NormalSpace::kTangent, twice);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("swizzle +X-X+Z names an axis twice"), std::string::npos)
      << refused.error().message;
}

TEST(Convert, ThreadsGiveIdenticalBits) {
  const Baked b = bakeBoth(test::torus, 80, 1);
  ConvertSettings cs;
  cs.samples = 3;
  cs.threads = 1;
  const Result<FloatImage> one =
      convertNormalMap(b.mesh, b.tangents, b.objectSpace, NormalSpace::kObject, NormalSpace::kTangent, cs);
  cs.threads = 2;
  const Result<FloatImage> two =
      convertNormalMap(b.mesh, b.tangents, b.objectSpace, NormalSpace::kObject, NormalSpace::kTangent, cs);
  ASSERT_TRUE(one.ok() && two.ok());
  EXPECT_EQ(std::memcmp(one->pixels.data(), two->pixels.data(), one->pixels.size() * sizeof(float)), 0);
}

TEST(Convert, RowsAreTheWholeConversionBandByBand) {
  // A tall image (three bands and a part), four channels, covered in part: the rows the sink
  // sees, assembled, are the whole conversion bit for bit, uncovered texels and alpha included.
  const Mesh mesh = test::gridMesh(test::sphere, 24, 16, [](double s, double t) {
    return Vec2d{0.1 + 0.8 * s, 0.05 + 0.9 * t};
  });
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  FloatImage input;
  input.width = 48;
  input.height = 3 * kBakeBandRows + 37;
  input.channels = 4;
  const std::size_t texels = static_cast<std::size_t>(input.width) * input.height;
  for (std::size_t i = 0; i < 4 * texels; ++i) {
    input.pixels.push_back(0.5f + 0.45f * static_cast<float>(std::sin(0.37 * static_cast<double>(i))));
  }
  input.coverage.assign(texels, 0.0f);
  for (const int samples : {1, 2}) {
    for (const NormalSpace to : {NormalSpace::kTangent, NormalSpace::kObject}) {
      ConvertSettings cs;
      cs.samples = samples;
      const NormalSpace from = to == NormalSpace::kTangent ? NormalSpace::kObject : NormalSpace::kTangent;
      const Result<FloatImage> whole = convertNormalMap(mesh, *tangents, input, from, to, cs);
      ASSERT_TRUE(whole.ok()) << whole.error().message;
      FloatImage rows;
      rows.pixels.assign(whole->pixels.size(), -1.0f);
      rows.coverage.assign(texels, -1.0f);
      int calls = 0, next = 0;
      const Status done = convertNormalMapRows(
          mesh, *tangents, input, from, to, cs, [&](const MutableImageRows& band) -> Status {
            ++calls;
            EXPECT_EQ(band.begin, next);  // no rows kept above a band
            next = band.end;
            for (int row = band.begin; row < band.end; ++row) {
              const std::size_t at = static_cast<std::size_t>(row) * input.width;
              std::copy(band.pixelRow(row), band.pixelRow(row) + 4 * input.width,
                        rows.pixels.begin() + static_cast<std::ptrdiff_t>(4 * at));
              std::copy(band.coverageRow(row), band.coverageRow(row) + input.width,
                        rows.coverage.begin() + static_cast<std::ptrdiff_t>(at));
            }
            return Ok{};
          });
      ASSERT_TRUE(done.ok()) << done.error().message;
      EXPECT_EQ(calls, 4);
      EXPECT_EQ(next, input.height);
      EXPECT_EQ(std::memcmp(rows.pixels.data(), whole->pixels.data(),
                            whole->pixels.size() * sizeof(float)), 0) << "samples " << samples;
      EXPECT_EQ(std::memcmp(rows.coverage.data(), whole->coverage.data(), texels * sizeof(float)), 0);
    }
  }
  // An error from the sink stops the conversion and comes back.
  int calls = 0;
  const Status stopped = convertNormalMapRows(
      mesh, *tangents, input, NormalSpace::kObject, NormalSpace::kTangent, {},
      [&](const MutableImageRows&) -> Status {
        ++calls;
        return Error::internal("disk full");
      });
  ASSERT_FALSE(stopped.ok());
  EXPECT_EQ(stopped.error().message, "disk full");
  EXPECT_EQ(calls, 1);
}

TEST(Convert, BadInputIsAnErrorValue) {
  const Mesh mesh = test::uvPlaneMesh({{{0, 0}, {1, 0}, {1, 1}}});
  const Result<CornerTangents> tangents = computeTangents(mesh.view(0));
  ASSERT_TRUE(tangents.ok());
  FloatImage image;
  image.width = image.height = 4;
  image.channels = 2;
  image.pixels.assign(32, 0.5f);
  EXPECT_FALSE(convertNormalMap(mesh, *tangents, image, NormalSpace::kObject, NormalSpace::kTangent).ok());
  image.channels = 3;
  EXPECT_FALSE(convertNormalMap(mesh, *tangents, image, NormalSpace::kObject, NormalSpace::kTangent).ok());
  image.pixels.assign(48, 0.5f);
  EXPECT_TRUE(convertNormalMap(mesh, *tangents, image, NormalSpace::kObject, NormalSpace::kTangent).ok());
  ConvertSettings cs;
  cs.uvSet = 2;
  EXPECT_FALSE(convertNormalMap(mesh, *tangents, image, NormalSpace::kObject, NormalSpace::kTangent, cs).ok());
  EXPECT_FALSE(convertNormalMap(mesh, CornerTangents{}, image, NormalSpace::kObject, NormalSpace::kTangent).ok());
  EXPECT_EQ(*parseNormalSpace("object"), NormalSpace::kObject);
  EXPECT_EQ(*parseNormalSpace("tangent"), NormalSpace::kTangent);
  EXPECT_FALSE(parseNormalSpace("world").ok());
}

}  // namespace
}  // namespace sgbake
