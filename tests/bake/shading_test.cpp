// The lane-parallel shaders (shadeBatch of the tangent- and object-normal, surface-gradient,
// derivative and height shaders) against their per-sample shade(), bit for bit: random
// triangles and barycentrics, every kind of layer stack
// (none, image heights through sampleMany, other height textures, masked and volume layers
// through the per-sample path, overflowing gradients), swizzled channels, and the rare
// samples that take a fallback (an interpolated normal or tangent that vanishes); each on the
// object as it is and on the object stretched in the world (shaded in world space).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "bake/shaders.hpp"
#include "bake_test_util.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/volume.hpp"
#include "sgbake/gradient/world_shading.hpp"
#include "support/analytic_textures.hpp"

namespace sgbake {
namespace {

using test::ConstantNormalTexture;

using bake_detail::SampleBatch;

/// Normal-map channels besides +X+Y+Z: a DirectX green, and every channel moved and two negated.
constexpr NormalSwizzle kDirectXGreen = {{{0, false}, {1, true}, {2, false}}};
constexpr NormalSwizzle kScrambled = {{{2, true}, {0, false}, {1, true}}};

/// Six triangles with random corners, normals and tangents, plus two made to hit fallbacks: one
/// whose corner normals cancel at the centroid region (N = 0 there) and one whose tangents are
/// parallel to the normals (a degenerate frame: the flat normal).
struct Scene {
  Mesh mesh;
  CornerTangents tangents;
};

Scene randomScene(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1, 1), uv(0, 1);
  std::vector<Vec3f> positions;
  std::vector<std::vector<std::uint32_t>> faces;
  std::vector<Vec2f> uvs;
  std::vector<Vec3f> normals;
  Scene s;
  auto unit = [](Vec3f v) { return cast<float>(normalizeOr(cast<double>(v), Vec3d{0, 0, 1})); };
  for (std::uint32_t t = 0; t < 8; ++t) {
    for (int k = 0; k < 3; ++k) {
      positions.push_back({u(rng), u(rng), u(rng)});
      uvs.push_back({uv(rng), uv(rng)});
      Vec3f n = unit({u(rng), u(rng), 1 + u(rng)});
      Vec3f tangent = unit({1, u(rng), u(rng)});
      if (t == 6) n = k == 0 ? Vec3f{0, 0, 1} : Vec3f{0, 0, -1};  // Σ bi·Ni = 0 where b0 = 1/2
      if (t == 7) tangent = n;                                      // T ∥ N everywhere
      normals.push_back(n);
      s.tangents.tangent.push_back(tangent);
      s.tangents.sign.push_back(k == 2 && t % 2 == 0 ? -1.0f : 1.0f);
    }
    faces.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  }
  s.mesh = test::polygonMesh(positions, faces, uvs, {0, 0, 1}, normals);
  return s;
}

/// Barycentrics of a batch: random, plus exact ones (corners, edge midpoints, b0 = 1/2 where
/// triangle 6's normal vanishes).
SampleBatch randomBatch(std::mt19937& rng, int count) {
  std::uniform_real_distribution<double> u(0, 1);
  SampleBatch b;
  b.count = count;
  for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) {
    double b0 = u(rng), b1 = u(rng), b2 = u(rng);
    switch (i % 9) {
      case 3: b0 = 1, b1 = 0, b2 = 0; break;
      case 5: b0 = 0.5, b1 = 0.5, b2 = 0; break;
      case 7: b0 = 0.5, b1 = 0.25, b2 = 0.25; break;
      default: {
        const double sum = b0 + b1 + b2;
        b0 /= sum, b1 /= sum, b2 /= sum;
      }
    }
    b.b0[i] = b0;
    b.b1[i] = b1;
    b.b2[i] = b2;
    b.x[i] = static_cast<int>(i);
    b.y[i] = 0;
  }
  return b;
}

Image noiseImage(std::mt19937& rng, int size) {
  std::uniform_real_distribution<float> u(0, 1);
  Image image(size, size, 1);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) image.at(x, y) = u(rng);
  return image;
}

/// Object-space normals that swing through every direction, some behind the surface: in the
/// stretched world, some of those in front of it decode behind it (NormalBelowSurface).
class SwirlNormalTexture final : public VectorTexture {
 public:
  Vec3d sample(Vec2d st) const override {
    const Vec3d n = normalizeOr(
        Vec3d{std::sin(5 * st.x), std::cos(4 * st.y), 0.3 + 0.5 * std::sin(3 * (st.x + st.y))},
        Vec3d{0, 0, 1});
    return 0.5 * n + Vec3d{0.5, 0.5, 0.5};
  }
};

class ShadeBatch : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937 rng(7);
    scene = randomScene(rng);
    const Image noise = noiseImage(rng, 16);
    bilinear = *ImageScalarTexture::create(noise, {.filter = Filter::kBilinear});
    bicubic = *ImageScalarTexture::create(noise, {.filter = Filter::kBicubic});
    sine = *DirectionalSine::create({.amplitude = 0.05, .frequency = 3, .direction = {1, 2, 0.5}});
  }

  /// shadeBatch of random batches of every size against shade(), sample by sample, bit for bit,
  /// for every shader that has one: on the object as it is, and on the object placed in the
  /// world by a stretching transform (shaded in world space, BakeShaderBase::world).
  void expectBatchEqualsSamples(std::span<const Layer> layers, NormalSwizzle channels,
                                const std::string& what, const WorldSpace* placement = nullptr) {
    if (placement == nullptr) placement = &stretched;
    for (const WorldSpace* space : {static_cast<const WorldSpace*>(nullptr), placement}) {
      world = space;
      const std::string where = what + (space != nullptr ? ", stretched in the world" : "");
      expectShaderBatchEqualsSamples<bake_detail::TangentNormalShader>(layers, channels, where);
      expectShaderBatchEqualsSamples<bake_detail::ObjectNormalShader>(layers, channels,
                                                                      where + " (object space)");
      expectShaderBatchEqualsSamples<bake_detail::SurfaceGradientShader>(
          layers, channels, where + " (surface gradient)");
      expectShaderBatchEqualsSamples<bake_detail::DerivativeShader>(layers, channels,
                                                                    where + " (derivative)");
    }
    world = nullptr;  // (height maps are not shaded in world space)
    expectShaderBatchEqualsSamples<bake_detail::HeightShader>(layers, channels, what + " (height)");
  }

  template <class Shader>
  void expectShaderBatchEqualsSamples(std::span<const Layer> layers, NormalSwizzle channels,
                                      const std::string& what) {
    constexpr bool kTangentSpace = std::is_same_v<Shader, bake_detail::TangentNormalShader>;
    constexpr bool kObjectSpace = std::is_same_v<Shader, bake_detail::ObjectNormalShader>;
    constexpr std::size_t kC = Shader::kChannels;
    bake_detail::BakeShaderBase base;
    base.mesh = &scene.mesh;
    base.tangents = kTangentSpace ? &scene.tangents : nullptr;
    base.layers = layers;
    base.channels = channels;
    base.world = world;
    base.bumpTexel = bumpTexel;
    Shader batchShader{base}, sampleShader{base};
    std::mt19937 rng(11);
    int fallbacks = 0;
    for (std::uint32_t t = 0; t < scene.mesh.numFaces(); ++t) {
      const std::array<std::uint32_t, 3> corners{3 * t, 3 * t + 1, 3 * t + 2};
      batchShader.beginTriangle(t, corners);
      sampleShader.beginTriangle(t, corners);
      for (const int count : {1, 2, 3, 17, SampleBatch::kMax}) {
        const SampleBatch batch = randomBatch(rng, count);
        std::vector<double> lanes(static_cast<std::size_t>(count) * kC);
        batchShader.shadeBatch(batch, lanes.data());
        for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) {
          double one[3] = {0, 0, 0};
          sampleShader.shade({batch.b0[i], batch.b1[i], batch.b2[i]}, batch.x[i], batch.y[i], one);
          const double* lane = &lanes[kC * i];
          ASSERT_EQ(std::memcmp(one, lane, kC * sizeof(double)), 0)
              << what << ": triangle " << t << ", batch of " << count << ", lane " << i << ": ("
              << lane[0] << ", " << (kC > 1 ? lane[1] : 0.0) << ", " << (kC > 2 ? lane[2] : 0.0)
              << ") against (" << one[0] << ", " << one[1] << ", " << one[2] << ")";
          // Tangent space: the flat frame's (0, 0, 1). Object space without layers: the face
          // normal, taken where Σ bi·Ni vanishes (triangle 6).
          const Vec3d ng = sampleShader.tri.faceNormal;
          double flat[3], face[3];
          base.putEncoded(0, 0, 1, flat);
          base.putEncoded(ng.x, ng.y, ng.z, face);
          if (kTangentSpace) fallbacks += std::memcmp(one, flat, sizeof flat) == 0;
          if (kObjectSpace) fallbacks += std::memcmp(one, face, sizeof face) == 0;
        }
      }
    }
    // (In the world, the object-space fallback is the world face normal brought back.)
    if (kTangentSpace || (kObjectSpace && layers.empty() && world == nullptr)) {
      EXPECT_GT(fallbacks, 0) << what << ": no sample took a fallback";
    }
  }

  Scene scene;
  /// A turned, stretched and moved object: scaled (2, 1, 0.5), turned 30° about (1, 1, 0).
  const WorldSpace stretched = [] {
    const double c = std::cos(kPi / 6), s = std::sin(kPi / 6), k = 1 / std::sqrt(2.0);
    // Rodrigues' rotation about the unit axis (k, k, 0).
    const Mat3 turn =
        Mat3::fromColumns({c + k * k * (1 - c), k * k * (1 - c), -k * s},
                          {k * k * (1 - c), c + k * k * (1 - c), k * s}, {k * s, -k * s, c});
    ObjectTransform transform;
    transform.linear = turn * Mat3::diagonal({2, 1, 0.5});
    transform.translation = {0.5, -1, 2};
    return *WorldSpace::of(transform);
  }();
  /// Squashed a hundredfold: normals 60° from N in object space end up far below the surface.
  const WorldSpace squashed = *WorldSpace::of({Mat3::diagonal({10, 1, 0.1}), {}});
  const WorldSpace* world = nullptr;  ///< the placement expectShaderBatchEqualsSamples shades in
  Vec2d bumpTexel{};                  ///< BakeShaderBase::bumpTexel of the shaders compared
  ImageScalarTexture bilinear = *ImageScalarTexture::create(Image(1, 1, 1));
  ImageScalarTexture bicubic = *ImageScalarTexture::create(Image(1, 1, 1));
  DirectionalSine sine = *DirectionalSine::create({});
  test::LinearHeight linear{0.3, -0.2};
};

TEST_F(ShadeBatch, WithoutLayers) {
  expectBatchEqualsSamples({}, kIdentitySwizzle, "no layers");
  expectBatchEqualsSamples({}, kDirectXGreen, "no layers, DirectX");
  expectBatchEqualsSamples({}, kScrambled, "no layers, -Z+X-Y");
}

TEST_F(ShadeBatch, ImageHeightLayers) {
  const std::vector<Layer> layers{
      Layer{UvHeightSource{&bilinear, 0, 0.02, {2, 3}, {0.25, -0.5}}, 1.0, {}},
      Layer{UvHeightSource{&bicubic, 0, 0.05}, -0.5, {}},
      Layer{UvHeightSource{&bilinear, 0, 0.1}, 0.0, {}},  // weight 0: skipped
  };
  expectBatchEqualsSamples(layers, kIdentitySwizzle, "image heights");
  expectBatchEqualsSamples(layers, kDirectXGreen, "image heights, DirectX");
  expectBatchEqualsSamples(layers, kScrambled, "image heights, -Z+X-Y");
}

TEST_F(ShadeBatch, ImageHeightLayersReadAsTheBumpNodeDoes) {
  UvHeightSource tiled{&bilinear, 0, 0.02, {2, 3}, {0.25, -0.5}};
  tiled.gradient = HeightGradient::kBumpNode;
  UvHeightSource cubic{&bicubic, 0, 0.05};
  cubic.gradient = HeightGradient::kBumpNode;
  const std::vector<Layer> layers{
      Layer{tiled, 1.0, {}}, Layer{cubic, -0.5, {}},
      Layer{UvHeightSource{&bilinear, 0, 0.1}, 0.7, {}},  // exact slopes beside them
  };
  bumpTexel = {1.0 / 64, 1.0 / 32};
  expectBatchEqualsSamples(layers, kIdentitySwizzle, "bump-node heights");
  expectBatchEqualsSamples(layers, kScrambled, "bump-node heights, -Z+X-Y");
  bumpTexel = {};  // no offsets: exact slopes
  expectBatchEqualsSamples(layers, kIdentitySwizzle, "bump-node heights without offsets");
}

TEST_F(ShadeBatch, OtherLayersTakeThePerSamplePath) {
  const std::vector<Layer> layers{
      Layer{UvHeightSource{&linear, 0, 0.5}, 1.0, {}},                  // not an image texture
      Layer{UvHeightSource{&bilinear, 0, 0.03}, 0.7, LayerMask{&bicubic, 0}},  // masked
      Layer{VolumeSource{&sine, GradientScheme::kAnalytic, 0, 1}, 1.0, {}},
      Layer{UvHeightSource{&bicubic, 1, 0.1}, 1.0, {}},  // a UV set the mesh does not have
  };
  expectBatchEqualsSamples(layers, kIdentitySwizzle, "mixed layers");
}

TEST_F(ShadeBatch, LayersOnTheLayersAbove) {
  // Layers based on the normal of the layers above (a chain of Bump nodes) interleaved with
  // layers the batch path takes whole.
  Layer onTop{UvHeightSource{&bilinear, 0, 0.08}, 1.0, {}};
  onTop.base = LayerBase::kLayersAbove;
  Layer strengthOnTop{UvHeightSource{&bicubic, 0, 0.05}, 0.8, {}};
  std::get<UvHeightSource>(strengthOnTop.source).strength = 0.6;
  strengthOnTop.base = LayerBase::kLayersAbove;
  Layer volumeOnTop{VolumeSource{&sine, GradientScheme::kAnalytic, 0, 1}, 1.0, {}};
  volumeOnTop.base = LayerBase::kLayersAbove;
  const std::vector<Layer> layers{
      Layer{UvHeightSource{&bilinear, 0, 0.02, {2, 3}, {0.25, -0.5}}, 1.0, {}},
      onTop,
      Layer{UvHeightSource{&bicubic, 0, 0.03}, -0.5, {}},
      strengthOnTop,
      volumeOnTop,
  };
  expectBatchEqualsSamples(layers, kIdentitySwizzle, "layers on the layers above");
}

TEST_F(ShadeBatch, NormalMapsDecodedBelowTheSurface) {
  // Alone, at Strength 1 and 0.6, such a map is shaded from its decoded normal in the world
  // (the per-sample path, also where the guard passes the mirror image N − Γ resolves to);
  // with a height on it, from the Γ sum. Either way the same bits.
  SwirlNormalTexture swirl;
  ObjectNormalSource weak{&swirl, 0};
  weak.strength = 0.6;
  const std::vector<Layer> alone{Layer{ObjectNormalSource{&swirl, 0}, 1.0, {}}};
  const std::vector<Layer> blended{Layer{weak, 1.0, {}}};
  const std::vector<Layer> withHeight{Layer{ObjectNormalSource{&swirl, 0}, 1.0, {}},
                                      Layer{UvHeightSource{&bilinear, 0, 0.02}, 1.0, {}}};
  for (const WorldSpace* placement : {&stretched, &squashed}) {
    expectBatchEqualsSamples(alone, kIdentitySwizzle, "normals below the surface", placement);
    expectBatchEqualsSamples(blended, kIdentitySwizzle, "normals below the surface, 0.6",
                             placement);
    expectBatchEqualsSamples(withHeight, kIdentitySwizzle, "normals below, and a height",
                             placement);
  }
}

/// ObjectNormalShader's output for @p layers on a flat triangle (N = Ng = ẑ, UVs = positions, no
/// MikkTSpace frames) placed by @p world (or not), lane-parallel and sample by sample: equal bit
/// for bit, and equal to the encoded @p expected.
void expectFlatTriangleBakes(std::span<const Layer> layers, const WorldSpace* world,
                             const Vec3d& expected, const std::string& what) {
  const Mesh mesh = test::uvPlaneMesh({{{0.1f, 0.1f}, {0.9f, 0.2f}, {0.3f, 0.8f}}});
  bake_detail::ObjectNormalShader shader;
  shader.mesh = &mesh;
  shader.layers = layers;
  shader.world = world;
  shader.beginTriangle(0, {0, 1, 2});
  std::mt19937 rng(5);
  const SampleBatch batch = randomBatch(rng, SampleBatch::kMax);
  std::vector<double> lanes(3 * static_cast<std::size_t>(batch.count));
  shader.shadeBatch(batch, lanes.data());
  const Vec3d encoded = bake_detail::encodeNormal(expected);
  for (std::size_t i = 0; i < static_cast<std::size_t>(batch.count); ++i) {
    double one[3];
    shader.shade({batch.b0[i], batch.b1[i], batch.b2[i]}, 0, 0, one);
    EXPECT_EQ(std::memcmp(one, &lanes[3 * i], sizeof one), 0) << what << ", lane " << i;
    EXPECT_LT(length(Vec3d{one[0], one[1], one[2]} - encoded), 1e-12) << what << ", lane " << i;
  }
}

// A normal map that decodes far below the surface: Cycles' guard passes such a normal as it is
// (its test reflects I about the normal's line), so the bake shows it below the surface; the Γ
// sum would give its mirror image above the plane (an object-space map) or a grazing one (a
// tangent-space texel with z < 0, whose slopes are clamped). Lane-parallel as sample by sample.
TEST(ShadeBatchBelowTheSurface, ANormalFarBelowIsBakedAsItIs) {
  // 150° from N in object space, for an object-space and a tangent-space map (the flat
  // triangle's UV-derivative frame is x̂, ŷ, ẑ).
  const Vec3d steep{std::sin(5 * kPi / 6), 0, std::cos(5 * kPi / 6)};
  ConstantNormalTexture steepMap(steep);
  expectFlatTriangleBakes(std::vector<Layer>{Layer{ObjectNormalSource{&steepMap, 0}, 1.0, {}}},
                          nullptr, steep, "object-space map");
  expectFlatTriangleBakes(std::vector<Layer>{Layer{TangentNormalSource{&steepMap, 0}, 1.0, {}}},
                          nullptr, steep, "tangent-space map");
  // A flat height stacked on it (a Bump node on the Normal Map's output) bumps that normal by
  // nothing: the same.
  test::LinearHeight flat{0, 0};
  Layer onTop{UvHeightSource{&flat, 0, 1.0}, 1.0, {}};
  onTop.base = LayerBase::kLayersAbove;
  expectFlatTriangleBakes(
      std::vector<Layer>{Layer{TangentNormalSource{&steepMap, 0}, 1.0, {}}, onTop}, nullptr, steep,
      "tangent-space map, a flat bump on it");
  // 60° from N in object space, under a shear that keeps ẑ but takes that normal 35° below the
  // world's tangent plane. Blender's baker brings it back to object space as a direction
  // (M^{-1}).
  const WorldSpace shear =
      *WorldSpace::of({Mat3::fromColumns({1, 0, 0}, {0, 1, 0}, {2, 0, 1}), {0.5, -1, 2}});
  const Vec3d v{std::sin(kPi / 3), 0, std::cos(kPi / 3)};
  ConstantNormalTexture map(v);
  const Vec3d below = normalizeOr(shear.normalToWorld * v, {});  // (0.57, 0, −0.82)
  ASSERT_LT(below.z, -0.8);
  expectFlatTriangleBakes(std::vector<Layer>{Layer{ObjectNormalSource{&map, 0}, 1.0, {}}}, &shear,
                          normalizeOr(shear.directionToObject * below, {}), "sheared");
}

TEST_F(ShadeBatch, OverflowingAndCancellingGradients) {
  // Γ overflows (dropped as non-finite) or nearly cancels N (N − Γ renormalized the slow way).
  const std::vector<Layer> layers{
      Layer{UvHeightSource{&bilinear, 0, 1e306}, 1e3, {}},
      Layer{UvHeightSource{&bicubic, 0, 40}, 1.0, {}},
  };
  expectBatchEqualsSamples(layers, kIdentitySwizzle, "extreme gradients");
}

}  // namespace
}  // namespace sgbake
