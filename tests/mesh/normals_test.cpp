// Face and smooth vertex normals against analytic values: planar polygons in a tilted plane,
// hand-derived angle-weighted sums, the symmetric octahedron, a UV sphere converging to its
// normalized positions, Blender's degenerate cases; and the Mesh invariant check.

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <string>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/mesh/io.hpp"
#include "sgbake/mesh/normals.hpp"

namespace sgbake {
namespace {

constexpr double kNormalTolerance = 1e-6;  // float rounding of a unit vector, with margin

// A mesh from positions and faces; normals and UVs left empty.
Mesh makeMesh(std::vector<Vec3f> positions, const std::vector<std::vector<std::uint32_t>>& faces) {
  Mesh mesh;
  mesh.source = "test mesh";
  mesh.positions = std::move(positions);
  for (const auto& face : faces) {
    mesh.cornerVertex.insert(mesh.cornerVertex.end(), face.begin(), face.end());
    mesh.faceStart.push_back(static_cast<std::uint32_t>(mesh.cornerVertex.size()));
  }
  return mesh;
}

double angleDegrees(Vec3d a, Vec3d b) { return angleBetween(a, b) * 180 / kPi; }

void expectNear(Vec3f actual, Vec3d expected, double tolerance = kNormalTolerance) {
  EXPECT_NEAR(actual.x, expected.x, tolerance);
  EXPECT_NEAR(actual.y, expected.y, tolerance);
  EXPECT_NEAR(actual.z, expected.z, tolerance);
}

// The normal of @p mesh at the corners of vertex @p v (all equal for smooth normals).
Vec3f vertexNormal(const Mesh& mesh, std::uint32_t v) {
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    if (mesh.cornerVertex[c] == v) return mesh.cornerNormals[c];
  }
  ADD_FAILURE() << "vertex " << v << " has no corner";
  return {};
}

TEST(MeshNormals, FaceNormalsOfPlanarPolygonsAreThePlaneNormal) {
  // Regular polygons in a tilted plane with normal n, counter-clockwise around n.
  const Vec3d n = normalizeOr(Vec3d{1, 2, 3}, Vec3d{});
  const Vec3d e1 = normalizeOr(cross(n, Vec3d{0, 0, 1}), Vec3d{});
  const Vec3d e2 = cross(n, e1);
  for (std::uint32_t sides : {3u, 4u, 5u, 8u}) {
    std::vector<Vec3f> points;
    std::vector<std::uint32_t> ccw, cw;
    for (std::uint32_t i = 0; i < sides; ++i) {
      const double a = 2 * kPi * i / sides;
      points.push_back(cast<float>(Vec3d{0.5, -1, 2} + std::cos(a) * e1 + std::sin(a) * e2));
      ccw.push_back(i);
      cw.push_back(sides - 1 - i);
    }
    const Mesh mesh = makeMesh(points, {ccw, cw});
    const std::vector<Vec3f> normals = computeFaceNormals(mesh.view());
    ASSERT_EQ(normals.size(), 2u);
    expectNear(normals[0], n);
    expectNear(normals[1], -n);
  }
}

TEST(MeshNormals, NonPlanarQuadUsesTheCrossProductOfItsDiagonals) {
  // (p0 - p2) × (p1 - p3) = (-1, -1, -1) × (1, -1, 0) = (-1, -1, 2).
  const Mesh mesh = makeMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 1}, {0, 1, 0}}, {{0, 1, 2, 3}});
  expectNear(computeFaceNormals(mesh.view())[0], Vec3d{-1, -1, 2} * (1 / std::sqrt(6.0)));
}

TEST(MeshNormals, ZeroAreaFacesGetPlusZ) {
  const Mesh mesh = makeMesh({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {5, 5, 5}},
                             {{0, 1, 2}, {0, 1, 2, 3}, {0, 1, 2, 3, 4}, {4, 3, 2}});
  for (const Vec3f& n : computeFaceNormals(mesh.view())) EXPECT_EQ(n, (Vec3f{0, 0, 1}));
}

TEST(MeshNormals, AngleWeightsHandDerived) {
  // At the origin: a triangle in z = 0 (normal +z, angle 90°) and one in x = 0 (normal +x,
  // angle 45°). Angle weighting: (π/2)(0,0,1) + (π/4)(1,0,0) ∝ (1, 0, 2). Both triangles have
  // area 1/2, so area weighting would give (1, 0, 1) instead.
  Mesh mesh =
      makeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, {{0, 1, 2}, {0, 3, 4}});
  computeSmoothNormals(mesh);
  EXPECT_EQ(mesh.normalSource, NormalSource::kComputed);
  const Vec3d expected = Vec3d{1, 0, 2} * (1 / std::sqrt(5.0));
  expectNear(vertexNormal(mesh, 0), expected);
  EXPECT_GT(angleDegrees(expected, normalizeOr(Vec3d{1, 0, 1}, Vec3d{})), 10.0);
}

TEST(MeshNormals, AngleWeightingIgnoresHowACubeCornerIsSplit) {
  // The corner at the origin of a solid filling x, y, z >= 0: a big 3×3 quad in z = 0, a small
  // 1×1 quad in y = 0 and a 1×2 rectangle in x = 0 split through the corner into triangles with
  // angles atan(2) and atan(1/2). Each plane contributes π/2, so the normal is (-1,-1,-1)/√3;
  // weighting by face count would give (-2,-1,-1), by area (-2,-1,-9).
  Mesh mesh = makeMesh({{0, 0, 0},
                        {0, 3, 0},
                        {3, 3, 0},
                        {3, 0, 0},  // z = 0
                        {1, 0, 0},
                        {1, 0, 1},
                        {0, 0, 1},  // y = 0
                        {0, 2, 1},
                        {0, 2, 0}},  // x = 0 (with (0,0,1))
                       {{0, 1, 2, 3}, {0, 4, 5, 6}, {0, 6, 7}, {0, 7, 8}});
  const std::vector<Vec3f> faces = computeFaceNormals(mesh.view());
  expectNear(faces[0], {0, 0, -1});
  expectNear(faces[1], {0, -1, 0});
  expectNear(faces[2], {-1, 0, 0});
  expectNear(faces[3], {-1, 0, 0});
  computeSmoothNormals(mesh);
  const Vec3d expected = Vec3d{-1, -1, -1} * (1 / std::sqrt(3.0));
  const Vec3f actual = vertexNormal(mesh, 0);
  expectNear(actual, expected);
  EXPECT_GT(angleDegrees(cast<double>(actual), normalizeOr(Vec3d{-2, -1, -1}, Vec3d{})), 10.0);
  EXPECT_GT(angleDegrees(cast<double>(actual), normalizeOr(Vec3d{-2, -1, -9}, Vec3d{})), 10.0);
}

TEST(MeshNormals, ZeroLengthEdgeWeighsHalfPiAsInBlender) {
  // Vertex 4 sits on vertex 0: the quad (0, 1, 2, 4) has a zero-length edge at vertex 0, which
  // Blender weighs acos(0) = π/2. With the triangle (0, 5, 6) (normal +x, 90° at vertex 0) the
  // normal at vertex 0 is (π/2)(0,0,1) + (π/2)(1,0,0) ∝ (1, 0, 1); weight 0 would give (1,0,0).
  Mesh mesh =
      makeMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {9, 9, 9}, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}},
               {{0, 1, 2, 4}, {0, 5, 6}});
  computeSmoothNormals(mesh);
  expectNear(vertexNormal(mesh, 0), Vec3d{1, 0, 1} * (1 / std::sqrt(2.0)));
}

TEST(MeshNormals, CancellingFacesFallBackToThePosition) {
  // Two copies of a triangle with opposite orientation: every vertex sum is exactly zero.
  Mesh away = makeMesh({{2, 0, 0}, {0, 3, 0}, {0, 0, 4}}, {{0, 1, 2}, {0, 2, 1}});
  computeSmoothNormals(away);
  expectNear(vertexNormal(away, 0), {1, 0, 0});
  expectNear(vertexNormal(away, 1), {0, 1, 0});
  expectNear(vertexNormal(away, 2), {0, 0, 1});
  Mesh atOrigin = makeMesh({{0, 0, 0}, {-1, 0, 0}, {0, -1, 0}}, {{0, 1, 2}, {0, 2, 1}});
  computeSmoothNormals(atOrigin);
  EXPECT_EQ(vertexNormal(atOrigin, 0), (Vec3f{0, 0, 1}));
  expectNear(vertexNormal(atOrigin, 1), {-1, 0, 0});
}

TEST(MeshNormals, OctahedronNormalsAreItsNormalizedPositions) {
  Result<Mesh> loaded = loadMesh(std::string(SGBAKE_TEST_DATA) + "/corpus/good/octahedron.off");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const Mesh& mesh = *loaded;
  EXPECT_EQ(mesh.normalSource, NormalSource::kComputed);
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    const Vec3f p = mesh.positions[mesh.cornerVertex[c]];
    expectNear(mesh.cornerNormals[c], normalizeOr(cast<double>(p), Vec3d{}));
  }
}

// A latitude-longitude unit sphere: triangle fans at the poles, quads elsewhere, outward.
Mesh uvSphere(std::uint32_t segments, std::uint32_t rings) {
  std::vector<Vec3f> points = {{0, 0, 1}};
  for (std::uint32_t r = 1; r < rings; ++r) {
    const double theta = kPi * r / rings;
    for (std::uint32_t s = 0; s < segments; ++s) {
      const double phi = 2 * kPi * s / segments;
      points.push_back(cast<float>(Vec3d{std::sin(theta) * std::cos(phi),
                                         std::sin(theta) * std::sin(phi), std::cos(theta)}));
    }
  }
  points.push_back({0, 0, -1});
  const auto south = static_cast<std::uint32_t>(points.size() - 1);
  auto at = [&](std::uint32_t r, std::uint32_t s) { return 1 + (r - 1) * segments + s % segments; };
  std::vector<std::vector<std::uint32_t>> faces;
  for (std::uint32_t s = 0; s < segments; ++s) {
    faces.push_back({0, at(1, s), at(1, s + 1)});
    for (std::uint32_t r = 1; r + 1 < rings; ++r) {
      faces.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s + 1)});
    }
    faces.push_back({at(rings - 1, s), south, at(rings - 1, s + 1)});
  }
  return makeMesh(points, faces);
}

// Largest angle (degrees) between a vertex normal and the normalized vertex position.
double worstSphereError(std::uint32_t segments, std::uint32_t rings) {
  Mesh mesh = uvSphere(segments, rings);
  computeSmoothNormals(mesh);
  EXPECT_TRUE(validate(mesh).ok());
  double worst = 0;
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    const Vec3d p = cast<double>(mesh.positions[mesh.cornerVertex[c]]);
    worst = std::max(worst, angleDegrees(cast<double>(mesh.cornerNormals[c]), p));
  }
  return worst;
}

TEST(MeshNormals, UvSphereNormalsConvergeToNormalizedPositions) {
  const double coarse = worstSphereError(16, 8);
  const double fine = worstSphereError(64, 32);
  EXPECT_LT(coarse, 3.0);
  EXPECT_LT(fine, 0.2);
  // Second order: halving the faces' size twice divides the error by about 16.
  EXPECT_LT(fine, coarse / 8);
}

TEST(MeshNormals, SmoothNormalsAreSharedByAllCornersOfAVertex) {
  Mesh mesh = uvSphere(12, 6);
  computeSmoothNormals(mesh);
  ASSERT_EQ(mesh.cornerNormals.size(), mesh.numCorners());
  std::vector<const Vec3f*> first(mesh.numVertices(), nullptr);
  for (std::size_t c = 0; c < mesh.numCorners(); ++c) {
    const Vec3f*& seen = first[mesh.cornerVertex[c]];
    if (seen == nullptr) seen = &mesh.cornerNormals[c];
    EXPECT_EQ(*seen, mesh.cornerNormals[c]) << "corner " << c;
  }
}

TEST(MeshNormals, SmoothNormalsDoNotDependOnTheNumberOfThreads) {
  // Large enough to be split among threads; each vertex adds its corners in corner order.
  Mesh parallel = uvSphere(400, 200);
  Mesh serial = parallel;
  computeSmoothNormals(parallel);
  tbb::task_arena one(1);
  one.execute([&] { computeSmoothNormals(serial); });
  EXPECT_TRUE(parallel.cornerNormals == serial.cornerNormals);
}

Mesh unitCube() {
  return makeMesh({{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                   {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},
                  {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6},
                   {3, 0, 4, 7}});
}

TEST(MeshNormals, SplitNormalsSplitWhereFacesMeetAtMoreThanTheAngle) {
  // The cube's faces meet at 90 degrees: at 30 (Blender's default) every corner is its face's
  // normal; at 90 exactly the edges stay smooth (sharp only above the angle) and the normals
  // are the smooth ones, bit for bit (same weights, same order).
  Mesh split = unitCube();
  computeSplitNormals(split, 30 * kPi / 180);
  const std::vector<Vec3f> faceNormals = computeFaceNormals(split.view());
  for (std::size_t f = 0; f < split.numFaces(); ++f) {
    for (std::uint32_t c = split.faceStart[f]; c < split.faceStart[f + 1]; ++c) {
      EXPECT_EQ(split.cornerNormals[c], faceNormals[f]) << "corner " << c;
    }
  }
  EXPECT_EQ(split.normalSource, NormalSource::kComputed);
  Mesh smooth = unitCube(), wide = unitCube();
  computeSmoothNormals(smooth);
  computeSplitNormals(wide, kPi / 2);
  EXPECT_TRUE(wide.cornerNormals == smooth.cornerNormals);
  Mesh sphere = uvSphere(24, 12), sphereSmooth = sphere;
  computeSplitNormals(sphere, kPi);
  computeSmoothNormals(sphereSmooth);
  EXPECT_TRUE(sphere.cornerNormals == sphereSmooth.cornerNormals);
}

TEST(MeshNormals, SmoothNormalsGiveFlatFacesTheirFaceNormal) {
  // The roof of the test below, its third quad flat: that quad's corners take its own normal;
  // the smooth quads' corners the vertex normal, which still sums the flat quad in (Blender's
  // vertex normals do), so at vertex 4 it differs from the sum of the smooth faces alone.
  Mesh roof = makeMesh({{0, 0, 0},
                        {0, 1, 0},
                        {1, 0, std::sqrt(3.0f)},
                        {1, 1, std::sqrt(3.0f)},
                        {2, 0, 0},
                        {2, 1, 0},
                        {3, 0, 0},
                        {3, 1, 0}},
                       {{0, 2, 3, 1}, {2, 4, 5, 3}, {4, 6, 7, 5}});
  Mesh smooth = roof;
  computeSmoothNormals(smooth);
  roof.faceFlat = {0, 0, 1};
  computeSmoothNormals(roof);
  const std::vector<Vec3f> faceNormals = computeFaceNormals(roof.view());
  for (std::uint32_t c = 8; c < 12; ++c) EXPECT_EQ(roof.cornerNormals[c], faceNormals[2]);
  for (std::uint32_t c = 0; c < 8; ++c) EXPECT_EQ(roof.cornerNormals[c], smooth.cornerNormals[c]);
  EXPECT_GT(angleDegrees(cast<double>(roof.cornerNormals[5]), cast<double>(faceNormals[1])), 1);
}

TEST(MeshNormals, SplitNormalsSeparateFlatFacesAndEachSideOfASharpEdge) {
  // A prism seen end-on: a roof of two quads sloping at 60 degrees, so that their normals are
  // 120 degrees apart, and a third quad flat-shaded beside them. At 150 degrees the ridge is
  // smooth: both roof quads share the ridge normal (their normalized sum). The flat quad keeps its own normal, and the roof corner
  // next to it does not take it in.
  Mesh roof = makeMesh({{0, 0, 0}, {0, 1, 0}, {1, 0, std::sqrt(3.0f)}, {1, 1, std::sqrt(3.0f)},
                        {2, 0, 0}, {2, 1, 0}, {3, 0, 0}, {3, 1, 0}},
                       {{0, 2, 3, 1}, {2, 4, 5, 3}, {4, 6, 7, 5}});
  roof.faceFlat = {0, 0, 1};
  computeSplitNormals(roof, 5 * kPi / 6);
  const std::vector<Vec3f> faceNormals = computeFaceNormals(roof.view());
  const Vec3d ridge =
      normalizeOr(cast<double>(faceNormals[0]) + cast<double>(faceNormals[1]), Vec3d{});
  expectNear(roof.cornerNormals[1], ridge);  // face 0 at vertex 2
  expectNear(roof.cornerNormals[4], ridge);  // face 1 at vertex 2
  for (std::uint32_t c = 8; c < 12; ++c) EXPECT_EQ(roof.cornerNormals[c], faceNormals[2]);
  expectNear(roof.cornerNormals[5], cast<double>(faceNormals[1]));  // face 1 at vertex 4
  // At 90 degrees the ridge is sharp: each roof quad is flat.
  computeSplitNormals(roof, kPi / 2);
  expectNear(roof.cornerNormals[1], cast<double>(faceNormals[0]));
  expectNear(roof.cornerNormals[4], cast<double>(faceNormals[1]));
}

TEST(MeshNormals, ValidateReportsEachBrokenInvariantOnOneLine) {
  Mesh good = makeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
  computeSmoothNormals(good);
  good.uvSets.push_back({"UVMap", {{0, 0}, {1, 0}, {0, 1}}});
  ASSERT_TRUE(validate(good).ok());

  const float nan = std::nanf("");
  std::vector<std::pair<std::string, Mesh>> broken;
  auto add = [&](std::string what, auto change) {
    Mesh m = good;
    change(m);
    broken.emplace_back(std::move(what), std::move(m));
  };
  add("faceStart not at 0", [](Mesh& m) { m.faceStart[0] = 1; });
  add("two-corner face", [](Mesh& m) { m.faceStart = {0, 2, 3}; });
  add("faceStart past the corners", [](Mesh& m) { m.faceStart.back() = 4; });
  add("vertex out of range", [](Mesh& m) { m.cornerVertex[2] = 3; });
  add("NaN position", [&](Mesh& m) { m.positions[1].y = nan; });
  add("missing normals", [](Mesh& m) { m.cornerNormals.pop_back(); });
  add("long normal", [](Mesh& m) { m.cornerNormals[0] = {0, 0, 1.01f}; });
  add("NaN normal", [&](Mesh& m) { m.cornerNormals[1].x = nan; });
  add("short UV set", [](Mesh& m) { m.uvSets[0].uvs.pop_back(); });
  add("infinite UV", [](Mesh& m) { m.uvSets[0].uvs[2].x = INFINITY; });
  for (const auto& [what, mesh] : broken) {
    const Status status = validate(mesh);
    ASSERT_FALSE(status.ok()) << what;
    EXPECT_EQ(status.error().code, ErrorCode::kBadInput) << what;
    EXPECT_EQ(status.error().message.rfind("test mesh: ", 0), 0u) << status.error().message;
    EXPECT_EQ(status.error().message.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace sgbake
