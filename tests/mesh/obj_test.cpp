// OBJ loading: per-corner UVs and normals, polygon sizes and corner order, relative indices,
// ignored statements, exact float round trips, and the OpenMesh behaviours the loader works around.
// Files under tests/corpus/good/ describe themselves in their first lines.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
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

Mesh loadObjText(const std::string& text, const LoadOptions& options = {}) {
  Result<Mesh> mesh = loadMeshFromMemory(text, "obj", "inline.obj", options);
  EXPECT_TRUE(mesh.ok()) << (mesh.ok() ? "" : mesh.error().message);
  return mesh.ok() ? std::move(mesh).value() : Mesh{};
}

std::uint32_t bits(float f) { return std::bit_cast<std::uint32_t>(f); }

// Every array of two meshes, compared bit for bit.
void expectSameMesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t v = 0; v < a.positions.size(); ++v) {
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(bits(a.positions[v][k]), bits(b.positions[v][k])) << "vertex " << v;
    }
  }
  EXPECT_EQ(a.faceStart, b.faceStart);
  EXPECT_EQ(a.cornerVertex, b.cornerVertex);
  ASSERT_EQ(a.cornerNormals.size(), b.cornerNormals.size());
  for (std::size_t c = 0; c < a.cornerNormals.size(); ++c) {
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(bits(a.cornerNormals[c][k]), bits(b.cornerNormals[c][k])) << "corner " << c;
    }
  }
  ASSERT_EQ(a.uvSets.size(), b.uvSets.size());
  for (std::size_t s = 0; s < a.uvSets.size(); ++s) {
    EXPECT_EQ(a.uvSets[s].name, b.uvSets[s].name);
    ASSERT_EQ(a.uvSets[s].uvs.size(), b.uvSets[s].uvs.size());
    for (std::size_t c = 0; c < a.uvSets[s].uvs.size(); ++c) {
      EXPECT_EQ(bits(a.uvSets[s].uvs[c].x), bits(b.uvSets[s].uvs[c].x)) << "corner " << c;
      EXPECT_EQ(bits(a.uvSets[s].uvs[c].y), bits(b.uvSets[s].uvs[c].y)) << "corner " << c;
    }
  }
  EXPECT_EQ(a.normalSource, b.normalSource);
}

TEST(MeshObj, SmoothingStatementsMarkFlatFacesAsBlendersImporterDoes) {
  // Blender 3.4's importer (measured): faces before any `s` are flat; `s N` with N > 0 smooth;
  // `s 0`, `s off` and even `s on` (not a number) flat. A file without `s` says nothing:
  // every face smooth (faceFlat empty).
  const std::string vertices = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  const Mesh marked = loadObjText(vertices +
                                  "f 1 2 3\ns 1\nf 1 3 4\ns off\nf 1 2 4\ns 0\nf 2 3 4\n"
                                  "s 2\nf 1 2 3\ns on\nf 1 3 4\n");
  EXPECT_EQ(marked.faceFlat, (std::vector<std::uint8_t>{1, 0, 1, 1, 0, 1}));
  EXPECT_TRUE(marked.isFlat(0));
  EXPECT_FALSE(marked.isFlat(1));
  const Mesh unmarked = loadObjText(vertices + "f 1 2 3\nf 1 3 4\n");
  EXPECT_TRUE(unmarked.faceFlat.empty());
  EXPECT_FALSE(unmarked.isFlat(0));
  // The writer marks them the same way, so they survive a round trip.
  EXPECT_EQ(loadObjText(formatObj(marked)).faceFlat, marked.faceFlat);
  EXPECT_EQ(formatObj(unmarked).find("\ns "), std::string::npos);
}

// `usemtl` gives each face the index of its material name, numbered in order of first
// appearance (faces before any `usemtl` get the name ""); a file without `usemtl` has none.
// The writer names every material first, in index order, so indices survive a round trip
// whatever order the faces come in.
TEST(MeshObj, UsemtlNumbersMaterialsInOrderOfFirstAppearance) {
  const std::string vertices = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  const Mesh named = loadObjText(vertices +
                                 "f 1 2 3\nusemtl Skin\nf 1 3 4\nusemtl Cloth Fine\nf 1 2 4\n"
                                 "usemtl Skin\nf 2 3 4\n");
  EXPECT_EQ(named.faceMaterial, (std::vector<std::uint32_t>{0, 1, 2, 1}));
  EXPECT_EQ(named.materialNames, (std::vector<std::string>{"", "Skin", "Cloth Fine"}));
  EXPECT_EQ(named.material(2), 2u);
  const Mesh none = loadObjText(vertices + "f 1 2 3\nf 1 3 4\n");
  EXPECT_TRUE(none.faceMaterial.empty());
  EXPECT_EQ(none.material(1), 0u);
  Mesh reordered = named;
  reordered.faceMaterial = {2, 0, 1, 2};
  EXPECT_EQ(loadObjText(formatObj(reordered)).faceMaterial, reordered.faceMaterial);
  Result<Mesh> bad = loadMeshFromMemory(vertices + "usemtl\nf 1 2 3\n", "obj", "bad.obj");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("usemtl without a material name"), std::string::npos)
      << bad.error().message;
}

TEST(MeshObj, NormalsThatOnlyAutoSmoothMakesSayItIsOn) {
  // Two triangles of a square, z up. Without Blender's Auto Smooth a flat face's corners carry
  // its polygon normal and a vertex's smooth corners share one normal; anything else in the
  // file is split or custom normals, which need Auto Smooth (Cycles then shades flat faces
  // with them).
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvn 0.1 0 0.995\n";
  const Mesh flat = loadObjText(square + "s 0\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n");
  EXPECT_FALSE(flat.autoSmooth);
  const Mesh smooth = loadObjText(square + "s 1\nf 1//1 2//1 3//2\nf 1//1 3//2 4//1\n");
  EXPECT_FALSE(smooth.autoSmooth) << "vertex 3 has one normal on both faces";
  const Mesh split = loadObjText(square + "s 1\nf 1//1 2//1 3//2\nf 1//1 3//1 4//1\n");
  EXPECT_TRUE(split.autoSmooth) << "vertex 3 has two normals";
  const Mesh custom = loadObjText(square + "s 0\nf 1//1 2//1 3//2\nf 1//1 3//1 4//1\n");
  EXPECT_TRUE(custom.autoSmooth) << "a flat face's corner off its polygon normal";
  EXPECT_FALSE(loadObjText(square + "s 0\nf 1 2 3\nf 1 3 4\n").autoSmooth) << "no normals";
}

TEST(MeshObj, WithoutNormalsFlatFacesAreShadedFlat) {
  // Blender 3.4 imports an OBJ without `vn` with the normals it computes: a face after `s off`
  // gets its own face normal (measured: the cube of flat quads imports with loop normals equal
  // to its faces'), a smooth one the vertex normal.
  const std::string cube =
      "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\n"
      "v -1 1 1\n";
  const std::string faces =
      "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\n"
      "f 4 1 5 8\n";
  const Mesh flat = loadObjText(cube + "s off\n" + faces);
  ASSERT_EQ(flat.cornerNormals.size(), 24u);
  const std::vector<Vec3f> faceNormals = computeFaceNormals(flat.view());
  for (std::size_t f = 0; f < flat.numFaces(); ++f) {
    for (std::uint32_t c = flat.faceStart[f]; c < flat.faceStart[f + 1]; ++c) {
      EXPECT_EQ(flat.cornerNormals[c], faceNormals[f]) << "face " << f << ", corner " << c;
    }
  }
  EXPECT_EQ(faceNormals[0], (Vec3f{0, 0, -1}));
  // `s 1`: the corners of a vertex share its (diagonal) normal.
  const Mesh smooth = loadObjText(cube + "s 1\n" + faces);
  EXPECT_NEAR(smooth.cornerNormals[0].x, -1 / std::sqrt(3.0f), 1e-6f);
  EXPECT_EQ(smooth.cornerNormals[0], smooth.cornerNormals[8]);  // vertex 1 in faces 0 and 2
}

TEST(MeshObj, SeamKeepsBothUvsOfASharedVertex) {
  const Mesh mesh = load(goodFile("seam.obj"));
  ASSERT_EQ(mesh.numFaces(), 2u);
  ASSERT_EQ(mesh.uvSets.size(), 1u);
  EXPECT_EQ(mesh.uvSets[0].name, "UVMap");
  const std::vector<Vec2f>& uv = mesh.uvSets[0].uvs;
  // The file: f 1/1 2/2 3/3 and f 2/5 4/7 3/6 with vt 2 = (0.5, 0), vt 5 = (1, 0.75), ...
  const std::vector<std::uint32_t> corners = {0, 1, 2, 1, 3, 2};
  const std::vector<Vec2f> expected = {{0, 0},     {0.5f, 0}, {0, 0.5f},
                                       {1, 0.75f}, {1, 1},    {0.75f, 1}};
  EXPECT_EQ(mesh.cornerVertex, corners);
  for (std::size_t c = 0; c < expected.size(); ++c) EXPECT_EQ(uv[c], expected[c]) << "corner " << c;
  // The shared vertices 2 and 3 (1 and 2 from 0) carry two different UVs, one per face.
  EXPECT_NE(uv[1], uv[3]);
  EXPECT_NE(uv[2], uv[5]);
}

TEST(MeshObj, FlatCubeKeepsThreeNormalsAtEveryCorner) {
  const Mesh mesh = load(goodFile("cube_flat.obj"));
  ASSERT_EQ(mesh.numVertices(), 8u);
  ASSERT_EQ(mesh.numFaces(), 6u);
  EXPECT_EQ(mesh.normalSource, NormalSource::kFile);
  const std::vector<Vec3f> faceNormals = computeFaceNormals(mesh.view());
  std::vector<std::set<std::tuple<float, float, float>>> normalsAtVertex(mesh.numVertices());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    // The file's vn is the outward axis of each face: the geometric normal of an axis-aligned face.
    for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
      EXPECT_EQ(mesh.cornerNormals[c], faceNormals[f]) << "face " << f;
      const Vec3f n = mesh.cornerNormals[c];
      normalsAtVertex[mesh.cornerVertex[c]].insert({n.x, n.y, n.z});
    }
  }
  for (std::size_t v = 0; v < mesh.numVertices(); ++v) {
    EXPECT_EQ(normalsAtVertex[v].size(), 3u) << "vertex " << v;
  }
}

TEST(MeshObj, QuadPentagonTriangleKeepSizesAndFileCornerOrder) {
  const Mesh mesh = load(goodFile("polygons.obj"));
  ASSERT_EQ(mesh.numFaces(), 3u);
  EXPECT_EQ(mesh.faceSize(0), 4u);
  EXPECT_EQ(mesh.faceSize(1), 5u);
  EXPECT_EQ(mesh.faceSize(2), 3u);
  // f 3 4 1 2 / f 5 6 7 3 2 / f 7 8 3, from 1 in the file, from 0 in the mesh.
  const std::vector<std::uint32_t> expected = {2, 3, 0, 1, 4, 5, 6, 2, 1, 6, 7, 2};
  ASSERT_EQ(mesh.cornerVertex, expected);
  ASSERT_EQ(mesh.uvSets.size(), 1u);
  // Every corner's UV is its vertex's position / 4 (the file is written that way).
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    const Vec3f p = mesh.positions[mesh.cornerVertex[c]];
    EXPECT_EQ(mesh.uvSets[0].uvs[c], (Vec2f{p.x / 4, p.y / 4})) << "corner " << c;
  }
  EXPECT_EQ(mesh.source, goodFile("polygons.obj"));
}

TEST(MeshObj, CrlfBomContinuationsAndIgnoredStatementsLoadLikeThePlainFile) {
  expectSameMesh(load(goodFile("statements_crlf.obj")), load(goodFile("polygons.obj")));
}

TEST(MeshObj, CommentEndingWithABackslashDoesNotContinue) {
  const Mesh mesh =
      loadObjText("# exported from C:\\models\\\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(mesh.numVertices(), 3u);
  EXPECT_EQ(mesh.numFaces(), 1u);
}

TEST(MeshObj, NegativeIndicesCountBackFromTheLastDefinedElement) {
  const std::string positive =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\n"
      "v 1 1 0\nvt 1 1\nf 2/2/1 4/4/1 3/3/1\n";
  const std::string negative =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf -3/-3/-1 -2/-2/-1 -1/-1/-1\n"
      "v 1 1 0\nvt 1 1\nf -3/-3/-1 -1/-1/-1 -2/-2/-1\n";
  expectSameMesh(loadObjText(negative), loadObjText(positive));
}

TEST(MeshObj, NineDigitFloatsRoundTripBitExact) {
  // Random finite floats over the whole range (denormals, signed zeros, huge values), printed
  // with %.9g, must load with exactly the same bits: positions, UVs and unit normals.
  std::mt19937 random(20240611u);
  std::uniform_int_distribution<std::uint32_t> anyBits;
  auto randomFloat = [&] {
    for (;;) {
      const float f = std::bit_cast<float>(anyBits(random));
      if (std::isfinite(f)) return f;
    }
  };
  auto print = [](float f) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.9g", static_cast<double>(f));
    return std::string(buffer);
  };
  constexpr int kTriangles = 300;
  std::vector<float> values;
  std::vector<Vec3f> normals;
  std::ostringstream obj;
  for (int i = 0; i < 3 * kTriangles; ++i) {
    const Vec3f p{randomFloat(), randomFloat(), randomFloat()};
    values.insert(values.end(), {p.x, p.y, p.z});
    obj << "v " << print(p.x) << ' ' << print(p.y) << ' ' << print(p.z) << '\n';
  }
  std::vector<Vec2f> uvs;
  for (int i = 0; i < 3 * kTriangles; ++i) {
    uvs.push_back({randomFloat(), randomFloat()});
    obj << "vt " << print(uvs.back().x) << ' ' << print(uvs.back().y) << '\n';
  }
  std::normal_distribution<float> gaussian;
  for (int i = 0; i < 3 * kTriangles; ++i) {
    // A unit vector rounded to float: its length is 1 within the loader's tolerance.
    const Vec3d d{gaussian(random), gaussian(random), gaussian(random)};
    const Vec3f n = cast<float>((1.0 / length(d)) * d);
    normals.push_back(n);
    obj << "vn " << print(n.x) << ' ' << print(n.y) << ' ' << print(n.z) << '\n';
  }
  for (int t = 0; t < kTriangles; ++t) {
    obj << 'f';
    for (int k = 1; k <= 3; ++k)
      obj << ' ' << (3 * t + k) << '/' << (3 * t + k) << '/' << (3 * t + k);
    obj << '\n';
  }
  const Mesh mesh = loadObjText(obj.str());
  ASSERT_EQ(mesh.numVertices(), values.size() / 3);
  for (std::size_t v = 0; v < mesh.numVertices(); ++v) {
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(bits(mesh.positions[v][k]), bits(values[3 * v + k])) << print(values[3 * v + k]);
    }
  }
  ASSERT_EQ(mesh.numCorners(), uvs.size());
  ASSERT_EQ(mesh.uvSets.size(), 1u);
  ASSERT_EQ(mesh.normalSource, NormalSource::kFile);
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    EXPECT_EQ(bits(mesh.uvSets[0].uvs[c].x), bits(uvs[c].x));
    EXPECT_EQ(bits(mesh.uvSets[0].uvs[c].y), bits(uvs[c].y));
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(bits(mesh.cornerNormals[c][k]), bits(normals[c][k])) << "corner " << c;
    }
  }
}

TEST(MeshObj, NumbersAreParsedStraightToFloatLikeOpenMesh) {
  // Just above the midpoint between 1 and the next float: rounding straight to float gives the
  // next float; rounding to double first lands exactly on the midpoint and then ties to 1.
  const Mesh mesh =
      loadObjText("v 1.00000005960464477539062500000001 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ASSERT_EQ(mesh.numVertices(), 3u);
  EXPECT_EQ(mesh.positions[0].x, std::nextafter(1.0f, 2.0f));
}

TEST(MeshObj, FacesWithoutVtGetUvZeroInAFileWithUvs) {
  const Mesh mesh = loadObjText(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0.25 0.5\nvt 0.75 0.5\nvt 0.5 1\n"
      "f 1/1 2/2 3/3\nf 2 4 3\n");
  ASSERT_EQ(mesh.uvSets.size(), 1u);
  const std::vector<Vec2f> expected = {{0.25f, 0.5f}, {0.75f, 0.5f}, {0.5f, 1},
                                       {0, 0},        {0, 0},        {0, 0}};
  EXPECT_EQ(mesh.uvSets[0].uvs, expected);
}

TEST(MeshObj, UnreferencedVtMeansNoUvs) {
  LoadOptions requireUvs;
  requireUvs.requireUvs = true;
  const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1 2 3\n";
  EXPECT_TRUE(loadObjText(text).uvSets.empty());
  Result<Mesh> mesh = loadMeshFromMemory(text, ".OBJ", "no_uvs.obj", requireUvs);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.error().code, ErrorCode::kBadInput);
  EXPECT_EQ(mesh.error().message,
            "no_uvs.obj: mesh has no texture coordinates (UVs are required for tangents)");
}

TEST(MeshObj, AnyCornerWithoutVnMeansComputedNormals) {
  // The first face has a (deliberately tilted) file normal, the second none: the file's normals
  // are ignored and every corner gets the computed smooth normal.
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0.6 0 0.8\nf 1//1 2//1 3//1\nf 2 4 3\n";
  Mesh mesh = loadObjText(text);
  EXPECT_EQ(mesh.normalSource, NormalSource::kComputed);
  Mesh expected = mesh;
  computeSmoothNormals(expected);
  EXPECT_EQ(mesh.cornerNormals, expected.cornerNormals);
  for (const Vec3f& n : mesh.cornerNormals) EXPECT_EQ(n, (Vec3f{0, 0, 1}));
}

TEST(MeshObj, FileNormalsAreNormalizedOnlyBeyondTheTolerance) {
  // (0, 0, 2) is renormalized; 0.6/0.8 rounded to float is unit within float rounding and kept
  // bit for bit; Blender's 4-decimal normals (length 1.00003) are renormalized.
  const Mesh mesh = loadObjText(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nvn 0 0.6 0.8\nvn 0.5774 0.5774 0.5774\n"
      "f 1//1 2//2 3//3\n");
  ASSERT_EQ(mesh.cornerNormals.size(), 3u);
  EXPECT_EQ(mesh.cornerNormals[0], (Vec3f{0, 0, 1}));
  EXPECT_EQ(mesh.cornerNormals[1], (Vec3f{0, 0.6f, 0.8f}));
  const float third = static_cast<float>(1 / std::sqrt(3.0));
  EXPECT_NEAR(mesh.cornerNormals[2].x, third, 1e-7);
  EXPECT_NE(mesh.cornerNormals[2].x, 0.5774f);
  EXPECT_TRUE(validate(mesh).ok());
}

TEST(MeshObj, NonManifoldFacesKeepFileVerticesUvsAndSilence) {
  // Three faces on the edge 1-3 make it non-manifold: OpenMesh 9.0 adds the later faces on
  // copies of their vertices, prints "complex edge" and stores their UVs rotated by one corner.
  // The loader maps the copies back to the file's vertices and reads every UV from its corner.
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 1\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
      "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\nf 3/4 1/5 5/2\nf 1/4 2/3 4/1\n";
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  const Mesh mesh = loadObjText(text);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  ASSERT_EQ(mesh.numVertices(), 5u);
  ASSERT_EQ(mesh.uvSets.size(), 1u);
  const std::vector<std::uint32_t> corners = {0, 1, 2, 0, 2, 3, 2, 0, 4, 0, 1, 3};
  EXPECT_EQ(mesh.cornerVertex, corners);
  const std::vector<Vec2f> vt = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5f, 0.5f}};
  const std::vector<int> uvIndex = {0, 1, 2, 0, 2, 3, 3, 4, 1, 3, 2, 0};
  for (std::size_t c = 0; c < uvIndex.size(); ++c) {
    EXPECT_EQ(mesh.uvSets[0].uvs[c], vt[uvIndex[c]]) << "corner " << c;
  }
}

TEST(MeshObj, ConcurrentLoadsGiveIdenticalMeshes) {
  // OpenMesh's readers are global singletons: the loader serialises them.
  const std::vector<std::string> files = {"seam.obj", "cube_flat.obj", "polygons.obj",
                                          "quad_tri_binary_le.ply", "quad_tri.off"};
  std::vector<Mesh> reference;
  for (const std::string& f : files) reference.push_back(load(goodFile(f)));
  constexpr int kThreads = 4, kRounds = 10;
  std::vector<std::vector<Mesh>> results(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int r = 0; r < kRounds; ++r) {
        for (const std::string& f : files) {
          Result<Mesh> mesh = loadMesh(goodFile(f));
          results[t].push_back(mesh.ok() ? std::move(mesh).value() : Mesh{});
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) {
    ASSERT_EQ(results[t].size(), files.size() * kRounds);
    for (std::size_t i = 0; i < results[t].size(); ++i) {
      expectSameMesh(results[t][i], reference[i % files.size()]);
    }
  }
}

TEST(MeshObj, FromMemoryEqualsFromDisk) {
  const std::string path = goodFile("cube_flat.obj");
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  Result<Mesh> fromMemory = loadMeshFromMemory(bytes.str(), ".obj", path);
  ASSERT_TRUE(fromMemory.ok()) << fromMemory.error().message;
  expectSameMesh(*fromMemory, load(path));
  EXPECT_EQ(fromMemory->source, path);
}

}  // namespace
}  // namespace sgbake
