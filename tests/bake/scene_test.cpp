/// @file scene_test.cpp
/// @brief The scene parser: the issue's example, defaults, paths, and one-line errors that name
/// the key, its place and a suggestion.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "sgbake/bake/scene.hpp"

namespace sgbake {
namespace {

/// The example scene of the issue, verbatim apart from picking one value per alternative.
constexpr const char* kIssueScene = R"({ "mesh": "m.obj", "uv": 0,
  "subdivision": {"level": "limit", "uv_smooth": "keep-boundaries", "boundary": "all"},
  "layers": [
    {"type": "height", "image": "h.exr", "scale": 0.1, "filter": "bicubic", "uv": 0, "weight": 1},
    {"type": "normal", "image": "n.png", "space": "tangent", "green": "directx", "uv": 0},
    {"type": "volume", "function": "sine", "amplitude": 1, "frequency": 1, "direction": [1,0,0],
     "phase": 0, "gradient": "tetrahedral", "step": 0.001},
    {"type": "triplanar", "image": "t.png", "kind": "tangent-normal",
     "scale": 0.1, "tiling": 1, "sharpness": 4} ],
  "outputs": [ {"map": "tangent-normal", "file": "out/n.png", "size": 2048, "margin": 16,
                "samples": 1, "green": "opengl"} ] })";

SceneParseOptions options(const std::string& base = "scenes") {
  SceneParseOptions o;
  o.baseDir = base;
  o.name = "scene.json";
  return o;
}

/// A scene with subdivision block @p block (JSON text) and one mask output.
std::string withSubdivision(const std::string& block) {
  return R"({"mesh": "m.obj", "subdivision": )" + block +
         R"(, "outputs": [{"map": "mask", "file": "m.png"}]})";
}

/// Parses @p text, expecting failure; returns the message.
std::string parseError(const std::string& text) {
  Result<Scene> scene = parseScene(text, options());
  if (scene) {
    ADD_FAILURE() << "parsed: " << text;
    return {};
  }
  EXPECT_EQ(scene.error().code, ErrorCode::kBadInput);
  EXPECT_EQ(scene.error().message.find('\n'), std::string::npos) << "one line";
  EXPECT_TRUE(scene.error().message.starts_with("scene.json: ")) << scene.error().message;
  return scene.error().message;
}

/// validateScene's message for @p scene, expecting failure.
std::string validationError(const Scene& scene) {
  Status status = validateScene(scene);
  if (status) {
    ADD_FAILURE() << "valid";
    return {};
  }
  return status.error().message;
}

/// A valid scene with @p output as its only output (and no layers).
std::string withOutput(const std::string& output) {
  return R"({"mesh": "m.obj", "outputs": [)" + output + "]}";
}

/// A valid scene with @p layer as its only layer.
std::string withLayer(const std::string& layer) {
  return R"({"mesh": "m.obj", "layers": [)" + layer +
         R"(], "outputs": [{"map": "height", "file": "h.exr"}]})";
}

TEST(Scene, ParsesTheIssueExample) {
  Result<Scene> parsed = parseScene(kIssueScene, options());
  ASSERT_TRUE(parsed) << parsed.error().message;
  const Scene& scene = *parsed;
  EXPECT_EQ(scene.mesh, std::filesystem::path("scenes/m.obj"));
  EXPECT_TRUE(scene.subdivision.present);
  EXPECT_TRUE(scene.subdivision.limit);
  EXPECT_TRUE(scene.subdivision.requested());
  EXPECT_EQ(scene.subdivision.uvSmooth, SubdivisionUvSmooth::kKeepBoundaries);
  ASSERT_EQ(scene.layers.size(), 4u);

  const SceneLayer& height = scene.layers[0];
  EXPECT_EQ(height.type, SceneLayerType::kHeight);
  EXPECT_EQ(height.image, std::filesystem::path("scenes/h.exr"));
  EXPECT_EQ(height.scale, 0.1);
  EXPECT_EQ(height.filter, Filter::kBicubic);
  EXPECT_TRUE(height.hasHeight());

  const SceneLayer& normal = scene.layers[1];
  EXPECT_EQ(normal.type, SceneLayerType::kNormal);
  EXPECT_EQ(normal.space, NormalSpace::kTangent);
  EXPECT_EQ(normal.green, NormalMapGreen::kDirectX);
  EXPECT_TRUE(normal.readsNormals());
  EXPECT_FALSE(normal.hasHeight());

  const SceneLayer& volume = scene.layers[2];
  EXPECT_EQ(volume.type, SceneLayerType::kVolume);
  EXPECT_EQ(volume.function, VolumeFunction::kSine);
  EXPECT_EQ(volume.gradient, GradientScheme::kTetrahedral);
  ASSERT_TRUE(volume.step.has_value());
  EXPECT_EQ(*volume.step, 0.001);
  EXPECT_EQ(volume.direction, (Vec3d{1, 0, 0}));

  const SceneLayer& triplanar = scene.layers[3];
  EXPECT_EQ(triplanar.kind, ProjectedKind::kTangentNormal);
  EXPECT_EQ(triplanar.tiling, (Vec2d{1, 1}));
  EXPECT_EQ(triplanar.sharpness, 4.0);

  ASSERT_EQ(scene.outputs.size(), 1u);
  const SceneOutput& output = scene.outputs[0];
  EXPECT_EQ(output.kind, OutputKind::kMap);
  EXPECT_EQ(output.map, MapKind::kTangentNormal);
  EXPECT_EQ(output.file, std::filesystem::path("scenes/out/n.png"));
  EXPECT_EQ(output.width, 2048);
  EXPECT_EQ(output.height, 2048);
  EXPECT_EQ(output.margin, 16);
  EXPECT_EQ(output.resolvedFormat(), ImageFormat::kPng);
  EXPECT_EQ(output.resolvedBitDepth(), 16);
}

TEST(Scene, DefaultsAndTopLevelUvSet) {
  Result<Scene> scene = parseScene(
      R"({"mesh": "m.obj", "uv": 1, "layers": [{"type": "height", "image": "h.png"},
          {"type": "height", "image": "h.png", "uv": 2, "mask": "m.png"},
          {"type": "volume", "mask": "m.png"}],
          "outputs": [{"map": "mask", "file": "mask.png"}]})",
      options());
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->layers[0].uvSet, 1);
  EXPECT_EQ(scene->layers[0].weight, 1.0);
  EXPECT_EQ(scene->layers[0].filter, Filter::kBilinear);
  ASSERT_TRUE(scene->layers[1].mask.has_value());
  EXPECT_EQ(scene->layers[1].mask->uvSet, 2) << "a mask follows its layer's UV set";
  EXPECT_EQ(scene->layers[2].mask->uvSet, 1) << "... or the scene's";
  const SceneOutput& output = scene->outputs[0];
  EXPECT_EQ(output.uvSet, 1);
  EXPECT_EQ(output.width, kDefaultOutputSize);
  EXPECT_EQ(output.margin, kDefaultMargin);
  EXPECT_EQ(output.padding, PaddingMode::kExtend);
  EXPECT_EQ(output.samples, 1);
  EXPECT_EQ(output.tile, kFirstUdimTile);
  EXPECT_EQ(output.resolvedBitDepth(), 8) << "masks are 8-bit in PNG";
  EXPECT_FALSE(scene->subdivision.present);
}

TEST(Scene, ExtendedKeys) {
  Result<Scene> scene = parseScene(
      R"({"mesh": "/abs/m.obj", "_comment": "ignored",
          "layers": [{"type": "height", "image": "h.png", "tiling": [2, 3], "offset": [0.5, 0],
                      "wrap": "clamp", "weight": -0.5, "scale": 0.2, "strength": 0.25, "channel": "a",
                      "mask": {"image": "mask.png", "uv": 1, "tiling": 4, "filter": "bicubic"}},
                     {"type": "volume", "function": "noise", "seed": 42, "octaves": 3, "base": "above",
                      "frequency": 8, "gradient": "central", "_note": "comment"},
                     {"type": "planar", "image": "p.png", "axis": "x", "kind": "object-normal"},
                     {"type": "normal", "image": "os.png", "space": "object", "strength": 0.5,
                      "mask": "m2.png"},
                     {"type": "normal", "image": "ts.png", "uv": 1, "tangent_uv": 0}],
          "outputs": [{"map": "derivative", "file": "d.<UDIM>.exr", "width": 300, "height": 200,
                       "padding": "push-pull", "bit_depth": "float", "alpha": true},
                      {"map": "corners", "file": "corners.csv"},
                      {"map": "height", "file": "h.tif", "format": "tiff", "bit_depth": 32,
                       "tile": 1002}]})",
      options());
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->mesh, std::filesystem::path("/abs/m.obj"));
  const SceneLayer& height = scene->layers[0];
  EXPECT_EQ(height.tiling, (Vec2d{2, 3}));
  EXPECT_EQ(height.scale, 0.2);      // the Bump node's Distance ...
  EXPECT_EQ(height.strength, 0.25);  // ... and its Strength, apart (a normal map's is its scale)
  EXPECT_EQ(height.offset, (Vec2d{0.5, 0}));
  EXPECT_EQ(height.wrap, Wrap::kClamp);
  EXPECT_EQ(height.weight, -0.5);
  EXPECT_EQ(height.base, LayerBase::kSurface);  // the default
  EXPECT_EQ(height.channel, ImageChannels::kAlpha);
  EXPECT_EQ(scene->layers[1].base, LayerBase::kLayersAbove);
  ASSERT_TRUE(height.mask.has_value());
  EXPECT_EQ(height.mask->image, std::filesystem::path("scenes/mask.png"));
  EXPECT_EQ(height.mask->uvSet, 1);
  EXPECT_EQ(height.mask->tiling, (Vec2d{4, 4}));
  const SceneLayer& noise = scene->layers[1];
  EXPECT_EQ(noise.function, VolumeFunction::kNoise);
  EXPECT_EQ(noise.seed, 42u);
  EXPECT_EQ(noise.octaves, 3);
  EXPECT_FALSE(noise.step.has_value());
  EXPECT_EQ(scene->layers[2].axis, ProjectionAxis::kX);
  EXPECT_EQ(scene->layers[3].space, NormalSpace::kObject);
  EXPECT_EQ(scene->layers[3].scale, 0.5);
  ASSERT_TRUE(scene->layers[3].mask.has_value());
  EXPECT_EQ(scene->layers[3].mask->image, std::filesystem::path("scenes/m2.png"));
  EXPECT_FALSE(scene->layers[3].tangentUvSet.has_value());
  EXPECT_EQ(scene->layers[4].uvSet, 1);
  EXPECT_EQ(scene->layers[4].tangentUvSet, std::optional<int>(0));

  const SceneOutput& derivative = scene->outputs[0];
  EXPECT_EQ(derivative.width, 300);
  EXPECT_EQ(derivative.height, 200);
  EXPECT_EQ(derivative.padding, PaddingMode::kPushPull);
  EXPECT_EQ(derivative.resolvedBitDepth(), 32);
  EXPECT_TRUE(derivative.alpha);
  EXPECT_EQ(scene->outputs[1].kind, OutputKind::kCorners);
  EXPECT_EQ(scene->outputs[2].tile, 1002);
  EXPECT_EQ(scene->outputs[2].resolvedFormat(), ImageFormat::kTiff);
}

TEST(Scene, OutputDirectoryMovesOnlyOutputs) {
  SceneParseOptions o = options();
  o.outputDir = "elsewhere";
  Result<Scene> scene = parseScene(withOutput(R"({"map": "mask", "file": "sub/m.png"})"), o);
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->outputs[0].file, std::filesystem::path("elsewhere/sub/m.png"));
  EXPECT_EQ(scene->mesh, std::filesystem::path("scenes/m.obj"));
}

TEST(Scene, DotDotAfterALinkedDirectoryIsWhereTheSystemGoes) {
  // real/dir/s.json reached as proj/link/s.json (link → ../real/dir): "../m.obj" is
  // real/m.obj, as the system resolves it, not proj/m.obj, as the text would say.
  namespace fs = std::filesystem;
  const fs::path root =
      fs::temp_directory_path() / ("sgbake_scene_dotdot_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root / "real" / "dir");
  fs::create_directories(root / "proj");
  fs::create_directory_symlink("../real/dir", root / "proj" / "link");
  SceneParseOptions o;
  o.baseDir = root / "proj" / "link";  // the scene file's directory
  Result<Scene> scene = parseScene(
      R"({"mesh": "../m.obj", "layers": [{"type": "height", "image": "./h.png"}],
          "outputs": [{"map": "mask", "file": "../out/m.png"}]})",
      o);
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->mesh, fs::canonical(root / "real") / "m.obj");
  EXPECT_EQ(scene->outputs[0].file, fs::canonical(root / "real") / "out" / "m.png");
  EXPECT_EQ(scene->layers[0].image, root / "proj" / "link" / "h.png") << "no .., kept as given";
  fs::remove_all(root);
}

TEST(Scene, TypoedKeyNamesItsPlaceAndTheClosestKey) {
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "sise": 4})")),
            "scene.json: outputs[0]: unknown key 'sise' (did you mean 'size'?)");
  EXPECT_EQ(parseError(R"({"mehs": "m.obj", "outputs": []})"),
            "scene.json: unknown key 'mehs' (did you mean 'mesh'?)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "scael": 2})")),
            "scene.json: layers[0]: unknown key 'scael' (did you mean 'scale'?)");
  const std::string far = parseError(withOutput(R"({"map": "mask", "file": "m.png", "xyz": 1})"));
  EXPECT_NE(far.find("unknown key 'xyz' (expected map, file, size"), std::string::npos) << far;
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "height", "image": "h.png", "mask": {"image": "m.png", "uvs": 1}})")),
            "scene.json: layers[0].mask: unknown key 'uvs' (did you mean 'uv'?)");
  EXPECT_EQ(parseError(R"({"mesh": "m.obj", "subdivision": {"levle": 2}, "outputs": []})"),
            "scene.json: subdivision: unknown key 'levle' (did you mean 'level'?)");
}

TEST(Scene, KeyOfAnotherLayerTypeSaysWhereItBelongs) {
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "amplitude": 2})")),
            "scene.json: layers[0]: key 'amplitude' does not apply to a height layer (it is for "
            "volume layers)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "noise", "phase": 1})")),
            "scene.json: layers[0]: key 'phase' does not apply to a noise volume (it is for sine "
            "and blender-wave)");
  EXPECT_EQ(parseError(withOutput(R"({"map": "corners", "file": "c.csv", "size": 4})")),
            "scene.json: outputs[0]: key 'size' does not apply to a corners output (it is for "
            "image maps)");
}

TEST(Scene, SizeOutOfRange) {
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "size": 0})")),
            "scene.json: outputs[0]: size 0 is out of range 1..65536");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "size": 100000})")),
            "scene.json: outputs[0]: size 100000 is out of range 1..65536");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "width": -3})")),
            "scene.json: outputs[0]: width -3 is out of range 1..65536");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "samples": 17})")),
            "scene.json: outputs[0]: samples 17 is out of range 1..16");
  EXPECT_EQ(
      parseError(withOutput(R"({"map": "mask", "file": "m.png", "size": 18446744073709551615})")),
      "scene.json: outputs[0]: size 18446744073709551615 is out of range 1..65536");
  EXPECT_NE(parseError(withOutput(R"({"map": "mask", "file": "m.png", "size": 1e20})"))
                .find("out of range 1..65536"),
            std::string::npos);
}

TEST(Scene, UnknownMapAndNames) {
  EXPECT_EQ(parseError(withOutput(R"({"map": "tangent-normals", "file": "n.png"})")),
            "scene.json: outputs[0]: unknown map 'tangent-normals' (did you mean "
            "'tangent-normal'?)");
  const std::string far = parseError(withOutput(R"({"map": "albedo", "file": "n.png"})"));
  EXPECT_NE(far.find("unknown map 'albedo' (expected tangent-normal, object-normal"),
            std::string::npos)
      << far;
  EXPECT_NE(far.find("or corners)"), std::string::npos) << far;
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "filter": "bicubc"})")),
            "scene.json: layers[0]: unknown filter 'bicubc' (did you mean 'bicubic'?)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "hieght", "image": "h.png"})")),
            "scene.json: layers[0]: unknown type 'hieght' (did you mean 'height'?)");
}

TEST(Scene, WrongTypes) {
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "size": "big"})")),
            "scene.json: outputs[0]: 'size' must be an integer, not a string");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "size": 20.5})")),
            "scene.json: outputs[0]: 'size' must be an integer, not 20.5");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "scale": [1]})")),
            "scene.json: layers[0]: 'scale' must be a number, not an array");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": 3})")),
            "scene.json: layers[0]: 'image' must be a string, not 3");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "alpha": 1})")),
            "scene.json: outputs[0]: 'alpha' must be true or false, not 1");
  EXPECT_EQ(parseError(R"({"mesh": "m.obj", "layers": {}, "outputs": []})"),
            "scene.json: 'layers' must be an array, not an object");
  EXPECT_EQ(parseError(R"([1, 2])"), "scene.json: expected an object for the scene, not an array");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "direction": [1, 0]})")),
            "scene.json: layers[0]: 'direction' must be an array of 3 numbers, not an array");
}

/// A scene with "transform": @p transform (JSON text) and one mask output.
std::string withTransform(const std::string& transform) {
  return R"({"mesh": "m.obj", "transform": )" + transform +
         R"(, "outputs": [{"map": "mask", "file": "m.png"}]})";
}

TEST(Scene, TransformIsBlendersMatrixWorld) {
  Result<Scene> rows4 = parseScene(
      withTransform("[[2, 0, 0, 1], [0, 1, 0.5, 2], [0, 0, 0.5, 3], [0, 0, 0, 1]]"), options());
  ASSERT_TRUE(rows4.ok()) << rows4.error().message;
  ASSERT_TRUE(rows4->transform.has_value());
  const ObjectTransform& t = *rows4->transform;
  EXPECT_EQ(t.linear(0, 0), 2);
  EXPECT_EQ(t.linear(1, 2), 0.5);  // row 1, column 2: rows as Blender lists them
  EXPECT_EQ(t.linear(2, 1), 0);
  EXPECT_EQ(t.translation.x, 1);
  EXPECT_EQ(t.translation.z, 3);
  EXPECT_FALSE(t.shadesAsObjectSpace());
  Result<Scene> rows3 = parseScene(withTransform("[[1, 0, 0], [0, 1, 0], [0, 0, 1]]"), options());
  ASSERT_TRUE(rows3.ok()) << rows3.error().message;
  EXPECT_TRUE(rows3->transform->shadesAsObjectSpace());
  EXPECT_FALSE(parseScene(withOutput(R"({"map": "mask", "file": "m.png"})"), options())
                   ->transform.has_value());

  const std::string shape =
      "scene.json: 'transform' must be 4 rows of 4 numbers (Blender's matrix_world) or 3 rows "
      "of 3, not ";
  EXPECT_EQ(parseError(withTransform("[[1, 0, 0], [0, 1, 0]]")), shape + "an array of 2");
  EXPECT_EQ(parseError(withTransform("{}")), shape + "an object");
  EXPECT_EQ(parseError(withTransform("[[1, 0, 0], [0, 1, 0], [0, 0]]")),
            "scene.json: transform[2] must be a row of 3 numbers (3 rows of 3), not an array of 2");
  EXPECT_EQ(parseError(withTransform(R"([[1, 0, 0], [0, "a", 0], [0, 0, 1]])")),
            "scene.json: transform[1][1] must be a number, not a string");
  EXPECT_EQ(parseError(withTransform("[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]")),
            "scene.json: 'transform' row 3 must be [0, 0, 0, 1] (an affine transform), not "
            "[0, 0, 1, 1]");
  EXPECT_EQ(parseError(withTransform("[[1, 0, 0], [0, 0, 0], [0, 0, 1]]")),
            "scene.json: 'transform' is singular (its 3 x 3 part has determinant 0): no normal "
            "can be carried through it");
}

TEST(Scene, LayerMaterialIsAnIndexOrAName) {
  Result<Scene> index =
      parseScene(withLayer(R"({"type": "height", "image": "h.png", "material": 2})"), options());
  ASSERT_TRUE(index.ok()) << index.error().message;
  EXPECT_EQ(index->layers[0].material, 2);
  EXPECT_FALSE(index->layers[0].materialName.has_value());
  Result<Scene> name = parseScene(
      withLayer(R"({"type": "volume", "function": "noise", "material": "Skin"})"), options());
  ASSERT_TRUE(name.ok()) << name.error().message;
  EXPECT_EQ(name->layers[0].materialName, "Skin");
  EXPECT_FALSE(name->layers[0].material.has_value());
  EXPECT_FALSE(parseScene(withLayer(R"({"type": "height", "image": "h.png"})"), options())
                   ->layers[0]
                   .material.has_value());
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "material": -1})")),
            "scene.json: layers[0]: material -1 is out of range 0..32766");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "material": 1.5})")),
            "scene.json: layers[0]: 'material' must be an integer, not 1.5");
}

TEST(Scene, MissingAndEmpty) {
  EXPECT_EQ(parseError(R"({"outputs": [{"map": "mask", "file": "m.png"}]})"),
            "scene.json: missing key 'mesh' in the scene");
  EXPECT_EQ(parseError(R"({"mesh": "m.obj"})"), "scene.json: missing key 'outputs' in the scene");
  EXPECT_EQ(parseError(R"({"mesh": "m.obj", "outputs": []})"),
            "scene.json: 'outputs' is empty: nothing to bake");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask"})")),
            "scene.json: outputs[0]: missing key 'file' in an output");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height"})")),
            "scene.json: layers[0]: missing key 'image' in a height layer");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": ""})")),
            "scene.json: outputs[0]: 'file' is empty");
  // A NUL would cut the name where the system reads it: "keep.exr\0.png" writes keep.exr.
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "keep.exr\u0000.png"})")),
            "scene.json: outputs[0]: 'file' holds a NUL character, which no file name can");
  EXPECT_EQ(parseError(R"({"mesh": "m\u0000.obj", "outputs": [{"map": "mask", "file": "m.png"}]})"),
            "scene.json: 'mesh' holds a NUL character, which no file name can");
}

TEST(Scene, SyntaxErrorsAndDuplicates) {
  const std::string syntax = parseError("{\"mesh\": \"m.obj\",\n \"outputs\": [}");
  EXPECT_NE(syntax.find("invalid JSON"), std::string::npos) << syntax;
  EXPECT_NE(syntax.find("line 2"), std::string::npos) << syntax;
  EXPECT_EQ(parseError(R"({"mesh": "a.obj", "mesh": "b.obj", "outputs": []})"),
            "scene.json: duplicate key 'mesh'");
}

TEST(Scene, FormatsAndBitDepths) {
  const std::string jpg = parseError(withOutput(R"({"map": "tangent-normal", "file": "n.jpg"})"));
  EXPECT_NE(jpg.find("outputs[0]: scenes/n.jpg: unknown image format '.jpg'"), std::string::npos)
      << jpg;
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "bit_depth": 32})")),
            "scene.json: outputs[0]: bit_depth 32 is not available in PNG (8 or 16)");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.exr", "bit_depth": 8})")),
            "scene.json: outputs[0]: bit_depth 8 is not available in EXR (16 = half or 32 = "
            "float)");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "format": "jpeg"})")),
            "scene.json: outputs[0]: unknown image format 'jpeg' (use exr, png or tiff)");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "green": "directx"})")),
            "scene.json: outputs[0]: key 'green' applies only to tangent-normal maps");
}

TEST(Scene, NumbersBeyondADoubleAreInvalidJson) {
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "size": 1e400})")),
            "scene.json: invalid JSON: number overflow parsing '1e400'");
}

TEST(Scene, MayBeSameFileExpandsUdimNamesInTheCurrentDirectory) {
  // A bare file name's directory is the current one (its parent path is empty).
  EXPECT_TRUE(mayBeSameFile("h_<UDIM>.png", "h_1001.png"));
  EXPECT_TRUE(mayBeSameFile("./h_1002.png", "h_<UDIM>.png"));
  EXPECT_TRUE(mayBeSameFile("h_<UDIM>.png", "h_<UDIM>.png"));
  EXPECT_FALSE(mayBeSameFile("h_<UDIM>.png", "h_1001.exr"));
  EXPECT_FALSE(mayBeSameFile("elsewhere/h_<UDIM>.png", "h_1001.png"));
  EXPECT_FALSE(mayBeSameFile("h_<UDIM>.png", "h_999.png"));
  // Two UDIM names sharing a file under different tile numbers: tile 1100 of x<UDIM>1.png and
  // tile 1001 of x1<UDIM>.png are both x11001.png.
  EXPECT_TRUE(mayBeSameFile("x<UDIM>1.png", "x1<UDIM>.png"));
  EXPECT_FALSE(mayBeSameFile("y<UDIM>.png", "x1<UDIM>.png"));
}

TEST(Scene, MayBeSameFileFollowsLinkedUdimTiles) {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() / ("sgbake_scene_links_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "links");
  std::ofstream(dir / "h_1001.png") << "tile";
  fs::create_symlink("../h_1001.png", dir / "links" / "h_1001.png");   // a tile that is a link
  fs::create_symlink("../o_1002.png", dir / "links" / "in_1002.png");  // a link to an output
  EXPECT_TRUE(mayBeSameFile(dir / "links" / "h_<UDIM>.png", dir / "h_1001.png"));
  EXPECT_TRUE(mayBeSameFile(dir / "links" / "h_<UDIM>.png", dir / "h_<UDIM>.png"));
  EXPECT_TRUE(mayBeSameFile(dir / "o_<UDIM>.png", dir / "links" / "in_<UDIM>.png"));
  EXPECT_FALSE(mayBeSameFile(dir / "links" / "h_<UDIM>.png", dir / "o_<UDIM>.png"));
  fs::remove_all(dir);
}

TEST(Scene, OutputsThatWouldOverwriteSomethingAreRefused) {
  // Inputs, the manifest, a format contradicting the extension, a corners table in an image's
  // name, and a UDIM output whose tile another output writes.
  const std::string height = R"(, "layers": [{"type": "height", "image": "h.png",
      "mask": {"image": "mask.png"}}]})";
  const auto scene = [&](const std::string& output, const std::string& layers) {
    return R"({"mesh": "m.obj", "outputs": [)" + output + "]" + layers;
  };
  EXPECT_NE(parseError(scene(R"({"map": "mask", "file": "h.png"})", height))
                .find("outputs[0]: file 'scenes/h.png' is the image of layers[0], which the "
                      "bake reads"),
            std::string::npos);
  EXPECT_NE(parseError(scene(R"({"map": "mask", "file": "./mask.png"})", height))
                .find("is the mask of layers[0]"),
            std::string::npos);
  EXPECT_NE(parseError(scene(R"({"map": "mask", "file": "m.obj", "format": "png"})", "}"))
                .find("is the mesh"),
            std::string::npos);
  EXPECT_NE(parseError(scene(R"({"map": "mask", "file": "h.<UDIM>.png"}, {"map": "mask",
      "file": "h.1002.png"})",
                             "}"))
                .find("outputs[1]: file 'scenes/h.1002.png' is also written by outputs[0]"),
            std::string::npos);
  EXPECT_NE(parseError(withOutput(R"({"map": "mask", "file": "<UDIM>/m.png"})"))
                .find("<UDIM> goes in the file's name, not in a directory"),
            std::string::npos);
  EXPECT_NE(parseError(withOutput(R"({"map": "corners", "file": ".sgbake-manifest.json"})"))
                .find("has the name of the manifest"),
            std::string::npos);
  EXPECT_NE(parseError(withOutput(R"({"map": "corners", "file": "c.png"})"))
                .find("the corners map is a CSV table, its file must end in .csv"),
            std::string::npos);
  EXPECT_NE(parseError(withOutput(R"({"map": "corners", "file": "c_<UDIM>.csv"})"))
                .find("its file cannot hold <UDIM>"),
            std::string::npos);
  EXPECT_NE(parseError(withOutput(R"({"map": "mask", "file": "m.png", "format": "exr"})"))
                .find("format 'exr' contradicts the extension of 'scenes/m.png' (png)"),
            std::string::npos);
  // Still accepted: the format for a name without a known extension, other tiles' names.
  EXPECT_TRUE(
      parseScene(withOutput(R"({"map": "mask", "file": "m.img", "format": "png"})"), options()));
  EXPECT_TRUE(parseScene(scene(R"({"map": "mask", "file": "h.<UDIM>.png"}, {"map": "mask",
      "file": "h.999.png"})",
                               "}"),
                         options()));
}

TEST(Scene, SignedMapsTakeARangeForIntegerFiles) {
  Result<Scene> scene = parseScene(withOutput(
      R"({"map": "derivative", "file": "d.png", "range": 0.25},
         {"map": "surface-gradient", "file": "g.exr"},
         {"map": "surface-gradient", "file": "g.tif", "bit_depth": 32})"), options());
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->outputs[0].range, 0.25);
  EXPECT_TRUE(scene->outputs[0].storesSignedRange());
  EXPECT_EQ(scene->outputs[1].range, 1.0);
  EXPECT_FALSE(scene->outputs[1].storesSignedRange());  // EXR stores the values
  EXPECT_FALSE(scene->outputs[2].storesSignedRange());  // so does float TIFF
  EXPECT_EQ(parseError(withOutput(R"({"map": "height", "file": "h.png", "range": 2})")),
            "scene.json: outputs[0]: key 'range' applies only to derivative and surface-gradient "
            "maps");
  EXPECT_EQ(parseError(withOutput(R"({"map": "derivative", "file": "d.png", "range": 0})")),
            "scene.json: outputs[0]: range 0 must be greater than 0");
  Result<Scene> automatic = parseScene(
      withOutput(R"({"map": "derivative", "file": "d.png", "range": "auto"})"), options());
  ASSERT_TRUE(automatic) << automatic.error().message;
  EXPECT_TRUE(automatic->outputs[0].rangeAuto);
  EXPECT_FALSE(scene->outputs[0].rangeAuto);
  EXPECT_EQ(parseError(withOutput(R"({"map": "derivative", "file": "d.exr", "range": 2})")),
            "scene.json: outputs[0]: key 'range' applies to integer files (PNG, 8- and 16-bit "
            "TIFF); this EXR stores the values themselves");
  EXPECT_EQ(parseError(withOutput(
                R"({"map": "derivative", "file": "d.tif", "bit_depth": 32, "range": "auto"})")),
            "scene.json: outputs[0]: key 'range' applies to integer files (PNG, 8- and 16-bit "
            "TIFF); this float TIFF stores the values themselves");
  EXPECT_EQ(parseError(withOutput(R"({"map": "derivative", "file": "d.png", "range": "max"})")),
            "scene.json: outputs[0]: range \"max\" must be a positive number or \"auto\"");
  EXPECT_EQ(parseError(withOutput(R"({"map": "height", "file": "h.png", "range": "auto"})")),
            "scene.json: outputs[0]: key 'range' applies only to derivative and surface-gradient "
            "maps");
}

TEST(Scene, InvalidCombinations) {
  EXPECT_EQ(parseError(withLayer(R"({"type": "normal", "image": "n.png", "filter": "hermite"})")),
            "scene.json: layers[0]: filter 'hermite' is only available for height images (use "
            "bilinear or bicubic)");
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "normal", "image": "n.png", "space": "object", "green": "opengl"})")),
            "scene.json: layers[0]: key 'green' applies only to tangent-space normal maps");
  EXPECT_EQ(
      parseError(withLayer(
          R"({"type": "triplanar", "image": "t.png", "kind": "tangent-normal", "base": "above"})")),
      "scene.json: layers[0]: 'base': 'above' applies only to heights (a normal map has no "
      "normal to start from)");
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "normal", "image": "n.png", "space": "object", "tangent_uv": 1})")),
            "scene.json: layers[0]: key 'tangent_uv' applies only to tangent-space normal maps "
            "(normal layers, and projected ones with 'projection': 'box', 'flat', 'sphere' or "
            "'tube')");
  EXPECT_EQ(parseError(withLayer(R"({"type": "normal", "image": "n.png", "base": "above"})")),
            "scene.json: layers[0]: key 'base' does not apply to a normal layer (it is for "
            "height, volume, planar or triplanar layers)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "normal", "image": "n.png", "channel": "r"})")),
            "scene.json: layers[0]: key 'channel' does not apply to a normal layer (it is for "
            "height layers)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "base": "top"})")),
            "scene.json: layers[0]: unknown base 'top' (expected surface or above)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "noise", "frequency": 0})")),
            "scene.json: layers[0]: frequency 0 must be greater than 0");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "step": -1})")),
            "scene.json: layers[0]: step -1 must be greater than 0");
  EXPECT_EQ(parseError(R"({"mesh": "m.obj", "outputs": [{"map": "mask", "file": "m.png"},
                                                        {"map": "height", "file": "m.png"}]})"),
            "scene.json: outputs[1]: file 'scenes/m.png' is also written by outputs[0]");
  EXPECT_EQ(parseError(withOutput(R"({"map": "mask", "file": "m.png", "size": 4, "width": 4})")),
            "scene.json: outputs[0]: give either 'size' or 'width'/'height', not both");
}

TEST(Scene, SwizzleIsParsedForNormalMapsAndInTheParametersOnlyWhenNotTheDefault) {
  const NormalSwizzle expected = {{{2, true}, {0, false}, {1, true}}};
  for (const char* given : {R"("-Z+X-Y")", R"(["-z", "+x", "-y"])", R"("NEG_Z,POS_X,NEG_Y")"}) {
    SCOPED_TRACE(given);
    Result<Scene> scene = parseScene(
        withOutput(std::string(R"({"map": "object-normal", "file": "n.png", "swizzle": )") + given +
                   "}"),
        options());
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(scene->outputs[0].swizzle, expected);
    EXPECT_NE(outputParametersJson(scene->outputs[0]).find(R"("swizzle":"-Z+X-Y")"),
              std::string::npos);
  }
  Result<Scene> plain = parseScene(
      withOutput(R"({"map": "tangent-normal", "file": "n.png", "swizzle": "+x+y+z"})"), options());
  ASSERT_TRUE(plain) << plain.error().message;
  // +X+Y+Z is the default: the text (and manifest hash) of scenes without the key.
  EXPECT_EQ(outputParametersJson(plain->outputs[0]).find("swizzle"), std::string::npos);

  EXPECT_EQ(parseError(withOutput(R"({"map": "height", "file": "h.exr", "swizzle": "+X+Y+Z"})")),
            "scene.json: outputs[0]: key 'swizzle' applies only to tangent-normal and "
            "object-normal maps");
  EXPECT_EQ(parseError(withOutput(R"({"map": "tangent-normal", "file": "n.png", "green": "directx",
                                      "swizzle": "+X-Y+Z"})")),
            "scene.json: outputs[0]: give the green channel's direction either with 'green' or "
            "in 'swizzle' (its second axis: +Y OpenGL, -Y DirectX), not both");
  EXPECT_EQ(
      parseError(withOutput(R"({"map": "tangent-normal", "file": "n.png", "swizzle": "+X+Y"})")),
      "scene.json: outputs[0]: swizzle '+X+Y' has 2 axes, not three (expected three signed "
      "axes, e.g. \"+X+Y+Z\" or \"+X-Y+Z\", or Blender's POS_X, NEG_Y, ...)");
  EXPECT_EQ(parseError(withOutput(R"({"map": "tangent-normal", "file": "n.png", "swizzle": 3})")),
            "scene.json: outputs[0]: swizzle 3 must be a string such as \"+X-Y+Z\" or three "
            "strings such as [\"+X\", \"-Y\", \"+Z\"]");
}

TEST(Scene, HeightGradientIsParsedAndInTheParametersOnlyWhenNotAnalytic) {
  Result<Scene> bump = parseScene(
      withLayer(R"({"type": "height", "image": "h.png", "gradient": "bump-node"})"), options());
  ASSERT_TRUE(bump) << bump.error().message;
  EXPECT_EQ(bump->layers[0].heightGradient, HeightGradient::kBumpNode);
  EXPECT_NE(layerParametersJson(bump->layers[0]).find(R"("gradient":"bump-node")"),
            std::string::npos);
  Result<Scene> exact = parseScene(
      withLayer(R"({"type": "height", "image": "h.png", "gradient": "analytic"})"), options());
  ASSERT_TRUE(exact) << exact.error().message;
  EXPECT_EQ(exact->layers[0].heightGradient, HeightGradient::kAnalytic);
  // The default: the text (and manifest hash) of scenes without the key.
  EXPECT_EQ(layerParametersJson(exact->layers[0]).find("gradient"), std::string::npos);

  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "gradient": "central"})")),
            "scene.json: layers[0]: unknown gradient 'central' (expected analytic or bump-node)");
  // Heights read at positions take it too (a volume among its schemes).
  for (const char* layer :
       {R"({"type": "volume", "function": "sine", "gradient": "bump-node"})",
        R"({"type": "planar", "image": "h.png", "kind": "height", "gradient": "bump-node"})",
        R"({"type": "triplanar", "image": "h.png", "kind": "height", "gradient": "bump-node"})"}) {
    Result<Scene> scene = parseScene(withLayer(layer), options());
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(scene->layers[0].heightGradient, HeightGradient::kBumpNode) << layer;
    EXPECT_NE(layerParametersJson(scene->layers[0]).find(R"("gradient":"bump-node")"),
              std::string::npos)
        << layer;
  }
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "sine", "gradient": "fd"})")),
            "scene.json: layers[0]: unknown gradient 'fd' (expected analytic, central, "
            "tetrahedral or bump-node)");
  EXPECT_EQ(
      parseError(withLayer(
          R"({"type": "planar", "image": "n.png", "kind": "object-normal", "gradient": "bump-node"})")),
      "scene.json: layers[0]: key 'gradient' applies only to projected heights (kind "
      "'height')");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "normal", "image": "n.png", "gradient": "analytic"})")),
      "scene.json: layers[0]: key 'gradient' does not apply to a normal layer (it is for "
      "height, volume, planar or triplanar layers)");
}

// A Bump node's Strength on heights read at positions: volumes and projected heights take
// "strength" as height layers do (written only when not 1, so that older scenes keep their
// hashes); a projected normal map's strength is its "scale".
TEST(Scene, HeightsReadAtPositionsTakeAStrength) {
  for (const char* layer :
       {R"({"type": "volume", "function": "sine", "strength": 0.25})",
        R"({"type": "planar", "image": "h.png", "strength": 0.25})",
        R"({"type": "triplanar", "image": "h.png", "projection": "box", "strength": 0.25})"}) {
    Result<Scene> scene = parseScene(withLayer(layer), options());
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(scene->layers[0].strength, 0.25) << layer;
    EXPECT_EQ(scene->layers[0].scale, 1) << layer;
    EXPECT_NE(layerParametersJson(scene->layers[0]).find(R"("strength":0.25)"), std::string::npos)
        << layer;
  }
  Result<Scene> plain =
      parseScene(withLayer(R"({"type": "volume", "function": "sine"})"), options());
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(layerParametersJson(plain->layers[0]).find("strength"), std::string::npos);
  EXPECT_EQ(parseError(withLayer(R"({"type": "triplanar", "image": "n.png",
                                     "kind": "object-normal", "strength": 0.5})")),
            "scene.json: layers[0]: key 'strength' applies to heights (a projected normal map's "
            "strength is its 'scale')");
}

TEST(Scene, BoxProjectionIsParsedAndInTheParametersOnlyWhenChosen) {
  Result<Scene> box = parseScene(
      withLayer(
          R"({"type": "triplanar", "image": "h.png", "projection": "box", "box_blend": 0.25})"),
      options());
  ASSERT_TRUE(box) << box.error().message;
  EXPECT_EQ(box->layers[0].projection, TriplanarProjection::kBox);
  EXPECT_EQ(box->layers[0].boxBlend, 0.25);
  const std::string parameters = layerParametersJson(box->layers[0]);
  EXPECT_NE(parameters.find(R"("projection":"box")"), std::string::npos) << parameters;
  EXPECT_NE(parameters.find(R"("box_blend":0.25)"), std::string::npos) << parameters;
  EXPECT_EQ(parameters.find("sharpness"), std::string::npos) << parameters;
  Result<Scene> blended = parseScene(
      withLayer(R"({"type": "triplanar", "image": "h.png", "projection": "blended"})"), options());
  ASSERT_TRUE(blended) << blended.error().message;
  EXPECT_EQ(blended->layers[0].projection, TriplanarProjection::kBlended);
  // The default: the text (and manifest hash) of scenes without the key.
  EXPECT_EQ(layerParametersJson(blended->layers[0]).find("projection"), std::string::npos);

  EXPECT_EQ(parseError(withLayer(
                R"({"type": "triplanar", "image": "h.png", "projection": "box", "sharpness": 2})")),
            "scene.json: layers[0]: key 'sharpness' applies only to 'projection': 'blended' "
            "(Blender's Box projection blends by 'box_blend')");
  EXPECT_EQ(parseError(withLayer(R"({"type": "triplanar", "image": "h.png", "box_blend": 0.2})")),
            "scene.json: layers[0]: key 'box_blend' applies only to 'projection': 'box'");
  // A Box-projected tangent-space map decodes in a UV set's frames, "tangent_uv" else "uv".
  Result<Scene> tangent = parseScene(withLayer(R"({"type": "triplanar", "image": "n.png",
                    "projection": "box", "kind": "tangent-normal", "tangent_uv": 1})"),
                                     options());
  ASSERT_TRUE(tangent) << tangent.error().message;
  EXPECT_TRUE(tangent->layers[0].decodesInUvTangentFrames());
  EXPECT_EQ(tangent->layers[0].frameUvSet(), 1);
  EXPECT_NE(layerParametersJson(tangent->layers[0]).find(R"("tangent_uv":1)"), std::string::npos);
  EXPECT_FALSE(box->layers[0].decodesInUvTangentFrames());
  for (const char* kind :
       {R"("projection": "box", "kind": "object-normal")", R"("kind": "tangent-normal")"}) {
    EXPECT_EQ(parseError(withLayer(std::string(R"({"type": "triplanar", "image": "n.png", )") +
                                   kind + R"(, "tangent_uv": 1})")),
              "scene.json: layers[0]: key 'tangent_uv' applies only to tangent-space normal maps "
              "(normal layers, and projected ones with 'projection': 'box', 'flat', 'sphere' or "
              "'tube')")
        << kind;
  }
  EXPECT_EQ(
      parseError(withLayer(
          R"({"type": "triplanar", "image": "h.png", "projection": "box", "box_blend": 1.5})")),
      "scene.json: layers[0]: box_blend must be a number from 0 to 1 (Blender's Blend)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "triplanar", "image": "h.png", "projection": "flat"})")),
      "scene.json: layers[0]: unknown projection 'flat' (expected blended or box)");
  // A planar layer's projections: along its axis (sgbake's), or Blender's Flat, whose normal
  // kinds decode as a Normal Map node does (a tangent-space one in a UV set's frames).
  EXPECT_EQ(parseError(withLayer(R"({"type": "planar", "image": "h.png", "projection": "box"})")),
            "scene.json: layers[0]: unknown projection 'box' (expected axis, flat, sphere or "
            "tube)");
  Result<Scene> flat = parseScene(withLayer(R"({"type": "planar", "image": "n.png",
                    "projection": "flat", "kind": "tangent-normal", "tangent_uv": 1})"),
                                  options());
  ASSERT_TRUE(flat) << flat.error().message;
  EXPECT_EQ(flat->layers[0].projection, TriplanarProjection::kFlat);
  EXPECT_TRUE(flat->layers[0].projectedByBlender());
  EXPECT_TRUE(flat->layers[0].decodesInUvTangentFrames());
  EXPECT_NE(layerParametersJson(flat->layers[0]).find(R"("projection":"flat")"), std::string::npos);
  Result<Scene> axis = parseScene(
      withLayer(R"({"type": "planar", "image": "n.png", "kind": "tangent-normal"})"), options());
  ASSERT_TRUE(axis) << axis.error().message;
  EXPECT_FALSE(axis->layers[0].decodesInUvTangentFrames());
  EXPECT_EQ(layerParametersJson(axis->layers[0]).find("projection"), std::string::npos);
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "planar", "image": "h.png", "projection": "flat", "axis": "x"})")),
            "scene.json: layers[0]: 'projection': 'flat' reads the (x, y) plane, as Blender's "
            "Flat projection does: 'axis' must be z");
  // Blender's Sphere and Tube: a planar layer's single lookups wrapped around z.
  for (const auto& [name, projection] : {std::pair{"sphere", TriplanarProjection::kSphere},
                                         std::pair{"tube", TriplanarProjection::kTube}}) {
    Result<Scene> wrapped = parseScene(
        withLayer(std::string(R"({"type": "planar", "image": "h.png", "projection": ")") + name +
                  R"("})"),
        options());
    ASSERT_TRUE(wrapped) << wrapped.error().message;
    EXPECT_EQ(wrapped->layers[0].projection, projection);
    EXPECT_TRUE(wrapped->layers[0].projectedByBlender());
    EXPECT_NE(layerParametersJson(wrapped->layers[0])
                  .find(std::string(R"("projection":")") + name + "\""),
              std::string::npos);
  }
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "planar", "image": "h.png", "projection": "tube", "axis": "y"})")),
            "scene.json: layers[0]: 'projection': 'tube' wraps the image around the z axis, as "
            "Blender's Tube projection does: 'axis' must be z");
}

// "height_space": a height's scale in world units (the default, in no manifest) or in object
// units along the normal (a Displacement node in Object space); a normal map has no height.
TEST(Scene, HeightSpaceIsParsedForHeightsOnly) {
  for (const char* layer : {R"({"type": "height", "image": "h.png", "height_space": "object"})",
                            R"({"type": "volume", "height_space": "object"})",
                            R"({"type": "planar", "image": "h.png", "height_space": "object"})"}) {
    Result<Scene> scene = parseScene(withLayer(layer), options());
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_TRUE(scene->layers[0].objectSpaceHeight) << layer;
    EXPECT_NE(layerParametersJson(scene->layers[0]).find(R"("height_space":"object")"),
              std::string::npos);
  }
  Result<Scene> world = parseScene(
      withLayer(R"({"type": "height", "image": "h.png", "height_space": "world"})"), options());
  ASSERT_TRUE(world) << world.error().message;
  EXPECT_FALSE(world->layers[0].objectSpaceHeight);
  EXPECT_EQ(layerParametersJson(world->layers[0]).find("height_space"), std::string::npos);
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "planar", "image": "n.png", "kind": "object-normal",
                    "height_space": "object"})")),
            "scene.json: layers[0]: key 'height_space' applies only to heights (a normal map "
            "has no height)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "height", "image": "h.png", "height_space": "local"})")),
      "scene.json: layers[0]: unknown height_space 'local' (expected world or object)");
}

// "remap": a height read through a piecewise-linear function (levels, clamps, a Color Ramp's
// table); in the parameters (and so the manifest) only when given; heights only.
TEST(Scene, RemapIsParsedForHeightsAndInTheParametersOnlyWhenGiven) {
  for (const char* layer :
       {R"({"type": "height", "image": "h.png", "remap": [[0, 0], [0.5, 1], [0.5, 0.2]]})",
        R"({"type": "volume", "remap": [[0, 0], [0.5, 1], [0.5, 0.2]]})",
        R"({"type": "triplanar", "image": "h.png", "remap": [[0, 0], [0.5, 1], [0.5, 0.2]]})"}) {
    Result<Scene> scene = parseScene(withLayer(layer), options());
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(scene->layers[0].remap, (std::vector<Vec2d>{{0, 0}, {0.5, 1}, {0.5, 0.2}}));
    EXPECT_NE(layerParametersJson(scene->layers[0]).find(R"("remap":[[0.0,0.0],[0.5,1.0],)"),
              std::string::npos)
        << layerParametersJson(scene->layers[0]);
  }
  Result<Scene> plain = parseScene(withLayer(R"({"type": "height", "image": "h.png"})"), options());
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(layerParametersJson(plain->layers[0]).find("remap"), std::string::npos);
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "normal", "image": "n.png", "remap": [[0, 0], [1, 1]]})")),
      "scene.json: layers[0]: key 'remap' does not apply to a normal layer (it is for "
      "height, volume, planar or triplanar layers)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "planar", "image": "n.png", "kind": "object-normal",
                                     "remap": [[0, 0], [1, 1]]})")),
            "scene.json: layers[0]: key 'remap' applies only to heights (a normal map's colour is "
            "not remapped)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "height", "image": "h.png", "remap": [[1, 0], [0, 1]]})")),
      "scene.json: layers[0]: 'remap': remap point 1 has a smaller x than the point before "
      "it");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "remap": [[1, 0]]})")),
            "scene.json: layers[0]: 'remap': a remap needs 2 to 65536 points, not 1");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "remap": [0, 1]})")),
            "scene.json: layers[0]: 'remap' must be an array of [x, y] points, not an array");
}

// "function": "blender-noise": Blender's Noise Texture, Blender's defaults (Scale 5 as
// "frequency", Detail 2, Roughness 0.5, Distortion 0), a Mapping node before it as "mapping".
// "coordinates": "uv" reads a volume at (u, v, 0) of its "uv" set (the scene's by default);
// finite differences and a UV set on object coordinates are refused, and validateScene refuses
// the same built in code.
TEST(Scene, VolumesOnUvCoordinatesNameTheirUvSet) {
  Result<Scene> onUv = parseScene(
      R"({"mesh": "m.obj", "uv": 1, "layers": [{"type": "volume", "function": "blender-noise",
          "coordinates": "uv", "gradient": "bump-node"}], "outputs": [{"map": "height",
          "file": "h.exr"}]})",
      options());
  ASSERT_TRUE(onUv) << onUv.error().message;
  EXPECT_EQ(onUv->layers[0].coordinates, VolumeCoordinates::kUv);
  EXPECT_EQ(onUv->layers[0].uvSet, 1);
  EXPECT_EQ(onUv->layers[0].heightGradient, HeightGradient::kBumpNode);
  EXPECT_NE(layerParametersJson(onUv->layers[0]).find(R"("coordinates":"uv")"), std::string::npos);
  EXPECT_NE(layerParametersJson(onUv->layers[0]).find(R"("uv":1)"), std::string::npos);
  EXPECT_EQ(describeLayer(onUv->layers[0]), "volume blender-noise on UV set 1's coordinates");
  Result<Scene> onObject = parseScene(
      withLayer(R"({"type": "volume", "function": "blender-noise", "coordinates": "object"})"),
      options());
  ASSERT_TRUE(onObject) << onObject.error().message;
  EXPECT_EQ(layerParametersJson(onObject->layers[0]).find("coordinates"), std::string::npos)
      << "object coordinates keep the manifests of scenes before the key";
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-noise", "uv": 1})")),
      "scene.json: layers[0]: key 'uv' applies to a volume on 'coordinates': 'uv' (this one is "
      "read at the object's positions)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "coordinates": "uv",
                                     "gradient": "tetrahedral"})")),
            "scene.json: layers[0]: 'gradient': 'tetrahedral' applies to volumes on "
            "'coordinates': 'object' (one on UV coordinates takes its slopes 'analytic' or "
            "'bump-node')");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "coordinates": "uv", "step": 0.1})")),
            "scene.json: layers[0]: key 'step' applies to volumes on 'coordinates': 'object' "
            "(one on UV coordinates takes no finite differences)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "coordinates": "uv"})")),
            "scene.json: layers[0]: key 'coordinates' does not apply to a height layer (it is "
            "for volume layers)");

  Scene scene = *onUv;
  scene.layers[0].gradient = GradientScheme::kCentral;
  EXPECT_EQ(validationError(scene),
            "layers[0]: a volume on UV coordinates takes its slopes 'analytic' or 'bump-node' "
            "(no finite differences)");
  scene.layers[0].gradient = GradientScheme::kAnalytic;
  EXPECT_TRUE(validateScene(scene));
  scene.layers[0].type = SceneLayerType::kHeight;
  scene.layers[0].image = "h.png";
  EXPECT_EQ(validationError(scene), "layers[0]: key 'coordinates' applies only to volumes");
}

// "blender-brick" takes the Brick Texture's inputs and properties (Blender's defaults unless
// given) and writes them back; others' keys, and bricks of no width, are refused.
TEST(Scene, BlenderBrickVolumesTakeTheNodesSettings) {
  Result<Scene> brick =
      parseScene(withLayer(R"({"type": "volume", "function": "blender-brick", "mortar_size": 0.05,
                    "brick_width": 0.6, "offset_frequency": 3, "squash": 1.5})"),
                 options());
  ASSERT_TRUE(brick) << brick.error().message;
  const BlenderBrickParams& b = brick->layers[0].brick;
  EXPECT_EQ(brick->layers[0].frequency, 5);
  EXPECT_EQ(b.mortarSize, 0.05);
  EXPECT_EQ(b.mortarSmooth, 0.1);
  EXPECT_EQ(b.brickWidth, 0.6);
  EXPECT_EQ(b.rowHeight, 0.25);
  EXPECT_EQ(b.offsetFrequency, 3);
  EXPECT_EQ(b.squash, 1.5);
  EXPECT_EQ(b.squashFrequency, 2);
  const std::string parameters = layerParametersJson(brick->layers[0]);
  for (const char* expected : {R"("mortar_size":0.05)", R"("brick_width":0.6)",
                               R"("offset_frequency":3)", R"("squash":1.5)"}) {
    EXPECT_NE(parameters.find(expected), std::string::npos) << expected << " in " << parameters;
  }
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-brick", "detail": 2})")),
      "scene.json: layers[0]: key 'detail' does not apply to a blender-brick volume (it is for "
      "blender-noise, blender-musgrave and blender-wave)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-noise", "squash": 2})")),
      "scene.json: layers[0]: key 'squash' does not apply to a blender-noise volume (it is for "
      "blender-brick)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-brick", "row_height": 0})")),
      "scene.json: layers[0]: row_height 0 must be greater than 0");
  EXPECT_NE(parseError(withLayer(R"({"type": "volume", "function": "blender-voronoi",
                                     "detail": 2})"))
                .find("key 'detail' does not apply to a blender-voronoi volume"),
            std::string::npos);
}

// "blender-gradient" takes the Gradient Texture's type (no Scale: no "frequency") and writes it
// back; "blender-magic" its Depth (an integer from 0 to 10) and Distortion (1 unless given).
// Others' keys, typos and values out of range are refused, each in one line.
TEST(Scene, BlenderGradientAndMagicVolumesTakeTheNodesSettings) {
  const auto layerOf = [](const char* json) {
    Result<Scene> scene = parseScene(withLayer(json), options());
    EXPECT_TRUE(scene) << scene.error().message;
    return scene->layers[0];
  };
  const SceneLayer linear = layerOf(R"({"type": "volume", "function": "blender-gradient"})");
  EXPECT_EQ(linear.gradientType, BlenderGradientType::kLinear);
  const SceneLayer radial =
      layerOf(R"({"type": "volume", "function": "blender-gradient", "gradient_type": "radial"})");
  EXPECT_EQ(radial.gradientType, BlenderGradientType::kRadial);
  const std::string radialJson = layerParametersJson(radial);
  EXPECT_NE(radialJson.find(R"("gradient_type":"radial")"), std::string::npos) << radialJson;
  EXPECT_EQ(radialJson.find("frequency"), std::string::npos) << radialJson;
  EXPECT_EQ(layerOf(R"({"type": "volume", "function": "blender-gradient",
                        "gradient_type": "quadratic-sphere"})")
                .gradientType,
            BlenderGradientType::kQuadraticSphere);
  const SceneLayer magic = layerOf(R"({"type": "volume", "function": "blender-magic"})");
  EXPECT_EQ(magic.frequency, 5);
  EXPECT_EQ(magic.magicDepth, 2);
  EXPECT_EQ(magic.noiseDistortion, 1);
  const SceneLayer deep = layerOf(
      R"({"type": "volume", "function": "blender-magic", "depth": 10, "distortion": 2.5,
          "frequency": 1.5})");
  EXPECT_EQ(deep.magicDepth, 10);
  EXPECT_EQ(deep.noiseDistortion, 2.5);
  EXPECT_EQ(deep.frequency, 1.5);
  const std::string deepJson = layerParametersJson(deep);
  for (const char* expected : {R"("depth":10)", R"("distortion":2.5)", R"("frequency":1.5)"}) {
    EXPECT_NE(deepJson.find(expected), std::string::npos) << expected << " in " << deepJson;
  }
  // The other volumes' manifests are as they were: no new keys.
  const std::string brick =
      layerParametersJson(layerOf(R"({"type": "volume", "function": "blender-brick"})"));
  EXPECT_EQ(brick.find("depth"), std::string::npos) << brick;
  EXPECT_EQ(brick.find("gradient_type"), std::string::npos) << brick;
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-gradient",
                                     "gradient_type": "sphere"})")),
            "scene.json: layers[0]: unknown gradient_type 'sphere' (expected linear, quadratic, "
            "easing, diagonal, spherical, quadratic-sphere or radial)");
  EXPECT_EQ(
      parseError(
          withLayer(R"({"type": "volume", "function": "blender-gradient", "frequency": 2})")),
      "scene.json: layers[0]: key 'frequency' does not apply to a blender-gradient volume (it is "
      "for the other functions: the Gradient Texture has no Scale)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-gradient", "depth": 2})")),
      "scene.json: layers[0]: key 'depth' does not apply to a blender-gradient volume (it is for "
      "blender-magic)");
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "volume", "function": "blender-magic", "gradient_type": "linear"})")),
            "scene.json: layers[0]: key 'gradient_type' does not apply to a blender-magic volume "
            "(it is for blender-gradient)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-magic", "depth": 11})")),
      "scene.json: layers[0]: depth 11 is out of range 0..10");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-magic", "depth": 2.5})")),
      "scene.json: layers[0]: 'depth' must be an integer, not 2.5");  // (as any integer key)
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-magic", "detph": 2})")),
            "scene.json: layers[0]: unknown key 'detph' (did you mean 'depth'?)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-noise", "depth": 2})")),
      "scene.json: layers[0]: key 'depth' does not apply to a blender-noise volume (it is for "
      "blender-magic)");
}

TEST(Scene, BlenderNoiseVolumesTakeTheNodesSettingsAndAMapping) {
  Result<Scene> plain =
      parseScene(withLayer(R"({"type": "volume", "function": "blender-noise"})"), options());
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(plain->layers[0].function, VolumeFunction::kBlenderNoise);
  EXPECT_EQ(plain->layers[0].frequency, 5);
  EXPECT_EQ(plain->layers[0].noiseDetail, 2);
  EXPECT_EQ(plain->layers[0].noiseRoughness, 0.5);
  EXPECT_EQ(plain->layers[0].noiseDistortion, 0);
  Result<Scene> set =
      parseScene(withLayer(R"({"type": "volume", "function": "blender-noise", "frequency": -2.5,
                    "detail": 3.5, "roughness": 0.7, "distortion": 0.4,
                    "mapping": {"location": [1, 0, 0]}})"),
                 options());
  ASSERT_TRUE(set) << set.error().message;
  EXPECT_EQ(set->layers[0].frequency, -2.5);  // any Scale, as the node takes
  ASSERT_TRUE(set->layers[0].mapping);
  const std::string parameters = layerParametersJson(set->layers[0]);
  for (const char* expected : {R"("detail":3.5)", R"("roughness":0.7)", R"("distortion":0.4)",
                               R"("mapping":{"location":[1.0,0.0,0.0])"}) {
    EXPECT_NE(parameters.find(expected), std::string::npos) << expected << " in " << parameters;
  }
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "sine", "detail": 3})")),
            "scene.json: layers[0]: key 'detail' does not apply to a sine volume (it is for "
            "blender-noise, blender-musgrave and blender-wave)");
  Result<Scene> musgrave =
      parseScene(withLayer(R"({"type": "volume", "function": "blender-musgrave", "detail": 3,
                    "dimension": 1.5, "lacunarity": 2.5})"),
                 options());
  ASSERT_TRUE(musgrave) << musgrave.error().message;
  EXPECT_EQ(musgrave->layers[0].frequency, 5);
  EXPECT_EQ(musgrave->layers[0].noiseDimension, 1.5);
  EXPECT_NE(layerParametersJson(musgrave->layers[0]).find(R"("lacunarity":2.5)"),
            std::string::npos);
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "volume", "function": "blender-musgrave", "roughness": 0.5})")),
            "scene.json: layers[0]: key 'roughness' does not apply to a blender-musgrave volume "
            "(it is for blender-noise)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-noise", "lacunarity": 2})")),
      "scene.json: layers[0]: key 'lacunarity' does not apply to a blender-noise volume "
      "(it is for blender-musgrave)");
  // The Musgrave Texture's type, fbm unless given, written back only when not fbm (so that the
  // manifests of scenes before the key stay valid); Offset and Gain where the type uses them,
  // written back only there (multifractal and fBM use neither, hetero terrain no gain).
  EXPECT_EQ(musgrave->layers[0].musgraveType, MusgraveType::kFbm);
  EXPECT_EQ(layerParametersJson(musgrave->layers[0]).find("musgrave_type"), std::string::npos);
  EXPECT_EQ(layerParametersJson(musgrave->layers[0]).find(R"("offset")"), std::string::npos);
  Result<Scene> ridged = parseScene(withLayer(R"({"type": "volume", "function": "blender-musgrave",
                    "musgrave_type": "ridged-multifractal", "offset": 0.8, "gain": 2.5})"),
                                    options());
  ASSERT_TRUE(ridged) << ridged.error().message;
  EXPECT_EQ(ridged->layers[0].musgraveType, MusgraveType::kRidgedMultifractal);
  EXPECT_EQ(ridged->layers[0].musgraveOffset, 0.8);
  EXPECT_EQ(ridged->layers[0].musgraveGain, 2.5);
  const std::string ridgedJson = layerParametersJson(ridged->layers[0]);
  for (const char* expected :
       {R"("musgrave_type":"ridged-multifractal")", R"("offset":0.8)", R"("gain":2.5)"}) {
    EXPECT_NE(ridgedJson.find(expected), std::string::npos) << expected << " in " << ridgedJson;
  }
  Result<Scene> hetero = parseScene(withLayer(R"({"type": "volume", "function": "blender-musgrave",
                    "musgrave_type": "hetero-terrain", "offset": -0.5})"),
                                    options());
  ASSERT_TRUE(hetero) << hetero.error().message;
  EXPECT_EQ(hetero->layers[0].musgraveType, MusgraveType::kHeteroTerrain);
  EXPECT_EQ(hetero->layers[0].musgraveGain, 1);  // Blender's default
  EXPECT_NE(layerParametersJson(hetero->layers[0]).find(R"("offset":-0.5)"), std::string::npos);
  EXPECT_EQ(layerParametersJson(hetero->layers[0]).find(R"("gain")"), std::string::npos);
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-musgrave",
                                     "musgrave_type": "multifractal", "offset": 1})")),
            "scene.json: layers[0]: key 'offset' does not apply to a blender-musgrave volume of "
            "musgrave_type 'multifractal' (it is for ridged-multifractal, hybrid-multifractal "
            "and hetero-terrain)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-musgrave",
                                     "musgrave_type": "hetero-terrain", "gain": 2})")),
            "scene.json: layers[0]: key 'gain' does not apply to a blender-musgrave volume of "
            "musgrave_type 'hetero-terrain' (it is for ridged-multifractal and "
            "hybrid-multifractal)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-musgrave", "gain": 2})")),
      "scene.json: layers[0]: key 'gain' does not apply to a blender-musgrave volume of "
      "musgrave_type 'fbm' (it is for ridged-multifractal and hybrid-multifractal)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-musgrave",
                                     "musgrave_type": "ridged"})")),
            "scene.json: layers[0]: unknown musgrave_type 'ridged' (expected fbm, multifractal, "
            "ridged-multifractal, hybrid-multifractal or hetero-terrain)");
  EXPECT_EQ(
      parseError(withLayer(R"({"type": "volume", "function": "blender-noise", "offset": 1})")),
      "scene.json: layers[0]: key 'offset' does not apply to a blender-noise volume "
      "(it is for blender-musgrave)");
  Result<Scene> wave =
      parseScene(withLayer(R"({"type": "volume", "function": "blender-wave", "wave": "rings",
                    "wave_direction": "spherical", "profile": "saw", "phase": 0.5,
                    "distortion": 2, "detail_scale": 3, "detail_roughness": 0.2})"),
                 options());
  ASSERT_TRUE(wave) << wave.error().message;
  EXPECT_EQ(wave->layers[0].waveType, WaveType::kRings);
  EXPECT_EQ(wave->layers[0].waveDirection, WaveDirection::kSpherical);
  EXPECT_EQ(wave->layers[0].waveProfile, WaveProfile::kSaw);
  EXPECT_NE(layerParametersJson(wave->layers[0]).find(R"("detail_scale":3.0)"), std::string::npos);
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-wave",
                                     "wave_direction": "spherical"})")),
            "scene.json: layers[0]: 'wave_direction': 'spherical' applies to 'wave': 'rings' "
            "only");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-wave",
                                     "wave": "rings", "wave_direction": "diagonal"})")),
            "scene.json: layers[0]: 'wave_direction': 'diagonal' applies to 'wave': 'bands' "
            "only");
  Result<Scene> voronoi =
      parseScene(withLayer(R"({"type": "volume", "function": "blender-voronoi", "randomness": 0.7,
                    "metric": "minkowski", "exponent": 1.5})"),
                 options());
  ASSERT_TRUE(voronoi) << voronoi.error().message;
  EXPECT_EQ(voronoi->layers[0].voronoiMetric, VoronoiMetric::kMinkowski);
  EXPECT_NE(layerParametersJson(voronoi->layers[0]).find(R"("metric":"minkowski")"),
            std::string::npos);
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-voronoi",
                                     "metric": "cosine"})")),
            "scene.json: layers[0]: unknown metric 'cosine' (expected euclidean, manhattan, "
            "chebyshev or minkowski)");
  // The Voronoi Texture's Feature Output, f1 unless given, written back only when not f1 (so that
  // the manifests of scenes before the key stay valid); Smoothness for smooth-f1 only.
  EXPECT_EQ(voronoi->layers[0].voronoiFeature, VoronoiFeature::kF1);
  EXPECT_EQ(layerParametersJson(voronoi->layers[0]).find("feature"), std::string::npos);
  EXPECT_EQ(layerParametersJson(voronoi->layers[0]).find("smoothness"), std::string::npos);
  Result<Scene> smooth = parseScene(withLayer(R"({"type": "volume", "function": "blender-voronoi",
                    "feature": "smooth-f1", "smoothness": 0.25})"),
                                    options());
  ASSERT_TRUE(smooth) << smooth.error().message;
  EXPECT_EQ(smooth->layers[0].voronoiFeature, VoronoiFeature::kSmoothF1);
  EXPECT_EQ(smooth->layers[0].voronoiSmoothness, 0.25);
  const std::string smoothJson = layerParametersJson(smooth->layers[0]);
  for (const char* expected : {R"("feature":"smooth-f1")", R"("smoothness":0.25)"}) {
    EXPECT_NE(smoothJson.find(expected), std::string::npos) << expected << " in " << smoothJson;
  }
  Result<Scene> edge = parseScene(withLayer(R"({"type": "volume", "function": "blender-voronoi",
                    "feature": "distance-to-edge", "metric": "manhattan"})"),
                                  options());
  ASSERT_TRUE(edge) << edge.error().message;  // the metric accepted, and ignored
  EXPECT_EQ(edge->layers[0].voronoiFeature, VoronoiFeature::kDistanceToEdge);
  const std::string edgeJson = layerParametersJson(edge->layers[0]);
  EXPECT_NE(edgeJson.find(R"("feature":"distance-to-edge")"), std::string::npos) << edgeJson;
  EXPECT_EQ(edgeJson.find("smoothness"), std::string::npos) << edgeJson;
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-voronoi",
                                     "feature": "f2", "smoothness": 0.5})")),
            "scene.json: layers[0]: key 'smoothness' does not apply to a blender-voronoi volume "
            "of feature 'f2' (it is for smooth-f1)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-voronoi",
                                     "smoothness": 0.5})")),
            "scene.json: layers[0]: key 'smoothness' does not apply to a blender-voronoi volume "
            "of feature 'f1' (it is for smooth-f1)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-voronoi",
                                     "feature": "radius"})")),
            "scene.json: layers[0]: unknown feature 'radius' (expected f1, f2, smooth-f1 or "
            "distance-to-edge)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-noise",
                                     "feature": "f2"})")),
            "scene.json: layers[0]: key 'feature' does not apply to a blender-noise volume (it "
            "is for blender-voronoi)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-noise",
                                     "profile": "saw"})")),
            "scene.json: layers[0]: key 'profile' does not apply to a blender-noise volume (it "
            "is for blender-wave)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-noise", "seed": 3})")),
            "scene.json: layers[0]: key 'seed' does not apply to a blender-noise volume (it is "
            "for noise)");
}

// The Noise and Musgrave Textures' Dimensions ("1D" … "4D", 3D unless given) and W (read in 1D
// and 4D only); both are written into the parameters only when not 3D, so the manifests of
// scenes before them stay valid.
TEST(Scene, NoiseAndMusgraveDimensionsAndW) {
  Result<Scene> noise = parseScene(
      withLayer(R"({"type": "volume", "function": "blender-noise", "dimensions": "4D", "w": 0.3})"),
      options());
  ASSERT_TRUE(noise) << noise.error().message;
  EXPECT_EQ(noise->layers[0].textureDimensions, 4);
  EXPECT_EQ(noise->layers[0].textureW, 0.3);
  const std::string noiseJson = layerParametersJson(noise->layers[0]);
  for (const char* expected : {R"("dimensions":"4D")", R"("w":0.3)"}) {
    EXPECT_NE(noiseJson.find(expected), std::string::npos) << expected << " in " << noiseJson;
  }
  Result<Scene> flat = parseScene(
      withLayer(R"({"type": "volume", "function": "blender-musgrave", "dimensions": "2D"})"),
      options());
  ASSERT_TRUE(flat) << flat.error().message;
  EXPECT_EQ(flat->layers[0].textureDimensions, 2);
  EXPECT_NE(layerParametersJson(flat->layers[0]).find(R"("dimensions":"2D")"), std::string::npos);
  EXPECT_EQ(layerParametersJson(flat->layers[0]).find(R"("w")"), std::string::npos);
  Result<Scene> plain =
      parseScene(withLayer(R"({"type": "volume", "function": "blender-noise"})"), options());
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(plain->layers[0].textureDimensions, 3);
  EXPECT_EQ(layerParametersJson(plain->layers[0]).find("dimensions"), std::string::npos);
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "volume", "function": "blender-noise", "dimensions": "4d"})")),
            "scene.json: layers[0]: unknown dimensions '4d' (did you mean '4D'?)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "volume", "function": "blender-noise", "w": 1})")),
            "scene.json: layers[0]: key 'w' does not apply to a 3D blender-noise volume (W is read "
            "by blender-noise and blender-musgrave of dimensions 1D and 4D)");
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "volume", "function": "blender-wave", "dimensions": "2D"})")),
            "scene.json: layers[0]: key 'dimensions' does not apply to a blender-wave volume (it "
            "is for blender-noise and blender-musgrave)");
}

TEST(Scene, ProjectionMappingIsParsedAndInTheParametersOnlyWhenGiven) {
  Result<Scene> mapped = parseScene(withLayer(R"({"type": "planar", "image": "h.png",
                    "mapping": {"location": [1, 2, 3], "rotation": [0, 0.5, 0]}})"),
                                    options());
  ASSERT_TRUE(mapped) << mapped.error().message;
  ASSERT_TRUE(mapped->layers[0].mapping);
  EXPECT_EQ(mapped->layers[0].mapping->location, (Vec3d{1, 2, 3}));
  EXPECT_EQ(mapped->layers[0].mapping->rotation, (Vec3d{0, 0.5, 0}));
  EXPECT_EQ(mapped->layers[0].mapping->scale, (Vec3d{1, 1, 1}));
  EXPECT_NE(layerParametersJson(mapped->layers[0]).find(R"("mapping":)"), std::string::npos);
  Result<Scene> plain =
      parseScene(withLayer(R"({"type": "triplanar", "image": "h.png"})"), options());
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_FALSE(plain->layers[0].mapping);
  EXPECT_EQ(layerParametersJson(plain->layers[0]).find("mapping"), std::string::npos);

  EXPECT_EQ(parseError(withLayer(
                R"({"type": "triplanar", "image": "h.png", "mapping": {"rotate": [0, 0, 1]}})")),
            "scene.json: layers[0].mapping: unknown key 'rotate' (expected type, location, "
            "rotation, scale or matrix)");
  // The Mapping node's type: Point unless given, and written only when it is not.
  EXPECT_EQ(mapped->layers[0].mapping->type, MappingType::kPoint);
  EXPECT_EQ(layerParametersJson(mapped->layers[0]).find(R"("type":"point")"), std::string::npos);
  Result<Scene> texture = parseScene(withLayer(R"({"type": "planar", "image": "h.png",
                    "mapping": {"type": "texture", "location": [1, 2, 3]}})"),
                                     options());
  ASSERT_TRUE(texture) << texture.error().message;
  EXPECT_EQ(texture->layers[0].mapping->type, MappingType::kTexture);
  EXPECT_NE(layerParametersJson(texture->layers[0]).find(R"("type":"texture")"), std::string::npos);
  EXPECT_EQ(parseError(withLayer(
                R"({"type": "planar", "image": "h.png", "mapping": {"type": "normal"}})")),
            "scene.json: layers[0].mapping: unknown type 'normal' (expected point, texture or "
            "vector)");
  EXPECT_EQ(parseError(
                withLayer(R"({"type": "planar", "image": "h.png", "mapping": {"scale": [1, 2]}})")),
            "scene.json: layers[0].mapping: 'scale' must be an array of 3 numbers, not an array");
  Result<Scene> matrix = parseScene(withLayer(R"({"type": "triplanar", "image": "h.png",
                    "mapping": {"matrix": [[0, 1, 0, 5], [2, 0, 0, 6], [0, 0, 3, 7]]}})"),
                                    options());
  ASSERT_TRUE(matrix) << matrix.error().message;
  ASSERT_TRUE(matrix->layers[0].mapping->matrix);
  EXPECT_EQ((*matrix->layers[0].mapping->matrix)(1, 0), 2);  // row 1, column 0
  EXPECT_EQ((*matrix->layers[0].mapping->matrix)(0, 1), 1);
  EXPECT_EQ(matrix->layers[0].mapping->matrixTranslation, (Vec3d{5, 6, 7}));
  EXPECT_NE(layerParametersJson(matrix->layers[0]).find(R"("matrix":[[0.0,1.0,0.0,5.0])"),
            std::string::npos)
      << layerParametersJson(matrix->layers[0]);
  EXPECT_EQ(parseError(withLayer(R"({"type": "planar", "image": "h.png",
                                     "mapping": {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0]]}})")),
            "scene.json: layers[0].mapping: matrix must be 3 rows of 4 numbers (or 4, the last "
            "[0, 0, 0, 1])");
  EXPECT_EQ(parseError(withLayer(R"({"type": "planar", "image": "h.png", "mapping": {"matrix":
                [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]}})")),
            "scene.json: layers[0].mapping: matrix row 3 must be [0, 0, 0, 1] (an affine map)");
  EXPECT_EQ(parseError(withLayer(R"({"type": "height", "image": "h.png", "mapping": {}})")),
            "scene.json: layers[0]: key 'mapping' does not apply to a height layer (it is for "
            "volume, planar or triplanar layers)");
}

TEST(Scene, SubdivisionIsParsedAndValidated) {
  Result<Scene> scene = parseScene(
      R"({"mesh": "m.obj", "subdivision": {"level": 2, "uv_smooth": "keep-corners",
          "boundary": "keep-corners"}, "outputs": [{"map": "mask", "file": "m.png"}]})",
      options());
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->subdivision.level, 2);
  EXPECT_FALSE(scene->subdivision.limit);
  EXPECT_EQ(scene->subdivision.uvSmooth, SubdivisionUvSmooth::kKeepCorners);
  EXPECT_EQ(scene->subdivision.boundary, SubdivisionBoundary::kKeepCorners);
  EXPECT_EQ(parseError(R"({"mesh": "m.obj", "subdivision": {"uv_smooth": "keep"},
                            "outputs": [{"map": "mask", "file": "m.png"}]})"),
            "scene.json: subdivision: unknown uv_smooth 'keep' (expected none, keep-corners, "
            "keep-corners-junctions, keep-corners-junctions-concave, keep-boundaries or all)");
  EXPECT_EQ(parseError(R"({"mesh": "m.obj", "subdivision": {"level": "max"},
                            "outputs": [{"map": "mask", "file": "m.png"}]})"),
            "scene.json: subdivision: level 'max' must be \"limit\" or a number");
  Result<Scene> none = parseScene(
      R"({"mesh": "m.obj", "subdivision": {"level": 0}, "outputs": [{"map": "mask", "file": "m.png"}]})",
      options());
  ASSERT_TRUE(none);
  EXPECT_FALSE(none->subdivision.requested());
}

TEST(Scene, CreasesAreParsedAndValidated) {
  Result<Scene> scene = parseScene(withSubdivision(R"({"level": 2, "use_creases": false,
                          "edge_creases": [[0, 1, 0.5], [3, 2, 1], [4, 5, 0]],
                          "vertex_creases": [[7, 0.25]]})"),
                                   options());
  ASSERT_TRUE(scene) << scene.error().message;
  const SubdivisionOptions parsed = scene->subdivision.options();
  EXPECT_FALSE(parsed.useCreases);
  ASSERT_EQ(parsed.edgeCreases.size(), 3u);
  EXPECT_EQ(parsed.edgeCreases[1].v0, 3u);
  EXPECT_EQ(parsed.edgeCreases[1].v1, 2u);
  EXPECT_EQ(parsed.edgeCreases[1].crease, 1.0f);
  EXPECT_EQ(parsed.edgeCreases[0].crease, 0.5f);
  ASSERT_EQ(parsed.vertexCreases.size(), 1u);
  EXPECT_EQ(parsed.vertexCreases[0].vertex, 7u);
  EXPECT_EQ(parsed.vertexCreases[0].crease, 0.25f);
  Result<Scene> defaults = parseScene(withSubdivision(R"({"level": 1})"), options());
  ASSERT_TRUE(defaults);
  EXPECT_TRUE(defaults->subdivision.useCreases);
  EXPECT_TRUE(defaults->subdivision.edgeCreases.empty());

  EXPECT_EQ(parseError(withSubdivision(R"({"use_creases": 1})")),
            "scene.json: subdivision: 'use_creases' must be true or false, not 1");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": {"0": 1}})")),
            "scene.json: subdivision: 'edge_creases' must be an array, not an object");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[0, 1]]})")),
            "scene.json: subdivision.edge_creases[0]: expected [a, b, c] (two vertex indices and a "
            "crease in [0, 1]), not an array of 2");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[0, 1, 1], 5]})")),
            "scene.json: subdivision.edge_creases[1]: expected [a, b, c] (two vertex indices and a "
            "crease in [0, 1]), not 5");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[0, -1, 0.5]]})")),
            "scene.json: subdivision.edge_creases[0]: vertex -1 is out of range (vertices are "
            "numbered from 0)");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[0, 1.5, 0.5]]})")),
            "scene.json: subdivision.edge_creases[0]: a vertex must be an integer, not 1.5");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [["0", 1, 0.5]]})")),
            "scene.json: subdivision.edge_creases[0]: a vertex must be an integer, not a string");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[0, 1, 1.5]]})")),
            "scene.json: subdivision.edge_creases[0]: crease 1.5 is out of range 0..1");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[0, 1, -0.1]]})")),
            "scene.json: subdivision.edge_creases[0]: crease -0.1 is out of range 0..1");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[0, 1, null]]})")),
            "scene.json: subdivision.edge_creases[0]: a crease must be a number, not a null");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[2, 2, 0.5]]})")),
            "scene.json: subdivision.edge_creases[0]: an edge joins two different vertices, not "
            "2 and itself");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_creases": [[0, 1, 0.5], [2, 3, 1], [1, 0, 1]]})")),
            "scene.json: subdivision.edge_creases[2]: the edge 0-1 is already creased by "
            "edge_creases[0]");
  EXPECT_EQ(parseError(withSubdivision(R"({"vertex_creases": [[0, 0.5, 1]]})")),
            "scene.json: subdivision.vertex_creases[0]: expected [v, c] (a vertex index and a "
            "crease in [0, 1]), not an array of 3");
  EXPECT_EQ(parseError(withSubdivision(R"({"vertex_creases": [[0, 2]]})")),
            "scene.json: subdivision.vertex_creases[0]: crease 2 is out of range 0..1");
  EXPECT_EQ(parseError(withSubdivision(R"({"vertex_creases": [[4, 1], [4, 0.5]]})")),
            "scene.json: subdivision.vertex_creases[1]: vertex 4 is already creased by "
            "vertex_creases[0]");
  EXPECT_EQ(parseError(withSubdivision(R"({"edge_crease": []})")),
            "scene.json: subdivision: unknown key 'edge_crease' (did you mean 'edge_creases'?)");
}

TEST(Scene, CreasesAreInTheSubdivisionParametersOnlyWhenThereAreAny) {
  SceneSubdivision subdivision;
  subdivision.present = true;
  subdivision.level = 2;
  const std::string plain = subdivisionParametersJson(subdivision);
  EXPECT_EQ(plain.find("crease"), std::string::npos) << plain;
  subdivision.useCreases = false;
  EXPECT_EQ(subdivisionParametersJson(subdivision), plain) << "no creases: nothing to turn off";
  subdivision.edgeCreases = {{0, 1, 0.5f}};
  const std::string off = subdivisionParametersJson(subdivision);
  subdivision.useCreases = true;
  const std::string half = subdivisionParametersJson(subdivision);
  subdivision.edgeCreases[0].crease = 0.75f;
  const std::string more = subdivisionParametersJson(subdivision);
  subdivision.edgeCreases.clear();
  subdivision.vertexCreases = {{1, 0.5f}};
  const std::string vertex = subdivisionParametersJson(subdivision);
  const std::set<std::string> distinct{plain, off, half, more, vertex};
  EXPECT_EQ(distinct.size(), 5u) << "every crease change changes the text (and manifest hash)";
  EXPECT_NE(half.find("\"edge_creases\":[[0,1,0.5]]"), std::string::npos) << half;
  EXPECT_NE(describeSubdivision(subdivision).find("0 edge and 1 vertex crease(s)"),
            std::string::npos)
      << describeSubdivision(subdivision);
}

TEST(Scene, QualityIsParsedAndInTheParametersOnlyWhenNotTheDefault) {
  Result<Scene> scene = parseScene(withSubdivision(R"({"level": 2, "quality": 5})"), options());
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->subdivision.options().quality, 5);
  EXPECT_NE(describeSubdivision(scene->subdivision).find("quality 5"), std::string::npos);
  const std::string five = subdivisionParametersJson(scene->subdivision);
  EXPECT_NE(five.find("\"quality\":5"), std::string::npos) << five;
  scene->subdivision.quality = 3;  // the default: the text (and manifest hash) of old scenes
  EXPECT_EQ(subdivisionParametersJson(scene->subdivision).find("quality"), std::string::npos);
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 2, "quality": 0})")),
            "scene.json: subdivision: quality 0 is out of range 1..10");
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 2, "quality": 11})")),
            "scene.json: subdivision: quality 11 is out of range 1..10");
}

TEST(Scene, UseLimitSurfaceIsParsedAndInTheParametersOnlyWhenOff) {
  Result<Scene> scene =
      parseScene(withSubdivision(R"({"level": 2, "use_limit_surface": false})"), options());
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_FALSE(scene->subdivision.options().useLimitSurface);
  EXPECT_NE(describeSubdivision(scene->subdivision).find("without the limit surface"),
            std::string::npos);
  const std::string off = subdivisionParametersJson(scene->subdivision);
  EXPECT_NE(off.find("\"use_limit_surface\":false"), std::string::npos) << off;
  scene->subdivision.useLimitSurface = true;  // the default: the text of older scenes
  EXPECT_EQ(subdivisionParametersJson(scene->subdivision).find("use_limit_surface"),
            std::string::npos);
  EXPECT_EQ(parseError(withSubdivision(R"({"level": "limit", "use_limit_surface": false})")),
            "scene.json: subdivision: \"level\": \"limit\" shades the limit surface itself; "
            "it cannot be combined with \"use_limit_surface\": false");
  EXPECT_TRUE(parseScene(withSubdivision(R"({"level": "limit", "use_limit_surface": true})"),
                         options()));
}

TEST(Scene, SubdivisionTypeIsParsedAndInTheParametersOnlyWhenSimple) {
  Result<Scene> scene = parseScene(withSubdivision(R"({"level": 2, "type": "simple"})"), options());
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->subdivision.options().type, SubdivisionType::kSimple);
  EXPECT_NE(describeSubdivision(scene->subdivision).find("simple"), std::string::npos);
  const std::string simple = subdivisionParametersJson(scene->subdivision);
  EXPECT_NE(simple.find("\"type\":\"simple\""), std::string::npos) << simple;
  scene->subdivision.type = SubdivisionType::kCatmullClark;  // the default: older scenes' text
  EXPECT_EQ(subdivisionParametersJson(scene->subdivision).find("type"), std::string::npos);
  EXPECT_NE(parseError(withSubdivision(R"({"level": 2, "type": "smooth"})")).find("smooth"),
            std::string::npos);
  EXPECT_EQ(parseError(withSubdivision(R"({"level": "limit", "type": "simple"})")),
            "scene.json: subdivision: \"level\": \"limit\" is the Catmull-Clark limit "
            "surface; it cannot be combined with \"type\": \"simple\"");
}

TEST(Scene, AutoSmoothIsParsedInDegreesAndInTheParametersOnlyWhenSet) {
  Result<Scene> scene =
      parseScene(withSubdivision(R"({"level": 1, "auto_smooth": 30})"), options());
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_TRUE(scene->subdivision.options().autoSmoothDegrees.has_value());
  EXPECT_EQ(*scene->subdivision.options().autoSmoothDegrees, 30.0);
  EXPECT_NE(describeSubdivision(scene->subdivision).find("auto smooth 30 deg"), std::string::npos);
  const std::string set = subdivisionParametersJson(scene->subdivision);
  EXPECT_NE(set.find("\"auto_smooth\":30"), std::string::npos) << set;
  scene->subdivision.autoSmoothDegrees.reset();  // off: older scenes' text
  EXPECT_EQ(subdivisionParametersJson(scene->subdivision).find("auto_smooth"), std::string::npos);
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 1, "auto_smooth": 181})")),
            "scene.json: subdivision: auto_smooth 181 must be at most 180 (degrees)");
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 1, "auto_smooth": -1})")),
            "scene.json: subdivision: auto_smooth -1 must be at least 0");
  Result<Scene> sharp = parseScene(
      withSubdivision(R"({"level": 1, "auto_smooth": 30, "sharp_edges": [[0, 1], [2, 1]]})"),
      options());
  ASSERT_TRUE(sharp) << sharp.error().message;
  ASSERT_EQ(sharp->subdivision.sharpEdges.size(), 2u);
  EXPECT_EQ(sharp->subdivision.sharpEdges[1].v0, 2u);
  EXPECT_NE(subdivisionParametersJson(sharp->subdivision).find("\"sharp_edges\":[[0,1],[2,1]]"),
            std::string::npos);
  EXPECT_NE(describeSubdivision(sharp->subdivision).find("2 sharp edge(s)"), std::string::npos);
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 1, "sharp_edges": [[0, 1, 2]]})")),
            "scene.json: subdivision.sharp_edges[0]: expected [a, b] (two vertex indices), not "
            "an array of 3");
  EXPECT_EQ(parseError(withSubdivision(R"({"level": "limit", "auto_smooth": 30})")),
            "scene.json: subdivision: \"level\": \"limit\" shades the exact surface's own "
            "normals; it cannot be combined with \"auto_smooth\"");
}

TEST(Scene, SettingsThatDoNothingWithoutSubdivisionAreRefused) {
  // As the command line refuses --edge-crease or --sharp-edge without --subdivide (Blender
  // accepts them at level 0 and changes nothing).
  const std::string where = "scene.json: subdivision: ";
  const std::string fix =
      " applies to a subdivided mesh; set \"level\" to 1 or more (at "
      "\"level\": 0 nothing is subdivided)";
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 0, "edge_creases": [[0, 1, 0.5]]})")),
            where + "\"edge_creases\"" + fix);
  EXPECT_EQ(parseError(withSubdivision(R"({"vertex_creases": [[0, 1]]})")),  // level 0 unsaid
            where + "\"vertex_creases\"" + fix);
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 0, "use_limit_surface": false})")),
            where + "\"use_limit_surface\": false" + fix);
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 0, "type": "simple"})")),
            where + "\"type\": \"simple\"" + fix);
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 0, "sharp_edges": [[0, 1]]})")),
            where +
                "\"sharp_edges\" need \"auto_smooth\" (edges marked sharp split the normals "
                "only with Auto Smooth)");
  // Nor at a level: without Auto Smooth marks split nothing, as in Blender.
  EXPECT_EQ(parseError(withSubdivision(R"({"level": 2, "sharp_edges": [[0, 1]]})")),
            where +
                "\"sharp_edges\" need \"auto_smooth\" (edges marked sharp split the normals "
                "only with Auto Smooth)");
  // The exact limit surface shades its own normals; Quality shapes the approximation of
  // Use Limit Surface only.
  EXPECT_EQ(parseError(withSubdivision(R"({"level": "limit", "sharp_edges": [[0, 1]]})")),
            where +
                "\"level\": \"limit\" shades the exact surface's own normals; it cannot be "
                "combined with \"sharp_edges\"");
  EXPECT_EQ(parseError(withSubdivision(R"({"level": "limit", "quality": 4})")),
            where +
                "\"quality\" applies with Use Limit Surface, not with \"level\": \"limit\" "
                "(the exact surface)");
  EXPECT_EQ(
      parseError(withSubdivision(R"({"level": 2, "use_limit_surface": false, "quality": 4})")),
      where +
          "\"quality\" applies with Use Limit Surface, not with "
          "\"use_limit_surface\": false");
  // What does something at level 0 stays accepted: Auto Smooth, with or without sharp edges,
  // and the settings whose defaults cannot be told from their absence.
  for (const char* accepted :
       {R"({"level": 0, "auto_smooth": 30, "sharp_edges": [[0, 1]]})",
        R"({"level": 0, "auto_smooth": 30})", R"({"level": 0, "use_creases": false})",
        R"({"level": 0, "type": "catmull-clark", "use_limit_surface": true, "quality": 4})"}) {
    Result<Scene> scene = parseScene(withSubdivision(accepted), options());
    EXPECT_TRUE(scene) << accepted << ": " << scene.error().message;
  }
  // A subdivided mesh takes every one of them.
  EXPECT_TRUE(parseScene(withSubdivision(R"({"level": 1, "edge_creases": [[0, 1, 0.5]],
      "vertex_creases": [[0, 1]], "sharp_edges": [[0, 1]], "auto_smooth": 30,
      "use_limit_surface": false, "type": "simple"})"),
                         options()));
}

TEST(Scene, SubdivisionOfOptionsIsTheInverseOfOptions) {
  // Every field away from its default, so that a field one side forgets shows.
  SubdivisionOptions o;
  o.level = 4;
  o.uvSmooth = SubdivisionUvSmooth::kAll;
  o.boundary = SubdivisionBoundary::kKeepCorners;
  o.useCreases = false;
  o.edgeCreases = {{1, 2, 0.5f}};
  o.vertexCreases = {{3, 0.25f}};
  o.quality = 7;
  o.useLimitSurface = false;
  o.type = SubdivisionType::kSimple;
  o.autoSmoothDegrees = 42.5;
  o.sharpEdges = {{7, 8}};
  const SceneSubdivision block = SceneSubdivision::of(o, false);
  EXPECT_TRUE(block.requested());
  EXPECT_FALSE(block.limitSurface());
  const SubdivisionOptions back = block.options();
  EXPECT_EQ(back.level, o.level);
  EXPECT_EQ(back.uvSmooth, o.uvSmooth);
  EXPECT_EQ(back.boundary, o.boundary);
  EXPECT_EQ(back.useCreases, o.useCreases);
  ASSERT_EQ(back.edgeCreases.size(), 1u);
  EXPECT_EQ(back.edgeCreases[0].v1, 2u);
  ASSERT_EQ(back.vertexCreases.size(), 1u);
  EXPECT_EQ(back.vertexCreases[0].crease, 0.25f);
  EXPECT_EQ(back.quality, o.quality);
  EXPECT_EQ(back.useLimitSurface, o.useLimitSurface);
  EXPECT_EQ(back.type, o.type);
  EXPECT_EQ(back.autoSmoothDegrees, o.autoSmoothDegrees);
  ASSERT_EQ(back.sharpEdges.size(), 1u);
  EXPECT_EQ(back.sharpEdges[0].v1, 8u);
  EXPECT_TRUE(SceneSubdivision::of({0}, true).limitSurface());
  EXPECT_FALSE(SceneSubdivision::of({0}, false).requested());
}

TEST(Scene, ValidateSceneChecksScenesBuiltInCode) {
  Scene scene;
  scene.mesh = "m.obj";
  SceneOutput output;
  output.file = "n.png";
  output.width = output.height = 0;
  scene.outputs.push_back(output);
  EXPECT_EQ(validationError(scene), "outputs[0]: size 0 is out of range 1..65536");
  scene.outputs[0].width = scene.outputs[0].height = 64;
  EXPECT_TRUE(validateScene(scene));
  SceneLayer layer;
  layer.image = "h.png";
  layer.weight = std::numeric_limits<double>::infinity();
  scene.layers.push_back(layer);
  EXPECT_EQ(validationError(scene), "layers[0]: weight must be a finite number");
  // Tangent frames named for a layer that decodes in none, built in code as in a scene file,
  // are refused.
  scene.layers[0].weight = 1;
  scene.layers[0].type = SceneLayerType::kTriplanar;
  scene.layers[0].kind = ProjectedKind::kObjectNormal;
  scene.layers[0].projection = TriplanarProjection::kBox;
  scene.layers[0].tangentUvSet = 0;
  EXPECT_EQ(validationError(scene),
            "layers[0]: key 'tangent_uv' applies only to tangent-space normal maps (normal "
            "layers, and projected ones with 'projection': 'box', 'flat', 'sphere' or 'tube')");
  scene.layers[0].kind = ProjectedKind::kTangentNormal;
  EXPECT_TRUE(validateScene(scene));
  // A remap built in code: on a normal map, or not a function, is refused as in a scene file.
  scene.layers[0].remap = {{0, 0}, {1, 1}};
  EXPECT_EQ(validationError(scene), "layers[0]: key 'remap' applies only to heights");
  scene.layers[0].kind = ProjectedKind::kHeight;
  scene.layers[0].tangentUvSet.reset();
  EXPECT_TRUE(validateScene(scene));
  scene.layers[0].remap = {{1, 0}, {0, 1}};
  EXPECT_EQ(validationError(scene),
            "layers[0]: 'remap': remap point 1 has a smaller x than the point before it");
}

TEST(Scene, PaddingModesAreParsedByTheirSceneNames) {
  EXPECT_EQ(*parsePaddingMode("extend"), PaddingMode::kExtend);
  EXPECT_EQ(*parsePaddingMode("push-pull"), PaddingMode::kPushPull);
  EXPECT_EQ(*parsePaddingMode("adjacent-faces"), PaddingMode::kAdjacentFaces);
  const Result<PaddingMode> bad = parsePaddingMode("keep");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("unknown padding 'keep'"), std::string::npos);
}

TEST(Scene, ClosestMatch) {
  const std::vector<std::string> keys{"size", "samples", "margin", "map"};
  EXPECT_EQ(closestMatch("sise", keys), "size");
  EXPECT_EQ(closestMatch("SIZE", keys), "size");
  EXPECT_EQ(closestMatch("margn", keys), "margin");
  EXPECT_EQ(closestMatch("zzzzzz", keys), "");
  EXPECT_EQ(closestMatch("x", keys), "");
}

// ---- Scenes of in-memory bakes (the C ABI) ------------------------------------------------------

/// Parses @p text as the scene of an in-memory bake.
Result<Scene> parseInMemory(const std::string& text) {
  SceneParseOptions o = options();
  o.inMemory = true;
  o.name = "sgbake_bake_map: scene_json";
  return parseScene(text, o);
}

TEST(Scene, InMemoryScenesNameImagesVerbatimAndHaveNoFiles) {
  Result<Scene> parsed = parseInMemory(
      R"({"layers": [{"type": "height", "image": "Bumps/../Height.001", "mask": "a//mask"}],
          "outputs": [{"map": "tangent-normal", "size": 64, "tile": 1002}]})");
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_TRUE(parsed->inMemory);
  EXPECT_EQ(parsed->mesh, kInMemoryMeshName);
  // Names are not paths: not resolved against the base directory, not normalized.
  EXPECT_EQ(parsed->layers[0].image, "Bumps/../Height.001");
  EXPECT_EQ(parsed->layers[0].mask->image, "a//mask");
  EXPECT_TRUE(parsed->outputs[0].file.empty());
  EXPECT_EQ(parsed->outputs[0].tile, 1002);
  EXPECT_TRUE(validateScene(*parsed));
}

TEST(Scene, InMemoryScenesRejectFileKeys) {
  const auto error = [](const std::string& text) {
    Result<Scene> parsed = parseInMemory(text);
    return parsed ? std::string("parsed") : parsed.error().message;
  };
  EXPECT_EQ(error(R"({"mesh": "m.obj", "outputs": [{"map": "height"}]})"),
            "sgbake_bake_map: scene_json: key 'mesh' is not used in memory (the mesh is given as "
            "arrays)");
  for (const char* key : {"file", "format", "bit_depth"}) {
    const std::string value = std::string(key) == "bit_depth" ? "16" : "\"exr\"";
    EXPECT_EQ(error(R"({"outputs": [{"map": "height", ")" + std::string(key) + "\": " + value +
                    "}]}"),
              "sgbake_bake_map: scene_json: outputs[0]: key '" + std::string(key) +
                  "' is not used in memory (the map is returned as pixels)");
  }
  EXPECT_EQ(error(R"({"outputs": [{"map": "corners"}]})"),
            "sgbake_bake_map: scene_json: outputs[0]: a corners table cannot be baked in memory "
            "(it is written as a file)");
  // The same scene as a file scene: a missing 'file' is still an error there.
  EXPECT_FALSE(parseScene(R"({"mesh": "m.obj", "outputs": [{"map": "height"}]})", options()));
}

}  // namespace
}  // namespace sgbake
