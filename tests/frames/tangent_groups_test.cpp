// MikkTSpace finds its groups of triangles around each vertex in one of two ways: each vertex on
// its own (in parallel) when no triangle is "group with any" (zero UV area), or one walk in
// triangle order otherwise, because then the order decides. Both must give the same frames.

#include <gtest/gtest.h>

#include <cstring>

#include "sgbake/frames/tangents.hpp"
#include "support/parametric_mesh.hpp"

namespace sgbake {
namespace {

CornerTangents tangentsOf(const Mesh& mesh, int threads) {
  auto result = computeTangents(mesh.view(), {threads});
  EXPECT_TRUE(result.ok()) << (result.ok() ? "" : result.error().message);
  return result.ok() ? std::move(result).value() : CornerTangents{};
}

// A torus whose UVs are mirrored in s at s = 0.5 and in t at t = 0.5: vertices on the mirror lines
// have several groups of opposite orientation, and the UV seams split the rest.
Mesh mirroredTorus() {
  return test::gridMesh(test::torus, 48, 24, [](double s, double t) {
    return Vec2d{s < 0.5 ? s : 1 - s, t < 0.5 ? t : 1 - t};
  });
}

// @p mesh plus one triangle of its own, far away, whose UVs coincide (zero UV area).
Mesh withIsolatedZeroUvAreaTriangle(Mesh mesh) {
  const auto first = static_cast<std::uint32_t>(mesh.positions.size());
  for (const Vec3f p : {Vec3f{10, 0, 0}, Vec3f{11, 0, 0}, Vec3f{10, 1, 0}}) mesh.positions.push_back(p);
  for (std::uint32_t i = 0; i < 3; ++i) {
    mesh.cornerVertex.push_back(first + i);
    mesh.cornerNormals.push_back({0, 0, 1});
    mesh.uvSets[0].uvs.push_back({0.25f, 0.25f});
  }
  mesh.faceStart.push_back(static_cast<std::uint32_t>(mesh.cornerVertex.size()));
  return mesh;
}

TEST(TangentGroups, PerVertexGroupsEqualTheWalkInTriangleOrder) {
  const Mesh healthy = mirroredTorus();
  const Mesh withAny = withIsolatedZeroUvAreaTriangle(healthy);
  for (int threads : {1, 2, 3}) {
    const CornerTangents a = tangentsOf(healthy, threads);    // groups found per vertex
    const CornerTangents b = tangentsOf(withAny, threads);    // groups found by the walk
    ASSERT_EQ(a.tangent.size(), healthy.numCorners());
    ASSERT_EQ(b.tangent.size(), withAny.numCorners());
    // The extra triangle shares nothing with the torus, so the torus's frames cannot change.
    EXPECT_EQ(0, std::memcmp(a.tangent.data(), b.tangent.data(), a.tangent.size() * sizeof(Vec3f)))
        << threads << " threads";
    EXPECT_EQ(0, std::memcmp(a.sign.data(), b.sign.data(), a.sign.size() * sizeof(float)))
        << threads << " threads";
  }
}

TEST(TangentGroups, MirroredUvsGiveBothSignsOnTheMirrorLines) {
  const Mesh mesh = mirroredTorus();
  const CornerTangents t = tangentsOf(mesh, 0);
  std::size_t positive = 0, negative = 0;
  for (const float s : t.sign) (s > 0 ? positive : negative) += 1;
  EXPECT_GT(positive, 0u);
  EXPECT_GT(negative, 0u);
}

}  // namespace
}  // namespace sgbake
