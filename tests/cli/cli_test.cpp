/// @file cli_test.cpp
/// @brief The `sgbake` executable as users run it: exit codes, one-line errors, CSV content,
/// all-or-nothing output files, --stats JSON, and every file of the bad-input corpus.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/files.hpp"
#include "run_process.hpp"
#include "sgbake/sgbake.h"

namespace sgbake {
namespace {

namespace fs = std::filesystem;
using test::listDirectory;
using test::readFile;
using test::writeFile;
using test::ProcessResult;

/// A quad, a triangle and a pentagon sharing edges, with a UV seam on the pentagon: 12 corners.
/// No normals, so the loader computes smooth ones.
constexpr const char* kSmallObj =
    "# three faces with UVs\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0.5\nv 2 1 0.5\nv 1.5 2 0.2\n"
    "vt 0 0\nvt 0.5 0\nvt 0.5 0.5\nvt 0 0.5\nvt 1 0\nvt 1 0.5\nvt 0.75 1\nvt 0.2 0.9\n"
    "f 1/1 2/2 3/3 4/4\n"
    "f 2/2 5/5 6/6\n"
    "f 2/2 6/6 7/7 3/3 4/8\n";
constexpr std::size_t kSmallObjCorners = 12;
constexpr std::size_t kSmallObjFaces = 3;

/// A valid mesh without texture coordinates: tangents cannot be computed.
constexpr const char* kNoUvObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// Checks the shape of every error report: exactly one line, `sgbake: error: ...`.
void expectOneErrorLine(const ProcessResult& r) {
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(r.err.starts_with("sgbake: error: ")) << r.err;
  EXPECT_TRUE(r.err.ends_with("\n")) << r.err;
}

/// One parsed CSV row.
struct Row {
  long face = -1, corner = -1;
  double t[3] = {};
  double sign = 0;
};

/// Parses the tangents CSV, checking the header and that every row has six fields.
std::vector<Row> parseCsv(const std::string& text) {
  std::vector<std::string> lines = splitLines(text);
  EXPECT_FALSE(lines.empty());
  if (lines.empty()) return {};
  EXPECT_EQ(lines[0], "face,corner,tx,ty,tz,sign");
  std::vector<Row> rows;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    Row row;
    char tail = 0;
    const int fields = std::sscanf(lines[i].c_str(), "%ld,%ld,%lf,%lf,%lf,%lf%c", &row.face,
                                   &row.corner, &row.t[0], &row.t[1], &row.t[2], &row.sign, &tail);
    EXPECT_EQ(fields, 6) << "line " << i + 1 << ": " << lines[i];
    rows.push_back(row);
  }
  return rows;
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("sgbake_cli_test-" + std::to_string(::getpid()) + "-" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  /// Runs `sgbake args...`.
  static ProcessResult sgbake(std::vector<std::string> args) {
    args.insert(args.begin(), SGBAKE_CLI);
    return test::runProcess(args);
  }

  /// Writes @p content to a file named @p name in the test's directory; returns its path.
  fs::path file(const std::string& name, const std::string& content) const {
    const fs::path path = dir_ / name;
    writeFile(path, content);
    return path;
  }

  fs::path dir_;
};

TEST_F(CliTest, HelpDescribesTheToolAndItsCommands) {
  const ProcessResult r = sgbake({"--help"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("Usage: sgbake"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tangents"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Exit codes"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");
}

TEST_F(CliTest, TangentsHelpListsOptionsWithDefaultsAndAnExample) {
  const ProcessResult r = sgbake({"tangents", "--help"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  for (const char* text : {"Usage: sgbake tangents", "MESH", "--output", "--uv N=0",
                           "--threads N=0", "--stats", "face,corner,tx,ty,tz,sign",
                           "Examples", "Exit codes"}) {
    EXPECT_NE(r.out.find(text), std::string::npos) << "missing '" << text << "' in\n" << r.out;
  }
}

TEST_F(CliTest, VersionPrintsTheLibraryVersion) {
  const ProcessResult r = sgbake({"--version"});
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_EQ(r.out, std::string("sgbake ") + sgbake_version() + "\n");
}

TEST_F(CliTest, UnknownCommandIsBadUsage) {
  const ProcessResult r = sgbake({"frobnicate", "x.obj"});
  EXPECT_EQ(r.exitCode, 2);
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find("frobnicate"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST_F(CliTest, NoCommandOrUnknownOptionIsBadUsage) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{}, {"--frobnicate"}, {"tangents"}, {"tangents", "--bogus", "a"},
        {"tangents", "a.obj", "b.obj"}, {"tangents", "a.obj", "--threads", "-1"},
        {"tangents", "a.obj", "--uv", "x"}}) {
    const ProcessResult r = sgbake(args);
    EXPECT_EQ(r.exitCode, 2) << testing::PrintToString(args);
    expectOneErrorLine(r);
  }
}

TEST_F(CliTest, MissingFileIsBadInputNamingTheFile) {
  const fs::path missing = dir_ / "no_such_mesh.obj";
  const ProcessResult r = sgbake({"tangents", missing.string()});
  EXPECT_EQ(r.exitCode, 2);
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find("no_such_mesh.obj"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST_F(CliTest, MeshWithoutUvsIsBadInputNamingTheFile) {
  const fs::path mesh = file("flat_no_uvs.obj", kNoUvObj);
  const ProcessResult r = sgbake({"tangents", mesh.string()});
  EXPECT_EQ(r.exitCode, 2);
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find("flat_no_uvs.obj"), std::string::npos) << r.err;
}

TEST_F(CliTest, MissingUvSetIsBadInputNamingTheFile) {
  const fs::path mesh = file("small.obj", kSmallObj);
  const ProcessResult r = sgbake({"tangents", mesh.string(), "--uv", "3"});
  EXPECT_EQ(r.exitCode, 2);
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find("small.obj"), std::string::npos) << r.err;
}

TEST_F(CliTest, WritesOneUnitTangentAndSignPerCorner) {
  const fs::path mesh = file("small.obj", kSmallObj);
  const ProcessResult r = sgbake({"tangents", mesh.string()});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err, "");

  const std::vector<Row> rows = parseCsv(r.out);
  ASSERT_EQ(rows.size(), kSmallObjCorners);
  // Faces in file order, each face's corners counted from 0.
  const long faceSizes[kSmallObjFaces] = {4, 3, 5};
  std::size_t i = 0;
  for (long f = 0; f < static_cast<long>(kSmallObjFaces); ++f) {
    for (long c = 0; c < faceSizes[f]; ++c, ++i) {
      EXPECT_EQ(rows[i].face, f);
      EXPECT_EQ(rows[i].corner, c);
    }
  }
  for (const Row& row : rows) {
    const double length = std::sqrt(row.t[0] * row.t[0] + row.t[1] * row.t[1] + row.t[2] * row.t[2]);
    EXPECT_NEAR(length, 1.0, 1e-6) << "face " << row.face << " corner " << row.corner;
    EXPECT_TRUE(row.sign == 1.0 || row.sign == -1.0) << row.sign;
  }
}

// A quad whose coordinates overflow single precision's squares (1e25) gets zero tangents, as
// it does in MikkTSpace; tangents and bake say so in one warning, the same quad at 1e18 not.
TEST_F(CliTest, CornersWithoutATangentAreAWarning) {
  const std::string quad =
      "v 0 0 0\nv S 0 0\nv S S 0\nv 0 S 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
  const auto scaled = [&](const std::string& scale) {
    std::string text = quad;
    for (std::size_t at = text.find('S'); at != std::string::npos; at = text.find('S', at)) {
      text.replace(at, 1, scale);
    }
    return text;
  };
  const fs::path huge = file("huge.obj", scaled("1e25"));
  const std::string warning = "sgbake: warning: " + huge.string() +
                              ": 4 of 4 face corners have no tangent (MikkTSpace found no usable "
                              "position and UV differences there: triangles of zero area in "
                              "space or in UV, as a large polygon's slivers or coordinates beyond "
                              "~1e19 that overflow single precision make them): tangent-space "
                              "values there mean nothing\n";
  const ProcessResult tangents = sgbake({"tangents", huge.string()});
  ASSERT_EQ(tangents.exitCode, 0) << tangents.err;
  EXPECT_EQ(tangents.err, warning);
  const ProcessResult bake = sgbake({"bake", "--mesh", huge.string(), "--map", "tangent", "--size",
                                     "8", "--no-manifest", "-o", (dir_ / "t.exr").string()});
  ASSERT_EQ(bake.exitCode, 0) << bake.err;
  EXPECT_EQ(bake.err, warning);
  const ProcessResult large = sgbake({"tangents", file("large.obj", scaled("1e18")).string()});
  ASSERT_EQ(large.exitCode, 0) << large.err;
  EXPECT_EQ(large.err, "");
}

TEST_F(CliTest, FileOutputEqualsStdoutAndLeavesNoTemporaryFiles) {
  const fs::path mesh = file("small.obj", kSmallObj);
  const ProcessResult toStdout = sgbake({"tangents", mesh.string()});
  ASSERT_EQ(toStdout.exitCode, 0) << toStdout.err;

  const fs::path out = file("out.csv", "an older file that must be replaced\n");
  const ProcessResult toFile = sgbake({"tangents", mesh.string(), "-o", out.string()});
  ASSERT_EQ(toFile.exitCode, 0) << toFile.err;
  EXPECT_EQ(toFile.out, "");
  EXPECT_EQ(readFile(out), toStdout.out);
  EXPECT_EQ(listDirectory(dir_), (std::set<std::string>{"small.obj", "out.csv"}));
}

TEST_F(CliTest, OutputIsTheSameForAnyNumberOfThreads) {
  const fs::path mesh = file("small.obj", kSmallObj);
  const ProcessResult one = sgbake({"tangents", mesh.string(), "--threads", "1"});
  const ProcessResult all = sgbake({"tangents", mesh.string(), "--threads", "0"});
  const ProcessResult four = sgbake({"tangents", mesh.string(), "--threads", "4"});
  ASSERT_EQ(one.exitCode, 0) << one.err;
  EXPECT_EQ(one.out, all.out);
  EXPECT_EQ(one.out, four.out);
}

TEST_F(CliTest, FailureLeavesAnExistingOutputByteIdenticalAndNoTemporaryFiles) {
  const std::string precious = "face,corner,tx,ty,tz,sign\n0,0,1,0,0,1\nprecious bytes\n";
  const fs::path out = file("out.csv", precious);
  const fs::path noUvs = file("no_uvs.obj", kNoUvObj);
  const fs::path missing = dir_ / "missing.obj";

  for (const fs::path& input : {noUvs, missing}) {
    const ProcessResult r = sgbake({"tangents", input.string(), "-o", out.string()});
    EXPECT_EQ(r.exitCode, 2) << input;
    expectOneErrorLine(r);
    EXPECT_EQ(readFile(out), precious);
    EXPECT_EQ(listDirectory(dir_), (std::set<std::string>{"out.csv", "no_uvs.obj"}));
  }
}

TEST_F(CliTest, UnwritableOutputIsBadInputNamingThePath) {
  const fs::path mesh = file("small.obj", kSmallObj);
  const fs::path out = dir_ / "no_such_dir" / "out.csv";
  const ProcessResult r = sgbake({"tangents", mesh.string(), "-o", out.string()});
  EXPECT_EQ(r.exitCode, 2);
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find(out.string()), std::string::npos) << r.err;

  const ProcessResult onDirectory = sgbake({"tangents", mesh.string(), "-o", dir_.string()});
  EXPECT_EQ(onDirectory.exitCode, 2);
  expectOneErrorLine(onDirectory);
  EXPECT_EQ(listDirectory(dir_), (std::set<std::string>{"small.obj"}));
}

TEST_F(CliTest, StatsAreOneLineOfJsonOnStderr) {
  const fs::path mesh = file("small.obj", kSmallObj);
  const fs::path out = dir_ / "out.csv";
  const ProcessResult r =
      sgbake({"tangents", mesh.string(), "-o", out.string(), "--stats", "--threads", "1"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  ASSERT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;

  const nlohmann::json stats = nlohmann::json::parse(r.err);  // throws (fails) if not JSON
  ASSERT_TRUE(stats.is_object());
  for (const char* key : {"load_s", "tangents_s", "write_s", "total_s"}) {
    ASSERT_TRUE(stats.contains(key) && stats[key].is_number()) << key << " in " << r.err;
    EXPECT_GE(stats[key].get<double>(), 0.0) << key;
  }
  EXPECT_GE(stats["total_s"].get<double>(), stats["load_s"].get<double>());
  EXPECT_EQ(stats["corners"], kSmallObjCorners);
  EXPECT_EQ(stats["faces"], kSmallObjFaces);
  EXPECT_EQ(stats["threads"], 1);
}

/// Every file of tests/corpus/bad/ is rejected the same way: exit 2, one line naming the file,
/// no output file. (The corpus grows independently of this test; an empty one is fine.)
TEST_F(CliTest, EveryBadCorpusFileIsRejectedCleanly) {
  const fs::path corpus = fs::path(SGBAKE_TEST_DATA) / "corpus" / "bad";
  if (!fs::is_directory(corpus)) GTEST_SKIP() << corpus << " does not exist yet";

  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(corpus)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  const fs::path out = dir_ / "out.csv";
  for (const fs::path& bad : files) {
    SCOPED_TRACE(bad.string());
    const ProcessResult r = sgbake({"tangents", bad.string(), "-o", out.string()});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    expectOneErrorLine(r);
    EXPECT_NE(r.err.find(bad.filename().string()), std::string::npos) << r.err;
    EXPECT_TRUE(listDirectory(dir_).empty()) << "output or temporary file left behind";
  }
}

}  // namespace
}  // namespace sgbake
