// MikkTSpace against analytic frames and invariants. The Blender comparison lives in
// tests/blender (BlenderTangentOracle).

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "sgbake/frames/tangents.hpp"
#include "support/parametric_mesh.hpp"

namespace sgbake {
namespace {

using test::angleDegrees;
using test::gridMesh;
using test::projectedDirection;

CornerTangents tangentsOf(const Mesh& mesh, int threads = 0) {
  auto result = computeTangents(mesh.view(), {threads});
  EXPECT_TRUE(result.ok()) << (result.ok() ? "" : result.error().message);
  return result.ok() ? std::move(result).value() : CornerTangents{};
}

// Worst angle (degrees) between each corner's tangent and the analytic ∂P/∂s projected into the
// corner's tangent plane, over corners whose parameter t lies in [tMin, tMax].
double worstTangentError(const Mesh& mesh, const CornerTangents& tangents, const test::Surface& surface,
                         double tMin = 0, double tMax = 1) {
  double worst = 0;
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    const Vec2f uv = mesh.uvSets[0].uvs[c];
    if (uv.y < tMin || uv.y > tMax) continue;
    const test::SurfacePoint p = surface(uv.x, uv.y);
    const Vec3d expected = projectedDirection(p.dPds, cast<double>(mesh.cornerNormals[c]));
    worst = std::max(worst, angleDegrees(cast<double>(tangents.tangent[c]), expected));
  }
  return worst;
}

TEST(Tangents, PlaneGivesTheUAxisWithPositiveSign) {
  const Mesh mesh = gridMesh(test::plane, 4, 3);
  const CornerTangents t = tangentsOf(mesh);
  ASSERT_EQ(t.tangent.size(), mesh.numCorners());
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    EXPECT_LT(angleDegrees(cast<double>(t.tangent[c]), {1, 0, 0}), 1e-5) << "corner " << c;
    EXPECT_EQ(t.sign[c], 1.0f);
  }
}

TEST(Tangents, CylinderMatchesTheParametricDerivativeIncludingTheSeam) {
  const Mesh mesh = gridMesh(test::cylinder, 24, 5);
  const CornerTangents t = tangentsOf(mesh);
  EXPECT_LT(worstTangentError(mesh, t, test::cylinder), 1e-4);
  for (float s : t.sign) EXPECT_EQ(s, 1.0f);
}

// Worst error at the finest of four refinements, after checking that every refinement shrinks it.
// Quads split on a diagonal tilt each face's derivative by O(h), so the error is first order:
// it halves with each refinement.
double convergedError(const test::Surface& surface, double tMin, double tMax) {
  double previous = 0;
  for (int n : {16, 32, 64, 128}) {
    const Mesh mesh = gridMesh(surface, 2 * n, n);
    const double error = worstTangentError(mesh, tangentsOf(mesh), surface, tMin, tMax);
    if (previous > 0) {
      EXPECT_LT(error, 0.6 * previous) << "n = " << n;
    }
    previous = error;
  }
  return previous;
}

TEST(Tangents, SphereConvergesToTheParametricDerivative) {
  EXPECT_LT(convergedError(test::sphere, 0.1, 0.9), 1.0);  // away from the poles
}

TEST(Tangents, TorusConvergesToTheParametricDerivative) {
  EXPECT_LT(convergedError(test::torus, 0, 1), 1.0);
}

TEST(Tangents, FramesAreUnitAndOrthogonalToTheNormal) {
  const Mesh mesh = gridMesh(test::sphere, 40, 20);
  const CornerTangents t = tangentsOf(mesh);
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    const Vec3d tc = cast<double>(t.tangent[c]);
    EXPECT_NEAR(length(tc), 1.0, 1e-6) << c;
    EXPECT_NEAR(dot(tc, cast<double>(mesh.cornerNormals[c])), 0.0, 1e-6) << c;
    EXPECT_TRUE(t.sign[c] == 1.0f || t.sign[c] == -1.0f);
  }
}

TEST(Tangents, MirroredUvsFlipTheSignAndKeepTheBitangentAlongV) {
  // Left half of a plane mapped normally, right half mirrored in u: a mirrored seam in the middle.
  const auto mirrored = [](double s, double t) { return Vec2d{s < 0.5 ? s : 1.0 - s, t}; };
  const Mesh mesh = gridMesh(test::plane, 8, 4, mirrored);
  const CornerTangents t = tangentsOf(mesh);
  int mirroredCorners = 0;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    // The face's centre tells which half it is on.
    double cx = 0;
    for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c)
      cx += mesh.positions[mesh.cornerVertex[c]].x / 4.0;
    const bool isMirrored = cx > 0.5;
    for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
      const Vec3d n = cast<double>(mesh.cornerNormals[c]);
      const Vec3d tangent = cast<double>(t.tangent[c]);
      const Vec3d bitangent = double(t.sign[c]) * cross(n, tangent);
      EXPECT_EQ(t.sign[c], isMirrored ? -1.0f : 1.0f) << "corner " << c;
      EXPECT_LT(angleDegrees(tangent, {isMirrored ? -1.0 : 1.0, 0, 0}), 1e-5) << "corner " << c;
      EXPECT_LT(angleDegrees(bitangent, {0, 1, 0}), 1e-5) << "corner " << c;
      mirroredCorners += isMirrored;
    }
  }
  EXPECT_EQ(mirroredCorners, 4 * 4 * 4);
}

Mesh scaled(Mesh mesh, float factor) {
  for (Vec3f& p : mesh.positions) p = factor * p;
  return mesh;
}

TEST(Tangents, ScaleByTenToThePlusMinusEightChangesNothing) {
  // A torus: no collapsed poles, whose quad splits are ties decided by rounding.
  const Mesh mesh = gridMesh(test::torus, 24, 12);
  const CornerTangents reference = tangentsOf(mesh);
  for (float factor : {1e-8f, 1e8f}) {
    const CornerTangents t = tangentsOf(scaled(mesh, factor));
    for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
      EXPECT_LT(angleDegrees(cast<double>(t.tangent[c]), cast<double>(reference.tangent[c])), 1e-4)
          << "scale " << factor << " corner " << c;
      EXPECT_EQ(t.sign[c], reference.sign[c]);
    }
  }
}

// A mesh with everything the algorithm treats specially: seams, mirrored islands, collapsed
// positions and collapsed UVs, so that thread scheduling would show if it leaked into results.
Mesh awkwardMesh() {
  const auto uvOf = [](double s, double t) {
    Vec2d uv{s < 0.5 ? s : 1.0 - s, t};
    if (t > 0.7 && t < 0.8) uv = {0.25, 0.75};  // a band of collapsed UVs
    return uv;
  };
  Mesh mesh = gridMesh(test::sphere, 200, 100, uvOf);
  // Collapse some vertices onto their neighbours: degenerate triangles and quads.
  for (std::size_t v = 0; v + 1 < mesh.positions.size(); v += 37) mesh.positions[v + 1] = mesh.positions[v];
  return mesh;
}

TEST(Tangents, OneThreadAndManyThreadsGiveTheSameBits) {
  const Mesh mesh = awkwardMesh();
  const CornerTangents one = tangentsOf(mesh, 1);
  for (int threads : {2, 3, 0}) {
    const CornerTangents many = tangentsOf(mesh, threads);
    ASSERT_EQ(one.tangent.size(), many.tangent.size());
    EXPECT_EQ(0, std::memcmp(one.tangent.data(), many.tangent.data(), one.tangent.size() * sizeof(Vec3f)))
        << threads << " threads";
    EXPECT_EQ(one.sign, many.sign) << threads << " threads";
  }
}

TEST(Tangents, DegenerateInputStaysFiniteAndUnit) {
  const Mesh mesh = awkwardMesh();
  const CornerTangents t = tangentsOf(mesh);
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    ASSERT_TRUE(isFinite(t.tangent[c])) << c;
    EXPECT_NEAR(length(cast<double>(t.tangent[c])), 1.0, 1e-6) << c;
  }
}

TEST(Tangents, QuadWithOneDegenerateHalfCopiesTheCollapsedCorner) {
  // Corners 2 and 3 coincide: one half of the quad is degenerate, the missing corner takes the
  // frame of the corner at the same position.
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 0}};
  mesh.faceStart = {0, 4};
  mesh.cornerVertex = {0, 1, 2, 3};
  mesh.cornerNormals.assign(4, Vec3f{0, 0, 1});
  mesh.uvSets.push_back({"UVMap", {{0, 0}, {1, 0}, {1, 1}, {0, 1}}});
  const CornerTangents t = tangentsOf(mesh);
  for (int c = 0; c < 4; ++c) {
    EXPECT_TRUE(isFinite(t.tangent[c]));
    EXPECT_NEAR(length(cast<double>(t.tangent[c])), 1.0, 1e-6);
  }
  EXPECT_EQ(t.tangent[3], t.tangent[2]);
  EXPECT_EQ(t.sign[3], t.sign[2]);
}

TEST(Tangents, NgonIsTriangulatedAndGetsThePlaneFrame) {
  Mesh mesh;
  const int k = 7;
  mesh.faceStart = {0, std::uint32_t(k)};
  UvSet uv{"UVMap", {}};
  for (int i = 0; i < k; ++i) {
    const double a = 2 * kPi * i / k;
    mesh.positions.push_back({float(std::cos(a)), float(std::sin(a)), 0});
    mesh.cornerVertex.push_back(std::uint32_t(i));
    mesh.cornerNormals.push_back({0, 0, 1});
    uv.uvs.push_back({float(0.5 + 0.5 * std::cos(a)), float(0.5 + 0.5 * std::sin(a))});
  }
  mesh.uvSets.push_back(uv);
  const CornerTangents t = tangentsOf(mesh);
  for (int c = 0; c < k; ++c) {
    EXPECT_LT(angleDegrees(cast<double>(t.tangent[c]), {1, 0, 0}), 1e-4) << c;
    EXPECT_EQ(t.sign[c], 1.0f);
  }
}

TEST(Tangents, MeshWithoutUvsIsABadInputError) {
  Mesh mesh = gridMesh(test::plane, 2, 2);
  mesh.uvSets.clear();
  const auto result = computeTangents(mesh.view());
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().code, ErrorCode::kBadInput);
  EXPECT_NE(result.error().message.find("texture coordinates"), std::string::npos);
}

}  // namespace
}  // namespace sgbake
