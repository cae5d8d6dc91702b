// PLY (ASCII, binary little and big endian) and OFF loading. The quad_tri files in
// tests/corpus/good/ hold one mesh (a quad and a triangle with per-vertex normals and UVs) in
// five encodings; the binary ones were written with Python's struct module from the same values
// as quad_tri_ascii.ply, with different list types (uint/int little endian, ushort/uint big
// endian), colours, a face property after vertex_indices, an edge element after the faces and a
// comment right before end_header (OpenMesh 9.0 mis-seeks the binary body after one).

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "sgbake/mesh/io.hpp"
#include "sgbake/mesh/normals.hpp"

namespace sgbake {
namespace {

std::string goodFile(const std::string& name) {
  return std::string(SGBAKE_TEST_DATA) + "/corpus/good/" + name;
}

Mesh load(const std::string& path) {
  Result<Mesh> mesh = loadMesh(path);
  EXPECT_TRUE(mesh.ok()) << (mesh.ok() ? "" : mesh.error().message);
  return mesh.ok() ? std::move(mesh).value() : Mesh{};
}

Mesh loadText(const std::string& text, const std::string& extension) {
  Result<Mesh> mesh = loadMeshFromMemory(text, extension, "inline." + extension);
  EXPECT_TRUE(mesh.ok()) << (mesh.ok() ? "" : mesh.error().message);
  return mesh.ok() ? std::move(mesh).value() : Mesh{};
}

template <class V>
bool sameBits(const std::vector<V>& a, const std::vector<V>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(V)) == 0;
}

void expectSameMesh(const Mesh& a, const Mesh& b) {
  EXPECT_TRUE(sameBits(a.positions, b.positions));
  EXPECT_EQ(a.faceStart, b.faceStart);
  EXPECT_EQ(a.cornerVertex, b.cornerVertex);
  EXPECT_TRUE(sameBits(a.cornerNormals, b.cornerNormals));
  ASSERT_EQ(a.uvSets.size(), b.uvSets.size());
  for (std::size_t s = 0; s < a.uvSets.size(); ++s) {
    EXPECT_TRUE(sameBits(a.uvSets[s].uvs, b.uvSets[s].uvs));
  }
  EXPECT_EQ(a.normalSource, b.normalSource);
}

// What quad_tri_*.ply and quad_tri.off contain, per vertex.
struct QuadTri {
  std::vector<Vec3f> positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0.5f, 0.25f}};
  std::vector<Vec3f> normals = {{0, 0, 1}, {0, 0, 2}, {0, 0.6f, 0.8f}, {0, 0, 1}, {0.6f, 0, 0.8f}};
  std::vector<Vec2f> uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5f, 0.1f}};
  std::vector<std::uint32_t> corners = {0, 1, 2, 3, 1, 4, 2};
};

TEST(MeshPly, AsciiMatchesTheFileContent) {
  const Mesh mesh = load(goodFile("quad_tri_ascii.ply"));
  const QuadTri expected;
  EXPECT_EQ(mesh.positions, expected.positions);
  EXPECT_EQ(mesh.faceStart, (std::vector<std::uint32_t>{0, 4, 7}));
  EXPECT_EQ(mesh.cornerVertex, expected.corners);
  EXPECT_EQ(mesh.normalSource, NormalSource::kFile);
  ASSERT_EQ(mesh.uvSets.size(), 1u);
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    const std::uint32_t v = mesh.cornerVertex[c];
    // Per-vertex values reach every corner of the vertex. Normals that are unit within float
    // rounding are kept as written; (0, 0, 2) is renormalized.
    const Vec3f n = v == 1 ? Vec3f{0, 0, 1} : expected.normals[v];
    EXPECT_EQ(mesh.cornerNormals[c], n) << "corner " << c;
    EXPECT_EQ(mesh.uvSets[0].uvs[c], expected.uvs[v]);
  }
}

TEST(MeshPly, AsciiBinaryLittleAndBigEndianGiveIdenticalMeshes) {
  const Mesh ascii = load(goodFile("quad_tri_ascii.ply"));
  ASSERT_EQ(ascii.numFaces(), 2u);
  expectSameMesh(load(goodFile("quad_tri_binary_le.ply")), ascii);
  expectSameMesh(load(goodFile("quad_tri_binary_be.ply")), ascii);
}

TEST(MeshPly, BinaryDoublesAreRoundedToFloat) {
  // Built here: little-endian doubles for x y z (OpenMesh reads and rounds them to float).
  const double xs[3] = {0.1, 1.0 / 3.0, -2.5e-3};
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n"
      "property double y\nproperty double z\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n";
  static_assert(std::endian::native == std::endian::little, "the bytes below are native");
  for (int v = 0; v < 3; ++v) {
    const double p[3] = {xs[v], double(v == 1), double(v == 2)};
    ply.append(reinterpret_cast<const char*>(p), sizeof p);
  }
  const unsigned char count = 3;
  const std::int32_t indices[3] = {0, 1, 2};
  ply.append(reinterpret_cast<const char*>(&count), 1);
  ply.append(reinterpret_cast<const char*>(indices), sizeof indices);
  const Mesh mesh = loadText(ply, "ply");
  ASSERT_EQ(mesh.numVertices(), 3u);
  for (int v = 0; v < 3; ++v) EXPECT_EQ(mesh.positions[v].x, static_cast<float>(xs[v]));
}

TEST(MeshPly, AliasesCrlfHeaderAndVertexIndexName) {
  const Mesh mesh = loadText(
      "ply\r\nformat ascii 1.0\r\nobj_info from a Windows tool\r\nelement vertex 3\r\n"
      "property float x\r\nproperty float y\r\nproperty float z\r\nproperty float texture_u\r\n"
      "property float texture_v\r\nelement face 1\r\nproperty list uchar int vertex_index\r\n"
      "end_header\r\n0 0 0 0 0\r\n1 0 0 1 0\r\n0 1 0 0 1\r\n3 0 1 2\r\n",
      "ply");
  ASSERT_EQ(mesh.uvSets.size(), 1u);
  EXPECT_EQ(mesh.uvSets[0].uvs, (std::vector<Vec2f>{{0, 0}, {1, 0}, {0, 1}}));
  EXPECT_EQ(mesh.normalSource, NormalSource::kComputed);
}

TEST(MeshOff, StcnoffMatchesThePly) {
  // quad_tri.off: texcoords, colours (4 values), normals, comments, a face colour.
  expectSameMesh(load(goodFile("quad_tri.off")), load(goodFile("quad_tri_ascii.ply")));
}

TEST(MeshOff, VariantsKeepTheirNormalsAndUvs) {
  const std::string points = "0 0 0\n1 0 0\n0 1 0\n";
  const Mesh plain = loadText("OFF\n3 1 0\n" + points + "3 0 1 2\n", "off");
  EXPECT_EQ(plain.normalSource, NormalSource::kComputed);
  EXPECT_TRUE(plain.uvSets.empty());

  const Mesh noff =
      loadText("NOFF\n3 1 0\n0 0 0 0 0.6 0.8\n1 0 0 0 0.6 0.8\n0 1 0 0 0.6 0.8\n3 0 1 2\n", "off");
  EXPECT_EQ(noff.normalSource, NormalSource::kFile);
  for (const Vec3f& n : noff.cornerNormals) EXPECT_EQ(n, (Vec3f{0, 0.6f, 0.8f}));

  const Mesh stoff =
      loadText("STOFF\n3 1 0\n0 0 0 0.5 0.25\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n", "off");
  ASSERT_EQ(stoff.uvSets.size(), 1u);
  EXPECT_EQ(stoff.uvSets[0].uvs, (std::vector<Vec2f>{{0.5f, 0.25f}, {1, 0}, {0, 1}}));

  const Mesh coff = loadText(
      "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0.5 0.5 0.5 1\n0 1 0 7\n"
      "3 0 1 2 0 0 255\n",
      "off");
  expectSameMesh(coff, plain);

  // A NOFF read right after a plain OFF must still have its normals (OpenMesh's OFF reader
  // would reuse the previous file's header flags).
  const Mesh again =
      loadText("NOFF\n3 1 0\n0 0 0 0 0.6 0.8\n1 0 0 0 0.6 0.8\n0 1 0 0 0.6 0.8\n3 0 1 2\n", "off");
  expectSameMesh(again, noff);
}

TEST(MeshOff, OctahedronWithCountsOnTheHeaderLine) {
  const Mesh mesh = load(goodFile("octahedron.off"));
  EXPECT_EQ(mesh.numVertices(), 6u);
  EXPECT_EQ(mesh.numFaces(), 8u);
  // Every face is outward: its normal points away from the origin.
  const std::vector<Vec3f> faceNormals = computeFaceNormals(mesh.view());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const Vec3f p = mesh.positions[mesh.cornerVertex[mesh.faceStart[f]]];
    EXPECT_GT(dot(faceNormals[f], p), 0.0f) << "face " << f;
  }
}

TEST(MeshCorpus, EveryGoodFileLoadsAndIsValid) {
  int count = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(SGBAKE_TEST_DATA) + "/corpus/good")) {
    Result<Mesh> mesh = loadMesh(entry.path());
    ASSERT_TRUE(mesh.ok()) << mesh.error().message;
    EXPECT_TRUE(validate(*mesh).ok()) << entry.path();
    ++count;
  }
  EXPECT_GE(count, 9);
}

}  // namespace
}  // namespace sgbake
