/// @file capi_test.cpp
/// @brief The C ABI (sgbake.h): same frames as the C++ API, and every inconsistent argument is a
/// status code with a message rather than a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "sgbake/frames/tangents.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/sgbake.h"
#include "support/files.hpp"

namespace sgbake {
namespace {

/// Two quads side by side (the right one bent up along the shared edge) and a triangle on top,
/// as flat C arrays; normals are the unit face normals, so faces are flat-shaded.
struct FlatMesh {
  std::vector<float> positions = {0, 0, 0,  1, 0, 0,  1, 1, 0,  0, 1, 0,
                                  2, 0, 1,  2, 1, 1,  0.5f, 2, 0};
  std::vector<std::uint32_t> faceStart = {0, 4, 8, 11};
  std::vector<std::uint32_t> cornerVertex = {0, 1, 2, 3,  1, 4, 5, 2,  3, 2, 6};
  std::vector<float> cornerNormals;
  std::vector<float> cornerUvs = {0, 0,  0.5f, 0,  0.5f, 0.5f,  0, 0.5f,
                                  0.5f, 0,  1, 0,  1, 0.5f,  0.5f, 0.5f,
                                  0, 0.5f,  0.5f, 0.5f,  0.25f, 1};

  FlatMesh() {
    const float s = 1.0f / std::sqrt(2.0f);
    const float faceNormals[3][3] = {{0, 0, 1}, {-s, 0, s}, {0, 0, 1}};
    for (std::size_t f = 0; f + 1 < faceStart.size(); ++f) {
      for (std::uint32_t c = faceStart[f]; c < faceStart[f + 1]; ++c) {
        cornerNormals.insert(cornerNormals.end(), faceNormals[f], faceNormals[f] + 3);
      }
    }
  }
  std::size_t numVertices() const { return positions.size() / 3; }
  std::size_t numFaces() const { return faceStart.size() - 1; }
  std::size_t numCorners() const { return cornerVertex.size(); }
};

/// The outputs and status of one sgbake_compute_tangents call.
struct CallResult {
  int status = -1;
  std::vector<float> tangents;
  std::vector<float> signs;
  std::string message;
};

CallResult callC(const FlatMesh& m, int threads = 0) {
  CallResult r;
  r.tangents.assign(3 * m.numCorners(), -7.0f);
  r.signs.assign(m.numCorners(), -7.0f);
  char error[256] = "untouched";
  r.status = sgbake_compute_tangents(m.positions.data(), m.numVertices(), m.faceStart.data(),
                                     m.numFaces(), m.cornerVertex.data(), m.cornerNormals.data(),
                                     m.cornerUvs.data(), m.numCorners(), threads,
                                     r.tangents.data(), r.signs.data(), error, sizeof error);
  r.message = error;
  return r;
}

TEST(CApi, VersionIsTheHeaderVersion) {
  ASSERT_NE(sgbake_version(), nullptr);
  EXPECT_STREQ(sgbake_version(), SGBAKE_VERSION_STRING);
}

TEST(CApi, GivesTheSameFramesAsTheCppApi) {
  const FlatMesh m;
  const CallResult c = callC(m);
  ASSERT_EQ(c.status, SGBAKE_OK) << c.message;
  EXPECT_EQ(c.message, "untouched");  // the error buffer is left alone on success

  std::vector<Vec3f> positions, normals;
  std::vector<Vec2f> uvs;
  for (std::size_t v = 0; v < m.numVertices(); ++v) {
    positions.push_back({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
  }
  for (std::size_t i = 0; i < m.numCorners(); ++i) {
    normals.push_back(
        {m.cornerNormals[3 * i], m.cornerNormals[3 * i + 1], m.cornerNormals[3 * i + 2]});
    uvs.push_back({m.cornerUvs[2 * i], m.cornerUvs[2 * i + 1]});
  }
  const MeshView view{positions, m.faceStart, m.cornerVertex, normals, uvs};
  const Result<CornerTangents> cpp = computeTangents(view);
  ASSERT_TRUE(cpp.ok()) << cpp.error().message;

  for (std::size_t i = 0; i < m.numCorners(); ++i) {
    // Bit-identical: the C ABI copies the arrays and calls the same kernel.
    EXPECT_EQ(c.tangents[3 * i], cpp->tangent[i].x) << "corner " << i;
    EXPECT_EQ(c.tangents[3 * i + 1], cpp->tangent[i].y) << "corner " << i;
    EXPECT_EQ(c.tangents[3 * i + 2], cpp->tangent[i].z) << "corner " << i;
    EXPECT_EQ(c.signs[i], cpp->sign[i]) << "corner " << i;
    EXPECT_TRUE(c.signs[i] == 1.0f || c.signs[i] == -1.0f);
  }
  // A sanity anchor independent of the C++ API: u runs along +x on the flat bottom-left quad.
  EXPECT_NEAR(c.tangents[0], 1.0f, 1e-6f);
  EXPECT_NEAR(c.tangents[1], 0.0f, 1e-6f);
  EXPECT_EQ(c.signs[0], 1.0f);
}

TEST(CApi, DoesNotLoadOpenImageIO) {
  // A program using only the C ABI (the Blender add-on) must not pull in OpenImageIO and its
  // ~260 libraries: image I/O is a module loaded on first use (sgbake/io/image_io.hpp).
  const CallResult c = callC(FlatMesh{});
  ASSERT_EQ(c.status, SGBAKE_OK) << c.message;
  const std::string maps = test::readFile("/proc/self/maps");
  ASSERT_FALSE(maps.empty());
  EXPECT_EQ(maps.find("libOpenImageIO"), std::string::npos);
  EXPECT_EQ(maps.find("libsgbake_oiio"), std::string::npos);
}

/// @p m as an sgbake_mesh with its one UV set at @p uvSets[0]; every face smooth.
sgbake_mesh meshOf(const FlatMesh& m, const float* const* uvSets) {
  return {m.positions.data(),
          m.numVertices(),
          m.faceStart.data(),
          m.numFaces(),
          m.cornerVertex.data(),
          m.cornerNormals.data(),
          uvSets,
          1,
          m.numCorners(),
          nullptr,
          0,
          nullptr};
}

TEST(CApi, BakeMapFromArraysDoesNotLoadOpenImageIO) {
  // An in-memory bake (images as arrays, if any) reads and writes no file: the add-on's bakes
  // must not load the image I/O module either.
  const FlatMesh m;
  const float* uvSets[] = {m.cornerUvs.data()};
  const sgbake_mesh mesh = meshOf(m, uvSets);
  std::vector<float> rgba(32 * 32 * 4);
  char error[256] = "";
  ASSERT_EQ(sgbake_bake_map(R"({"layers": [{"type": "volume", "function": "noise"}],
                                "outputs": [{"map": "tangent-normal", "size": 32}]})",
                            &mesh, nullptr, 0, 0, nullptr, rgba.data(), rgba.size(), error,
                            sizeof error),
            SGBAKE_OK)
      << error;
  EXPECT_NE(rgba[4 * (8 * 32 + 8)], rgba[4 * (8 * 32 + 9)]);  // the noise bumps the normals
  const std::string maps = test::readFile("/proc/self/maps");
  EXPECT_EQ(maps.find("libOpenImageIO"), std::string::npos);
  EXPECT_EQ(maps.find("libsgbake_oiio"), std::string::npos);
}

TEST(CApi, BakeMapReportsProgressAndStopsWhenCancelled) {
  const FlatMesh m;
  const float* uvSets[] = {m.cornerUvs.data()};
  const sgbake_mesh mesh = meshOf(m, uvSets);
  const char* scene = R"({"layers": [{"type": "volume", "function": "noise"}],
                          "outputs": [{"map": "tangent-normal", "size": 1024}]})";
  std::vector<float> plain(1024 * 1024 * 4), tracked(plain.size());
  char error[256] = "";
  ASSERT_EQ(sgbake_bake_map(scene, &mesh, nullptr, 0, 0, nullptr, plain.data(), plain.size(),
                            error, sizeof error),
            SGBAKE_OK)
      << error;
  sgbake_progress progress{-1.0f, 0};
  ASSERT_EQ(sgbake_bake_map(scene, &mesh, nullptr, 0, 0, &progress, tracked.data(),
                            tracked.size(), error, sizeof error),
            SGBAKE_OK)
      << error;
  EXPECT_EQ(progress.fraction, 1.0f);
  EXPECT_EQ(tracked, plain);
  // Cancelled before it starts: the first band is baked, then the call stops.
  progress = {-1.0f, 1};
  std::strcpy(error, "untouched");
  EXPECT_EQ(sgbake_bake_map(scene, &mesh, nullptr, 0, 0, &progress, tracked.data(),
                            tracked.size(), error, sizeof error),
            SGBAKE_CANCELLED);
  EXPECT_EQ(std::string(error), "sgbake_bake_map: bake: cancelled");
  EXPECT_GT(progress.fraction, 0.0f);
  EXPECT_LT(progress.fraction, 1.0f);
}

TEST(CApi, ThreadCountDoesNotChangeTheResult) {
  const FlatMesh m;
  const CallResult one = callC(m, 1);
  const CallResult all = callC(m, 0);
  ASSERT_EQ(one.status, SGBAKE_OK) << one.message;
  ASSERT_EQ(all.status, SGBAKE_OK) << all.message;
  EXPECT_EQ(one.tangents, all.tangents);
  EXPECT_EQ(one.signs, all.signs);
}

TEST(CApi, EmptyMeshSucceeds) {
  char error[64] = "";
  EXPECT_EQ(sgbake_compute_tangents(nullptr, 0, nullptr, 0, nullptr, nullptr, nullptr, 0, 0,
                                    nullptr, nullptr, error, sizeof error),
            SGBAKE_OK)
      << error;
}

/// A bad argument is SGBAKE_ERROR_BAD_INPUT and a message that mentions @p mention.
void expectBadInput(const FlatMesh& m, const std::string& mention, int threads = 0) {
  const CallResult r = callC(m, threads);
  EXPECT_EQ(r.status, SGBAKE_ERROR_BAD_INPUT) << r.message;
  EXPECT_NE(r.message.find(mention), std::string::npos) << r.message;
  EXPECT_EQ(r.message.find('\n'), std::string::npos) << r.message;
}

TEST(CApi, RejectsCornerVertexOutOfRange) {
  FlatMesh m;
  m.cornerVertex[5] = 7;
  expectBadInput(m, "corner_vertex[5] = 7");
}

TEST(CApi, RejectsNonFiniteData) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  {
    FlatMesh m;
    m.positions[4] = nan;
    expectBadInput(m, "positions[1]");
  }
  {
    FlatMesh m;
    m.cornerNormals[9] = inf;
    expectBadInput(m, "corner_normals[3]");
  }
  {
    FlatMesh m;
    m.cornerUvs[21] = nan;
    expectBadInput(m, "corner_uvs[10]");
  }
}

TEST(CApi, RejectsInconsistentFaceStart) {
  {
    FlatMesh m;
    m.faceStart = {0, 8, 4, 11};  // not monotone
    expectBadInput(m, "face_start");
  }
  {
    FlatMesh m;
    m.faceStart = {0, 4, 6, 11};  // a two-corner face
    expectBadInput(m, "face 1 has 2 corners");
  }
  {
    FlatMesh m;
    m.faceStart = {1, 4, 8, 11};
    expectBadInput(m, "face_start[0]");
  }
  {
    FlatMesh m;
    m.faceStart = {0, 4, 7, 10};  // does not end at num_corners
    expectBadInput(m, "num_corners");
  }
  {
    FlatMesh m;
    m.faceStart = {0, 4, 8, 11, 14, 17, 20};  // more faces than 11 corners can hold
    expectBadInput(m, "num_faces");
  }
}

TEST(CApi, RejectsNonUnitNormalsAndNegativeThreads) {
  {
    FlatMesh m;
    m.cornerNormals[0] = 2.0f;
    expectBadInput(m, "unit length");
  }
  expectBadInput(FlatMesh{}, "threads", -1);
}

TEST(CApi, RejectsNullArrays) {
  const FlatMesh m;
  std::vector<float> tangents(3 * m.numCorners()), signs(m.numCorners());
  char error[256] = "";
  EXPECT_EQ(sgbake_compute_tangents(m.positions.data(), m.numVertices(), m.faceStart.data(),
                                    m.numFaces(), m.cornerVertex.data(), m.cornerNormals.data(),
                                    nullptr, m.numCorners(), 0, tangents.data(), signs.data(),
                                    error, sizeof error),
            SGBAKE_ERROR_BAD_INPUT);
  EXPECT_NE(std::string(error).find("corner_uvs is NULL"), std::string::npos) << error;
  EXPECT_EQ(sgbake_compute_tangents(m.positions.data(), m.numVertices(), m.faceStart.data(),
                                    m.numFaces(), m.cornerVertex.data(), m.cornerNormals.data(),
                                    m.cornerUvs.data(), m.numCorners(), 0, nullptr, signs.data(),
                                    error, sizeof error),
            SGBAKE_ERROR_BAD_INPUT);
  EXPECT_NE(std::string(error).find("out_tangents is NULL"), std::string::npos) << error;
}

TEST(CApi, TruncatesTheMessageToATooSmallErrorBuffer) {
  FlatMesh m;
  m.cornerVertex[0] = 99;
  std::vector<float> tangents(3 * m.numCorners()), signs(m.numCorners());
  const auto call = [&](char* buffer, std::size_t size) {
    return sgbake_compute_tangents(m.positions.data(), m.numVertices(), m.faceStart.data(),
                                   m.numFaces(), m.cornerVertex.data(), m.cornerNormals.data(),
                                   m.cornerUvs.data(), m.numCorners(), 0, tangents.data(),
                                   signs.data(), buffer, size);
  };

  char buffer[16];
  std::memset(buffer, '#', sizeof buffer);
  EXPECT_EQ(call(buffer, 8), SGBAKE_ERROR_BAD_INPUT);
  EXPECT_EQ(std::strlen(buffer), 7u);  // 7 characters and the terminating NUL
  EXPECT_EQ(std::string(buffer), "sgbake_");
  for (std::size_t i = 8; i < sizeof buffer; ++i) EXPECT_EQ(buffer[i], '#') << "overrun at " << i;

  char one = '#';
  EXPECT_EQ(call(&one, 1), SGBAKE_ERROR_BAD_INPUT);
  EXPECT_EQ(one, '\0');
  EXPECT_EQ(call(nullptr, 0), SGBAKE_ERROR_BAD_INPUT);
  EXPECT_EQ(call(nullptr, 100), SGBAKE_ERROR_BAD_INPUT);
}

TEST(CApi, LoopTrianglesAreBlendersAndBadArraysAreRefused) {
  // A triangle, a quad split on its 1–3 diagonal (corners 1 and 3 on the same side of 0–2, as
  // Blender's float test finds) and a regular pentagon, whose loop triangles Blender 3.4.1
  // gives as (4, 0, 1), (1, 2, 3), (1, 3, 4) (tests/mesh/triangulate_test.cpp, "reg5").
  std::vector<float> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0,                  // triangle
                                  0, 0, 1, 1, 0, 1, 1, 1, 1, 0.2f, 0.1f, 1};  // concave quad
  const float reg5[5][2] = {{1.0f, 0.0f},
                            {0.309017003f, 0.95105654f},
                            {-0.809017003f, 0.587785244f},
                            {-0.809017003f, -0.587785244f},
                            {0.309017003f, -0.95105654f}};
  for (const auto& q : reg5) positions.insert(positions.end(), {q[0], q[1], 2.0f});
  const std::vector<std::uint32_t> faceStart = {0, 3, 7, 12};
  const std::vector<std::uint32_t> cornerVertex = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  std::vector<std::uint32_t> triangles(3 * (12 - 2 * 3), 99);
  char error[256] = "untouched";
  ASSERT_EQ(sgbake_loop_triangles(positions.data(), positions.size() / 3, faceStart.data(), 3,
                                  cornerVertex.data(), 12, triangles.data(), error, sizeof error),
            SGBAKE_OK)
      << error;
  // The quad: 1 and 3 lie on the same side of the 0–2 diagonal (3 is inside the triangle 0 1 2).
  const std::vector<std::uint32_t> expected = {0,  1, 2, 3, 4, 6,  4, 5,  6,
                                               11, 7, 8, 8, 9, 10, 8, 10, 11};
  EXPECT_EQ(triangles, expected);
  EXPECT_STREQ(error, "untouched");

  EXPECT_EQ(sgbake_loop_triangles(positions.data(), positions.size() / 3, faceStart.data(), 3,
                                  cornerVertex.data(), 12, nullptr, error, sizeof error),
            SGBAKE_ERROR_BAD_INPUT);
  EXPECT_STREQ(error, "sgbake_loop_triangles: out_triangles is NULL");
  const std::vector<std::uint32_t> shortFace = {0, 2, 7, 12};
  EXPECT_EQ(sgbake_loop_triangles(positions.data(), positions.size() / 3, shortFace.data(), 3,
                                  cornerVertex.data(), 12, triangles.data(), error, sizeof error),
            SGBAKE_ERROR_BAD_INPUT);
  EXPECT_NE(std::string(error).find("sgbake_loop_triangles: face 0 has 2 corners"),
            std::string::npos)
      << error;
}

}  // namespace
}  // namespace sgbake
