/// @file planner_test.cpp
/// @brief The planner: only the work the outputs need (tangents, layers, images loaded once),
/// --explain, the manifest (up to date, --force, changed inputs and outputs), execution, and
/// all-or-nothing outputs on failure.
#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "sgbake/bake/image_output.hpp"
#include "sgbake/bake/planner.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/gradient/corners.hpp"
#include "sgbake/sgbake.h"
#include "support/files.hpp"
#include "support/plane_scene.hpp"

namespace sgbake {
namespace {

namespace fs = std::filesystem;
using test::listDirectory;
using test::readFile;
using test::kHeightLayer;
using test::kNoUvObj;
using test::kPlaneObj;
using test::planeScene;
using test::writeFile;


/// The same square placed in UDIM tile 1002 (u in [1, 2]).
constexpr const char* kTile1002Obj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "vt 1.25 0.25\nvt 1.75 0.25\nvt 1.75 0.75\nvt 1.25 0.75\n"
    "f 1/1 2/2 3/3 4/4\n";


/// A W×H single-channel image: a ramp in x plus @p bias.
FloatImage heightImage(int size, float bias = 0) {
  FloatImage image;
  image.channels = 1;
  image.width = image.height = size;
  image.pixels.resize(static_cast<std::size_t>(size * size));
  image.coverage.assign(image.pixels.size(), 1.0f);
  for (int row = 0; row < size; ++row) {
    for (int x = 0; x < size; ++x) {
      image.at(x, row, 0) = bias + 0.5f * static_cast<float>(x) / static_cast<float>(size);
    }
  }
  return image;
}

/// A flat tangent-space normal map (0.5, 0.5, 1).
FloatImage flatNormalImage(int size) {
  FloatImage image;
  image.width = image.height = size;
  image.channels = 3;
  image.pixels.resize(static_cast<std::size_t>(size * size * 3));
  for (std::size_t i = 0; i < image.pixels.size(); i += 3) {
    image.pixels[i] = 0.5f;
    image.pixels[i + 1] = 0.5f;
    image.pixels[i + 2] = 1.0f;
  }
  image.coverage.assign(static_cast<std::size_t>(size * size), 1.0f);
  return image;
}

/// The pixels of an image file as floats, channels interleaved.
std::vector<float> readPixels(const fs::path& path) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(in) << path;
  if (!in) return {};
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> pixels(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
  return pixels;
}

/// A directory with a plane mesh, a height map and a normal map; scenes are written into it.
class PlannerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("sgbake_planner_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    writeFile(dir_ / "plane.obj", kPlaneObj);
    writeFile(dir_ / "tile1002.obj", kTile1002Obj);
    writeFile(dir_ / "nouv.obj", kNoUvObj);
    ASSERT_TRUE(writeImage(heightImage(16), dir_ / "h.png"));
    ASSERT_TRUE(writeImage(flatNormalImage(16), dir_ / "n.png"));
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Parses @p json as the scene file dir_/scene.json.
  Scene scene(const std::string& json) {
    writeFile(dir_ / "scene.json", json);
    Result<Scene> parsed = loadScene(dir_ / "scene.json");
    EXPECT_TRUE(parsed) << parsed.error().message;
    return parsed ? *parsed : Scene{};
  }

  Plan plan(const std::string& json, const PlanOptions& options = {}) {
    Result<Plan> planned = makePlan(scene(json), options);
    EXPECT_TRUE(planned) << planned.error().message;
    return planned ? *planned : Plan{};
  }

  /// Plans and runs @p json; returns the report.
  ExecuteReport bake(const std::string& json, const PlanOptions& options = {}) {
    Result<Plan> planned = makePlan(scene(json), options);
    EXPECT_TRUE(planned) << planned.error().message;
    if (!planned) return {};
    Result<ExecuteReport> report = executePlan(*planned);
    EXPECT_TRUE(report) << report.error().message;
    return report ? *report : ExecuteReport{};
  }

  fs::path dir_;
};

constexpr const char* kNormalLayer = R"({"type": "normal", "image": "n.png"})";

TEST(Hash, Fnv1a64KnownValues) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ULL);
  // Incremental use gives the same hash as one call.
  EXPECT_EQ(fnv1a64("bar", fnv1a64("foo")), fnv1a64("foobar"));
}

TEST_F(PlannerTest, ExplainSaysHowMuchOfTheImageIsInMemory) {
  // Extend padding bakes in bands into a ring of 2·256 + 2·margin rows (capped at the height);
  // push-pull and adjacent faces hold the whole image. Values and coverage are 4-byte floats.
  const Plan p =
      plan(planeScene(kHeightLayer,
                      R"({"map": "object-normal", "file": "o.png", "size": 1000, "margin": 22},
                                    {"map": "height", "file": "h.exr", "size": 100},
                                    {"map": "object-normal", "file": "p.png", "size": 500, "padding": "push-pull"},
                                    {"map": "object-normal", "file": "a.png", "size": 250, "margin": 5,
                                     "padding": "adjacent-faces"})"));
  const std::string text = explainPlan(p);
  // 556 rows × 1000 × 4 floats × 4 bytes = 8.9 MB; the 100-row height map fits whole: 100 rows.
  EXPECT_NE(text.find("in bands of 256 rows, 556 rows (8.9 MB) in memory at a time"), std::string::npos) << text;
  EXPECT_NE(text.find("in bands of 256 rows, 100 rows (0.1 MB) in memory at a time"), std::string::npos) << text;
  // 500 × 500 × 4 floats × 4 bytes = 4 MB, and its pyramid a third of it: 5.3 MB.
  EXPECT_NE(text.find("the whole image in memory for push-pull (5.3 MB)"), std::string::npos)
      << text;
  // 250 × 250 × (4 floats × 4 bytes + 12 bytes of faces, distances and margin lists) = 1.75 MB,
  // padded once the whole image is baked.
  EXPECT_NE(text.find("the whole image in memory for adjacent-faces (1.8 MB)"), std::string::npos)
      << text;
  EXPECT_NE(text.find("a.png: adjacent faces, 5 texels"), std::string::npos) << text;
}

TEST_F(PlannerTest, NoTangentsForHeightAndObjectNormalMaps) {
  const Plan p = plan(planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8},
                                               {"map": "object-normal", "file": "o.png", "size": 8})"));
  EXPECT_TRUE(p.loadMesh);
  EXPECT_FALSE(p.computeTangents);
  const std::string text = explainPlan(p);
  EXPECT_NE(text.find("tangent frames (MikkTSpace): no map to bake is tangent-normal"),
            std::string::npos)
      << text;
  const ExecuteReport report =
      bake(planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8})"));
  EXPECT_FALSE(report.tangentsComputed);
}

TEST_F(PlannerTest, TangentsForTangentNormalMapsAndTangentSpaceLayers) {
  EXPECT_TRUE(plan(planeScene(kHeightLayer, R"({"map": "tangent-normal", "file": "n_out.png"})"))
                  .computeTangents);
  EXPECT_TRUE(plan(planeScene("", R"({"map": "bitangent", "file": "b.png"})")).computeTangents);
  // A tangent-space normal map on UV set 0 is decoded in the MikkTSpace frame.
  const Plan p = plan(planeScene(kNormalLayer, R"({"map": "object-normal", "file": "o.png"})"));
  EXPECT_TRUE(p.computeTangents);
  EXPECT_NE(
      explainPlan(p).find("layers[0], a tangent-space normal map, is decoded in those of UV set 0"),
      std::string::npos)
      << explainPlan(p);
  // ... and so is one Blender's Box projection reads (a Normal Map node after the Image
  // Texture), on its "tangent_uv" ...
  const Plan box = plan(planeScene(R"({"type": "triplanar", "image": "n.png", "projection": "box",
                                       "kind": "tangent-normal"})",
                                   R"({"map": "object-normal", "file": "o.png"})"));
  EXPECT_TRUE(box.computeTangents);
  // ... but not an object-space one, nor sgbake's blended triplanar (each plane's own frame).
  EXPECT_FALSE(plan(planeScene(R"({"type": "normal", "image": "n.png", "space": "object"})",
                               R"({"map": "object-normal", "file": "o.png"})"))
                   .computeTangents);
  EXPECT_FALSE(plan(planeScene(R"({"type": "triplanar", "image": "n.png",
                                   "kind": "tangent-normal"})",
                               R"({"map": "object-normal", "file": "o.png"})"))
                   .computeTangents);
  const ExecuteReport report =
      bake(planeScene(kHeightLayer, R"({"map": "tangent-normal", "file": "t.png", "size": 8})"));
  EXPECT_TRUE(report.tangentsComputed);
}

TEST_F(PlannerTest, MaskAndTangentMapsReadNoLayers) {
  const Plan mask = plan(planeScene(std::string(kHeightLayer) + "," + kNormalLayer,
                                    R"({"map": "mask", "file": "m.png"})"));
  EXPECT_TRUE(mask.layers.empty());
  EXPECT_TRUE(mask.images.empty());
  EXPECT_FALSE(mask.computeTangents);
  const std::string text = explainPlan(mask);
  EXPECT_NE(text.find("skipped:"), std::string::npos);
  EXPECT_NE(text.find("layers[0] (height image"), std::string::npos) << text;
  EXPECT_NE(text.find("and its image: no output to bake reads it: mask maps read no layers"),
            std::string::npos)
      << text;

  const Plan tangent =
      plan(planeScene(kHeightLayer, R"({"map": "tangent", "file": "t.png", "size": 4})"));
  EXPECT_TRUE(tangent.layers.empty());
  EXPECT_TRUE(tangent.images.empty());
  EXPECT_TRUE(tangent.computeTangents);
  const ExecuteReport report =
      bake(planeScene(kHeightLayer, R"({"map": "mask", "file": "m.png", "size": 4})"));
  EXPECT_EQ(report.imagesLoaded, 0u);
}

TEST_F(PlannerTest, HeightMapsSkipNormalLayersAndZeroWeights) {
  const Plan p = plan(planeScene(std::string(kHeightLayer) + "," + kNormalLayer +
                                     R"(, {"type": "volume", "function": "sine", "weight": 0})",
                                 R"({"map": "height", "file": "h.exr"})"));
  ASSERT_EQ(p.layers.size(), 1u);
  EXPECT_EQ(p.layers[0].sceneLayer, 0u);
  ASSERT_EQ(p.images.size(), 1u);
  EXPECT_EQ(p.images[0].path.filename(), "h.png");
  const std::string text = explainPlan(p);
  EXPECT_NE(text.find("height maps read only layers with a height"), std::string::npos) << text;
  EXPECT_NE(text.find("layers[2] (volume sine): no output to bake reads it: weight 0"),
            std::string::npos)
      << text;
}

TEST_F(PlannerTest, AnImageUsedByTwoLayersIsLoadedOnce) {
  // The same file under three spellings (one through a symbolic link), two filters: one load,
  // two textures.
  fs::create_symlink("h.png", dir_ / "alias.png");
  const std::string layers =
      R"({"type": "height", "image": "h.png", "filter": "bicubic"},
         {"type": "triplanar", "image": "./sub/../h.png", "kind": "height"},
         {"type": "height", "image": "alias.png", "filter": "bicubic", "tiling": 3})";
  const Plan p =
      plan(planeScene(layers, R"({"map": "object-normal", "file": "o.png", "size": 8})"));
  ASSERT_EQ(p.images.size(), 1u);
  EXPECT_EQ(p.images[0].users.size(), 3u);
  EXPECT_EQ(p.textures.size(), 2u) << "bicubic and bilinear";
  EXPECT_EQ(p.layers[0].texture, p.layers[2].texture);
  const ExecuteReport report =
      bake(planeScene(layers, R"({"map": "object-normal", "file": "o.png", "size": 8})"));
  EXPECT_EQ(report.imagesLoaded, 1u);
  EXPECT_EQ(report.texturesCreated, 2u);
  // A normal-map use of the same file needs its RGB channels: a second, different load.
  const Plan both = plan(
      planeScene(R"({"type": "height", "image": "n.png"}, {"type": "normal", "image": "n.png"})",
                 R"({"map": "object-normal", "file": "o.png"})"));
  EXPECT_EQ(both.images.size(), 2u);
}

TEST_F(PlannerTest, ExplainListsStepsAndSkippedWork) {
  const Plan p = plan(planeScene(
      std::string(kHeightLayer) + R"(, {"type": "triplanar", "image": "h.png", "kind": "height"})",
      R"({"map": "tangent-normal", "file": "n_out.png", "size": 64, "margin": 4},
         {"map": "mask", "file": "m.png", "size": 64})"));
  const std::string text = explainPlan(p);
  EXPECT_TRUE(text.starts_with("plan for ")) << text;
  EXPECT_NE(text.find("2 of 2 outputs to bake, 1 image to load for 2 layer inputs\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("1. load mesh "), std::string::npos) << text;
  EXPECT_NE(text.find("load image "), std::string::npos) << text;
  EXPECT_NE(text.find("compute MikkTSpace tangent frames (the tangent-normal map "),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("pad "), std::string::npos) << text;
  EXPECT_NE(text.find("skipped:\n"), std::string::npos) << text;
  EXPECT_NE(text.find("texels outside the UV islands"), std::string::npos) << text;
  EXPECT_NE(text.find("triplanar planes of layers[1] with blend weight below 0.001"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("for " + (dir_ / "m.png").string() + ": mask maps read no layers"),
            std::string::npos)
      << text;
  // Explaining writes nothing.
  EXPECT_FALSE(fs::exists(dir_ / "n_out.png"));
}

TEST_F(PlannerTest, ExplainSaysTheMeshIsSubdivided) {
  Result<Plan> p = makePlan(scene(R"({"mesh": "plane.obj", "subdivision": {"level": 2},
                                      "outputs": [{"map": "mask", "file": "m.png"}]})"));
  ASSERT_TRUE(p) << p.error().message;
  const std::string text = explainPlan(*p);
  EXPECT_NE(text.find("subdivide the mesh to level 2 (uv_smooth keep-boundaries, boundary all)"),
            std::string::npos)
      << text;
  Result<Plan> limit = makePlan(scene(R"({"mesh": "plane.obj", "subdivision": {"level": "limit"},
                                          "outputs": [{"map": "mask", "file": "m.png"}]})"));
  ASSERT_TRUE(limit) << limit.error().message;
  const std::string limitText = explainPlan(*limit);
  EXPECT_NE(limitText.find("subdivide the mesh to the limit surface (uv_smooth keep-boundaries, "
                           "boundary all): every sample is shaded on the exact surface"),
            std::string::npos)
      << limitText;

  // A tangent-space map and layer on the exact surface: its own frames, no MikkTSpace pass.
  // The unit square's limit surface (all boundaries sharp) is the square itself, whose
  // MikkTSpace frame is the UV derivatives': a tilted normal map gives the same map either way.
  FloatImage tilted = flatNormalImage(4);
  for (std::size_t i = 0; i < tilted.pixels.size(); i += 3) {
    tilted.pixels[i] = 0.75f;
    tilted.pixels[i + 1] = 0.4f;
    tilted.pixels[i + 2] = 0.9f;
  }
  ASSERT_TRUE(writeImage(tilted, dir_ / "tilted.exr"));
  const auto tangentSpace = [](const std::string& subdivision, const std::string& file) {
    return R"({"mesh": "plane.obj", )" + subdivision +
           R"("layers": [{"type": "normal", "image": "tilted.exr"}],
               "outputs": [{"map": "tangent-normal", "file": ")" +
           file + R"(", "size": 8, "bit_depth": 32}]})";
  };
  const Plan frames = plan(tangentSpace(R"("subdivision": {"level": "limit"}, )", "t.exr"));
  EXPECT_FALSE(frames.computeTangents);
  EXPECT_NE(explainPlan(frames).find("tangent frames (MikkTSpace): the exact limit surface gives "
                                     "every sample its own frame"),
            std::string::npos)
      << explainPlan(frames);
  EXPECT_FALSE(
      bake(tangentSpace(R"("subdivision": {"level": "limit"}, )", "t.exr")).tangentsComputed);
  EXPECT_TRUE(bake(tangentSpace("", "mesh.exr")).tangentsComputed);
  const std::vector<float> exact = readPixels(dir_ / "t.exr"), mesh = readPixels(dir_ / "mesh.exr");
  ASSERT_EQ(exact.size(), std::size_t{8 * 8 * 3});
  ASSERT_EQ(mesh.size(), exact.size());
  for (std::size_t i = 0; i < exact.size(); ++i) EXPECT_NEAR(exact[i], mesh[i], 1e-5) << i;
  EXPECT_NEAR(exact[0], 0.5 + 0.5 * (0.5 / std::sqrt(0.25 + 0.04 + 0.64)), 1e-4)
      << "the normal map's tilt, decoded in the plane's frame";
}

// A remapped height bakes G(h) and G′(h)·∇h: the height and derivative maps of the same layer
// without its remap, read through it (h.png ramps 0 … 0.5 in x; G clamps 3h − 0.3 to [0, 0.6]).
TEST_F(PlannerTest, ARemappedHeightBakesTheRemapOfTheHeightAndItsSlopes) {
  const auto bakeTo = [&](const std::string& remap, const std::string& prefix) {
    bake(planeScene(R"({"type": "height", "image": "h.png", "scale": 0.1)" + remap + "}",
                    R"({"map": "height", "file": ")" + prefix +
                        R"(h.exr", "size": 16, "bit_depth": 32},
                       {"map": "derivative", "file": ")" +
                        prefix + R"(d.exr", "size": 16, "bit_depth": 32})"));
    return std::pair{readPixels(dir_ / (prefix + "h.exr")), readPixels(dir_ / (prefix + "d.exr"))};
  };
  const auto [height, derivative] = bakeTo("", "plain_");
  const auto [remappedHeight, remappedDerivative] =
      bakeTo(R"(, "remap": [[0.1, 0], [0.3, 0.6]])", "remapped_");
  ASSERT_EQ(height.size(), std::size_t{16 * 16});
  ASSERT_EQ(remappedHeight.size(), height.size());
  const std::size_t channels = derivative.size() / height.size();
  ASSERT_GE(channels, 2u);
  ASSERT_EQ(remappedDerivative.size(), derivative.size());
  int onSlope = 0, flat = 0;
  for (std::size_t i = 0; i < height.size(); ++i) {
    const double h = height[i] / 0.1;
    EXPECT_NEAR(remappedHeight[i], 0.1 * std::clamp(3 * h - 0.3, 0.0, 0.6), 1e-6) << i;
    if (std::abs(h - 0.1) < 0.01 || std::abs(h - 0.3) < 0.01) continue;  // next to a kink
    const double slope = h > 0.1 && h < 0.3 ? 3 : 0;
    (slope != 0 ? onSlope : flat) += 1;
    for (std::size_t c = 0; c < 2; ++c) {
      EXPECT_NEAR(remappedDerivative[i * channels + c], slope * derivative[i * channels + c], 1e-5)
          << i;
    }
  }
  EXPECT_GT(onSlope, 40);
  EXPECT_GT(flat, 40);
  EXPECT_GT(std::abs(derivative[channels * 8 * 16 + channels * 8]), 1e-3) << "a bump to remap";
  const std::string text = explainPlan(
      plan(planeScene(R"({"type": "height", "image": "h.png", "remap": [[0.1, 0], [0.3, 0.6]]})",
                      R"({"map": "height", "file": "h.exr"})")));
  EXPECT_NE(text.find("(sampled by layers[0] through a remap of 2 points)"), std::string::npos)
      << text;
}

// A volume on "coordinates": "uv" is read at (u, v, 0): on a plane whose UVs are (2x, y + 0.25)
// it bakes what the same volume bakes on the object's coordinates through the Mapping node that
// makes (2x, y + 0.25, z): heights, slopes and normals, exact and as the Bump node takes them.
TEST_F(PlannerTest, AVolumeOnUvCoordinatesIsReadAtTheUvs) {
  writeFile(dir_ / "stretched.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
            "vt 0 0.25\nvt 2 0.25\nvt 2 1.25\nvt 0 1.25\n"
            "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
  const std::string noise = R"({"type": "volume", "function": "blender-noise", "amplitude": 0.05,
                                "frequency": 3, "detail": 1.5)";
  const std::string mapping = R"(, "mapping": {"location": [0, 0.25, 0], "scale": [2, 1, 1]})";
  const auto bakeTo = [&](const std::string& layer, const std::string& prefix) {
    bake(planeScene(layer,
                    R"({"map": "height", "file": ")" + prefix +
                        R"(h.exr", "size": 16, "margin": 0, "bit_depth": 32},
                       {"map": "derivative", "file": ")" +
                        prefix + R"(d.exr", "size": 16, "margin": 0, "bit_depth": 32},
                       {"map": "object-normal", "file": ")" +
                        prefix + R"(n.exr", "size": 16, "margin": 0, "bit_depth": 32})",
                    "stretched.obj"));
    std::vector<float> all;
    for (const char* map : {"h.exr", "d.exr", "n.exr"}) {
      const std::vector<float> pixels = readPixels(dir_ / (prefix + map));
      all.insert(all.end(), pixels.begin(), pixels.end());
    }
    return all;
  };
  const auto largestDifference = [](const std::vector<float>& a, const std::vector<float>& b) {
    EXPECT_EQ(a.size(), b.size());
    double largest = 0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
      largest = std::max(largest, std::abs(static_cast<double>(a[i]) - b[i]));
    }
    return largest;
  };
  for (const std::string gradient : {"analytic", "bump-node"}) {
    const std::string how = R"(, "gradient": ")" + gradient + R"(")";
    const std::vector<float> onUv = bakeTo(noise + how + R"(, "coordinates": "uv"})", "uv_");
    const std::vector<float> onObject = bakeTo(noise + how + mapping + "}", "object_");
    const std::vector<float> unmapped = bakeTo(noise + how + "}", "unmapped_");
    ASSERT_EQ(onUv.size(), std::size_t{16 * 16 * (1 + 2 + 3)}) << gradient;
    EXPECT_LT(largestDifference(onUv, onObject), 1e-5) << gradient;
    EXPECT_GT(largestDifference(onUv, unmapped), 1e-2) << gradient << ": the control must differ";
  }
  const std::string text = explainPlan(plan(
      planeScene(noise + R"(, "coordinates": "uv"})", R"({"map": "height", "file": "h.exr"})")));
  EXPECT_NE(text.find("volume blender-noise on UV set 0's coordinates"), std::string::npos) << text;
}

TEST_F(PlannerTest, MissingInputsAreNamed) {
  Result<Plan> image = makePlan(scene(planeScene(R"({"type": "height", "image": "missing.png"})",
                                                 R"({"map": "height", "file": "h.exr"})")));
  ASSERT_FALSE(image);
  EXPECT_EQ(image.error().code, ErrorCode::kBadInput);
  EXPECT_NE(image.error().message.find("layers[0]: image " + (dir_ / "missing.png").string() +
                                       " does not exist"),
            std::string::npos)
      << image.error().message;
  // Without the manifest the check happens as well.
  PlanOptions noManifest;
  noManifest.useManifest = false;
  EXPECT_FALSE(makePlan(scene(planeScene(R"({"type": "height", "image": "missing.png"})",
                                         R"({"map": "height", "file": "h.exr"})")),
                        noManifest));
  Result<Plan> mesh =
      makePlan(scene(planeScene("", R"({"map": "mask", "file": "m.png"})", "x.obj")));
  ASSERT_FALSE(mesh);
  EXPECT_NE(mesh.error().message.find("x.obj does not exist"), std::string::npos);
  EXPECT_TRUE(listDirectory(dir_).count("m.png") == 0);
}

TEST_F(PlannerTest, ExecutionWritesEveryMapAtItsSize) {
  const ExecuteReport report = bake(planeScene(
      std::string(kHeightLayer) + R"(, {"type": "volume", "function": "noise", "amplitude": 0.01,
                                        "frequency": 4})",
      R"({"map": "tangent-normal", "file": "out/n.png", "size": 32},
         {"map": "height", "file": "out/h.exr", "width": 16, "height": 8, "padding": "push-pull"},
         {"map": "derivative", "file": "out/d.tif", "size": 8, "bit_depth": 32, "alpha": true},
         {"map": "corners", "file": "out/corners.csv"})"));
  ASSERT_EQ(report.outputs.size(), 4u);
  for (const OutputReport& output : report.outputs) EXPECT_TRUE(output.baked) << output.file;
  EXPECT_EQ(report.imagesLoaded, 1u);

  const auto spec = [](const fs::path& path) {
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path.string());
    EXPECT_TRUE(in) << path;
    return in ? in->spec() : OIIO::ImageSpec();
  };
  const OIIO::ImageSpec normal = spec(dir_ / "out/n.png");
  EXPECT_EQ(normal.width, 32);
  EXPECT_EQ(normal.nchannels, 3);
  EXPECT_EQ(normal.format, OIIO::TypeDesc::UINT16);
  const OIIO::ImageSpec height = spec(dir_ / "out/h.exr");
  EXPECT_EQ(height.width, 16);
  EXPECT_EQ(height.height, 8);
  EXPECT_EQ(height.format, OIIO::TypeDesc::HALF);
  const OIIO::ImageSpec derivative = spec(dir_ / "out/d.tif");
  EXPECT_EQ(derivative.format, OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(derivative.nchannels, 4) << "R, G, zero B, alpha";
  const std::string csv = readFile(dir_ / "out/corners.csv");
  EXPECT_TRUE(csv.starts_with(std::string(kCornerTableHeader) + "\n")) << csv;
  EXPECT_TRUE(fs::exists(dir_ / "out" / kManifestName));
}

TEST_F(PlannerTest, SignedMapsInIntegerFilesAreRemappedByTheirRange) {
  // h = 0.1 · (0.5·u) on the unit plane: ∂h/∂u = 0.05, ∂h/∂v = 0. A 16-bit PNG with range 0.1
  // stores 0.05 / 0.2 + 0.5 = 0.75 and 0.5; EXR stores the derivatives themselves.
  bake(planeScene(kHeightLayer, R"({"map": "derivative", "file": "d.png", "size": 16, "range": 0.1},
                                   {"map": "derivative", "file": "d.exr", "size": 16,
                                    "bit_depth": 32})"));
  const auto read = [](const fs::path& path) {
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path.string());
    std::vector<float> pixels;
    if (!in) {
      ADD_FAILURE() << path;
      return pixels;
    }
    pixels.resize(static_cast<std::size_t>(in->spec().image_pixels()) * in->spec().nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, in->spec().nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
    return pixels;
  };
  const std::vector<float> png = read(dir_ / "d.png"), exr = read(dir_ / "d.exr");
  ASSERT_EQ(png.size(), std::size_t{16 * 16 * 3});  // R, G and a zero B
  ASSERT_EQ(exr.size(), std::size_t{16 * 16 * 2});
  for (int row = 4; row < 12; ++row) {  // away from the wrap of the ramp at the image's edge
    for (int x = 4; x < 12; ++x) {
      const std::size_t t = static_cast<std::size_t>(row * 16 + x);
      EXPECT_NEAR(exr[t * 2], 0.05, 2e-3);
      EXPECT_NEAR(exr[t * 2 + 1], 0.0, 1e-6);
      EXPECT_NEAR(png[t * 3], exr[t * 2] / 0.2 + 0.5, 1e-4);
      EXPECT_NEAR(png[t * 3 + 1], 0.5, 1e-4);
    }
  }
}

TEST_F(PlannerTest, UdimFileNamesBakeEveryTouchedTile) {
  const ExecuteReport report =
      bake(planeScene("", R"({"map": "mask", "file": "m.<UDIM>.png", "size": 8})", "tile1002.obj"));
  ASSERT_EQ(report.outputs.size(), 1u);
  ASSERT_EQ(report.outputs[0].files.size(), 1u);
  EXPECT_EQ(report.outputs[0].files[0], dir_ / "m.1002.png");
  EXPECT_TRUE(fs::exists(dir_ / "m.1002.png"));
  EXPECT_FALSE(fs::exists(dir_ / "m.1001.png"));
  // The manifest knows the tile files: a second run is up to date.
  EXPECT_TRUE(
      plan(planeScene("", R"({"map": "mask", "file": "m.<UDIM>.png", "size": 8})", "tile1002.obj"))
          .outputs[0]
          .upToDate);
}

TEST_F(PlannerTest, ManifestMakesTheSecondRunBakeNothing) {
  const std::string json =
      planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8},
                       {"map": "mask", "file": "m.png", "size": 8})");
  const ExecuteReport first = bake(json);
  EXPECT_TRUE(first.outputs[0].baked);
  const std::string bytes = readFile(dir_ / "h.exr");
  const auto written = fs::last_write_time(dir_ / "h.exr");

  const Plan second = plan(json);
  EXPECT_EQ(second.outputsToBake(), 0u);
  EXPECT_FALSE(second.loadMesh);
  EXPECT_TRUE(second.images.empty());
  EXPECT_NE(explainPlan(second).find("up to date"), std::string::npos);
  Result<ExecuteReport> report = executePlan(second);
  ASSERT_TRUE(report);
  EXPECT_FALSE(report->outputs[0].baked);
  EXPECT_FALSE(report->outputs[1].baked);
  EXPECT_EQ(report->tilesBaked, 0u);
  EXPECT_EQ(readFile(dir_ / "h.exr"), bytes);
  EXPECT_EQ(fs::last_write_time(dir_ / "h.exr"), written);

  // --force bakes everything again.
  PlanOptions force;
  force.force = true;
  EXPECT_EQ(plan(json, force).outputsToBake(), 2u);
  // Without the manifest, everything is baked.
  PlanOptions noManifest;
  noManifest.useManifest = false;
  EXPECT_EQ(plan(json, noManifest).outputsToBake(), 2u);
}

TEST_F(PlannerTest, ChangedInputsParametersAndOutputsAreRebaked) {
  const std::string json =
      planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8},
                       {"map": "mask", "file": "m.png", "size": 8})");
  bake(json);
  ASSERT_EQ(plan(json).outputsToBake(), 0u);

  // A changed image re-bakes the output that reads it, not the mask (which reads no layers).
  ASSERT_TRUE(writeImage(heightImage(16, 0.25f), dir_ / "h.png"));
  Plan touched = plan(json);
  EXPECT_FALSE(touched.outputs[0].upToDate);
  EXPECT_EQ(touched.outputs[0].whyBake, fs::canonical(dir_ / "h.png").string() + " changed");
  EXPECT_TRUE(touched.outputs[1].upToDate);
  EXPECT_EQ(touched.outputs[1].whyBake, "");
  EXPECT_NE(explainPlan(touched).find("(because " + touched.outputs[0].whyBake + "; reads "),
            std::string::npos)
      << explainPlan(touched);
  ASSERT_TRUE(executePlan(touched));
  EXPECT_EQ(plan(json).outputsToBake(), 0u);

  // A changed parameter.
  const std::string wider =
      planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8, "margin": 2},
                       {"map": "mask", "file": "m.png", "size": 8})");
  EXPECT_EQ(plan(wider).outputsToBake(), 1u);
  EXPECT_EQ(plan(wider).outputs[0].whyBake, "its parameters changed: \"output\"");

  // A deleted output, and an output changed by someone else.
  fs::remove(dir_ / "m.png");
  EXPECT_FALSE(plan(json).outputs[1].upToDate);
  EXPECT_EQ(plan(json).outputs[1].whyBake, (dir_ / "m.png").string() + " is missing");
  bake(json);
  writeFile(dir_ / "h.exr", "edited");
  EXPECT_FALSE(plan(json).outputs[0].upToDate);
  EXPECT_EQ(plan(json).outputs[0].whyBake,
            (dir_ / "h.exr").string() + " was changed since it was baked");
  EXPECT_TRUE(plan(json).outputs[1].upToDate);

  // A changed mesh re-bakes everything.
  bake(json);
  writeFile(dir_ / "plane.obj", std::string(kPlaneObj) + "# edited\n");
  EXPECT_EQ(plan(json).outputsToBake(), 2u);
  EXPECT_EQ(plan(json).outputs[1].whyBake, fs::canonical(dir_ / "plane.obj").string() + " changed");
  PlanOptions force;
  force.force = true;
  EXPECT_EQ(plan(json, force).outputs[1].whyBake, "of --force");
  fs::remove(dir_ / kManifestName);
  EXPECT_EQ(plan(json).outputs[1].whyBake,
            "it is not in " + (dir_ / kManifestName).string() + " yet");

  // A corrupt manifest counts as empty, with a warning naming it; the next bake replaces it.
  bake(json);
  EXPECT_TRUE(plan(json).warnings.empty());
  for (const auto& [text, problem] :
       {std::pair<std::string, std::string>{"{ not json", "not valid JSON"},
        {"[1, 2]", "not a JSON object"},
        {R"({"sgbake_manifest": 99, "outputs": {}})", "its \"sgbake_manifest\" is 99"},
        {R"({"outputs": {}})", "its \"sgbake_manifest\" is missing"},
        {R"({"sgbake_manifest": 1, "outputs": 5})", "its \"outputs\" is not an object"},
        {R"({"sgbake_manifest": 1, "outputs": {"n_out.png": {"files": "x"}}})",
         "its entries for 'n_out.png' are not what sgbake writes"},
        // Last, so that the bake below writes over it: a value nested 100,000 deep, which
        // crashed the manifest's writing (stack overflow) before entries were checked.
        {R"({"sgbake_manifest": 1, "outputs": {"y": )" + std::string(100000, '[') +
             std::string(100000, ']') + "}}",
         "its entries for 'y' are not what sgbake writes"}}) {
    writeFile(dir_ / kManifestName, text);
    const Plan corrupt = plan(json);
    EXPECT_EQ(corrupt.outputsToBake(), 2u) << text;
    ASSERT_EQ(corrupt.warnings.size(), 1u) << text;
    EXPECT_NE(corrupt.warnings[0].find(kManifestName), std::string::npos) << corrupt.warnings[0];
    EXPECT_NE(corrupt.warnings[0].find(problem), std::string::npos) << corrupt.warnings[0];
  }
  bake(json);
  EXPECT_TRUE(plan(json).warnings.empty());
  EXPECT_EQ(plan(json).outputsToBake(), 0u);
}

TEST_F(PlannerTest, AProjectMovedAsAWholeIsUpToDate) {
  // The manifest names files relative to its directory: a project renamed, moved or checked
  // out elsewhere as a whole needs no re-bake; a changed input there still does.
  fs::create_directories(dir_ / "masks");
  ASSERT_TRUE(writeImage(heightImage(16), dir_ / "masks" / "m.png"));
  const std::string json =
      planeScene(R"({"type": "height", "image": "h.png", "scale": 0.1, "mask": "masks/m.png"})",
                 R"({"map": "height", "file": "out/h.exr", "size": 8},
         {"map": "mask", "file": "m.png", "size": 8})");
  bake(json);
  ASSERT_EQ(plan(json).outputsToBake(), 0u);
  const fs::path moved = dir_.string() + "_moved";
  fs::remove_all(moved);
  fs::rename(dir_, moved);
  dir_ = moved;                   // (TearDown removes it)
  const Plan there = plan(json);  // (the old build: every output re-baked here)
  EXPECT_EQ(there.outputsToBake(), 0u) << explainPlan(there);
  writeFile(dir_ / "plane.obj", std::string(kPlaneObj) + "# edited\n");
  EXPECT_EQ(plan(json).outputs[1].whyBake, (dir_ / "plane.obj").string() + " changed");
}

TEST_F(PlannerTest, ASubdivisionBlockThatChangesNothingIsNoChange) {
  const std::string plain =
      planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8})");
  bake(plain);
  std::string levelZero = plain;
  levelZero.insert(1, R"("subdivision": {"level": 0, "uv_smooth": "all"}, )");
  EXPECT_EQ(plan(levelZero).outputsToBake(), 0u) << explainPlan(plan(levelZero));
  std::string levelOne = plain;
  levelOne.insert(1, R"("subdivision": {"level": 1}, )");
  EXPECT_EQ(plan(levelOne).outputsToBake(), 1u);
  EXPECT_EQ(plan(levelOne).outputs[0].whyBake, "its parameters changed: \"subdivision\"");
}

// The object transform re-bakes the maps it shades (normals, Γ), not heights or masks; a
// translation alone shades nothing differently and re-bakes nothing. Explain names the step.
TEST_F(PlannerTest, TheTransformReBakesWhatItShades) {
  const std::string outputs = R"({"map": "object-normal", "file": "o.exr", "size": 8},
                       {"map": "height", "file": "h.exr", "size": 8},
                       {"map": "mask", "file": "m.png", "size": 8})";
  const std::string plain = planeScene(kHeightLayer, outputs);
  bake(plain);
  std::string moved = plain;
  moved.insert(1, R"("transform": [[1, 0, 0, 5], [0, 1, 0, 6], [0, 0, 1, 7], [0, 0, 0, 1]], )");
  EXPECT_EQ(plan(moved).outputsToBake(), 0u) << explainPlan(plan(moved));
  std::string stretched = plain;
  stretched.insert(1, R"("transform": [[2, 0, 0], [0, 1, 0], [0, 0, 0.5]], )");
  const Plan p = plan(stretched);
  EXPECT_EQ(p.outputsToBake(), 1u);
  EXPECT_FALSE(p.outputs[0].upToDate);
  EXPECT_EQ(p.outputs[0].whyBake, "its parameters changed: \"transform\"");
  const std::string explained = explainPlan(p);
  EXPECT_NE(explained.find("shade in world space through the object transform"), std::string::npos)
      << explained;
  EXPECT_EQ(explainPlan(plan(plain)).find("world space"), std::string::npos);
  // A turn with a uniform scale shades as object space, heights divided by the scale.
  std::string turned = plain;
  turned.insert(1, R"("transform": [[0, -2, 0], [2, 0, 0], [0, 0, 2]], )");
  const std::string turnedPlan = explainPlan(plan(turned));
  EXPECT_NE(turnedPlan.find("shade in object space with heights in world units divided by the "
                            "object's uniform scale 2 "),
            std::string::npos)
      << turnedPlan;
  EXPECT_EQ(turnedPlan.find("world space through"), std::string::npos) << turnedPlan;
  // Not with heights differenced as the Bump node does: its offsets do not turn with the
  // object.
  std::string bumpNode = turned;
  const std::size_t layer = bumpNode.find(R"("type": "height")");
  ASSERT_NE(layer, std::string::npos) << bumpNode;
  bumpNode.insert(layer, R"("gradient": "bump-node", )");
  const std::string bumpNodePlan = explainPlan(plan(bumpNode));
  EXPECT_NE(bumpNodePlan.find("shade in world space through the object transform"),
            std::string::npos)
      << bumpNodePlan;
  const std::string before = readFile(dir_ / "o.exr");
  ASSERT_TRUE(executePlan(p));
  EXPECT_NE(readFile(dir_ / "o.exr"), before);
  EXPECT_EQ(plan(stretched).outputsToBake(), 0u);
}

// A layer's "material" names a material of the mesh by index or by its OBJ `usemtl` name: a
// name the mesh lacks is bad input listing the names; an index no face has, a warning; the
// material is a parameter of the manifest.
TEST_F(PlannerTest, LayerMaterialsByIndexOrName) {
  writeFile(dir_ / "split.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "usemtl Skin\nf 1/1 2/2 3/3\nusemtl Cloth\nf 1/1 3/3 4/4\n");
  const auto withMaterial = [](const std::string& material) {
    return R"({"type": "height", "image": "h.png", "scale": 0.1, "material": )" + material + "}";
  };
  const std::string output = R"({"map": "height", "file": "h.exr", "size": 8})";
  const ExecuteReport byName = bake(planeScene(withMaterial(R"("Cloth")"), output, "split.obj"));
  EXPECT_TRUE(byName.warnings.empty());
  const std::vector<float> cloth = readPixels(dir_ / "h.exr");
  bake(planeScene(withMaterial("1"), output, "split.obj"), {.force = true});
  EXPECT_EQ(readPixels(dir_ / "h.exr"), cloth) << "Cloth is material 1";
  bake(planeScene(withMaterial("0"), output, "split.obj"), {.force = true});
  EXPECT_NE(readPixels(dir_ / "h.exr"), cloth);
  EXPECT_EQ(plan(planeScene(withMaterial("1"), output, "split.obj")).outputs[0].whyBake,
            "its parameters changed: \"layers\"");

  Result<Plan> unknown = makePlan(scene(planeScene(withMaterial(R"("Skn")"), output, "split.obj")));
  ASSERT_TRUE(unknown);
  Result<ExecuteReport> refused = executePlan(*unknown);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("layers[0]: material 'Skn' is not in"), std::string::npos)
      << refused.error().message;
  EXPECT_NE(refused.error().message.find("(its materials: 'Skin', 'Cloth')"), std::string::npos)
      << refused.error().message;
  const ExecuteReport nobody =
      bake(planeScene(withMaterial("4"), output, "split.obj"), {.force = true});
  ASSERT_EQ(nobody.warnings.size(), 1u);
  EXPECT_NE(nobody.warnings[0].find("layers[0]: no face of"), std::string::npos)
      << nobody.warnings[0];
  EXPECT_NE(nobody.warnings[0].find("has material 4: the layer bakes nothing"), std::string::npos)
      << nobody.warnings[0];
}

TEST_F(PlannerTest, ValuesAFileCannotStoreAreAWarningNamingTheFileAndTheRemedy) {
  // h.png rises by 0.5 across the plane: with scale 4, ∂h/∂u = 2 and heights reach 2.
  const std::string layer = R"({"type": "height", "image": "h.png", "scale": 4})";
  const ExecuteReport clipped =
      bake(planeScene(layer, R"({"map": "derivative", "file": "d.png", "size": 16, "margin": 0},
                {"map": "height", "file": "h_out.png", "size": 16, "margin": 0},
                {"map": "tangent-normal", "file": "n_out.png", "size": 16, "margin": 0})"));
  ASSERT_EQ(clipped.warnings.size(), 2u);
  EXPECT_NE(clipped.warnings[0].find("d.png: "), std::string::npos) << clipped.warnings[0];
  EXPECT_NE(clipped.warnings[0].find("range"), std::string::npos) << clipped.warnings[0];
  EXPECT_NE(clipped.warnings[1].find("h_out.png: "), std::string::npos) << clipped.warnings[1];
  EXPECT_NE(clipped.warnings[1].find("outside [0, 1]"), std::string::npos) << clipped.warnings[1];
  // Every ∂h/∂u texel of the plane is clipped; the normal map (always in range) is not named.
  EXPECT_NE(clipped.warnings[0].find(" values were beyond the stored range ±1"), std::string::npos);

  // A range that holds the derivatives (−32 where the repeating ramp drops back from 0.5 to 0
  // within a texel of the 16² height map), and a float file for the heights: no warning.
  const ExecuteReport kept = bake(planeScene(
      layer, R"({"map": "derivative", "file": "d.png", "size": 16, "margin": 0, "range": 64},
                {"map": "height", "file": "h_out.exr", "size": 16, "margin": 0})"));
  EXPECT_TRUE(kept.warnings.empty()) << kept.warnings.front();

  // "range": "auto" holds every finite value: what is left to clamp is infinite (slopes beyond
  // the largest float), and the warning says so rather than suggesting "auto".
  const ExecuteReport infinite = bake(planeScene(
      R"({"type": "height", "image": "h.png", "scale": 1e39})",
      R"({"map": "derivative", "file": "d.png", "size": 16, "margin": 0, "range": "auto"})"));
  ASSERT_EQ(infinite.warnings.size(), 1u);
  EXPECT_NE(infinite.warnings[0].find("values were infinite or NaN"), std::string::npos)
      << infinite.warnings[0];
}

TEST_F(PlannerTest, BakedFilesSayHowTheyAreEncoded) {
  bake(planeScene(kHeightLayer,
                  R"({"map": "derivative", "file": "d.png", "size": 8, "range": 2.5},
                     {"map": "derivative", "file": "d.exr", "size": 8},
                     {"map": "tangent-normal", "file": "n_<UDIM>.exr", "size": 8,
                      "green": "directx"},
                     {"map": "tangent-normal", "file": "n_swizzled.exr", "size": 8,
                      "swizzle": "+X-Y+Z"},
                     {"map": "tangent-normal", "file": "n_moved.exr", "size": 8,
                      "swizzle": "+Y-X+Z"},
                     {"map": "object-normal", "file": "o_moved.exr", "size": 8,
                      "swizzle": "-X+Y+Z"},
                     {"map": "height", "file": "h_out.png", "size": 8, "uv": 0})"));
  // What OpenImageIO reads back: PNG text chunks and EXR header attributes.
  auto attributes = [&](const std::string& name) {
    std::map<std::string, std::string> found;
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open((dir_ / name).string());
    EXPECT_TRUE(in) << name;
    if (!in) return found;
    for (const OIIO::ParamValue& p : in->spec().extra_attribs) {
      const std::string key = p.name().string();
      if (key.starts_with("sgbake:")) found[key] = p.get_string();
    }
    return found;
  };
  using Attributes = std::map<std::string, std::string>;
  const std::string version = sgbake_version();
  EXPECT_EQ(attributes("d.png"), (Attributes{{"sgbake:map", "derivative"},
                                             {"sgbake:encoding", "value/(2*range)+0.5"},
                                             {"sgbake:range", "2.5"},
                                             {"sgbake:uv", "0"},
                                             {"sgbake:udim_tile", "1001"},
                                             {"sgbake:version", version}}));
  EXPECT_EQ(attributes("d.exr"), (Attributes{{"sgbake:map", "derivative"},
                                             {"sgbake:encoding", "value"},
                                             {"sgbake:uv", "0"},
                                             {"sgbake:udim_tile", "1001"},
                                             {"sgbake:version", version}}));
  EXPECT_EQ(attributes("n_1001.exr"), (Attributes{{"sgbake:map", "tangent-normal"},
                                                  {"sgbake:encoding", "n/2+0.5"},
                                                  {"sgbake:green", "directx"},
                                                  {"sgbake:uv", "0"},
                                                  {"sgbake:udim_tile", "1001"},
                                                  {"sgbake:version", version}}));
  // A DirectX green said as a swizzle is a DirectX green; other swizzles are said as such (and
  // G's direction, when G holds ±y).
  EXPECT_EQ(attributes("n_swizzled.exr"), attributes("n_1001.exr"));
  EXPECT_EQ(attributes("n_moved.exr").at("sgbake:swizzle"), "+Y-X+Z");
  EXPECT_EQ(attributes("n_moved.exr").count("sgbake:green"), 0u);
  EXPECT_EQ(attributes("o_moved.exr").at("sgbake:swizzle"), "-X+Y+Z");
  EXPECT_EQ(attributes("h_out.png").at("sgbake:encoding"), "value");
}

TEST_F(PlannerTest, UdimHeightImagesAreReadTileByTile) {
  // The same square in tile 1001 (UVs 0.25–0.75) and in tile 1002 (1.25–1.75).
  writeFile(dir_ / "quarter.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
            "vt 0.25 0.25\nvt 0.75 0.25\nvt 0.75 0.75\nvt 0.25 0.75\n"
            "f 1/1 2/2 3/3 4/4\n");
  const std::string output =
      R"({"map": "surface-gradient", "file": "g.exr", "size": 16, "bit_depth": 32})";
  bake(planeScene(kHeightLayer, output, "quarter.obj"));
  const std::vector<float> single = readPixels(dir_ / "g.exr");

  // h_1002.png is h.png: tile 1002 of the UDIM image read in tile 1002 is h.png read in 1001.
  fs::copy_file(dir_ / "h.png", dir_ / "h_1002.png");
  const std::string udimLayer = R"({"type": "height", "image": "h_<UDIM>.png", "scale": 0.1})";
  const ExecuteReport report = bake(planeScene(
      udimLayer,
      R"({"map": "surface-gradient", "file": "g_<UDIM>.exr", "size": 16, "bit_depth": 32})",
      "tile1002.obj"));
  EXPECT_EQ(report.imagesLoaded, 1u);
  const std::vector<float> tiled = readPixels(dir_ / "g_1002.exr");
  ASSERT_EQ(tiled.size(), single.size());
  double largest = 0;
  for (std::size_t i = 0; i < single.size(); ++i) {
    largest = std::max(largest, std::abs(static_cast<double>(single[i])));
    EXPECT_NEAR(tiled[i], single[i], 1e-5) << i;
  }
  EXPECT_GT(largest, 0.01) << "the height map bumps the square";

  // Only tile 1001 given: the square in tile 1002 reads no tile, so it is not bumped.
  fs::remove(dir_ / "h_1002.png");
  fs::copy_file(dir_ / "h.png", dir_ / "h_1001.png");
  bake(planeScene(
      udimLayer,
      R"({"map": "surface-gradient", "file": "g_<UDIM>.exr", "size": 16, "bit_depth": 32})",
      "tile1002.obj"));
  for (const float v : readPixels(dir_ / "g_1002.exr")) ASSERT_EQ(v, 0.0f);

  // The manifest hashes the tiles the UVs reach: one added, changed or removed there re-bakes;
  // tiles elsewhere (another object's, sharing the set) do not.
  const std::string udimOutput = R"({"map": "height", "file": "u.exr", "size": 8})";
  const auto toBake = [&](const char* mesh) {
    return plan(planeScene(udimLayer, udimOutput, mesh)).outputsToBake();
  };
  bake(planeScene(udimLayer, udimOutput, "quarter.obj"));  // tile 1001 only
  EXPECT_EQ(toBake("quarter.obj"), 0u);
  fs::copy_file(dir_ / "h.png", dir_ / "h_1005.png");
  EXPECT_EQ(toBake("quarter.obj"), 0u) << "no UV reaches tile 1005";
  ASSERT_TRUE(writeImage(heightImage(16, 0.25f), dir_ / "h_1005.png"));
  EXPECT_EQ(toBake("quarter.obj"), 0u) << "no UV reaches tile 1005";
  ASSERT_TRUE(writeImage(heightImage(16, 0.25f), dir_ / "h_1001.png"));
  EXPECT_EQ(toBake("quarter.obj"), 1u) << "tile 1001 changed";
  bake(planeScene(udimLayer, udimOutput, "quarter.obj"));
  EXPECT_EQ(toBake("quarter.obj"), 0u);
  fs::remove(dir_ / "h_1005.png");
  EXPECT_EQ(toBake("quarter.obj"), 0u) << "no UV reaches tile 1005";
  // The square in tile 1002, which had no file: adding one re-bakes, removing it again too.
  bake(planeScene(udimLayer, udimOutput, "tile1002.obj"));
  EXPECT_EQ(toBake("tile1002.obj"), 0u);
  fs::copy_file(dir_ / "h.png", dir_ / "h_1002.png");
  EXPECT_EQ(toBake("tile1002.obj"), 1u) << "tile 1002 added where the UVs are";
  EXPECT_EQ(plan(planeScene(udimLayer, udimOutput, "tile1002.obj")).outputs[0].whyBake,
            fs::canonical(dir_ / "h_1002.png").string() + " is new");
  bake(planeScene(udimLayer, udimOutput, "tile1002.obj"));
  EXPECT_EQ(toBake("tile1002.obj"), 0u);
  fs::remove(dir_ / "h_1002.png");
  EXPECT_EQ(toBake("tile1002.obj"), 1u) << "tile 1002 removed where the UVs are";
  EXPECT_EQ(plan(planeScene(udimLayer, udimOutput, "tile1002.obj")).outputs[0].whyBake,
            (dir_ / "h_1002.png").string() + " is gone");
}

TEST_F(PlannerTest, UdimOutputsBakeAgainOnlyTheTilesThatChanged) {
  // One square in tile 1001, one in 1002, a UDIM height image of both tiles and a UDIM output.
  writeFile(dir_ / "two_tiles.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 3 1 0\nv 2 1 0\n"
            "vt 0.25 0.25\nvt 0.75 0.25\nvt 0.75 0.75\nvt 0.25 0.75\n"
            "vt 1.25 0.25\nvt 1.75 0.25\nvt 1.75 0.75\nvt 1.25 0.75\n"
            "f 1/1 2/2 3/3 4/4\nf 5/5 6/6 7/7 8/8\n");
  fs::copy_file(dir_ / "h.png", dir_ / "h_1001.png");
  fs::copy_file(dir_ / "h.png", dir_ / "h_1002.png");
  const auto scene = [&](const std::string& layerExtra) {
    return planeScene(
        R"({"type": "height", "image": "h_<UDIM>.png", "scale": 0.1)" + layerExtra + "}",
        R"({"map": "object-normal", "file": "n_<UDIM>.exr", "size": 16})", "two_tiles.obj");
  };
  const ExecuteReport first = bake(scene(""));
  ASSERT_EQ(first.outputs[0].files.size(), 2u);
  const auto written1001 = fs::last_write_time(dir_ / "n_1001.exr");
  const std::string bytes1001 = readFile(dir_ / "n_1001.exr");
  const std::vector<float> pixels1001 = readPixels(dir_ / "n_1001.exr");
  const std::vector<float> pixels1002 = readPixels(dir_ / "n_1002.exr");

  // Tile 1002 of the image changes: tile 1002 of the output is baked again, 1001 stays.
  FloatImage steeper = heightImage(16);
  for (float& v : steeper.pixels) v *= 1.5f;
  ASSERT_TRUE(writeImage(steeper, dir_ / "h_1002.png"));
  const Plan changed = plan(scene(""));
  ASSERT_EQ(changed.outputsToBake(), 1u);
  EXPECT_EQ(changed.outputs[0].keptTiles, std::vector<int>{1001});
  EXPECT_EQ(changed.outputs[0].whyBake, "tile(s) 1002 changed (" +
                                            fs::canonical(dir_ / "h_1002.png").string() +
                                            " changed); tile(s) 1001 are kept as they are");
  const ExecuteReport second = bake(scene(""));
  EXPECT_EQ(second.outputs[0].files, std::vector<fs::path>{dir_ / "n_1002.exr"});
  EXPECT_EQ(second.outputs[0].kept, std::vector<fs::path>{dir_ / "n_1001.exr"});
  EXPECT_EQ(second.tilesBaked, 1u);
  EXPECT_EQ(second.imagesLoaded, 1u) << "h_1001.png is not read";
  EXPECT_EQ(fs::last_write_time(dir_ / "n_1001.exr"), written1001);
  EXPECT_EQ(readFile(dir_ / "n_1001.exr"), bytes1001);
  EXPECT_NE(readPixels(dir_ / "n_1002.exr"), pixels1002) << "the new height bumps tile 1002";
  // The manifest keeps both tiles: nothing to do now, and the same files as a full bake.
  EXPECT_EQ(plan(scene("")).outputsToBake(), 0u);
  // (Pixels, not bytes: an EXR records the time it was written.)
  const std::vector<float> partial1002 = readPixels(dir_ / "n_1002.exr");
  PlanOptions force;
  force.force = true;
  bake(scene(""), force);
  EXPECT_EQ(readPixels(dir_ / "n_1001.exr"), pixels1001);
  EXPECT_EQ(readPixels(dir_ / "n_1002.exr"), partial1002);

  // A tile file edited by hand is baked again, alone.
  writeFile(dir_ / "n_1001.exr", "not an image");
  EXPECT_EQ(plan(scene("")).outputs[0].keptTiles, std::vector<int>{1002});
  bake(scene(""));
  EXPECT_EQ(readPixels(dir_ / "n_1001.exr"), pixels1001);

  // A tile file of the image removed: its tile is baked again, without the bump, alone.
  const std::vector<float> bumped1001 = readPixels(dir_ / "n_1001.exr");
  ASSERT_TRUE(fs::remove(dir_ / "h_1002.png"));
  const Plan removed = plan(scene(""));
  EXPECT_EQ(removed.outputs[0].keptTiles, std::vector<int>{1001});
  EXPECT_EQ(removed.outputs[0].whyBake, "tile(s) 1002 changed (" +
                                            (fs::canonical(dir_) / "h_1002.png").string() +
                                            " is gone); tile(s) 1001 are kept as they are");
  const ExecuteReport third = bake(scene(""));
  EXPECT_EQ(third.outputs[0].files, std::vector<fs::path>{dir_ / "n_1002.exr"});
  EXPECT_EQ(readPixels(dir_ / "n_1001.exr"), bumped1001);
  const std::vector<float> flat1002 = readPixels(dir_ / "n_1002.exr");
  for (std::size_t i = 0; i + 2 < flat1002.size(); i += 3) {
    if (flat1002[i] == 0 && flat1002[i + 1] == 0 && flat1002[i + 2] == 0) continue;  // uncovered
    EXPECT_NEAR(flat1002[i + 2], 1.0f, 1e-3f) << "no tile file: no bump (texel " << i / 3 << ")";
  }
  // A manifest of before the tiles' numbers were recorded: the whole output is baked again.
  ASSERT_TRUE(writeImage(steeper, dir_ / "h_1002.png"));
  bake(scene(""));
  nlohmann::json manifest = nlohmann::json::parse(readFile(dir_ / kManifestName));
  for (auto& [name, entry] : manifest["outputs"].items()) entry.erase("input_tiles");
  writeFile(dir_ / kManifestName, manifest.dump());
  ASSERT_TRUE(fs::remove(dir_ / "h_1002.png"));
  EXPECT_TRUE(plan(scene("")).outputs[0].keptTiles.empty());

  // The mesh changes (or the parameters, or a plain image): every tile is baked again.
  writeFile(dir_ / "two_tiles.obj", readFile(dir_ / "two_tiles.obj") + "# edited\n");
  const Plan edited = plan(scene(""));
  EXPECT_EQ(edited.outputsToBake(), 1u);
  EXPECT_TRUE(edited.outputs[0].keptTiles.empty());
  EXPECT_EQ(bake(scene("")).outputs[0].files.size(), 2u);
}

TEST_F(PlannerTest, UdimNormalMapsAreFlatWhereNoTileIs) {
  // A square tilted 36.87° about x (normal (0, −0.6, 0.8)), its UVs in tile 1002; the normal
  // maps have only tile 1001, which holds +Z: unread, so both spaces leave the normal as it is.
  writeFile(dir_ / "tilted.obj",
            "v 0 0 0\nv 1 0 0\nv 1 0.8 0.6\nv 0 0.8 0.6\n"
            "vt 1.25 0.25\nvt 1.75 0.25\nvt 1.75 0.75\nvt 1.25 0.75\n"
            "f 1/1 2/2 3/3 4/4\n");
  fs::copy_file(dir_ / "n.png", dir_ / "n_1001.png");
  for (const char* space : {"object", "tangent"}) {
    const std::string layer =
        R"({"type": "normal", "image": "n_<UDIM>.png", "space": ")" + std::string(space) + "\"}";
    const ExecuteReport report =
        bake(planeScene(layer,
                        R"({"map": "object-normal", "file": "o_<UDIM>.exr", "size": 8,
                            "bit_depth": 32, "margin": 0, "alpha": true})",
                        "tilted.obj"));
    // Said once: the UVs reach tile 1002, which has no file.
    EXPECT_EQ(report.warnings,
              std::vector<std::string>{(dir_ / "n_<UDIM>.png").string() +
                                       ": UV set 0 reaches tiles without a file (" +
                                       (dir_ / "n_1002.png").string() + "): no bump there"})
        << space;
    const std::vector<float> pixels = readPixels(dir_ / "o_1002.exr");
    ASSERT_EQ(pixels.size(), std::size_t{8 * 8 * 4}) << space;
    int covered = 0;
    for (std::size_t t = 0; t < 64; ++t) {
      if (pixels[t * 4 + 3] < 1) continue;
      ++covered;
      EXPECT_NEAR(pixels[t * 4 + 0], 0.5, 1e-6) << space << " texel " << t;
      EXPECT_NEAR(pixels[t * 4 + 1], 0.5 * -0.6 + 0.5, 1e-6) << space << " texel " << t;
      EXPECT_NEAR(pixels[t * 4 + 2], 0.5 * 0.8 + 0.5, 1e-6) << space << " texel " << t;
    }
    EXPECT_GE(covered, 9) << space;
  }
}

TEST_F(PlannerTest, UdimTilesNoUvReachesAreNotLoaded) {
  // The square lies in tile 1002: tile 1002 is read, 1005 (not even an image) is not.
  fs::copy_file(dir_ / "h.png", dir_ / "h_1002.png");
  writeFile(dir_ / "h_1005.png", "not an image");
  writeFile(dir_ / "u_1001.exr", "an earlier bake's tile");
  const std::string layer = R"({"type": "height", "image": "h_<UDIM>.png", "scale": 0.1})";
  const ExecuteReport report = bake(
      planeScene(layer, R"({"map": "height", "file": "u_<UDIM>.exr", "size": 8})", "tile1002.obj"));
  EXPECT_EQ(report.imagesLoaded, 1u);
  EXPECT_TRUE(fs::exists(dir_ / "u_1002.exr"));
  // The output tile the UVs no longer reach is left, with a warning.
  EXPECT_EQ(readFile(dir_ / "u_1001.exr"), "an earlier bake's tile");
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("tile(s) 1001 of an earlier bake are left as they were"),
            std::string::npos)
      << report.warnings[0];
  // A mesh that reaches tile 1005 reads it, and its bad file is then an error.
  writeFile(dir_ / "tile1005.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
            "vt 4.25 0.25\nvt 4.75 0.25\nvt 4.75 0.75\nvt 4.25 0.75\nf 1/1 2/2 3/3 4/4\n");
  Result<Plan> planned = makePlan(scene(planeScene(
      layer, R"({"map": "height", "file": "v_<UDIM>.exr", "size": 8})", "tile1005.obj")));
  ASSERT_TRUE(planned) << planned.error().message;
  Result<ExecuteReport> failed = executePlan(*planned);
  ASSERT_FALSE(failed);
  EXPECT_NE(failed.error().message.find("h_1005.png"), std::string::npos) << failed.error().message;

  // The unit square's UVs end exactly at 1: its texels sample tile 1001 only, but its corner
  // table samples the corners at u = 1 in tile 1002 (and 1011, 1012), so only the table reads it.
  fs::copy_file(dir_ / "h.png", dir_ / "h_1001.png");
  const ExecuteReport map =
      bake(planeScene(layer, R"({"map": "height", "file": "w.exr", "size": 8})"));
  EXPECT_EQ(map.imagesLoaded, 1u) << "tile 1001";
  const ExecuteReport table = bake(planeScene(layer, R"({"map": "corners", "file": "c.csv"})"));
  EXPECT_EQ(table.imagesLoaded, 2u) << "tiles 1001 and 1002 (1011, 1012 have no file)";
  // Tile 1002 changed: the map is up to date, the table is not.
  ASSERT_TRUE(writeImage(heightImage(16, 0.25f), dir_ / "h_1002.png"));
  EXPECT_EQ(
      plan(planeScene(layer, R"({"map": "height", "file": "w.exr", "size": 8})")).outputsToBake(),
      0u);
  EXPECT_EQ(plan(planeScene(layer, R"({"map": "corners", "file": "c.csv"})")).outputsToBake(), 1u);
}

TEST_F(PlannerTest, AutoRangeHoldsEveryValueOfEveryTileInOneRange) {
  // Two squares, one per UDIM tile, UVs 0.5 wide: a unit square in tile 1001 and a 4-unit one
  // in tile 1002. The ramp's ∂h/∂u = 0.05 gives an object-space gradient of 0.025 in the first
  // and 0.00625 in the second; one range serves both files.
  writeFile(dir_ / "two.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 10 0 0\nv 14 0 0\nv 14 4 0\nv 10 4 0\n"
            "vt 0.25 0.25\nvt 0.75 0.25\nvt 0.75 0.75\nvt 0.25 0.75\n"
            "vt 1.25 0.25\nvt 1.75 0.25\nvt 1.75 0.75\nvt 1.25 0.75\n"
            "f 1/1 2/2 3/3 4/4\nf 5/5 6/6 7/7 8/8\n");
  const std::string both = planeScene(
      kHeightLayer,
      R"({"map": "surface-gradient", "file": "g_<UDIM>.png", "size": 32, "range": "auto"},
         {"map": "surface-gradient", "file": "g_<UDIM>.exr", "size": 32, "bit_depth": 32})",
      "two.obj");
  const std::string text = explainPlan(plan(both));
  EXPECT_NE(text.find("find the range of " + (dir_ / "g_<UDIM>.png").string() +
                      ": bake it once for its largest |value| over every tile"),
            std::string::npos)
      << text;
  const ExecuteReport report = bake(both);
  ASSERT_EQ(report.outputs.size(), 2u);
  const double range = report.outputs[0].autoRange;
  EXPECT_EQ(report.outputs[1].autoRange, 0.0) << "no range for a float file";
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();

  double largest = 0;
  for (const char* tile : {"1001", "1002"}) {
    const fs::path png = dir_ / ("g_" + std::string(tile) + ".png");
    const std::vector<float> codes = readPixels(png);
    const std::vector<float> values = readPixels(dir_ / ("g_" + std::string(tile) + ".exr"));
    ASSERT_EQ(codes.size(), values.size()) << tile;
    double tileLargest = 0;
    for (std::size_t i = 0; i < values.size(); ++i) {
      tileLargest = std::max(tileLargest, std::abs(static_cast<double>(values[i])));
      // Decoded as the file says: v = (code − 0.5) · 2 · range, within half a 16-bit step.
      EXPECT_NEAR((codes[i] - 0.5) * 2 * range, values[i], 1.01 * range / 65535)
          << tile << " " << i;
    }
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(png.string());
    ASSERT_TRUE(in);
    // The number the file records is exactly the range its codes were made with.
    EXPECT_EQ(std::stod(in->spec().get_string_attribute("sgbake:range", "0")), range) << tile;
    largest = std::max(largest, tileLargest);
    EXPECT_GT(tileLargest, 0.005) << tile << ": the height map bumps the square";
  }
  // The range is the largest value rounded up: nothing clipped, under 1 % of the codes unused.
  EXPECT_EQ(range, roundRangeUp(largest));
  EXPECT_GE(range, largest);
  EXPECT_LE(range, largest * 1.01);

  // "auto" is a parameter like any other: unchanged, the second run is up to date.
  EXPECT_EQ(plan(planeScene(kHeightLayer,
                            R"({"map": "surface-gradient", "file": "g_<UDIM>.png", "size": 32,
                                "range": "auto"})",
                            "two.obj"))
                .outputsToBake(),
            0u);
}

TEST(AutoRange, RoundsUpToThreeSignificantDigits) {
  EXPECT_EQ(roundRangeUp(0), 1.0);
  EXPECT_EQ(roundRangeUp(-2), 1.0);
  EXPECT_EQ(roundRangeUp(std::numeric_limits<double>::infinity()), 1.0);
  EXPECT_EQ(roundRangeUp(2), 2.0);
  EXPECT_EQ(roundRangeUp(3.14159), 3.15);
  EXPECT_EQ(roundRangeUp(123456), 124000.0);
  EXPECT_EQ(roundRangeUp(0.0012345), 0.00124);
  // Invariants over many magnitudes: never below the value, at most 1 % above, and the
  // shortest form of the number (what files record) has at most 3 significant digits.
  double x = 1.234567e-9;
  for (int i = 0; i < 400; ++i, x *= 1.1373) {
    const double range = roundRangeUp(x);
    EXPECT_GE(range, x) << x;
    EXPECT_LE(range, x * 1.01) << x;
    char text[32];
    std::snprintf(text, sizeof text, "%g", range);  // the shortest form, as files record it
    std::string digits;
    for (const char c : std::string(text).substr(0, std::string(text).find('e'))) {
      if (c >= '0' && c <= '9' && !(digits.empty() && c == '0')) digits += c;
    }
    while (!digits.empty() && digits.back() == '0') digits.pop_back();
    const std::size_t significant = digits.size();
    EXPECT_LE(significant, 3u) << text;
  }
}

TEST_F(PlannerTest, UdimImagesThatCannotWorkAreBadInput) {
  const std::string out = R"({"map": "height", "file": "u.exr", "size": 8})";
  for (const auto& [layer, message] : {
           std::pair{R"({"type": "height", "image": "none_<UDIM>.png"})",
                     "layers[0]: no tile of the UDIM image " + (dir_ / "none_<UDIM>.png").string() +
                         " exists (" + (dir_ / "none_1001.png").string() + " to " +
                         (dir_ / "none_2000.png").string() + ")"},
           {R"({"type": "height", "image": "h_<UDIM>.png", "tiling": 2})",
            "is a UDIM image: its tiles lie where the UVs do, so tiling and offset cannot apply"},
           {R"({"type": "triplanar", "image": "h_<UDIM>.png"})",
            "images are for UV layers (height, normal), not projections"},
           {R"({"type": "height", "image": "<UDIM>/h.png"})",
            "<UDIM> must be in the file name, not a directory"},
       }) {
    fs::copy_file(dir_ / "h.png", dir_ / "h_1001.png", fs::copy_options::overwrite_existing);
    writeFile(dir_ / "scene.json", planeScene(layer, out));
    Result<Scene> parsed = loadScene(dir_ / "scene.json");
    Result<Plan> planned = parsed ? makePlan(std::move(*parsed)) : Result<Plan>(parsed.error());
    ASSERT_FALSE(planned) << layer;
    EXPECT_EQ(planned.error().code, ErrorCode::kBadInput);
    EXPECT_NE(planned.error().message.find(message), std::string::npos) << planned.error().message;
  }
  // A tile name taken by something that is not a file is named, not taken for a missing tile.
  fs::create_directory(dir_ / "h_1002.png");
  writeFile(dir_ / "scene.json", planeScene(R"({"type": "height", "image": "h_<UDIM>.png"})", out));
  Result<Scene> parsed = loadScene(dir_ / "scene.json");
  ASSERT_TRUE(parsed) << parsed.error().message;
  Result<Plan> planned = makePlan(std::move(*parsed));
  ASSERT_FALSE(planned);
  EXPECT_NE(planned.error().message.find("tile file " + (dir_ / "h_1002.png").string() +
                                         " is not a regular file (a directory)"),
            std::string::npos)
      << planned.error().message;
  // "tile" picks the tile of a file without <UDIM>; with it, every tile is baked.
  writeFile(dir_ / "scene.json",
            planeScene("", R"({"map": "mask", "file": "m_<UDIM>.png", "tile": 1002})"));
  Result<Scene> tiled = loadScene(dir_ / "scene.json");
  ASSERT_FALSE(tiled);
  EXPECT_NE(tiled.error().message.find("key 'tile' applies only to a file without <UDIM>"),
            std::string::npos)
      << tiled.error().message;
}

TEST_F(PlannerTest, FailingBakeLeavesExistingOutputsUntouched) {
  writeFile(dir_ / "n_out.png", "previous output");
  const std::set<std::string> before = listDirectory(dir_);
  // A mesh without UVs fails at execution, after planning.
  Result<Plan> p = makePlan(scene(
      planeScene(kHeightLayer, R"({"map": "tangent-normal", "file": "n_out.png"})", "nouv.obj")));
  ASSERT_TRUE(p) << p.error().message;
  Result<ExecuteReport> report = executePlan(*p);
  ASSERT_FALSE(report);
  EXPECT_EQ(report.error().code, ErrorCode::kBadInput);
  EXPECT_EQ(readFile(dir_ / "n_out.png"), "previous output");
  std::set<std::string> after = listDirectory(dir_);
  after.erase("scene.json");
  std::set<std::string> expected = before;
  expected.erase("scene.json");
  EXPECT_EQ(after, expected) << "no temporary files, no manifest";

  // A UV set the mesh does not have.
  Result<Plan> uv = makePlan(
      scene(planeScene(kHeightLayer, R"({"map": "height", "file": "n_out.png", "uv": 1})")));
  ASSERT_TRUE(uv);
  Result<ExecuteReport> failed = executePlan(*uv);
  ASSERT_FALSE(failed);
  EXPECT_NE(failed.error().message.find("has 1 UV set(s) but outputs[0] uses UV set 1"),
            std::string::npos)
      << failed.error().message;
  EXPECT_EQ(readFile(dir_ / "n_out.png"), "previous output");
}

TEST_F(PlannerTest, ProgressIsReported) {
  Result<Plan> p =
      makePlan(scene(planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8},
                       {"map": "mask", "file": "m.png", "size": 8})")));
  ASSERT_TRUE(p);
  std::size_t calls = 0;
  std::size_t lastDone = 0, lastTotal = 0;
  ExecuteOptions options;
  options.threads = 1;
  options.progress = [&](const BakeProgress& progress) {
    ++calls;
    EXPECT_LE(progress.done, progress.total);
    EXPECT_GE(progress.done, lastDone);
    lastDone = progress.done;
    lastTotal = progress.total;
  };
  ASSERT_TRUE(executePlan(*p, options));
  EXPECT_GE(calls, 4u);
  EXPECT_EQ(lastDone, lastTotal);
  EXPECT_EQ(lastTotal, 4u) << "mesh, image, two outputs";
}

}  // namespace
}  // namespace sgbake
