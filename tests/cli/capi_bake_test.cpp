/// @file capi_bake_test.cpp
/// @brief sgbake_bake_map (the C ABI's in-memory bake) gives the values `sgbake bake` writes to
/// a float file of the same scene, texel for texel, in Blender's bottom-first RGBA layout.
///
/// The reference is executePlan on a scene file (the path the CLI takes), writing 32-bit float
/// EXR, read back with loadImage. Suzanne (meshes/suzanne.obj) is baked with a height layer from
/// an RGB image (read as luminance), a tangent-space normal map and a volume, into maps that
/// exercise Extend and push-pull padding, two- and one-channel maps and the coverage alpha.
/// (Its own binary: it loads OpenImageIO, which capi_test checks the C ABI alone does not.)
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include "sgbake/bake/image_output.hpp"
#include "sgbake/bake/planner.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/mesh/io.hpp"
#include "sgbake/sgbake.h"
#include "support/files.hpp"

namespace sgbake {
namespace {

namespace fs = std::filesystem;

constexpr int kTextureSize = 64;

/// A smooth RGB bump texture (channels differ, so luminance is not any one of them).
FloatImage bumpTexture() {
  FloatImage image;
  image.width = image.height = kTextureSize;
  image.channels = 3;
  image.pixels.resize(static_cast<std::size_t>(kTextureSize * kTextureSize * 3));
  image.coverage.assign(static_cast<std::size_t>(kTextureSize * kTextureSize), 1.0f);
  for (int row = 0; row < kTextureSize; ++row) {
    for (int x = 0; x < kTextureSize; ++x) {
      const double s = (x + 0.5) / kTextureSize, t = (row + 0.5) / kTextureSize;
      image.at(x, row, 0) = static_cast<float>(0.5 + 0.5 * std::sin(6.283185307179586 * 3 * s));
      image.at(x, row, 1) = static_cast<float>(0.5 + 0.5 * std::cos(6.283185307179586 * 2 * t));
      image.at(x, row, 2) = static_cast<float>(s * t);
    }
  }
  return image;
}

/// A tangent-space normal map tilted along u and v, encoded n/2 + 0.5.
FloatImage normalTexture() {
  FloatImage image = bumpTexture();
  for (int row = 0; row < kTextureSize; ++row) {
    for (int x = 0; x < kTextureSize; ++x) {
      const double nx = 0.3 * std::sin(0.2 * x), ny = 0.2 * std::cos(0.3 * row);
      const double nz = std::sqrt(1 - nx * nx - ny * ny);
      image.at(x, row, 0) = static_cast<float>(nx / 2 + 0.5);
      image.at(x, row, 1) = static_cast<float>(ny / 2 + 0.5);
      image.at(x, row, 2) = static_cast<float>(nz / 2 + 0.5);
    }
  }
  return image;
}

/// An sgbake_image of @p image (rows top first) in Blender's bottom-first layout.
struct MemoryImage {
  std::string name;
  std::vector<float> pixels;
  int width = 0, height = 0, channels = 0;
  MemoryImage(std::string imageName, const FloatImage& image)
      : name(std::move(imageName)), width(image.width), height(image.height),
        channels(image.channels) {
    const std::size_t rowValues = static_cast<std::size_t>(width * channels);
    for (int row = height - 1; row >= 0; --row) {
      const auto first = image.pixels.begin() + static_cast<std::ptrdiff_t>(row * rowValues);
      pixels.insert(pixels.end(), first, first + static_cast<std::ptrdiff_t>(rowValues));
    }
  }
  sgbake_image view() const { return {name.c_str(), pixels.data(), width, height, channels}; }
};

const char* const kLayers =
    R"([{"type": "height", "image": "%BUMPS%", "scale": 0.05, "filter": "bicubic"},
        {"type": "normal", "image": "%NORMALS%", "space": "tangent", "weight": 0.5},
        {"type": "volume", "function": "sine", "amplitude": 0.01, "frequency": 3,
         "direction": [1, 2, 0]}])";

std::string replaceAll(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
    text.replace(at, from.size(), to);
    at += to.size();
  }
  return text;
}

class CApiBake : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sgbake_capi_bake_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ASSERT_TRUE(writeImage(bumpTexture(), dir_ / "bumps.exr", {.bitDepth = 32}));
    ASSERT_TRUE(writeImage(normalTexture(), dir_ / "normals.exr", {.bitDepth = 32}));
    Result<Mesh> mesh = loadMesh(fs::path(SGBAKE_MESHES) / "suzanne.obj");
    ASSERT_TRUE(mesh) << mesh.error().message;
    mesh_ = std::move(*mesh);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path meshFile_ = fs::path(SGBAKE_MESHES) / "suzanne.obj";  ///< what fileBake reads
  std::string layers_ = kLayers;             ///< the scene's layers (%BUMPS%, %NORMALS%)
  std::vector<std::uint32_t> faceMaterial_;  ///< memoryBake's face_material, or none

  /// The output @p output baked by executePlan into a float EXR and read back (rows top first).
  Image fileBake(const std::string& output) {
    const std::string scene =
        R"({"mesh": ")" + meshFile_.string() + R"(", "layers": )" +
        replaceAll(replaceAll(layers_, "%BUMPS%", "bumps.exr"), "%NORMALS%", "normals.exr") +
        R"(, "outputs": [)" + output + "]}";
    test::writeFile(dir_ / "scene.json", scene);
    Result<Scene> parsed = loadScene(dir_ / "scene.json");
    EXPECT_TRUE(parsed) << parsed.error().message;
    if (!parsed) return {};
    Result<Plan> plan = makePlan(std::move(*parsed), {.force = true, .useManifest = false});
    EXPECT_TRUE(plan) << plan.error().message;
    if (!plan) return {};
    Result<ExecuteReport> report = executePlan(*plan);
    EXPECT_TRUE(report) << report.error().message;
    Result<Image> image = loadImage(dir_ / "out.exr");
    EXPECT_TRUE(image) << image.error().message;
    return image ? *image : Image{};
  }

  /// The same output through sgbake_bake_map: status, message and the RGBA buffer. The bump
  /// image is given as @p bumpsImage and the height layer names it @p bumpsKey.
  int memoryBake(const std::string& output, int size, std::vector<float>& rgba,
                 std::string& message, const std::string& bumpsImage = "Bumps",
                 const std::string& bumpsKey = "Bumps") {
    const MemoryImage bumps(bumpsImage, bumpTexture()), normals("Normal Map.001", normalTexture());
    const sgbake_image images[] = {bumps.view(), normals.view()};
    const std::string scene =
        R"({"layers": )" +
        replaceAll(replaceAll(layers_, "%BUMPS%", bumpsKey), "%NORMALS%", "Normal Map.001") +
        R"(, "outputs": [)" + output + "]}";
    std::vector<float> positions, normalsArray, uvs;
    for (const Vec3f& p : mesh_.positions) positions.insert(positions.end(), {p.x, p.y, p.z});
    for (const Vec3f& n : mesh_.cornerNormals) normalsArray.insert(normalsArray.end(), {n.x, n.y, n.z});
    for (const Vec2f& uv : mesh_.uvSets[0].uvs) uvs.insert(uvs.end(), {uv.x, uv.y});
    const float* uvSets[] = {uvs.data()};
    const sgbake_mesh mesh{positions.data(),
                           mesh_.numVertices(),
                           mesh_.faceStart.data(),
                           mesh_.numFaces(),
                           mesh_.cornerVertex.data(),
                           normalsArray.data(),
                           uvSets,
                           1,
                           mesh_.numCorners(),
                           nullptr,
                           0,
                           faceMaterial_.empty() ? nullptr : faceMaterial_.data()};
    rgba.assign(static_cast<std::size_t>(size) * size * 4, -1.0f);
    char error[512] = "";
    const int status = sgbake_bake_map(scene.c_str(), &mesh, images, 2, 0, nullptr,
                                       rgba.data(), rgba.size(), error, sizeof error);
    message = error;
    return status;
  }

  /// Bakes @p output ("file" is added for the file bake) both ways and compares every texel:
  /// @p channels of the map in RGB as sgbake.h lays them out, alpha the coverage or 1.
  void expectSameAsFile(const std::string& output, int size, int channels, bool alpha) {
    const Image file = fileBake(R"({"file": "out.exr", "bit_depth": 32, )" + output.substr(1));
    ASSERT_EQ(file.width(), size);
    std::vector<float> rgba;
    std::string message;
    ASSERT_EQ(memoryBake(output, size, rgba, message), SGBAKE_OK) << message;
    std::size_t differing = 0, covered = 0;
    for (int y = 0; y < size; ++y) {  // Image and the RGBA buffer both count y from the bottom
      for (int x = 0; x < size; ++x) {
        const float* got = &rgba[4 * (static_cast<std::size_t>(y) * size + x)];
        float want[4] = {file.at(x, y, 0), 0, 0, 1};
        want[1] = channels == 1 ? want[0] : file.at(x, y, 1);
        want[2] = channels == 1 ? want[0] : channels == 2 ? 0.0f : file.at(x, y, 2);
        if (alpha) want[3] = file.at(x, y, file.channels() - 1);
        if (alpha && want[3] > 0) ++covered;
        for (int c = 0; c < 4; ++c) {
          if (got[c] != want[c] && ++differing <= 5) {
            ADD_FAILURE() << "texel (" << x << ", " << y << ") channel " << c << ": got "
                          << got[c] << ", the file has " << want[c];
          }
        }
      }
    }
    EXPECT_EQ(differing, 0u);
    if (alpha) {
      EXPECT_GT(covered, static_cast<std::size_t>(size * size / 10));
    }
  }

  fs::path dir_;
  Mesh mesh_;
};

TEST_F(CApiBake, UdimImagesAreTheImagesNamedWithATileNumber) {
  // Suzanne's UVs lie in tile 1001: "Bumps.<UDIM>" reading the image "Bumps.1001" is "Bumps".
  const std::string output = R"({"map": "tangent-normal", "size": 64})";
  std::vector<float> single, tiled;
  std::string message;
  ASSERT_EQ(memoryBake(output, 64, single, message), SGBAKE_OK) << message;
  ASSERT_EQ(memoryBake(output, 64, tiled, message, "Bumps.1001", "Bumps.<UDIM>"), SGBAKE_OK)
      << message;
  EXPECT_EQ(tiled, single);
  // Only tile 1002 given: the UVs reach no tile, so the bump layer changes nothing there.
  std::vector<float> elsewhere;
  ASSERT_EQ(memoryBake(output, 64, elsewhere, message, "Bumps.1002", "Bumps.<UDIM>"), SGBAKE_OK)
      << message;
  EXPECT_NE(elsewhere, single);
  // No image with a tile number in place of <UDIM>: bad input naming the layer and the names.
  std::vector<float> none;
  EXPECT_EQ(memoryBake(output, 64, none, message, "Bumps", "Bumps.<UDIM>"), SGBAKE_ERROR_BAD_INPUT);
  EXPECT_NE(message.find("sgbake_bake_map: layers[0]: no tile of the UDIM image Bumps.<UDIM> is "
                         "among the images given (names Bumps.1001 to Bumps.2000)"),
            std::string::npos)
      << message;
}

TEST_F(CApiBake, TangentNormalWithExtendMarginIsTheFileBake) {
  expectSameAsFile(R"({"map": "tangent-normal", "size": 96, "margin": 3})", 96, 3, false);
}

// A layer of one material applies to that material's faces: Suzanne's faces in two materials,
// the bump on material 1 and the normal map on material 0 (OBJ `usemtl` for the file bake,
// face_material in memory), the volume on every face. Same texels both ways, and not those of
// the bake with every layer on every face.
TEST_F(CApiBake, LayersOfOneMaterialAreTheFileBake) {
  std::vector<float> everywhere;
  std::string message;
  ASSERT_EQ(memoryBake(R"({"map": "tangent-normal", "size": 64})", 64, everywhere, message),
            SGBAKE_OK)
      << message;
  faceMaterial_.resize(mesh_.numFaces());
  for (std::size_t f = 0; f < faceMaterial_.size(); ++f) faceMaterial_[f] = f % 3 == 0 ? 1 : 0;
  Mesh split = mesh_;
  split.faceMaterial = faceMaterial_;
  meshFile_ = dir_ / "split.obj";
  test::writeFile(meshFile_, formatObj(split));
  layers_ = replaceAll(replaceAll(kLayers, R"("scale": 0.05,)", R"("scale": 0.05, "material": 1,)"),
                       R"("weight": 0.5})", R"("weight": 0.5, "material": 0})");
  ASSERT_NE(layers_, kLayers);
  {
    Result<Mesh> reread = loadMesh(meshFile_);
    ASSERT_TRUE(reread) << reread.error().message;
    EXPECT_EQ(reread->faceMaterial, faceMaterial_) << "the OBJ's usemtl statements";
    EXPECT_EQ(reread->cornerNormals.size(), mesh_.cornerNormals.size());
    EXPECT_EQ(reread->faceFlat, mesh_.faceFlat);
  }
  expectSameAsFile(R"({"map": "tangent-normal", "size": 64})", 64, 3, false);
  std::vector<float> split64;
  ASSERT_EQ(memoryBake(R"({"map": "tangent-normal", "size": 64})", 64, split64, message), SGBAKE_OK)
      << message;
  EXPECT_NE(split64, everywhere);
}

TEST_F(CApiBake, DirectXObjectNormalAndPushPullAreTheFileBake) {
  expectSameAsFile(R"({"map": "object-normal", "size": 64, "padding": "push-pull"})", 64, 3,
                   false);
  expectSameAsFile(R"({"map": "tangent-normal", "size": 64, "green": "directx", "samples": 2})",
                   64, 3, false);
}

TEST_F(CApiBake, AdjacentFacesMarginIsTheFileBake) {
  expectSameAsFile(
      R"({"map": "tangent-normal", "size": 96, "margin": 4, "padding": "adjacent-faces"})", 96, 3,
      false);
}

TEST_F(CApiBake, SignedTwoChannelAndOneChannelMapsAreTheFileBake) {
  expectSameAsFile(R"({"map": "derivative", "size": 64, "margin": 2})", 64, 2, false);
  expectSameAsFile(R"({"map": "height", "size": 64, "margin": 2, "alpha": true})", 64, 1, true);
}

TEST_F(CApiBake, MaskIsTheCoverage) {
  expectSameAsFile(R"({"map": "mask", "size": 64, "alpha": true})", 64, 1, true);
}

TEST_F(CApiBake, FlatFacesAreShadedPerTriangle) {
  // A quad whose corners are not coplanar: flagged flat (face_flat), each of its triangles
  // (0-1-2, 0-2-3) shows its own normal, as Cycles shades it; smooth, or flat with Auto Smooth
  // on (auto_smooth), the corner normals (the polygon's) show.
  const float positions[] = {0, 0, 0, 1, 0, 0.4f, 1, 1, 0, 0, 1, 0.1f};
  const float uv[] = {0, 0, 1, 0, 1, 1, 0, 1};
  const float* uvSets[] = {uv};
  const Vec3d polygon = normalizeOr(Vec3d{-0.1467348, 0.1467348, 0.9782320}, {});
  std::vector<float> normals;
  for (int i = 0; i < 4; ++i) {
    normals.insert(normals.end(), {static_cast<float>(polygon.x), static_cast<float>(polygon.y),
                                   static_cast<float>(polygon.z)});
  }
  const std::uint32_t faceStart[] = {0, 4}, corners[] = {0, 1, 2, 3};
  const Vec3d first = normalizeOr(cross(Vec3d{1, 0, 0.4}, Vec3d{1, 1, 0}), {});
  const Vec3d second = normalizeOr(cross(Vec3d{1, 1, 0}, Vec3d{0, 1, 0.1}), {});
  for (const auto& [flagged, autoSmooth] :
       {std::pair{true, false}, std::pair{false, false}, std::pair{true, true}}) {
    const bool flat = flagged && !autoSmooth;
    const std::uint8_t faceFlat[] = {static_cast<std::uint8_t>(flagged ? 1 : 0)};
    const sgbake_mesh mesh{positions,          4,      faceStart, 1, corners,
                           normals.data(),     uvSets, 1,         4, faceFlat,
                           autoSmooth ? 1 : 0, nullptr};
    std::vector<float> out(16 * 16 * 4);
    char error[256] = "";
    ASSERT_EQ(sgbake_bake_map(R"({"outputs": [{"map": "object-normal", "size": 16}]})", &mesh,
                              nullptr, 0, 0, nullptr, out.data(), out.size(), error, sizeof error),
              SGBAKE_OK)
        << error;
    // (12, 3) lies in 0-1-2 and (3, 12) in 0-2-3; rows from the bottom.
    for (const auto& [x, y, n] :
         {std::tuple{12, 3, flat ? first : polygon}, std::tuple{3, 12, flat ? second : polygon}}) {
      const float* texel = &out[4 * (static_cast<std::size_t>(y) * 16 + x)];
      EXPECT_NEAR(texel[0], 0.5 * n.x + 0.5, 1e-6) << int(flat) << " " << x << "," << y;
      EXPECT_NEAR(texel[1], 0.5 * n.y + 0.5, 1e-6) << int(flat) << " " << x << "," << y;
      EXPECT_NEAR(texel[2], 0.5 * n.z + 0.5, 1e-6) << int(flat) << " " << x << "," << y;
    }
  }
}

TEST_F(CApiBake, NamesAMissingImageAndAWrongBufferSize) {
  std::vector<float> rgba;
  std::string message;
  EXPECT_EQ(memoryBake(R"({"map": "tangent-normal", "size": 32, "file": "n.png"})", 32, rgba,
                       message),
            SGBAKE_ERROR_BAD_INPUT);
  EXPECT_EQ(message,
            "sgbake_bake_map: scene_json: outputs[0]: key 'file' is not used in memory (the map "
            "is returned as pixels)");

  // out_floats is checked against the output's size before anything is baked.
  const MemoryImage bumps("Bumps", bumpTexture());
  const sgbake_image image = bumps.view();
  const float uv[] = {0, 0, 1, 0, 0, 1};
  const float* uvSets[] = {uv};
  const float positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint32_t faceStart[] = {0, 3}, corners[] = {0, 1, 2};
  const sgbake_mesh mesh{positions, 3, faceStart, 1,       corners, nullptr,
                         uvSets,    1, 3,         nullptr, 0,       nullptr};
  std::vector<float> out(16 * 16 * 4);
  char error[256] = "";
  EXPECT_EQ(sgbake_bake_map(R"({"outputs": [{"map": "height", "size": 16}],
                                "layers": [{"type": "height", "image": "Bump"}]})",
                            &mesh, &image, 1, 0, nullptr, out.data(), out.size(), error,
                            sizeof error),
            SGBAKE_ERROR_BAD_INPUT);
  EXPECT_NE(std::string(error).find("no image named 'Bump'"), std::string::npos) << error;
  // Names come from the caller: a control character in one does not break the message's line.
  EXPECT_EQ(sgbake_bake_map(R"({"outputs": [{"map": "height", "size": 16}],
                                "layers": [{"type": "height", "image": "Bu\nmp"}]})",
                            &mesh, &image, 1, 0, nullptr, out.data(), out.size(), error,
                            sizeof error),
            SGBAKE_ERROR_BAD_INPUT);
  EXPECT_NE(std::string(error).find("no image named 'Bu?mp'"), std::string::npos) << error;
  EXPECT_EQ(sgbake_bake_map(R"({"outputs": [{"map": "height", "size": 16}]})", &mesh, &image, 1,
                            0, nullptr, out.data(), out.size() - 1, error, sizeof error),
            SGBAKE_ERROR_BAD_INPUT);
  EXPECT_NE(std::string(error).find("out_floats = 1023"), std::string::npos) << error;
  // Without normals the triangle is smooth-shaded by sgbake: its object normal is +z.
  ASSERT_EQ(sgbake_bake_map(R"({"outputs": [{"map": "object-normal", "size": 16}]})", &mesh,
                            &image, 1, 0, nullptr, out.data(), out.size(), error,
                            sizeof error),
            SGBAKE_OK)
      << error;
  const float* texel = &out[4 * (2 * 16 + 2)];  // x = 2, y = 2: inside the triangle
  EXPECT_FLOAT_EQ(texel[0], 0.5f);
  EXPECT_FLOAT_EQ(texel[1], 0.5f);
  EXPECT_FLOAT_EQ(texel[2], 1.0f);
  EXPECT_FLOAT_EQ(texel[3], 1.0f);
}

}  // namespace
}  // namespace sgbake
