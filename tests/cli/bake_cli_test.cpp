/// @file bake_cli_test.cpp
/// @brief `sgbake bake` and `sgbake convert` as users run them: exit codes, one-line errors that
/// name the culprit, no output on failure, --explain, the manifest, the one-map shorthand,
/// --stats, and the default scene.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/files.hpp"
#include "support/plane_scene.hpp"
#include "run_process.hpp"

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
using test::ProcessResult;


void expectOneErrorLine(const ProcessResult& r) {
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(r.err.starts_with("sgbake: error: ")) << r.err;
}

/// Writes a W×H image with OIIO: channel c of texel (x, row) = values[c] (+ x/W on channel 0
/// when @p ramp).
void writeTestImage(const fs::path& path, int size, std::vector<float> values, bool ramp) {
  const int channels = static_cast<int>(values.size());
  std::vector<float> pixels(static_cast<std::size_t>(size * size * channels));
  for (int row = 0; row < size; ++row) {
    for (int x = 0; x < size; ++x) {
      for (int c = 0; c < channels; ++c) {
        float v = values[static_cast<std::size_t>(c)];
        if (ramp && c == 0) v += 0.5f * static_cast<float>(x) / static_cast<float>(size);
        pixels[(static_cast<std::size_t>(row) * size + x) * channels + c] = v;
      }
    }
  }
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(size, size, channels, OIIO::TypeDesc::UINT16);
  ASSERT_TRUE(out->open(path.string(), spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
  ASSERT_TRUE(out->close());
}

/// A working directory with a plane, a mesh without UVs, a height map and a normal map.
class BakeCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("sgbake_bake_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    writeFile(dir_ / "plane.obj", kPlaneObj);
    writeFile(dir_ / "nouv.obj", kNoUvObj);
    writeTestImage(dir_ / "h.png", 16, {0.25f}, true);
    writeTestImage(dir_ / "n.png", 16, {0.5f, 0.5f, 1.0f}, false);
  }
  void TearDown() override { fs::remove_all(dir_); }

  ProcessResult run(std::vector<std::string> args) {
    args.insert(args.begin(), SGBAKE_CLI);
    return test::runProcess(args);
  }

  /// Writes dir_/scene.json and runs `sgbake bake scene.json extra...`.
  ProcessResult bakeScene(const std::string& json, std::vector<std::string> extra = {}) {
    writeFile(dir_ / "scene.json", json);
    std::vector<std::string> args{"bake", (dir_ / "scene.json").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  }

  fs::path dir_;
};


/// Checks that a bad scene exits 2 with one line containing @p expected, creating no file.
void expectBadScene(const ProcessResult& r, const std::string& expected,
                    const std::set<std::string>& before, const fs::path& dir) {
  EXPECT_EQ(r.exitCode, 2) << r.err;
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_EQ(listDirectory(dir), before) << "no output, no temporary, no manifest";
}

TEST_F(BakeCliTest, BadScenesExitTwoNamingTheProblemAndCreateNothing) {
  writeFile(dir_ / "scene.json", "{}");
  const std::set<std::string> before = listDirectory(dir_);
  const std::string out = R"("map": "tangent-normal", "file": "out.png")";
  expectBadScene(bakeScene(planeScene(kHeightLayer, "{" + std::string(out) + R"(, "sise": 64})")),
                 "outputs[0]: unknown key 'sise' (did you mean 'size'?)", before, dir_);
  expectBadScene(bakeScene(planeScene(kHeightLayer, "{" + std::string(out) + R"(, "size": 0})")),
                 "outputs[0]: size 0 is out of range 1..65536", before, dir_);
  expectBadScene(
      bakeScene(planeScene(kHeightLayer, "{" + std::string(out) + R"(, "size": 100000})")),
      "outputs[0]: size 100000 is out of range 1..65536", before, dir_);
  expectBadScene(bakeScene(planeScene(kHeightLayer, R"({"map": "albedo", "file": "out.png"})")),
                 "outputs[0]: unknown map 'albedo'", before, dir_);
  expectBadScene(
      bakeScene(planeScene(kHeightLayer,
                           "{" + std::string(out) + R"(, "padding": "push-pull", "margin": 4})")),
      "outputs[0]: key 'margin' applies to padding \"extend\" and \"adjacent-faces\"", before,
      dir_);
  expectBadScene(bakeScene(planeScene(R"({"type": "height", "image": "nothere.png"})",
                                      "{" + std::string(out) + "}")),
                 "layers[0]: image " + (dir_ / "nothere.png").string() + " does not exist", before,
                 dir_);
  expectBadScene(bakeScene(planeScene(kHeightLayer, "{" + std::string(out) + "}", "nouv.obj")),
                 "nouv.obj", before, dir_);
  expectBadScene(bakeScene(R"({"mesh": "plane.obj", "subdivision": {"level": "limt"},
                              "outputs": [{"map": "mask", "file": "m.png"}]})"),
                 "subdivision", before, dir_);
  expectBadScene(bakeScene("{\"mesh\": "), "invalid JSON", before, dir_);
  // The scene file itself.
  const ProcessResult missing = run({"bake", (dir_ / "none.json").string()});
  EXPECT_EQ(missing.exitCode, 2);
  expectOneErrorLine(missing);
  EXPECT_NE(missing.err.find("none.json: cannot open scene (no such file)"), std::string::npos);
}

// Inputs a fuzzing run got through: a NUL byte ends nlohmann's JSON (what follows was ignored)
// and cut the printed error short (fputs); a mask spelled as a string kept a NUL; an empty
// option value read as 0 or as not given; a device as the image convert reads never returned;
// `tangents -o` replaced a file of any name with CSV.
TEST_F(BakeCliTest, NulBytesEmptyValuesDevicesAndOddTableNamesAreBadInput) {
  writeFile(dir_ / "scene.json", "{}");
  const std::set<std::string> before = listDirectory(dir_);
  const std::string out = R"({"map": "mask", "file": "m.png", "size": 8})";
  expectBadScene(bakeScene(planeScene(kHeightLayer, out) + std::string("\0 not JSON {{", 13)),
                 "invalid JSON: a NUL byte at line ", before, dir_);
  expectBadScene(
      bakeScene(planeScene(R"({"type": "height", "image": "h.png", "mask": "h.png\u0000x"})",
                           R"({"map": "height", "file": "h.exr", "size": 8})")),
      "layers[0].mask: 'mask' holds a NUL character", before, dir_);
  const ProcessResult quoted =
      bakeScene(planeScene(R"({"type": "height", "image": "h.png", "sca\u0000le": 1})", out));
  expectBadScene(quoted, "unknown key 'sca\\0le'", before, dir_);
  EXPECT_TRUE(quoted.err.ends_with("\n")) << "the whole line: " << quoted.err;

  for (const std::vector<std::string>& flags : {std::vector<std::string>{"--height-scale", ""},
                                                {"--transform", ""},
                                                {"--out-dir", ""},
                                                {"--bit-depth", ""}}) {
    std::vector<std::string> args{"bake",
                                  "--mesh",
                                  (dir_ / "plane.obj").string(),
                                  "--height",
                                  (dir_ / "h.png").string(),
                                  "--map",
                                  "tangent-normal",
                                  "--size",
                                  "8",
                                  "-o",
                                  (dir_ / "t.png").string(),
                                  "--no-manifest"};
    if (flags[0] != "--height-scale") args.insert(args.end(), {"--height-scale", "0.1"});
    args.insert(args.end(), flags.begin(), flags.end());
    const ProcessResult r = run(args);
    EXPECT_EQ(r.exitCode, 2) << flags[0];
    expectOneErrorLine(r);
    EXPECT_NE(r.err.find("bake: " + flags[0] + " is given an empty value"), std::string::npos)
        << r.err;
  }
  EXPECT_EQ(listDirectory(dir_), before);

  const ProcessResult device =
      run({"convert", "/dev/zero", "--mesh", (dir_ / "plane.obj").string(), "--from", "object",
           "--to", "tangent", "-o", (dir_ / "c.png").string()});
  EXPECT_EQ(device.exitCode, 2);
  expectOneErrorLine(device);
  EXPECT_NE(device.err.find("/dev/zero: cannot read file (it is not a regular file"),
            std::string::npos)
      << device.err;

  writeFile(dir_ / "picture.png", "not a table");
  const ProcessResult table =
      run({"tangents", (dir_ / "plane.obj").string(), "-o", (dir_ / "picture.png").string()});
  EXPECT_EQ(table.exitCode, 2);
  expectOneErrorLine(table);
  EXPECT_NE(table.err.find("its file must end in .csv"), std::string::npos) << table.err;
  EXPECT_EQ(readFile(dir_ / "picture.png"), "not a table");
}

// The directories a failed run created for its outputs are removed again, deepest first; a
// run that succeeds keeps them.
TEST_F(BakeCliTest, FailedRunsRemoveTheDirectoriesTheyCreated) {
  fs::create_directories(dir_ / "taken.png");  // an output that is a directory: bad input
  writeFile(dir_ / "scene.json", "{}");
  const std::set<std::string> before = listDirectory(dir_);
  expectBadScene(bakeScene(R"({"mesh": "plane.obj", "outputs": [
                              {"map": "mask", "file": "new/deeper/a.png", "size": 8},
                              {"map": "mask", "file": "taken.png", "size": 8}]})"),
                 "taken.png: is a directory", before, dir_);
  EXPECT_FALSE(fs::exists(dir_ / "new"));
  const ProcessResult good = bakeScene(
      R"({"mesh": "plane.obj", "outputs": [{"map": "mask", "file": "new/deeper/a.png", "size": 8}]})");
  EXPECT_EQ(good.exitCode, 0) << good.err;
  EXPECT_TRUE(fs::is_regular_file(dir_ / "new" / "deeper" / "a.png"));
}

TEST_F(BakeCliTest, UnreadableImageExitsTwoAndCreatesNothing) {
  writeFile(dir_ / "broken.png", "this is not a png");
  writeFile(dir_ / "scene.json", "{}");
  const std::set<std::string> before = listDirectory(dir_);
  expectBadScene(bakeScene(planeScene(R"({"type": "height", "image": "broken.png"})",
                                      R"({"map": "height", "file": "h.exr", "size": 8})")),
                 "broken.png", before, dir_);
}

TEST_F(BakeCliTest, MissingImageModuleIsOneErrorLineNamingItAndWritesNothing) {
  // The image codec is a module beside libsgbake (sgbake/io/image_io.hpp); a broken install
  // must say which file is missing, exit 1 (not the input's fault) and write nothing.
  const fs::path module = dir_ / "nowhere" / "libsgbake_oiio.so";
  writeFile(dir_ / "scene.json", "{}");
  const std::set<std::string> before = listDirectory(dir_);
  ::setenv("SGBAKE_IMAGE_IO_MODULE", module.c_str(), 1);
  const ProcessResult r = bakeScene(
      planeScene(kHeightLayer, R"({"map": "tangent-normal", "file": "n.png", "size": 8})"));
  ::unsetenv("SGBAKE_IMAGE_IO_MODULE");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find(module.string() + ": cannot load the image I/O module"), std::string::npos)
      << r.err;
  EXPECT_EQ(listDirectory(dir_), before) << "no output, no temporary, no manifest";
}

TEST_F(BakeCliTest, HeightLayersReadOneChannelOfAPackedMap) {
  // A height in the alpha (or blue) channel of an RGBA map bakes as the same height alone in a
  // grey file; a file without the channel is refused, naming it.
  const int size = 16;
  std::vector<float> packed(static_cast<std::size_t>(size * size * 4));
  std::vector<float> grey(static_cast<std::size_t>(size * size));
  for (std::size_t i = 0; i < grey.size(); ++i) {
    const float h = static_cast<float>((i * 37) % 101) / 100.0f;
    grey[i] = h;
    packed[4 * i] = 0.9f;
    packed[4 * i + 1] = 0.1f;
    packed[4 * i + 2] = h;
    packed[4 * i + 3] = h;
  }
  const auto write = [&](const fs::path& path, int channels, const std::vector<float>& pixels) {
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(size, size, channels, OIIO::TypeDesc::UINT16);
    if (channels == 4) spec.alpha_channel = 3;
    ASSERT_TRUE(out->open(path.string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    ASSERT_TRUE(out->close());
  };
  write(dir_ / "packed.tif", 4, packed);  // TIFF: alpha kept as stored (not premultiplied)
  write(dir_ / "grey.tif", 1, grey);
  ::setenv("SOURCE_DATE_EPOCH", "0", 1);  // the files are compared byte for byte
  const auto bake = [&](const std::string& layer, const std::string& file) {
    return bakeScene(planeScene(layer, R"({"map": "object-normal", "file": ")" + file +
                                           R"(", "size": 24, "bit_depth": 32})"),
                     {"--no-manifest"});
  };
  ASSERT_EQ(bake(R"({"type": "height", "image": "grey.tif", "scale": 0.2})", "grey.exr").exitCode,
            0);
  for (const char* channel : {"a", "b"}) {
    const std::string file = std::string(channel) + ".exr";
    const ProcessResult r =
        bake(R"({"type": "height", "image": "packed.tif", "scale": 0.2, "channel": ")" +
                 std::string(channel) + R"("})",
             file);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(readFile(dir_ / file), readFile(dir_ / "grey.exr")) << channel;
  }
  const ProcessResult luminance =
      bake(R"({"type": "height", "image": "packed.tif", "scale": 0.2})", "l.exr");
  ASSERT_EQ(luminance.exitCode, 0) << luminance.err;
  EXPECT_NE(readFile(dir_ / "l.exr"), readFile(dir_ / "grey.exr"));
  const ProcessResult noAlpha =
      bake(R"({"type": "height", "image": "n.png", "scale": 0.2, "channel": "a"})", "x.exr");
  EXPECT_EQ(noAlpha.exitCode, 2);
  expectOneErrorLine(noAlpha);
  EXPECT_NE(noAlpha.err.find("n.png: image has 3 channels but an alpha channel is needed"),
            std::string::npos)
      << noAlpha.err;
  ::unsetenv("SOURCE_DATE_EPOCH");
}

TEST_F(BakeCliTest, SourceDateEpochMakesExrAndTiffFilesReproducible) {
  // OpenImageIO stamps EXR and TIFF files with the time of writing; SOURCE_DATE_EPOCH (the
  // reproducible-builds convention) replaces it, so two bakes give the same bytes.
  const std::string scene =
      planeScene(kHeightLayer, R"({"map": "tangent-normal", "file": "n.exr", "size": 8},
                       {"map": "height", "file": "h.tif", "size": 8})");
  std::map<std::string, std::string> first;
  ::setenv("SOURCE_DATE_EPOCH", "1700000000", 1);
  for (int run = 0; run < 2; ++run) {
    const ProcessResult r = bakeScene(scene, {"--force"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* name : {"n.exr", "h.tif"}) {
      const std::string bytes = readFile(dir_ / name);
      if (run == 0) {
        first[name] = bytes;
        // 2023-11-14 22:13:20 UTC, as TIFF's DateTime and EXR's capDate write it.
        EXPECT_NE(bytes.find("2023:11:14 22:13:20"), std::string::npos) << name;
      } else {
        EXPECT_EQ(bytes, first[name]) << name;
      }
    }
  }
  ::unsetenv("SOURCE_DATE_EPOCH");
}

TEST_F(BakeCliTest, FailingBakeLeavesTheExistingOutputByteIdentical) {
  writeFile(dir_ / "out.png", "the previous bake");
  writeFile(dir_ / "scene.json", "{}");
  const std::set<std::string> before = listDirectory(dir_);
  const ProcessResult r = bakeScene(planeScene(
      kHeightLayer, R"({"map": "tangent-normal", "file": "out.png", "size": 8})", "nouv.obj"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(readFile(dir_ / "out.png"), "the previous bake");
  EXPECT_EQ(listDirectory(dir_), before);
}

TEST_F(BakeCliTest, FailedPngWriteIsAnErrorAndLeavesTheExistingOutput) {
  // A file-size limit (as a full disk would) stops the PNG partway: OpenImageIO's PNG writer
  // does not notice, so sgbake writes PNGs through a file that does. sgbake ignores SIGXFSZ
  // (which would kill it, leaving its temporaries), so the write fails with EFBIG.
  writeFile(dir_ / "out.png", "the previous bake");
  const std::set<std::string> before = listDirectory(dir_);
  const std::string command =
      "ulimit -f 2; exec '" + std::string(SGBAKE_CLI) + "' bake --mesh '" +
      (dir_ / "plane.obj").string() + "' --height '" + (dir_ / "h.png").string() +
      "' --height-scale 0.3 --map object-normal --size 1024 --margin 0 --no-manifest -o '" +
      (dir_ / "out.png").string() + "'";
  const ProcessResult r = test::runProcess({"/bin/sh", "-c", command});
  EXPECT_EQ(r.exitCode, 1) << r.err;
  expectOneErrorLine(r);
  // The reason once, not followed by one OpenImageIO line per later write.
  EXPECT_NE(r.err.find("out.png: cannot write image (File too large)\n"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.out.find("wrote"), std::string::npos) << r.out;
  EXPECT_EQ(readFile(dir_ / "out.png"), "the previous bake");
  EXPECT_EQ(listDirectory(dir_), before);
}

TEST_F(BakeCliTest, ARunThatFailsChangesNoOutputEvenThoseItFinished) {
  // Two outputs: a small mask, then a map too large for the file-size limit. The mask is baked
  // and written first, but outputs replace their files only once all are written: after the
  // failure both keep their previous content, and no manifest or temporary appears.
  writeFile(dir_ / "a.png", "previous a");
  writeFile(dir_ / "b.png", "previous b");
  writeFile(dir_ / "scene.json", planeScene(kHeightLayer,
                                            R"({"map": "mask", "file": "a.png", "size": 8},
                          {"map": "object-normal", "file": "b.png", "size": 1024, "margin": 0})"));
  const std::set<std::string> before = listDirectory(dir_);
  const std::string command = "ulimit -f 2; exec '" + std::string(SGBAKE_CLI) + "' bake '" +
                              (dir_ / "scene.json").string() + "'";
  const ProcessResult r = test::runProcess({"/bin/sh", "-c", command});
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("b.png: cannot write image (File too large"), std::string::npos) << r.err;
  EXPECT_EQ(readFile(dir_ / "a.png"), "previous a");
  EXPECT_EQ(readFile(dir_ / "b.png"), "previous b");
  EXPECT_EQ(listDirectory(dir_), before);
  // Without the limit both are replaced and recorded.
  const ProcessResult ok = bakeScene(readFile(dir_ / "scene.json"));
  EXPECT_EQ(ok.exitCode, 0) << ok.err;
  EXPECT_NE(readFile(dir_ / "a.png"), "previous a");
  EXPECT_TRUE(fs::exists(dir_ / ".sgbake-manifest.json"));
}

TEST_F(BakeCliTest, ManifestThatCannotBeWrittenIsReportedBeforeBaking) {
  // A directory where the manifest goes: one line naming it, exit 2, nothing baked.
  fs::create_directories(dir_ / "out" / ".sgbake-manifest.json");
  const std::set<std::string> before = listDirectory(dir_ / "out");
  const ProcessResult r = bakeScene(
      planeScene(kHeightLayer, R"({"map": "tangent-normal", "file": "out/n.png", "size": 8})"));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find(".sgbake-manifest.json: is a directory"), std::string::npos) << r.err;
  EXPECT_EQ(listDirectory(dir_ / "out"), before);
}

TEST_F(BakeCliTest, MapsNoTriangleReachesAreBakedWithAWarning) {
  // UVs all below 0: the 0-1 square and every UDIM tile are empty. The maps are written (the
  // background), and stderr says so, one line each.
  writeFile(dir_ / "away.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt -0.9 -0.9\nvt -0.1 -0.9\nvt -0.1 -0.1\n"
            "vt -0.9 -0.1\nf 1/1 2/2 3/3 4/4\n");
  const ProcessResult single =
      run({"bake", "--mesh", (dir_ / "away.obj").string(), "--map", "mask", "--size", "8",
           "--no-manifest", "-o", (dir_ / "m.png").string()});
  EXPECT_EQ(single.exitCode, 0) << single.err;
  EXPECT_NE(single.err.find(
                "sgbake: warning: " + (dir_ / "m.png").string() +
                ": no triangle of UV set 0 with a non-zero UV area lies in the 0-1 UV square; the "
                "map holds "
                "only the background\n"),
            std::string::npos)
      << single.err;
  const ProcessResult tiles =
      run({"bake", "--mesh", (dir_ / "away.obj").string(), "--map", "mask", "--size", "8",
           "--no-manifest", "-o", (dir_ / "m_<UDIM>.png").string()});
  EXPECT_EQ(tiles.exitCode, 0) << tiles.err;
  EXPECT_NE(tiles.err.find("area lies in a UDIM tile (1001 to 2000); tile 1001 holds only the "
                           "background"),
            std::string::npos)
      << tiles.err;
  EXPECT_TRUE(fs::exists(dir_ / "m_1001.png"));
  // Some triangles in tiles, two at negative u: baked, and the two counted.
  writeFile(dir_ / "partly.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0.1 0.1\nvt 0.9 0.1\nvt 0.9 0.9\n"
            "vt 0.1 0.9\nvt -0.9 -0.9\nvt -0.1 -0.9\nvt -0.1 -0.1\nvt -0.9 -0.1\n"
            "f 1/1 2/2 3/3 4/4\nf 1/5 2/6 3/7 4/8\n");
  const ProcessResult partly =
      run({"bake", "--mesh", (dir_ / "partly.obj").string(), "--map", "mask", "--size", "8",
           "--no-manifest", "-o", (dir_ / "q_<UDIM>.png").string()});
  EXPECT_EQ(partly.exitCode, 0) << partly.err;
  EXPECT_EQ(partly.err, "sgbake: warning: " + (dir_ / "q_<UDIM>.png").string() +
                            ": 2 triangle(s) of UV set 0 lie outside UDIM tiles 1001 to 2000 "
                            "(negative u or v, u ≥ 10 or v ≥ 100) and are not baked\n");
  // A mesh in the square: no warning.
  const ProcessResult plane =
      run({"bake", "--mesh", (dir_ / "plane.obj").string(), "--map", "mask", "--size", "8",
           "--no-manifest", "-o", (dir_ / "p.png").string()});
  EXPECT_EQ(plane.err, "");
}

TEST_F(BakeCliTest, InterruptedBakeLeavesNoTemporaryAndNoOutput) {
  // A long bake (8192², 4×4 samples) is interrupted once its image's temporary exists: the
  // process dies of the signal and removes the temporary the library was writing, and the two
  // directories it made for it. Ctrl-C, a reader that went away (SIGPIPE), and a signal a job
  // scheduler may send.
  for (const int signal : {SIGINT, SIGPIPE, SIGUSR1}) {
    const fs::path top = dir_ / ("out" + std::to_string(signal));
    fs::create_directories(top);
    const fs::path out = top / "new" / "maps";  // made by the bake
    const std::vector<std::string> args = {SGBAKE_CLI,
                                           "bake",
                                           "--mesh",
                                           (dir_ / "plane.obj").string(),
                                           "--map",
                                           "object-normal",
                                           "--size",
                                           "8192",
                                           "--samples",
                                           "4",
                                           "--no-manifest",
                                           "-o",
                                           (out / "n.exr").string()};
    std::vector<char*> argv;
    for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    pid_t pid = 0;
    ASSERT_EQ(::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);

    // Wait (up to 30 s) for the image's temporary, then a little longer: well inside the bake.
    bool sawTemporary = false;
    for (int i = 0; i < 3000 && !sawTemporary; ++i) {
      std::error_code ec;
      if (fs::is_directory(out, ec)) {
        for (const std::string& name : listDirectory(out))
          sawTemporary = sawTemporary || name.find(".tmp-") != std::string::npos;
      }
      if (!sawTemporary) ::usleep(10000);
    }
    ::usleep(300000);
    ::kill(pid, signal);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(sawTemporary) << signal;
    ASSERT_TRUE(WIFSIGNALED(status)) << "the bake finished before signal " << signal;
    EXPECT_EQ(WTERMSIG(status), signal);
    // No temporary, no output, no directory made for them.
    EXPECT_EQ(listDirectory(top), std::set<std::string>{}) << signal;
  }
}

TEST_F(BakeCliTest, BakesAScene) {
  const ProcessResult r = bakeScene(planeScene(
      kHeightLayer, R"({"map": "tangent-normal", "file": "out/n.png", "size": 32, "margin": 2},
                       {"map": "mask", "file": "out/m.png", "size": 32})"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err, "") << "silent on a pipe: no progress bar";
  EXPECT_NE(r.out.find("wrote " + (dir_ / "out/n.png").string()), std::string::npos) << r.out;
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open((dir_ / "out/n.png").string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 32);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT16);
  std::unique_ptr<OIIO::ImageInput> mask = OIIO::ImageInput::open((dir_ / "out/m.png").string());
  ASSERT_TRUE(mask);
  EXPECT_EQ(mask->spec().format, OIIO::TypeDesc::UINT8);
  EXPECT_EQ(listDirectory(dir_ / "out"),
            (std::set<std::string>{"n.png", "m.png", ".sgbake-manifest.json"}));
}

// Linux file names are bytes, not always UTF-8, and a manifest is JSON text: such names (and
// '%', which their encoding uses) bake, are recorded, and are up to date the second time.
TEST_F(BakeCliTest, FileNamesThatAreNotUtf8AreBakedAndRecorded) {
  const std::string mesh = (dir_ / "m\xff.obj").string(), height = (dir_ / "h\xfe%41.png").string();
  fs::copy_file(dir_ / "plane.obj", mesh);
  fs::copy_file(dir_ / "h.png", height);
  const std::string output = (dir_ / "o\xfd%.png").string();
  const std::vector<std::string> args = {"bake",   "--mesh", mesh, "--height", height,
                                         "--size", "8",      "-o", output};
  const ProcessResult first = run(args);
  ASSERT_EQ(first.exitCode, 0) << first.err;
  EXPECT_EQ(first.out, "wrote " + output + "\n");
  const ProcessResult again = run(args);
  ASSERT_EQ(again.exitCode, 0) << again.err;
  EXPECT_EQ(again.out, "up to date: " + output + "\n");
  // The manifest is valid UTF-8 JSON naming them with %HH.
  const std::string manifest = readFile(dir_ / ".sgbake-manifest.json");
  EXPECT_NE(manifest.find("o%FD%25.png"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("h%FE%2541.png"), std::string::npos) << manifest;
  // Changing the height image with the odd name re-bakes.
  writeTestImage(height, 16, {0.5f}, true);
  const ProcessResult touched = run(args);
  ASSERT_EQ(touched.exitCode, 0) << touched.err;
  EXPECT_EQ(touched.out, "wrote " + output + "\n");
}

// A run killed outright (SIGKILL) leaves its temporary, which nothing can remove then: the
// next run writing that output names it (its process is gone), and leaves other files alone.
TEST_F(BakeCliTest, TemporariesOfKilledRunsAreNamed) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);  // a pid whose process is gone
  const std::string dead =
      dir_.string() + "/m.png.tmp-" + std::to_string(child) + "-0123456789abcdef";
  const std::string alive =
      dir_.string() + "/m.png.tmp-" + std::to_string(::getpid()) + "-0123456789abcdef";
  writeFile(dead, "partial");
  writeFile(alive, "partial");
  writeFile(dir_ / "m.png.tmp-notes", "mine");
  const ProcessResult r = run({"bake", "--mesh", (dir_ / "plane.obj").string(), "--map", "mask",
                               "--size", "8", "--no-manifest", "-o", (dir_ / "m.png").string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err, "sgbake: warning: " + dead +
                       ": a temporary left by a run that was killed (its process is gone); "
                       "remove it\n");
  EXPECT_TRUE(fs::exists(dead));  // said, not removed
  EXPECT_TRUE(fs::exists(alive));
}

TEST_F(BakeCliTest, ManifestUpToDateForceAndTouchedInputs) {
  const std::string json =
      planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8},
                                                       {"map": "mask", "file": "m.png", "size": 8})");
  ASSERT_EQ(bakeScene(json).exitCode, 0);
  const std::string bytes = readFile(dir_ / "h.exr");

  const ProcessResult again = bakeScene(json);
  ASSERT_EQ(again.exitCode, 0) << again.err;
  EXPECT_EQ(again.out, "up to date: " + (dir_ / "h.exr").string() +
                           "\nup to date: " + (dir_ / "m.png").string() + "\n");
  EXPECT_EQ(readFile(dir_ / "h.exr"), bytes);

  const ProcessResult forced = bakeScene(json, {"--force"});
  ASSERT_EQ(forced.exitCode, 0) << forced.err;
  EXPECT_NE(forced.out.find("wrote " + (dir_ / "h.exr").string()), std::string::npos);
  EXPECT_NE(forced.out.find("wrote " + (dir_ / "m.png").string()), std::string::npos);

  // Touching the height image re-bakes the height map only.
  writeTestImage(dir_ / "h.png", 16, {0.5f}, true);
  const ProcessResult touched = bakeScene(json);
  ASSERT_EQ(touched.exitCode, 0) << touched.err;
  EXPECT_NE(touched.out.find("wrote " + (dir_ / "h.exr").string()), std::string::npos);
  EXPECT_NE(touched.out.find("up to date: " + (dir_ / "m.png").string()), std::string::npos);
  EXPECT_NE(readFile(dir_ / "h.exr"), bytes);

  // A deleted output is baked again.
  fs::remove(dir_ / "m.png");
  const ProcessResult deleted = bakeScene(json);
  EXPECT_NE(deleted.out.find("wrote " + (dir_ / "m.png").string()), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "m.png"));
}

TEST_F(BakeCliTest, ExplainPrintsThePlanAndBakesNothing) {
  const ProcessResult r =
      bakeScene(planeScene(kHeightLayer, R"({"map": "height", "file": "h.exr", "size": 8},
                                  {"map": "mask", "file": "m.png", "size": 8})"),
                {"--explain"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("steps:\n  1. load mesh "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("skipped:\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tangent frames (MikkTSpace): no map to bake"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mask maps read no layers"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "h.exr"));
  EXPECT_FALSE(fs::exists(dir_ / ".sgbake-manifest.json"));

  // A plan, the list of files written, help or the version that cannot be written is an
  // error, not exit 0.
  for (const char* words : {" --help", " --version", " bake --help"}) {
    const ProcessResult full = test::runProcess(
        {"/bin/sh", "-c", "exec '" + std::string(SGBAKE_CLI) + "'" + words + " > /dev/full"});
    EXPECT_EQ(full.exitCode, 1) << words << ": " << full.err;
    EXPECT_NE(full.err.find("sgbake: error: cannot write to standard output"), std::string::npos)
        << full.err;
  }
  for (const char* extra : {" --explain", ""}) {
    const ProcessResult full =
        test::runProcess({"/bin/sh", "-c",
                          "exec '" + std::string(SGBAKE_CLI) + "' bake '" +
                              (dir_ / "scene.json").string() + "'" + extra + " > /dev/full"});
    EXPECT_EQ(full.exitCode, 1) << extra << ": " << full.err;
    EXPECT_NE(full.err.find("sgbake: error: cannot write to standard output"), std::string::npos)
        << full.err;
  }
}

TEST_F(BakeCliTest, OutDirMovesRelativeOutputs) {
  const ProcessResult r =
      bakeScene(planeScene("", R"({"map": "mask", "file": "m.png", "size": 4})"),
                {"--out-dir", (dir_ / "elsewhere").string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "elsewhere" / "m.png"));
  EXPECT_FALSE(fs::exists(dir_ / "m.png"));
}

TEST_F(BakeCliTest, StatsPrintOneJsonLineOfTimings) {
  const ProcessResult r = bakeScene(
      planeScene(kHeightLayer, R"({"map": "tangent-normal", "file": "n.png", "size": 8})"),
      {"--stats", "--threads", "2"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  ASSERT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(r.err);
  for (const char* key : {"load_s", "tangents_s", "bake_s", "pad_s", "write_s", "total_s"}) {
    ASSERT_TRUE(stats.contains(key)) << key;
    EXPECT_GE(stats[key].get<double>(), 0.0) << key;
  }
  EXPECT_EQ(stats["command"], "bake");
  EXPECT_EQ(stats["baked"], 1);
  EXPECT_EQ(stats["tangents"], true);
  EXPECT_EQ(stats["images_loaded"], 1);
  EXPECT_LE(stats["threads"].get<int>(), 2);
}

TEST_F(BakeCliTest, OneMapShorthand) {
  const fs::path out = dir_ / "short.png";
  const ProcessResult r =
      run({"bake", "--mesh", (dir_ / "plane.obj").string(), "--height", (dir_ / "h.png").string(),
           "--height-scale", "0.1", "--map", "tangent-normal", "--size", "16", "--margin", "0",
           "--filter", "bicubic", "-o", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(out.string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 16);
  EXPECT_EQ(in->spec().height, 16);

  const ProcessResult normal =
      run({"bake", "--mesh", (dir_ / "plane.obj").string(), "--normal", (dir_ / "n.png").string(),
           "--normal-space", "tangent", "--map", "object-normal", "--size", "8", "--padding",
           "push-pull", "-o", (dir_ / "os.exr").string()});
  ASSERT_EQ(normal.exitCode, 0) << normal.err;
  EXPECT_TRUE(fs::exists(dir_ / "os.exr"));
  const ProcessResult bumpNode =
      run({"bake", "--mesh", (dir_ / "plane.obj").string(), "--height", (dir_ / "h.png").string(),
           "--height-gradient", "bump-node", "--size", "8", "-o", (dir_ / "bn.exr").string()});
  ASSERT_EQ(bumpNode.exitCode, 0) << bumpNode.err;
  EXPECT_TRUE(fs::exists(dir_ / "bn.exr"));
  // --height-remap X:Y,…: the layer's "remap", the same bake as the scene's.
  const ProcessResult remapped =
      run({"bake", "--mesh", (dir_ / "plane.obj").string(), "--height", (dir_ / "h.png").string(),
           "--height-remap", "0.1:0,0.3:0.6,0.3:0.2", "--map", "height", "--size", "8",
           "--bit-depth", "32", "--no-manifest", "-o", (dir_ / "remap_flags.exr").string()});
  ASSERT_EQ(remapped.exitCode, 0) << remapped.err;
  writeFile(dir_ / "remap.json",
            R"({"mesh": "plane.obj", "layers": [{"type": "height", "image": "h.png",
                "remap": [[0.1, 0], [0.3, 0.6], [0.3, 0.2]]}],
                "outputs": [{"map": "height", "file": "remap_scene.exr", "size": 8,
                             "bit_depth": 32}]})");
  const ProcessResult scene = run({"bake", (dir_ / "remap.json").string(), "--no-manifest"});
  ASSERT_EQ(scene.exitCode, 0) << scene.err;
  const auto pixels = [](const fs::path& path) {
    std::unique_ptr<OIIO::ImageInput> file = OIIO::ImageInput::open(path.string());
    std::vector<float> values;
    if (!file) return values;
    const OIIO::ImageSpec& spec = file->spec();
    values.resize(static_cast<std::size_t>(spec.image_pixels()) * spec.nchannels);
    if (!file->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, values.data()))
      values.clear();
    return values;
  };
  const std::vector<float> flags = pixels(dir_ / "remap_flags.exr");
  ASSERT_EQ(flags.size(), std::size_t{8 * 8});
  EXPECT_EQ(flags, pixels(dir_ / "remap_scene.exr"));
  const auto [low, high] = std::minmax_element(flags.begin(), flags.end());
  EXPECT_GE(*low, 0.0f);
  EXPECT_LE(*high, 0.6f);  // the remap's range
  EXPECT_GT(*high, *low);
  const ProcessResult adjacent =
      run({"bake", "--mesh", (dir_ / "plane.obj").string(), "--map", "object-normal", "--size", "8",
           "--margin", "2", "--padding", "adjacent-faces", "-o", (dir_ / "adj.exr").string()});
  ASSERT_EQ(adjacent.exitCode, 0) << adjacent.err;
  EXPECT_TRUE(fs::exists(dir_ / "adj.exr"));

  // --range auto: the range chosen is said beside the file, and recorded in it.
  const ProcessResult autoRange = run({"bake", "--mesh", (dir_ / "plane.obj").string(), "--height",
                                       (dir_ / "h.png").string(), "--map", "derivative", "--size",
                                       "8", "--range", "auto", "-o", (dir_ / "d.png").string()});
  ASSERT_EQ(autoRange.exitCode, 0) << autoRange.err;
  const std::size_t said = autoRange.out.find("wrote " + (dir_ / "d.png").string() + " (range ±");
  ASSERT_NE(said, std::string::npos) << autoRange.out;
  const std::string number = autoRange.out.substr(said).substr(
      autoRange.out.substr(said).find("±") + std::string("±").size());
  std::unique_ptr<OIIO::ImageInput> derivative = OIIO::ImageInput::open((dir_ / "d.png").string());
  ASSERT_TRUE(derivative);
  EXPECT_EQ(std::stod(number), std::stod(derivative->spec().get_string_attribute("sgbake:range")))
      << autoRange.out;
}

TEST_F(BakeCliTest, OneMapShorthandErrors) {
  const std::string mesh = (dir_ / "plane.obj").string();
  const std::set<std::string> before = listDirectory(dir_);
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"bake", "--mesh", mesh, "--size", "0", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--size", "100000", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--map", "albedo", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "-o", (dir_ / "o.jpg").string()},
           {"bake", "--mesh", mesh},
           {"bake", "--mesh", mesh, "--height", (dir_ / "nothere.png").string(), "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", (dir_ / "nouv.obj").string(), "-o", (dir_ / "o.png").string()},
           {"bake", (dir_ / "scene.json").string(), "--mesh", mesh},
           {"bake"},
           {"bake", "--mesh", mesh, "--padding", "extnd", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--padding", "push-pull", "--margin", "4", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--map", "mask", "--margin", "4", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--map", "mask", "--padding", "adjacent-faces", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--map", "derivative", "--range", "0", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--map", "corners", "--size", "64", "-o",
            (dir_ / "o.csv").string()},
           {"bake", "--mesh", mesh, "--map", "corners", "--alpha", "-o", (dir_ / "o.csv").string()},
           {"bake", "--mesh", mesh, "--normal", (dir_ / "n.png").string(), "--filter", "hermite",
            "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--map", "derivative", "--range", "automatic", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--map", "derivative", "--range", "auto", "-o",
            (dir_ / "o.exr").string()},
           // Options that would change nothing: no layer for them, another map, no subdivision.
           {"bake", "--mesh", mesh, "--height-scale", "2", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--filter", "bicubic", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--height-gradient", "bump-node", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--height-remap", "0:0,1:1", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--height", (dir_ / "h.png").string(), "--height-remap",
            "0.5:0,0.2:1", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--height", (dir_ / "h.png").string(), "--height-remap",
            "0.5:0,1", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--height", (dir_ / "h.png").string(), "--height-gradient",
            "central", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--height", (dir_ / "h.png").string(), "--normal-space",
            "object", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--map", "mask", "--green", "directx", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--uv-smooth", "all", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--subdivision-quality", "4", "-o", (dir_ / "o.png").string()},
       }) {
    const ProcessResult r = run(args);
    EXPECT_EQ(r.exitCode, 2) << args.back() << ": " << r.err;
    expectOneErrorLine(r);
  }
  EXPECT_EQ(listDirectory(dir_), before);
  // Messages about the scene the flags build are said in the flags' words.
  const ProcessResult depth = run({"bake", "--mesh", mesh, "--map", "tangent-normal", "--bit-depth",
                                   "8", "-o", (dir_ / "o.exr").string()});
  EXPECT_EQ(depth.err,
            "sgbake: error: bake: --bit-depth 8 is not available in EXR (16 = half or 32 = "
            "float)\n");
  const ProcessResult self = run({"bake", "--mesh", mesh, "--height", (dir_ / "h.png").string(),
                                  "-o", (dir_ / "h.png").string()});
  EXPECT_NE(self.err.find("is the image of the --height image, which the bake reads"),
            std::string::npos)
      << self.err;
  EXPECT_EQ(self.err.find("layers[0]"), std::string::npos) << self.err;
  const ProcessResult green = run({"bake", "--mesh", mesh, "--map", "mask", "--green", "directx",
                                   "-o", (dir_ / "o.png").string()});
  EXPECT_NE(green.err.find("bake: --green applies only with --map tangent-normal"),
            std::string::npos)
      << green.err;
  const ProcessResult swizzleMask = run({"bake", "--mesh", mesh, "--map", "mask", "--swizzle",
                                         "+X+Y+Z", "-o", (dir_ / "o.png").string()});
  EXPECT_EQ(swizzleMask.err,
            "sgbake: error: bake: --swizzle applies only with --map tangent-normal or "
            "object-normal\n");
  const ProcessResult both = run({"bake", "--mesh", mesh, "--green", "directx", "--swizzle",
                                  "+X-Y+Z", "-o", (dir_ / "o.png").string()});
  EXPECT_NE(both.err.find("either with --green or in --swizzle"), std::string::npos) << both.err;
  const ProcessResult badSwizzle =
      run({"bake", "--mesh", mesh, "--swizzle", "+X+Y+W", "-o", (dir_ / "o.png").string()});
  EXPECT_EQ(badSwizzle.exitCode, 2);
  EXPECT_NE(badSwizzle.err.find("bake: --swizzle: swizzle '+X+Y+W' has a sign without an axis"),
            std::string::npos)
      << badSwizzle.err;
  EXPECT_FALSE(fs::exists(dir_ / "o.png"));
  const ProcessResult smooth =
      run({"bake", "--mesh", mesh, "--uv-smooth", "all", "-o", (dir_ / "o.png").string()});
  EXPECT_NE(smooth.err.find("bake: --uv-smooth applies to a subdivided mesh; add --subdivide N"),
            std::string::npos)
      << smooth.err;
  // Values CLI11 would describe in its own words: sgbake's say what is expected.
  for (const auto& [args, expected] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--size", "1e1"}, "bake: --size: '1e1' is not an integer from 1 to 65536"},
           {{"--threads", "99999999999"},
            "bake: --threads: '99999999999' is not an integer from 0 to 2147483647"},
           {{"--subdivide", "1", "--subdivision-type", "loop"},
            "bake: --subdivision-type: unknown value 'loop' (expected catmull-clark or simple)"},
       }) {
    std::vector<std::string> command{"bake", "--mesh", mesh, "-o", (dir_ / "o.png").string()};
    command.insert(command.end(), args.begin(), args.end());
    const ProcessResult r = run(command);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  }
  // A script's copy of a modifier at level 0 (--subdivide 0 given) is taken, as Blender does.
  EXPECT_EQ(run({"bake", "--mesh", mesh, "--subdivide", "0", "--uv-smooth", "all", "--map", "mask",
                 "--size", "8", "--no-manifest", "-o", (dir_ / "o.png").string()})
                .exitCode,
            0);
  const ProcessResult map =
      run({"bake", "--mesh", mesh, "--map", "tangent-normals", "-o", (dir_ / "o.png").string()});
  EXPECT_NE(map.err.find("unknown map"), std::string::npos) << map.err;
  const ProcessResult padding =
      run({"bake", "--mesh", mesh, "--padding", "extnd", "-o", (dir_ / "o.png").string()});
  EXPECT_NE(padding.err.find("did you mean 'extend'?"), std::string::npos) << padding.err;
}

/// A cube of size 2 with one UV square per face (a row of six squares over u in [0, 1]).
constexpr const char* kCubeObj =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
    "vt 0 0.2\nvt 0.16 0.2\nvt 0.16 0.8\nvt 0 0.8\n"
    "vt 0.17 0.2\nvt 0.33 0.2\nvt 0.33 0.8\nvt 0.17 0.8\n"
    "vt 0.34 0.2\nvt 0.5 0.2\nvt 0.5 0.8\nvt 0.34 0.8\n"
    "vt 0.51 0.2\nvt 0.66 0.2\nvt 0.66 0.8\nvt 0.51 0.8\n"
    "vt 0.67 0.2\nvt 0.83 0.2\nvt 0.83 0.8\nvt 0.67 0.8\n"
    "vt 0.84 0.2\nvt 1 0.2\nvt 1 0.8\nvt 0.84 0.8\n"
    "f 1/1 4/2 3/3 2/4\nf 5/5 6/6 7/7 8/8\nf 1/9 2/10 6/11 5/12\n"
    "f 2/13 3/14 7/15 6/16\nf 3/17 4/18 8/19 7/20\nf 4/21 1/22 5/23 8/24\n";

/// The pixels of an image file as floats (the files themselves differ in their time stamp).
std::vector<float> readPixels(const fs::path& path) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path.string());
  if (!in) return {};
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> pixels(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data())) return {};
  return pixels;
}

TEST_F(BakeCliTest, ProjectionsReadBlendersBoxPlanesAndMappedCoordinates) {
  // On the plane z = 0 (N = +z) a triplanar layer reads its Z plane alone: sgbake's blend at
  // (x, y), Blender's Box at (1 − y, x) (mirrored on the +z side), and the blend after a Mapping
  // node's quarter turn about z at (−y, x), the Box's lookup on the repeating image. h.png
  // ramps along its s, so the blend's height map ramps along x, the others along y.
  const auto bake = [&](const std::string& extra, const std::string& file) {
    const ProcessResult r =
        bakeScene(planeScene(R"({"type": "triplanar", "image": "h.png", "scale": 1)" + extra + "}",
                             R"({"map": "height", "file": ")" + file +
                                 R"(", "size": 16, "margin": 0, "bit_depth": 32})"),
                  {"--no-manifest"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return readPixels(dir_ / file);
  };
  const std::vector<float> blended = bake("", "blended.exr");
  const std::vector<float> box = bake(R"(, "projection": "box")", "box.exr");
  const std::vector<float> turned =
      bake(R"(, "mapping": {"rotation": [0, 0, 1.5707963267948966]})", "turned.exr");
  ASSERT_EQ(blended.size(), 256u);
  ASSERT_EQ(box.size(), 256u);
  ASSERT_EQ(turned.size(), 256u);
  const auto at = [](const std::vector<float>& h, int x, int row) {
    return h[static_cast<std::size_t>(row * 16 + x)];
  };
  // The ramp: 0.5 per unit of s, 0.25 across 8 texels.
  EXPECT_NEAR(at(blended, 12, 8) - at(blended, 4, 8), 0.25, 1e-3);
  EXPECT_NEAR(at(blended, 8, 12) - at(blended, 8, 4), 0, 1e-6);
  EXPECT_NEAR(at(box, 8, 12) - at(box, 8, 4), 0.25, 1e-3);  // rows go down in y: s = 1 − y up
  EXPECT_NEAR(at(box, 12, 8) - at(box, 4, 8), 0, 1e-6);
  float worst = 0;
  for (std::size_t i = 0; i < box.size(); ++i)
    worst = std::max(worst, std::abs(box[i] - turned[i]));
  EXPECT_LT(worst, 1e-5);
}

TEST_F(BakeCliTest, SubdivisionFromSceneAndFlags) {
  writeFile(dir_ / "cube.obj", kCubeObj);
  const std::string mesh = (dir_ / "cube.obj").string();
  const auto scene = [&](int level, const std::string& file) {
    return R"({"mesh": "cube.obj", "subdivision": {"level": )" + std::to_string(level) +
           R"(}, "outputs": [{"map": "object-normal", "file": ")" + file +
           R"(", "size": 64, "margin": 0, "bit_depth": 32}]})";
  };
  ASSERT_EQ(bakeScene(scene(2, "l2.exr")).exitCode, 0);
  ASSERT_EQ(bakeScene(scene(0, "l0.exr")).exitCode, 0);
  // The shorthand with --subdivide gives the same file, whatever the number of threads.
  for (const char* threads : {"1", "2"}) {
    const fs::path out = dir_ / (std::string("flags") + threads + ".exr");
    const ProcessResult r = run({"bake", "--mesh", mesh, "--map", "object-normal", "--size", "64",
                                 "--margin", "0", "--bit-depth", "32", "--subdivide", "2",
                                 "--threads", threads, "--no-manifest", "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::vector<float> pixels = readPixels(out);
    EXPECT_FALSE(pixels.empty());
    EXPECT_TRUE(pixels == readPixels(dir_ / "l2.exr")) << "--threads " << threads;
  }
  // Subdividing rounds the cube: its object-space normals are no longer the six face normals.
  EXPECT_FALSE(readPixels(dir_ / "l2.exr") == readPixels(dir_ / "l0.exr"));
  // "limit": the exact surface under every texel; close to level 2, not the same.
  const auto limitScene = [&](const std::string& file) {
    return R"({"mesh": "cube.obj", "subdivision": {"level": "limit"}, "outputs": [{"map": )"
           R"("object-normal", "file": ")" + file + R"(", "size": 64, "margin": 0, "bit_depth": 32}]})";
  };
  ASSERT_EQ(bakeScene(limitScene("limit.exr")).exitCode, 0);
  const std::vector<float> limit = readPixels(dir_ / "limit.exr"), l2 = readPixels(dir_ / "l2.exr");
  ASSERT_EQ(limit.size(), l2.size());
  double meanDifference = 0;
  for (std::size_t i = 0; i < limit.size(); ++i) meanDifference += std::abs(limit[i] - l2[i]);
  meanDifference /= static_cast<double>(limit.size());
  EXPECT_GT(meanDifference, 0.0);
  EXPECT_LT(meanDifference, 0.01);
  const ProcessResult flag = run({"bake", "--mesh", mesh, "--map", "object-normal", "--size", "64",
                                  "--margin", "0", "--bit-depth", "32", "--subdivide", "limit",
                                  "--no-manifest", "-o", (dir_ / "limit_flag.exr").string()});
  ASSERT_EQ(flag.exitCode, 0) << flag.err;
  EXPECT_TRUE(readPixels(dir_ / "limit_flag.exr") == limit);
  // A subdivision block beside "level": 2 bakes another map than level 2 alone, and its flags
  // on the one-map shorthand bake the same file.
  const auto expectSceneKeyEqualsFlag = [&](const std::string& key, const std::string& name,
                                           const std::vector<std::string>& flags) {
    ASSERT_EQ(bakeScene(R"({"mesh": "cube.obj", "subdivision": {"level": 2, )" + key +
                        R"(}, "outputs": [{"map": "object-normal", "file": ")" + name +
                        R"(.exr", "size": 64, "margin": 0, "bit_depth": 32}]})")
                  .exitCode,
              0);
    const std::vector<float> fromScene = readPixels(dir_ / (name + ".exr"));
    EXPECT_FALSE(fromScene == l2) << key;
    std::vector<std::string> args = {"bake",     "--mesh",       mesh, "--map", "object-normal",
                                     "--size",   "64",           "--margin",    "0",
                                     "--bit-depth", "32",        "--subdivide", "2"};
    args.insert(args.end(), flags.begin(), flags.end());
    const fs::path out = dir_ / (name + "_flag.exr");
    args.insert(args.end(), {"--no-manifest", "-o", out.string()});
    const ProcessResult r = run(args);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(readPixels(out) == fromScene) << key;
  };
  // "use_limit_surface": false: the refined cage, not the limit.
  expectSceneKeyEqualsFlag(R"("use_limit_surface": false)", "cage", {"--no-limit-surface"});
  // "type": "simple": the cube split, not rounded.
  expectSceneKeyEqualsFlag(R"("type": "simple")", "simple", {"--subdivision-type", "simple"});
  // A different level is a different bake (the manifest hashes the subdivision block).
  const ProcessResult same = bakeScene(scene(2, "l2.exr"));
  EXPECT_NE(same.out.find("up to date: " + (dir_ / "l2.exr").string()), std::string::npos)
      << same.out;
  const ProcessResult changed = bakeScene(scene(1, "l2.exr"));
  EXPECT_NE(changed.out.find("wrote " + (dir_ / "l2.exr").string()), std::string::npos)
      << changed.out;
  const ProcessResult explained = bakeScene(scene(3, "l3.exr"), {"--explain"});
  EXPECT_NE(explained.out.find("subdivide the mesh to level 3"), std::string::npos)
      << explained.out;

  // `tangents --subdivide --mesh-out`: one CSV row per corner of the mesh it writes.
  const ProcessResult tangents = run({"tangents", mesh, "--subdivide", "1", "--uv-smooth", "none",
                                      "--mesh-out", (dir_ / "fine.obj").string()});
  ASSERT_EQ(tangents.exitCode, 0) << tangents.err;
  const std::string obj = readFile(dir_ / "fine.obj");
  EXPECT_EQ(std::count(obj.begin(), obj.end(), 'f'), 24);  // 24 quads; no other 'f' in it
  EXPECT_EQ(std::count(tangents.out.begin(), tangents.out.end(), '\n'), 1 + 24 * 4);
  // The extension is compared without regard to case, as the mesh reader compares it.
  const ProcessResult upper = run({"tangents", mesh, "--subdivide", "1", "--uv-smooth", "none",
                                   "--mesh-out", (dir_ / "FINE.OBJ").string()});
  ASSERT_EQ(upper.exitCode, 0) << upper.err;
  EXPECT_EQ(readFile(dir_ / "FINE.OBJ"), obj);

  const std::set<std::string> before = listDirectory(dir_);
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"bake", "--mesh", mesh, "--subdivide", "7", "-o", (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--subdivide", "limt", "-o", (dir_ / "o.png").string()},
           {"tangents", mesh, "--subdivide", "limit", "-o", (dir_ / "t.csv").string()},
           {"bake", "--mesh", mesh, "--subdivide", "1", "--uv-smooth", "smooth", "-o",
            (dir_ / "o.png").string()},
           {"tangents", mesh, "--subdivide", "-1", "-o", (dir_ / "t.csv").string()},
           {"convert", "--mesh", mesh, "--subdivide", "1", "--boundary-smooth", "none", "--from",
            "object", "--to", "tangent", (dir_ / "l0.exr").string(), "-o",
            (dir_ / "c.exr").string()},
           {"bake", "--mesh", mesh, "--subdivide", "limit", "--no-limit-surface", "-o",
            (dir_ / "o.png").string()},
           {"convert", "--mesh", mesh, "--subdivide", "limit", "--no-limit-surface", "--from",
            "object", "--to", "tangent", (dir_ / "l0.exr").string(), "-o",
            (dir_ / "c.exr").string()},
           // Subdivision flags belong to the one-map shorthand, not to a scene file.
           {"bake", (dir_ / "scene.json").string(), "--subdivision-quality", "5"},
           {"bake", (dir_ / "scene.json").string(), "--no-limit-surface"},
           {"bake", "--mesh", mesh, "--subdivide", "limit", "--subdivision-type", "simple", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--subdivide", "1", "--subdivision-type", "smooth", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--subdivide", "1", "--auto-smooth", "200", "-o",
            (dir_ / "o.png").string()},
           {"bake", (dir_ / "scene.json").string(), "--auto-smooth", "30"},
           // Subdivision shaping without --subdivide: a forgotten level, not silently ignored.
           {"bake", "--mesh", mesh, "--edge-crease", "0,1,1", "-o", (dir_ / "o.png").string()},
           {"tangents", mesh, "--sharp-edge", "0,1", "-o", (dir_ / "t.csv").string()},
           {"convert", "--mesh", mesh, "--sharp-edge", "0,1", "--from", "object", "--to", "tangent",
            (dir_ / "l0.exr").string(), "-o", (dir_ / "c.exr").string()},
           {"convert", "--mesh", mesh, "--subdivide", "limit", "--auto-smooth", "30", "--from",
            "object", "--to", "tangent", (dir_ / "l0.exr").string(), "-o",
            (dir_ / "c.exr").string()},
           // Settings that would change nothing at a level either.
           {"tangents", mesh, "--subdivide", "1", "--sharp-edge", "0,1", "-o",
            (dir_ / "t.csv").string()},
           {"bake", "--mesh", mesh, "--subdivide", "limit", "--sharp-edge", "0,1", "-o",
            (dir_ / "o.png").string()},
           {"bake", "--mesh", mesh, "--subdivide", "limit", "--subdivision-quality", "1", "-o",
            (dir_ / "o.png").string()},
           {"tangents", mesh, "--subdivide", "1", "--no-limit-surface", "--subdivision-quality",
            "1", "-o", (dir_ / "t.csv").string()},
       }) {
    const ProcessResult r = run(args);
    EXPECT_EQ(r.exitCode, 2) << args[2] << ": " << r.err;
    expectOneErrorLine(r);
  }
  EXPECT_EQ(listDirectory(dir_), before);
  const ProcessResult forgotten =
      run({"tangents", mesh, "--sharp-edge", "0,1", "-o", (dir_ / "t.csv").string()});
  EXPECT_NE(forgotten.err.find("tangents: --sharp-edge needs --auto-smooth DEG (edges marked "
                               "sharp split the normals only with Auto Smooth)"),
            std::string::npos)
      << forgotten.err;
  // --auto-smooth alone shades the mesh as it is: the cube's faces meet at 90 degrees, so at
  // 30 every corner's normal in the mesh written is its face's axis (no diagonal component).
  const fs::path shaded = dir_ / "shaded.obj";
  const ProcessResult autoSmooth = run({"tangents", mesh, "--auto-smooth", "30", "--mesh-out",
                                        shaded.string(), "-o", (dir_ / "t.csv").string()});
  ASSERT_EQ(autoSmooth.exitCode, 0) << autoSmooth.err;
  std::istringstream lines(readFile(shaded));
  int normals = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("vn ", 0) != 0) continue;
    std::istringstream values(line.substr(3));
    double x = 0, y = 0, z = 0;
    values >> x >> y >> z;
    EXPECT_EQ(std::abs(x) + std::abs(y) + std::abs(z), 1.0) << line;
    ++normals;
  }
  EXPECT_EQ(normals, 24);
  fs::remove(shaded);
  fs::remove(dir_ / "t.csv");
  const ProcessResult both = run({"bake", "--mesh", mesh, "--subdivide", "limit",
                                  "--no-limit-surface", "-o", (dir_ / "o.png").string()});
  EXPECT_NE(both.err.find("bake: --no-limit-surface cannot be combined with --subdivide limit"),
            std::string::npos)
      << both.err;
}

// Auto Smooth without subdivision ("level": 0, or --auto-smooth alone): the cube's faces meet
// at 90 degrees, so at 30 every texel's object-space normal is its face's axis, encoded as
// channels 0.5 ± 0.5 on that axis and 0.5 on the others; without Auto Smooth the normals are
// the cube's smooth vertex normals, which are not.
TEST_F(BakeCliTest, AutoSmoothWithoutSubdivisionFromSceneAndFlag) {
  writeFile(dir_ / "cube.obj", kCubeObj);
  const auto scene = [](const std::string& subdivision, const std::string& file) {
    return R"({"mesh": "cube.obj")" + subdivision +
           R"(, "outputs": [{"map": "object-normal", "file": ")" + file +
           R"(", "size": 32, "margin": 0, "bit_depth": 32, "alpha": true}]})";
  };
  const std::string level0 = R"(, "subdivision": {"level": 0, "auto_smooth": 30})";
  const ProcessResult explained = bakeScene(scene(level0, "split.exr"), {"--explain"});
  ASSERT_EQ(explained.exitCode, 0) << explained.err;
  EXPECT_NE(explained.out.find("split the mesh's normals by Auto Smooth at 30 deg (not "
                               "subdivided)"),
            std::string::npos)
      << explained.out;
  ASSERT_EQ(bakeScene(scene(level0, "split.exr")).exitCode, 0);
  ASSERT_EQ(bakeScene(scene("", "smooth.exr")).exitCode, 0);
  const std::vector<float> split = readPixels(dir_ / "split.exr");
  const std::vector<float> smooth = readPixels(dir_ / "smooth.exr");
  ASSERT_EQ(split.size(), std::size_t{32 * 32 * 4});
  ASSERT_EQ(smooth.size(), split.size());
  int covered = 0, smoothOffAxis = 0;
  for (std::size_t t = 0; t < split.size() / 4; ++t) {
    if (split[4 * t + 3] == 0) continue;  // alpha: coverage
    ++covered;
    int onAxis = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      const float v = split[4 * t + c];
      EXPECT_TRUE(v == 0.5f || v == 0.0f || v == 1.0f) << "texel " << t << " channel " << c;
      onAxis += v != 0.5f;
      smoothOffAxis += c == 0 && smooth[4 * t] != 0.5f && smooth[4 * t + 1] != 0.5f;
    }
    EXPECT_EQ(onAxis, 1) << "texel " << t;
  }
  EXPECT_GT(covered, 100);
  EXPECT_GT(smoothOffAxis, covered / 2);
  // The flag bakes the same file; --sharp-edge alone is refused (see SubdivisionFromScene…).
  const ProcessResult flag =
      run({"bake", "--mesh", (dir_ / "cube.obj").string(), "--map", "object-normal", "--size",
           "32", "--margin", "0", "--bit-depth", "32", "--alpha", "--auto-smooth", "30", "-o",
           (dir_ / "split_flag.exr").string()});
  ASSERT_EQ(flag.exitCode, 0) << flag.err;
  EXPECT_EQ(readPixels(dir_ / "split_flag.exr"), split);
}

// A vertex shared by over 100 faces makes subdividing slow (about n³: OpenSubdiv's end caps, in
// Blender too): a warning names it, so that a long run is explained; 100 faces do not.
TEST_F(BakeCliTest, SubdividingAroundAVertexOfManyFacesWarns) {
  const auto fan = [&](int n) {
    std::string obj = "v 0 0 0.2\nvt 0.5 0.5\n";
    for (int i = 0; i < n; ++i) {
      const double a = 2 * 3.141592653589793 * i / n;
      obj += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
      obj += "vt " + std::to_string(0.5 + 0.4 * std::cos(a)) + " " +
             std::to_string(0.5 + 0.4 * std::sin(a)) + "\n";
    }
    for (int i = 0; i < n; ++i) {
      const std::string b = std::to_string(i + 2), c = std::to_string((i + 1) % n + 2);
      obj += "f 1/1 " + b + "/" + b + " " + c + "/" + c + "\n";
    }
    const fs::path path = dir_ / ("fan" + std::to_string(n) + ".obj");
    writeFile(path, obj);
    return run({"bake", "--mesh", path.string(), "--map", "mask", "--size", "16", "--subdivide",
                "1", "--no-manifest", "-o", (dir_ / "m.png").string()});
  };
  const ProcessResult many = fan(101);
  ASSERT_EQ(many.exitCode, 0) << many.err;
  EXPECT_EQ(many.err, "sgbake: warning: " + (dir_ / "fan101.obj").string() +
                          ": vertex 1 is a corner of 101 faces: subdividing around it is slow "
                          "(about 2 s at 128 faces, 2 minutes at 400; Blender's modifier too)\n");
  const ProcessResult fewer = fan(100);
  ASSERT_EQ(fewer.exitCode, 0) << fewer.err;
  EXPECT_EQ(fewer.err, "");
}

// An OBJ whose normals only Auto Smooth makes (split at vertex 3) says Auto Smooth was on, not
// its angle: subdivided without "auto_smooth", it is shaded smooth, which a warning says.
TEST_F(BakeCliTest, SubdividingSplitNormalsWithoutAnAngleWarns) {
  const std::string square =
      "v 0 0 0\nv 1 0 0\nv 1 1 0.2\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
      "vn 0 0 1\nvn 0.1 0 0.995\ns 1\n";
  writeFile(dir_ / "split.obj", square + "f 1/1/1 2/2/1 3/3/2\nf 1/1/1 3/3/1 4/4/1\n");
  writeFile(dir_ / "shared.obj", square + "f 1/1/1 2/2/1 3/3/2\nf 1/1/1 3/3/2 4/4/1\n");
  const auto bake = [&](const std::string& mesh, std::vector<std::string> extra) {
    std::vector<std::string> args = {"bake",
                                     "--mesh",
                                     (dir_ / mesh).string(),
                                     "--map",
                                     "object-normal",
                                     "--size",
                                     "16",
                                     "--margin",
                                     "0",
                                     "--no-manifest",
                                     "-o",
                                     (dir_ / "n.exr").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  };
  const std::string prefix = "sgbake: warning: " + (dir_ / "split.obj").string() +
                             ": its normals are split at sharp edges (Auto Smooth), but ";
  const ProcessResult subdivided = bake("split.obj", {"--subdivide", "1"});
  ASSERT_EQ(subdivided.exitCode, 0) << subdivided.err;
  EXPECT_EQ(subdivided.err,
            prefix +
                "the subdivided mesh is shaded smooth: give \"auto_smooth\" "
                "(--auto-smooth DEG) with the object's Auto Smooth angle to split its "
                "normals as Blender does\n");
  const ProcessResult limit = bake("split.obj", {"--subdivide", "limit"});
  ASSERT_EQ(limit.exitCode, 0) << limit.err;
  EXPECT_EQ(limit.err, prefix + "the exact limit surface is shaded with its own smooth normals\n");
  // No warning: an angle given, no subdivision, or normals that do not show Auto Smooth.
  for (const auto& [mesh, extra] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"split.obj", {"--subdivide", "1", "--auto-smooth", "30"}},
           {"split.obj", {}},
           {"shared.obj", {"--subdivide", "1"}}}) {
    const ProcessResult quiet = bake(mesh, extra);
    ASSERT_EQ(quiet.exitCode, 0) << quiet.err;
    EXPECT_EQ(quiet.err, "") << mesh << " " << extra.size();
  }
}

TEST_F(BakeCliTest, CreasesFromSceneAndFlags) {
  writeFile(dir_ / "cube.obj", kCubeObj);
  const std::string mesh = (dir_ / "cube.obj").string();
  const auto scene = [](const std::string& creases, const std::string& file,
                        const std::string& level = "2") {
    return R"({"mesh": "cube.obj", "subdivision": {"level": )" + level + creases +
           R"(}, "outputs": [{"map": "object-normal", "file": ")" + file +
           R"(", "size": 32, "margin": 0, "bit_depth": 32}]})";
  };
  const std::string creased =
      R"(, "edge_creases": [[0, 1, 1], [1, 2, 0.5]], "vertex_creases": [[6, 1]])";
  ASSERT_EQ(bakeScene(scene("", "smooth.exr")).exitCode, 0);
  const ProcessResult first = bakeScene(scene(creased, "creased.exr"));
  ASSERT_EQ(first.exitCode, 0) << first.err;
  EXPECT_FALSE(readPixels(dir_ / "creased.exr") == readPixels(dir_ / "smooth.exr"));
  // The same creases as flags bake the same file.
  const ProcessResult flags = run({"bake",
                                   "--mesh",
                                   mesh,
                                   "--map",
                                   "object-normal",
                                   "--size",
                                   "32",
                                   "--margin",
                                   "0",
                                   "--bit-depth",
                                   "32",
                                   "--subdivide",
                                   "2",
                                   "--edge-crease",
                                   "0,1,1",
                                   "--edge-crease",
                                   "1,2,0.5",
                                   "--vertex-crease",
                                   "6,1",
                                   "--no-manifest",
                                   "-o",
                                   (dir_ / "flags.exr").string()});
  ASSERT_EQ(flags.exitCode, 0) << flags.err;
  EXPECT_TRUE(readPixels(dir_ / "flags.exr") == readPixels(dir_ / "creased.exr"));
  // The manifest hashes the creases: the same scene is up to date, a changed crease re-bakes,
  // and "use_creases": false bakes the smooth cube again.
  EXPECT_NE(bakeScene(scene(creased, "creased.exr")).out.find("up to date"), std::string::npos);
  const std::string changed =
      R"(, "edge_creases": [[0, 1, 1], [1, 2, 0.6]], "vertex_creases": [[6, 1]])";
  EXPECT_NE(bakeScene(scene(changed, "creased.exr")).out.find("wrote"), std::string::npos);
  ASSERT_EQ(bakeScene(scene(changed + R"(, "use_creases": false)", "off.exr")).exitCode, 0);
  EXPECT_TRUE(readPixels(dir_ / "off.exr") == readPixels(dir_ / "smooth.exr"));

  // Creases that do not fit the mesh: exit 2, one line naming the scene and the key, no file.
  const std::set<std::string> before = listDirectory(dir_);
  const std::string sceneFile = (dir_ / "scene.json").string();
  expectBadScene(bakeScene(scene(R"(, "edge_creases": [[0, 1, 1], [0, 2, 0.5]])", "bad.exr")),
                 sceneFile +
                     ": subdivision.edge_creases[1]: vertices 0 and 2 are not the ends of "
                     "an edge of the mesh (" +
                     mesh + ")",
                 before, dir_);
  expectBadScene(bakeScene(scene(R"(, "vertex_creases": [[8, 1]])", "bad.exr")),
                 sceneFile +
                     ": subdivision.vertex_creases[0]: vertex 8 is out of range (the mesh "
                     "has 8 vertices, numbered from 0)",
                 before, dir_);
  expectBadScene(bakeScene(scene(R"(, "edge_creases": [[0, 9, 1]])", "bad.exr", "\"limit\"")),
                 sceneFile + ": subdivision.edge_creases[0]: vertex 9 is out of range", before,
                 dir_);
  expectBadScene(bakeScene(scene(R"(, "auto_smooth": 30, "sharp_edges": [[0, 6]])", "bad.exr")),
                 sceneFile +
                     ": subdivision.sharp_edges[0]: vertices 0 and 6 are not the ends of an "
                     "edge of the mesh (" +
                     mesh + ")",
                 before, dir_);
  expectBadScene(bakeScene(scene(R"(, "edge_creases": [[0, 1, 2]])", "bad.exr")),
                 sceneFile + ": subdivision.edge_creases[0]: crease 2 is out of range 0..1", before,
                 dir_);
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"tangents", mesh, "--subdivide", "1", "--edge-crease", "0,2,1", "-o",
            (dir_ / "t.csv").string()},
           {"tangents", mesh, "--subdivide", "1", "--edge-crease", "0,1", "-o",
            (dir_ / "t.csv").string()},
           {"tangents", mesh, "--subdivide", "1", "--vertex-crease", "0,1.5", "-o",
            (dir_ / "t.csv").string()},
           {"bake", "--mesh", mesh, "--subdivide", "1", "--vertex-crease", "99,1", "-o",
            (dir_ / "o.png").string()},
       }) {
    const ProcessResult r = run(args);
    EXPECT_EQ(r.exitCode, 2) << args[4] << " " << args[5] << ": " << r.err;
    expectOneErrorLine(r);
    // A scene made from options names the option, not a key no one wrote.
    if (args[0] == "bake") {
      EXPECT_NE(r.err.find(mesh + ": --vertex-crease #1: vertex 99 is out of range"),
                std::string::npos)
          << r.err;
    }
  }
  EXPECT_EQ(listDirectory(dir_), before);
}

TEST_F(BakeCliTest, ConvertObjectToTangentAndBack) {
  // An object-space map of the flat plane: every texel (0, 0, 1) → tangent space (0, 0, 1).
  writeTestImage(dir_ / "os.png", 8, {0.5f, 0.5f, 1.0f}, false);
  const ProcessResult r =
      run({"convert", "--mesh", (dir_ / "plane.obj").string(), "--from", "object", "--to",
           "tangent", (dir_ / "os.png").string(), "-o", (dir_ / "ts.exr").string(), "--stats"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.err).contains("total_s"));
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open((dir_ / "ts.exr").string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 8) << "output size = input size";
  EXPECT_EQ(in->spec().height, 8);
  std::vector<float> pixels(8 * 8 * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data()));
  EXPECT_NEAR(pixels[(3 * 8 + 4) * 3 + 0], 0.5f, 2e-3);
  EXPECT_NEAR(pixels[(3 * 8 + 4) * 3 + 1], 0.5f, 2e-3);
  EXPECT_NEAR(pixels[(3 * 8 + 4) * 3 + 2], 1.0f, 2e-3);
  EXPECT_EQ(in->spec().get_string_attribute("sgbake:map"), "tangent-normal");
  EXPECT_EQ(in->spec().get_string_attribute("sgbake:green"), "opengl");
  EXPECT_EQ(in->spec().get_string_attribute("sgbake:udim_tile"), "1001");

  const ProcessResult back =
      run({"convert", "--mesh", (dir_ / "plane.obj").string(), "--from", "tangent", "--to",
           "object", (dir_ / "ts.exr").string(), "-o", (dir_ / "os2.png").string()});
  ASSERT_EQ(back.exitCode, 0) << back.err;
  EXPECT_TRUE(fs::exists(dir_ / "os2.png"));
  EXPECT_EQ(back.err, "") << "encoded normals fit the PNG: no warning";

  // A tile the plane's UVs do not reach: the image is copied, and the run says so.
  const ProcessResult away = run(
      {"convert", "--mesh", (dir_ / "plane.obj").string(), "--from", "object", "--to", "tangent",
       "--tile", "1002", (dir_ / "os.png").string(), "-o", (dir_ / "ts1002.exr").string()});
  ASSERT_EQ(away.exitCode, 0) << away.err;
  EXPECT_EQ(away.err, "sgbake: warning: " + (dir_ / "ts1002.exr").string() +
                          ": no triangle of UV set 0 lies in UDIM tile 1002; every texel keeps "
                          "the input's value\n");

  // The converted file says what it holds: read with the wrong --from it is refused.
  const ProcessResult wrongSpace =
      run({"convert", "--mesh", (dir_ / "plane.obj").string(), "--from", "object", "--to",
           "tangent", (dir_ / "ts.exr").string(), "-o", (dir_ / "again.exr").string()});
  EXPECT_EQ(wrongSpace.exitCode, 2);
  EXPECT_EQ(wrongSpace.err, "sgbake: error: " + (dir_ / "ts.exr").string() +
                                ": the file says it is a tangent-normal map (sgbake:map); --from "
                                "object would misread it\n");
  // A map baked with its channels swizzled (and a DirectX green) is read in the order its
  // sgbake:swizzle says: it converts to what the unswizzled map converts to. --swizzle writes
  // the output's channels in its order, and says so.
  const std::string plane = (dir_ / "plane.obj").string();
  for (const auto& [file, swizzle] :
       {std::pair{"plain.exr", "+X-Y+Z"}, {"swizzled.exr", "-Y-X+Z"}}) {
    const ProcessResult baked =
        run({"bake", "--mesh", plane, "--map", "tangent-normal", "--size", "8", "--height",
             (dir_ / "h.png").string(), "--height-scale", "0.3", "--margin", "0", "--swizzle",
             swizzle, "--bit-depth", "32", "-o", (dir_ / file).string()});
    ASSERT_EQ(baked.exitCode, 0) << baked.err;
  }
  for (const char* name : {"plain", "swizzled"}) {
    const ProcessResult converted =
        run({"convert", "--mesh", plane, "--from", "tangent", "--to", "object", "--swizzle",
             "+Z-X+Y", (dir_ / (std::string(name) + ".exr")).string(), "-o",
             (dir_ / (std::string(name) + "_os.exr")).string()});
    ASSERT_EQ(converted.exitCode, 0) << converted.err;
  }
  const std::vector<float> plainBack = readPixels(dir_ / "plain_os.exr");
  const std::vector<float> swizzledBack = readPixels(dir_ / "swizzled_os.exr");
  ASSERT_EQ(plainBack.size(), swizzledBack.size());
  ASSERT_FALSE(plainBack.empty());
  for (std::size_t i = 0; i < plainBack.size(); ++i)
    EXPECT_NEAR(swizzledBack[i], plainBack[i], 1e-6) << i;
  std::unique_ptr<OIIO::ImageInput> written =
      OIIO::ImageInput::open((dir_ / "plain_os.exr").string());
  ASSERT_TRUE(written);
  EXPECT_EQ(written->spec().get_string_attribute("sgbake:swizzle"), "+Z-X+Y");
  const ProcessResult both =
      run({"convert", "--mesh", plane, "--from", "object", "--to", "tangent", "--green", "directx",
           "--swizzle", "+X-Y+Z", (dir_ / "plain_os.exr").string(), "-o",
           (dir_ / "again.exr").string()});
  EXPECT_EQ(both.exitCode, 2);
  EXPECT_NE(both.err.find("either with --green or in --swizzle"), std::string::npos) << both.err;
  EXPECT_FALSE(fs::exists(dir_ / "again.exr"));
  // Its tile is the default of --tile: a map of tile 1002 converts back as tile 1002.
  writeFile(dir_ / "plane1002.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 1 0\nvt 2 0\nvt 2 1\nvt 1 1\n"
            "f 1/1 2/2 3/3 4/4\n");
  const std::string mesh1002 = (dir_ / "plane1002.obj").string();
  ASSERT_EQ(run({"convert", "--mesh", mesh1002, "--from", "object", "--to", "tangent", "--tile",
                 "1002", (dir_ / "os.png").string(), "-o", (dir_ / "ts1002b.exr").string()})
                .exitCode,
            0);
  const ProcessResult tileBack =
      run({"convert", "--mesh", mesh1002, "--from", "tangent", "--to", "object",
           (dir_ / "ts1002b.exr").string(), "-o", (dir_ / "os1002.exr").string()});
  ASSERT_EQ(tileBack.exitCode, 0) << tileBack.err;
  EXPECT_EQ(tileBack.err, "") << "tile 1002, which the UVs reach";
  std::unique_ptr<OIIO::ImageInput> back1002 =
      OIIO::ImageInput::open((dir_ / "os1002.exr").string());
  ASSERT_TRUE(back1002);
  EXPECT_EQ(back1002->spec().get_string_attribute("sgbake:udim_tile"), "1002");
  // An explicit --tile wins, with a warning.
  const ProcessResult overridden =
      run({"convert", "--mesh", mesh1002, "--from", "tangent", "--to", "object", "--tile", "1001",
           (dir_ / "ts1002b.exr").string(), "-o", (dir_ / "os1001.exr").string()});
  EXPECT_NE(overridden.err.find("the file says it is UDIM tile 1002 (sgbake:udim_tile); "
                                "converted as tile 1001, as --tile says"),
            std::string::npos)
      << overridden.err;

  // An alpha of 2 (kept as it is) does not fit a PNG: clamped, with a warning counting it.
  writeTestImage(dir_ / "os_alpha.exr", 8, {0.5f, 0.5f, 1.0f, 2.0f}, false);
  const ProcessResult alpha =
      run({"convert", "--mesh", (dir_ / "plane.obj").string(), "--from", "object", "--to",
           "tangent", (dir_ / "os_alpha.exr").string(), "-o", (dir_ / "ts_alpha.png").string()});
  ASSERT_EQ(alpha.exitCode, 0) << alpha.err;
  EXPECT_EQ(alpha.err, "sgbake: warning: " + (dir_ / "ts_alpha.png").string() +
                           ": 64 of 256 values were outside [0, 1], all an integer file stores, "
                           "and were clamped to it: an EXR or a 32-bit TIFF keeps them\n");
}

TEST_F(BakeCliTest, ConvertPadsTheConvertedIslandsWhenAsked) {
  // The plane's UVs cover the left half of an 8² map. Left: the object-space +Z the plane
  // shows; right: +X, as a padding in object space would have left there — not a tangent-space
  // normal. By default the right half keeps it; with --padding it is padded from the converted
  // island (tangent-space +Z, (0.5, 0.5, 1)).
  writeFile(dir_ / "half.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 0.5 0\nvt 0.5 1\nvt 0 1\n"
            "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
  {
    std::vector<float> pixels(8 * 8 * 3);
    for (int row = 0; row < 8; ++row) {
      for (int x = 0; x < 8; ++x) {
        const std::array<float, 3> c =
            x < 4 ? std::array<float, 3>{0.5f, 0.5f, 1.0f} : std::array<float, 3>{1.0f, 0.5f, 0.5f};
        std::copy(c.begin(), c.end(), pixels.begin() + (row * 8 + x) * 3);
      }
    }
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("os.exr");
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open((dir_ / "os_half.exr").string(),
                          OIIO::ImageSpec(8, 8, 3, OIIO::TypeDesc::FLOAT)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    ASSERT_TRUE(out->close());
  }
  // Columns that end up tangent-space +Z, per padding (the rest keep the input's +X).
  const std::vector<std::pair<std::vector<std::string>, int>> cases{
      {{}, 4},                                                // keep
      {{"--padding", "extend", "--margin", "2"}, 6},          // two columns
      {{"--padding", "adjacent-faces", "--margin", "2"}, 7},  // margin + 1: Blender's reach
      {{"--padding", "push-pull"}, 8}};                       // all
  const auto convert = [&](const std::vector<std::string>& flags) {
    std::vector<std::string> args{"convert",
                                  "--mesh",
                                  (dir_ / "half.obj").string(),
                                  "--from",
                                  "object",
                                  "--to",
                                  "tangent",
                                  (dir_ / "os_half.exr").string(),
                                  "-o",
                                  (dir_ / "ts_half.exr").string()};
    args.insert(args.end(), flags.begin(), flags.end());
    return run(args);
  };
  for (const auto& [flags, flat] : cases) {
    const ProcessResult r = convert(flags);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open((dir_ / "ts_half.exr").string());
    ASSERT_TRUE(in);
    std::vector<float> pixels(8 * 8 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data()));
    for (int row = 0; row < 8; ++row) {
      for (int x = 0; x < 8; ++x) {
        const float* c = &pixels[(row * 8 + x) * 3];
        const std::array<float, 3> expected = x < flat ? std::array<float, 3>{0.5f, 0.5f, 1.0f}
                                                       : std::array<float, 3>{1.0f, 0.5f, 0.5f};
        for (int k = 0; k < 3; ++k) {
          ASSERT_NEAR(c[k], expected[static_cast<std::size_t>(k)], 1e-4)
              << (flags.empty() ? "keep" : flags[1]) << " texel " << x << "," << row;
        }
      }
    }
  }
  // --margin with a padding that has no margin, and an unknown padding: refused, nothing written.
  fs::remove(dir_ / "ts_half.exr");
  for (const std::vector<std::string>& flags : {std::vector<std::string>{"--margin", "3"},
                                                {"--padding", "push-pull", "--margin", "3"},
                                                {"--padding", "extnd"}}) {
    const ProcessResult r = convert(flags);
    EXPECT_EQ(r.exitCode, 2) << flags.back();
    expectOneErrorLine(r);
    EXPECT_FALSE(fs::exists(dir_ / "ts_half.exr"));
  }
}

TEST_F(BakeCliTest, ConvertErrors) {
  const std::string mesh = (dir_ / "plane.obj").string();
  const std::set<std::string> before = listDirectory(dir_);
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"convert", "--mesh", mesh, "--from", "object", (dir_ / "n.png").string(), "-o",
            (dir_ / "o.png").string()},
           {"convert", "--mesh", mesh, "--from", "objekt", "--to", "tangent",
            (dir_ / "n.png").string(), "-o", (dir_ / "o.png").string()},
           {"convert", "--mesh", mesh, "--from", "object", "--to", "object",
            (dir_ / "n.png").string(), "-o", (dir_ / "o.png").string()},
           {"convert", "--mesh", mesh, "--from", "object", "--to", "tangent",
            (dir_ / "none.png").string(), "-o", (dir_ / "o.png").string()},
           {"convert", "--mesh", mesh, "--from", "object", "--to", "tangent",
            (dir_ / "h.png").string(), "-o", (dir_ / "o.png").string()},
           {"convert", "--mesh", (dir_ / "nouv.obj").string(), "--from", "object", "--to",
            "tangent", (dir_ / "n.png").string(), "-o", (dir_ / "o.png").string()},
           {"convert", "--mesh", mesh, "--from", "object", "--to", "tangent",
            (dir_ / "n.png").string(), "-o", (dir_ / "missing" / "o.png").string()},
           // Outputs that would overwrite an input: the image, the mesh (by its format).
           {"convert", "--mesh", mesh, "--from", "object", "--to", "tangent",
            (dir_ / "n.png").string(), "-o", (dir_ / "." / "n.png").string()},
           {"tangents", mesh, "-o", mesh},
           {"tangents", mesh, "--mesh-out", mesh},
           {"tangents", mesh, "--mesh-out", (dir_ / "m.ply").string()},
           {"tangents", mesh, "--mesh-out", (dir_ / "m.obj").string(), "-o",
            (dir_ / "m.obj").string()},
       }) {
    const ProcessResult r = run(args);
    EXPECT_EQ(r.exitCode, 2) << args.back() << ": " << r.err;
    expectOneErrorLine(r);
  }
  EXPECT_EQ(listDirectory(dir_), before);
}

// --transform (the object's matrix_world) shades the one-map bake in world space, as the
// scene's "transform" does; a translation alone changes nothing; convert's object-space side is
// then Blender's map of the placed object, and object -> tangent -> object comes back.
TEST_F(BakeCliTest, TransformFlagForBakeAndConvert) {
  const std::string mesh = (dir_ / "plane.obj").string();
  const auto bakeWith = [&](const std::string& name, const std::vector<std::string>& extra) {
    std::vector<std::string> args{"bake",
                                  "--mesh",
                                  mesh,
                                  "--height",
                                  (dir_ / "h.png").string(),
                                  "--height-scale",
                                  "0.1",
                                  "--map",
                                  "tangent-normal",
                                  "--size",
                                  "16",
                                  "--margin",
                                  "0",
                                  "--bit-depth",
                                  "32",
                                  "-o",
                                  (dir_ / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const ProcessResult r = run(args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return readPixels(dir_ / name);
  };
  const std::vector<float> plain = bakeWith("plain.exr", {});
  EXPECT_EQ(bakeWith("moved.exr", {"--transform", "1,0,0,5, 0,1,0,6, 0,0,1,7"}), plain);
  const std::vector<float> squeezed =
      bakeWith("squeezed.exr", {"--transform", "1 0 0 0 1 0 0 0 0.5"});
  ASSERT_EQ(squeezed.size(), plain.size());
  EXPECT_NE(squeezed, plain);
  // Squeezed across the plane, the same world bump tilts the object-space normal twice as much:
  // the texels' slopes (x/z) double.
  int compared = 0;
  for (std::size_t i = 0; i + 2 < plain.size(); i += 3) {
    const double px = 2.0 * plain[i] - 1, pz = 2.0 * plain[i + 2] - 1;
    const double sx = 2.0 * squeezed[i] - 1, sz = 2.0 * squeezed[i + 2] - 1;
    if (std::abs(px / pz) < 1e-3) continue;
    EXPECT_NEAR((sx / sz) / (px / pz), 2.0, 1e-4) << i;
    ++compared;
  }
  EXPECT_GT(compared, 50);

  writeTestImage(dir_ / "os.exr", 8, {0.8f, 0.5f, 0.9f}, false);  // n = (0.6, 0, 0.8)
  const std::string transform = "2,0,0,0, 0,1,0,0, 0,0,0.5,0, 0,0,0,1";
  const auto convert = [&](const std::string& from, const std::string& to, const fs::path& in,
                           const fs::path& out, bool transformed) {
    std::vector<std::string> args{"convert",     "--mesh", mesh, "--from",
                                  from,          "--to",   to,   in.string(),
                                  "--bit-depth", "32",     "-o", out.string()};
    if (transformed) args.insert(args.end(), {"--transform", transform});
    const ProcessResult r = run(args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
  };
  convert("object", "tangent", dir_ / "os.exr", dir_ / "ts_t.exr", true);
  convert("object", "tangent", dir_ / "os.exr", dir_ / "ts.exr", false);
  convert("tangent", "object", dir_ / "ts_t.exr", dir_ / "os_back.exr", true);
  EXPECT_NE(readPixels(dir_ / "ts_t.exr"), readPixels(dir_ / "ts.exr"));
  const std::vector<float> input = readPixels(dir_ / "os.exr");  // as stored (half floats)
  const std::vector<float> back = readPixels(dir_ / "os_back.exr");
  ASSERT_EQ(back.size(), 8u * 8u * 3u);
  ASSERT_EQ(input.size(), back.size());
  const std::size_t at = (4 * 8 + 4) * 3;
  const double x = 2.0 * input[at] - 1, z = 2.0 * input[at + 2] - 1, length = std::hypot(x, z);
  EXPECT_NEAR(back[at], 0.5 * x / length + 0.5, 1e-6);  // the input's normal, normalized
  EXPECT_NEAR(back[at + 2], 0.5 * z / length + 0.5, 1e-6);

  const std::set<std::string> before = listDirectory(dir_);
  for (const std::string bad :
       {"1,2,3", "1,0,0,0,0,0,0,0,1", "1,0,0,x,1,0,0,0,1", "1,0,0,0,0,1,0,0,0,0,1,0,1,0,0,1"}) {
    for (const std::string command : {"bake", "convert"}) {
      std::vector<std::string> args =
          command == "bake"
              ? std::vector<std::string>{"bake", "--mesh", mesh, "-o", (dir_ / "t.png").string()}
              : std::vector<std::string>{"convert", "--mesh",
                                         mesh,      "--from",
                                         "object",  "--to",
                                         "tangent", (dir_ / "os.exr").string(),
                                         "-o",      (dir_ / "t.exr").string()};
      args.insert(args.end(), {"--transform", bad});
      const ProcessResult r = run(args);
      EXPECT_EQ(r.exitCode, 2) << bad << ": " << r.err;
      expectOneErrorLine(r);
      EXPECT_NE(r.err.find("--transform"), std::string::npos) << r.err;
    }
  }
  EXPECT_EQ(listDirectory(dir_), before);
}

TEST_F(BakeCliTest, HelpTexts) {
  const ProcessResult bake = run({"bake", "--help"});
  EXPECT_EQ(bake.exitCode, 0);
  for (const char* text : {"Examples:", "--explain", "--force", "SCENE", "--height-scale",
                           "Output keys:", "Exit codes:", ".sgbake-manifest.json"}) {
    EXPECT_NE(bake.out.find(text), std::string::npos) << text;
  }
  const ProcessResult convert = run({"convert", "--help"});
  EXPECT_EQ(convert.exitCode, 0);
  EXPECT_NE(convert.out.find("Examples:"), std::string::npos);
  const ProcessResult top = run({"--help"});
  EXPECT_NE(top.out.find("bake"), std::string::npos);
  EXPECT_NE(top.out.find("convert"), std::string::npos);
}

TEST(DefaultScene, ExplainsWithoutErrors) {
  const std::string scene = std::string(SGBAKE_MESHES) + "/default_scene.json";
  const ProcessResult r =
      test::runProcess({SGBAKE_CLI, "bake", scene, "--explain", "--no-manifest", "--out-dir",
                        (fs::temp_directory_path() / "sgbake_default_scene_explain").string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("4 of 4 outputs to bake"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("load image "), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n') > 5, true);
  // The bundled height map stays small.
  EXPECT_LT(fs::file_size(std::string(SGBAKE_MESHES) + "/height.png"), 300u * 1024u);
}

}  // namespace
}  // namespace sgbake
