// The malformed-mesh corpus: every file under tests/corpus/bad/ must fail with kBadInput and a
// one-line message naming the file, and the cases below must fail for the stated reason.
//
// Most files are a few lines of text (read them). The others were generated:
// - obj_garbage.obj: printf '\x7fELF\x02\x01\x01\x00...\nv 0 0 0\xff\xfe\x00\x01\n' (an ELF
// header);
// - ply_*_binary.ply, ply_trailing_bytes.ply, ply_binary_int_coordinates.ply: Python's struct,
//   a 4-vertex, 2-triangle little-endian mesh (truncated by 7 bytes, a NaN y, index 4, index -1,
//   4 extra bytes, int coordinates);
// - empty.obj: zero bytes.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "sgbake/mesh/io.hpp"

namespace sgbake {
namespace {

const std::filesystem::path kBadDir = std::filesystem::path(SGBAKE_TEST_DATA) / "corpus" / "bad";

// What each corpus file must be rejected for (a substring of the message, including the line).
const std::map<std::string, std::string>& expectedProblems() {
  static const std::map<std::string, std::string> problems = {
      {"empty.obj", "empty.obj: file is empty"},
      {"obj_bad_index.obj", ":4: face corner '3x' has an invalid vertex index"},
      {"obj_bad_number.obj", ":2: coordinate '1.0.0' is not a number"},
      {"obj_garbage.obj", ":1: binary data in a text file"},
      {"obj_index_out_of_range.obj",
       ":10: face corner refers to vertex 99 but only 3 vertices are defined"},
      {"obj_inf.obj", ":3: coordinate '-inf' is not a finite number"},
      {"obj_missing_vertex_index.obj", ":8: face corner '/1' has no vertex index"},
      {"obj_mixed_uv_face.obj", ":6: face gives texture coordinates to only some of its corners"},
      {"obj_nan.obj", ":2: coordinate 'nan' is not a finite number"},
      {"obj_no_faces.obj", "obj_no_faces.obj: mesh has no faces"},
      {"obj_old_mac_line_ends.obj", ":1: carriage return inside a line"},
      {"obj_overflow.obj", ":2: coordinate '1e999' is out of range for a float"},
      {"obj_relative_index_before_start.obj",
       ":4: face corner refers to vertex -4 but only 3 vertices are defined before this line"},
      {"obj_repeated_vertex.obj", ":5: face uses vertex 1 twice"},
      {"obj_truncated.obj", ":8: face corner '3/3/' ends with an empty index"},
      {"obj_two_coordinates.obj", ":1: vertex needs x, y and z"},
      {"obj_two_corner_face.obj", ":5: face has 2 corners (at least 3 are needed)"},
      {"obj_unknown_statement.obj", ":4: unknown OBJ statement 'vertex'"},
      {"obj_vn_out_of_range.obj",
       ":5: face corner refers to normal 5 but only 1 normal is defined"},
      {"obj_vt_one_component.obj", ":4: texture coordinate needs u and v"},
      {"obj_vt_out_of_range.obj",
       ":7: face corner refers to texture coordinate 7 but only 3 texture coordinates are defined"},
      {"obj_zero_index.obj", ":4: face corner '0' uses vertex index 0 (OBJ indices start at 1)"},
      {"obj_zero_normal.obj", ":4: normal has zero length"},
      {"off_4d.off", ":1: unsupported OFF variant '4OFF'"},
      {"off_bad_counts.off", ":2: OFF count 'x' is not a count"},
      {"off_binary.off", ":1: binary OFF is not supported"},
      {"off_extra_data.off", ":7: unexpected data after the last face"},
      {"off_index_out_of_range.off",
       ":8: face corner refers to vertex 4 but only 4 vertices are defined"},
      {"off_long_counts.off",
       ":2: OFF counts line has 6 values; it needs the vertex, face and edge counts alone (the "
       "vertices start on the next line)"},
      {"off_nan.off", ":4: coordinate 'NaN' is not a finite number"},
      {"off_one_line.off",
       ":1: OFF header has 23 values after the keyword; it needs the vertex, face and edge counts "
       "alone (the vertices start on the next line)"},
      {"off_no_faces.off", "off_no_faces.off: mesh has no faces"},
      {"off_short_vertex.off", ":5: OFF vertex needs 3 numbers, found 2"},
      {"off_truncated.off", ":8: file is truncated: it ends after 2 of 3 faces"},
      {"off_two_corner_face.off", ":8: face has 2 corners (at least 3 are needed)"},
      {"off_zero_normal.off", ":4: normal has zero length"},
      {"ply_bad_header.ply", ":4: unknown PLY type 'flaot'"},
      {"ply_binary_int_coordinates.ply",
       ".ply: binary PLY vertex property 'x' is int; positions, normals and UVs must be float"},
      {"ply_extra_data.ply", ":16: unexpected data after the last PLY element"},
      {"ply_face_texcoord_list.ply", ".ply: PLY face list property 'texcoord' is not supported"},
      {"ply_index_out_of_range.ply",
       ":15: face corner refers to vertex 7 but only 4 vertices are defined"},
      {"ply_index_out_of_range_binary.ply",
       ".ply: face 1: face corner refers to vertex 4 but only 4 vertices are defined"},
      {"ply_nan.ply", ":11: coordinate 'nan' is not a finite number"},
      {"ply_nan_binary.ply", ".ply: vertex 0: coordinate y is NaN"},
      {"ply_negative_index_binary.ply", ".ply: face 1: face corner refers to vertex -1"},
      {"ply_no_end_header.ply", ":7: unknown PLY header line '0 0 0'"},
      {"ply_no_faces.ply", "ply_no_faces.ply: mesh has no faces"},
      {"ply_repeated_vertex.ply", ":15: face uses vertex 0 twice"},
      {"ply_trailing_bytes.ply", ".ply: 4 bytes of unexpected data after the last PLY element"},
      {"ply_truncated_ascii.ply", ":15: file is truncated: it ends inside face 1"},
      {"ply_truncated_binary.ply", ".ply: file is truncated: it ends inside face 1"},
      {"ply_two_corner_face.ply", ":15: face has 2 corners (at least 3 are needed)"},
      {"ply_two_format_lines.ply", ":3: PLY header has a second format line"},
      {"ply_value_too_many_ascii.ply",
       ":19: file is truncated: it ends inside face 1 (the header declares 2); face 1 starts on "
       "line 17, where the one before it ends: that line may hold a value too many"},
      {"ply_zero_normal.ply", ":14: normal has zero length"},
      {"unknown_extension.stl", ".stl: unsupported file extension '.stl'"},
  };
  return problems;
}

std::vector<std::string> corpusFiles() {
  std::vector<std::string> names;
  if (!std::filesystem::is_directory(kBadDir)) return names;
  for (const auto& entry : std::filesystem::directory_iterator(kBadDir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(MeshBadInput, CorpusHoldsEveryRequiredCase) {
  const std::vector<std::string> files = corpusFiles();
  ASSERT_FALSE(files.empty()) << "no files in " << kBadDir;
  for (const char* required : {"obj_index_out_of_range.obj",
                               "obj_zero_index.obj",
                               "obj_missing_vertex_index.obj",
                               "obj_nan.obj",
                               "obj_inf.obj",
                               "obj_two_corner_face.obj",
                               "obj_vt_out_of_range.obj",
                               "obj_vn_out_of_range.obj",
                               "obj_repeated_vertex.obj",
                               "obj_garbage.obj",
                               "empty.obj",
                               "obj_no_faces.obj",
                               "obj_bad_number.obj",
                               "obj_truncated.obj",
                               "ply_truncated_binary.ply",
                               "ply_index_out_of_range.ply",
                               "ply_nan.ply",
                               "ply_bad_header.ply",
                               "off_truncated.off",
                               "off_index_out_of_range.off",
                               "off_two_corner_face.off",
                               "off_nan.off"}) {
    EXPECT_TRUE(std::find(files.begin(), files.end(), required) != files.end()) << required;
  }
  // Every file has a stated reason, and every stated reason has its file.
  for (const std::string& f : files) EXPECT_TRUE(expectedProblems().count(f)) << f;
  for (const auto& [f, problem] : expectedProblems()) {
    EXPECT_TRUE(std::find(files.begin(), files.end(), f) != files.end()) << f;
  }
}

class MeshBadCorpus : public testing::TestWithParam<std::string> {};

TEST_P(MeshBadCorpus, FailsWithOneLineNamingTheFileAndTheProblem) {
  const std::string name = GetParam();
  const std::filesystem::path path = kBadDir / name;
  const Result<Mesh> mesh = loadMesh(path);
  ASSERT_FALSE(mesh.ok()) << name << " loaded";
  const Error& error = mesh.error();
  EXPECT_EQ(error.code, ErrorCode::kBadInput) << error.message;
  EXPECT_EQ(error.message.find('\n'), std::string::npos) << error.message;
  EXPECT_EQ(error.message.rfind(path.string(), 0), 0u) << error.message;  // starts with the path
  const auto expected = expectedProblems().find(name);
  if (expected != expectedProblems().end()) {
    EXPECT_NE(error.message.find(expected->second), std::string::npos)
        << "message: " << error.message << "\nexpected: " << expected->second;
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, MeshBadCorpus, testing::ValuesIn(corpusFiles()),
                         [](const testing::TestParamInfo<std::string>& param) {
                           std::string id = param.param;
                           for (char& c : id) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return id;
                         });

TEST(MeshBadInput, MissingFileCannotBeOpened) {
  const std::filesystem::path path = kBadDir / "does_not_exist.obj";
  const Result<Mesh> mesh = loadMesh(path);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.error().code, ErrorCode::kBadInput);
  EXPECT_EQ(mesh.error().message.rfind(path.string() + ": cannot open file", 0), 0u)
      << mesh.error().message;
}

TEST(MeshBadInput, DirectoryCannotBeRead) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "sgbake_dir.obj";
  std::filesystem::create_directories(dir);
  const Result<Mesh> mesh = loadMesh(dir);
  std::filesystem::remove(dir);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.error().code, ErrorCode::kBadInput);
  EXPECT_EQ(mesh.error().message.rfind(dir.string() + ": cannot read file", 0), 0u)
      << mesh.error().message;
}

TEST(MeshBadInput, MemoryInputIsCheckedLikeFiles) {
  struct Case {
    std::string bytes, extension, expected;
  };
  const std::vector<Case> cases = {
      {"v 0 0 0\n", "stl", "m: unsupported file extension 'stl'"},
      {"", ".off", "m: file is empty"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n", "obj",
       "m:4: face corner refers to vertex 4 but only 3 vertices are defined"},
      {std::string("v 0 0 0\0\n", 10), "obj", "m:1: binary data in a text file (byte '\\x00')"},
      {"ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty float x\n"
       "property float y\nproperty float z\nelement face 1\nproperty list uchar int "
       "vertex_indices\n"
       "end_header\n",
       "ply", "m: file is truncated: it ends inside vertex 0 (the header declares 1000000)"},
  };
  for (const Case& c : cases) {
    const Result<Mesh> mesh = loadMeshFromMemory(c.bytes, c.extension, "m");
    ASSERT_FALSE(mesh.ok()) << c.expected;
    EXPECT_EQ(mesh.error().code, ErrorCode::kBadInput);
    EXPECT_EQ(mesh.error().message.rfind(c.expected, 0), 0u) << mesh.error().message;
  }
}

TEST(MeshBadInput, ControlCharactersInTheNameStayOnOneLine) {
  const Result<Mesh> mesh = loadMeshFromMemory("", "obj", "evil\nname.obj");
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.error().message, "evil?name.obj: file is empty");
}

}  // namespace
}  // namespace sgbake
