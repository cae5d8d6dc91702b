// subdivideMesh: counts, closed-form limit points of regular Catmull-Clark patches, UVs with
// linear face-varying interpolation, and a watertight, consistently oriented result.
#include "sgbake/subdiv/subdivide.hpp"
#include "sgbake/subdiv/limit_surface.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/mesh/normals.hpp"
#include "support/bspline_torus.hpp"

namespace sgbake {
namespace {

using test::meshOf;
using test::torusGrid;
using test::torusGridWithUvs;
using test::torusGridLimit;


Mesh cube() {
  return meshOf({{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                     {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},
                    {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6},
                     {3, 0, 4, 7}});
}

/// A prism over a regular n-gon: two n-gon caps and n quads (n = 3: triangles).
Mesh prism(std::uint32_t n) {
  std::vector<Vec3f> positions;
  for (std::uint32_t z = 0; z < 2; ++z) {
    for (std::uint32_t k = 0; k < n; ++k) {
      const double a = 2 * kPi * k / n;
      positions.push_back({static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)),
                           static_cast<float>(z)});
    }
  }
  std::vector<std::vector<std::uint32_t>> faces(2);
  for (std::uint32_t k = 0; k < n; ++k) {
    faces[0].push_back(n - 1 - k);  // bottom, facing -z
    faces[1].push_back(n + k);      // top, facing +z
    faces.push_back({k, (k + 1) % n, n + (k + 1) % n, n + k});
  }
  return meshOf(std::move(positions), faces);
}


Vec3d at(const Mesh& mesh, std::uint32_t v) { return cast<double>(mesh.positions[v]); }

/// Index of the vertex of @p mesh nearest to @p p, and its distance.
std::pair<std::uint32_t, double> nearest(const Mesh& mesh, Vec3d p) {
  std::pair<std::uint32_t, double> best{0, 1e30};
  for (std::uint32_t v = 0; v < mesh.numVertices(); ++v) {
    const double d = length(at(mesh, v) - p);
    if (d < best.second) best = {v, d};
  }
  return best;
}

/// Every directed edge appears once and its reverse once: closed, manifold, consistently
/// oriented.
void expectClosedAndOriented(const Mesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const std::uint32_t first = mesh.faceStart[f], n = mesh.faceSize(f);
    for (std::uint32_t k = 0; k < n; ++k) {
      ++edges[{mesh.cornerVertex[first + k], mesh.cornerVertex[first + (k + 1) % n]}];
    }
  }
  for (const auto& [edge, count] : edges) {
    ASSERT_EQ(count, 1) << "edge " << edge.first << "-" << edge.second << " used twice";
    ASSERT_EQ(edges.count({edge.second, edge.first}), 1u)
        << "edge " << edge.first << "-" << edge.second << " has no opposite";
  }
}

TEST(Subdivide, CountsAreThoseOfBlendersModifier) {
  // A quad becomes 4^L quads; an n-gon n·4^(L-1). Vertices: V + E·(2^L - 1) + interior.
  for (int level = 1; level <= 3; ++level) {
    Result<Mesh> fine = subdivideMesh(cube(), {level});
    ASSERT_TRUE(fine) << fine.error().message;
    const std::size_t side = (std::size_t{1} << level);
    EXPECT_EQ(fine->numFaces(), 6 * side * side);
    EXPECT_EQ(fine->numVertices(), 8 + 12 * (side - 1) + 6 * (side - 1) * (side - 1));
    EXPECT_EQ(fine->numCorners(), 4 * fine->numFaces());
  }
  for (std::uint32_t n : {3u, 5u, 7u}) {
    Result<Mesh> fine = subdivideMesh(prism(n), {2});
    ASSERT_TRUE(fine) << fine.error().message;
    EXPECT_EQ(fine->numFaces(), 2 * n * 4 + n * 16) << n << "-gon prism";
    // A closed genus-0 surface has V - E + F = 2 (each edge has two corners per side).
    const std::size_t edges = fine->numCorners() / 2;
    EXPECT_EQ(fine->numVertices() + fine->numFaces(), edges + 2) << n << "-gon prism";
  }
}

TEST(Subdivide, ResultIsClosedAndConsistentlyOrientedOutward) {
  for (const Mesh& coarse : {cube(), prism(3), prism(5), prism(8)}) {
    for (int level = 1; level <= 3; ++level) {
      Result<Mesh> fine = subdivideMesh(coarse, {level});
      ASSERT_TRUE(fine) << fine.error().message;
      expectClosedAndOriented(*fine);
      // Convex input, so every new face faces away from the centre of the coarse mesh.
      Vec3d centre{0, 0, 0};
      for (std::uint32_t v = 0; v < coarse.numVertices(); ++v) centre = centre + at(coarse, v);
      centre = (1.0 / static_cast<double>(coarse.numVertices())) * centre;
      const std::vector<Vec3f> normals = computeFaceNormals(fine->view());
      for (std::size_t f = 0; f < fine->numFaces(); ++f) {
        Vec3d mid{0, 0, 0};
        for (std::uint32_t c = fine->faceStart[f]; c < fine->faceStart[f + 1]; ++c) {
          mid = mid + at(*fine, fine->cornerVertex[c]);
        }
        mid = (1.0 / fine->faceSize(f)) * mid;
        ASSERT_GT(dot(cast<double>(normals[f]), mid - centre), 0.0) << "face " << f;
      }
    }
  }
}

TEST(Subdivide, RegularPatchesAreTheUniformBicubicBSpline) {
  // Every vertex of the torus grid has valence 4, so each face is one bicubic B-spline patch of
  // its 4×4 neighbourhood: the limit of vertex P is (16 P + 4 Σ edge neighbours + Σ diagonal
  // neighbours) / 36, and the middle of a face has weights (1, 23, 23, 1)/48 in each direction.
  const int nu = 12, nv = 8;
  const Mesh coarse = torusGrid(nu, nv);
  Result<Mesh> fine = subdivideMesh(coarse, {2});
  ASSERT_TRUE(fine) << fine.error().message;
  const auto grid = [&](int i, int j) {
    return at(coarse, static_cast<std::uint32_t>(((j + nv) % nv) * nu + (i + nu) % nu));
  };
  double worst = 0;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const Vec3d vertexLimit =
          (16.0 * grid(i, j) +
           4.0 * (grid(i - 1, j) + grid(i + 1, j) + grid(i, j - 1) + grid(i, j + 1)) +
           grid(i - 1, j - 1) + grid(i + 1, j - 1) + grid(i - 1, j + 1) + grid(i + 1, j + 1));
      const Vec3d limit = (1.0 / 36) * vertexLimit;
      // Coarse vertices keep their indices (as in Blender).
      const auto v = static_cast<std::uint32_t>(j * nu + i);
      worst = std::max(worst, length(at(*fine, v) - limit));
      const double w[4] = {1.0 / 48, 23.0 / 48, 23.0 / 48, 1.0 / 48};
      Vec3d faceMiddle{0, 0, 0};
      for (int b = 0; b < 4; ++b) {
        for (int a = 0; a < 4; ++a) faceMiddle = faceMiddle + w[a] * w[b] * grid(i - 1 + a, j - 1 + b);
      }
      worst = std::max(worst, nearest(*fine, faceMiddle).second);
    }
  }
  EXPECT_LT(worst, 2e-6);  // float positions of size ~1.4
}

TEST(Subdivide, LinearUvsInterpolateEachFaceBilinearly) {
  // uv_smooth "none": UVs are linear, so a grid of UV squares becomes the grid of half squares,
  // each new corner at the average of the coarse corners around it.
  Mesh coarse = cube();
  for (std::size_t c = 0; c < coarse.numCorners(); ++c) {
    const std::size_t f = c / 4, k = c % 4;
    coarse.uvSets[0].uvs[c] = {static_cast<float>(f) + (k == 1 || k == 2 ? 1.0f : 0.0f),
                               k >= 2 ? 1.0f : 0.0f};
  }
  Result<Mesh> fine = subdivideMesh(coarse, {1, SubdivisionUvSmooth::kNone});
  ASSERT_TRUE(fine) << fine.error().message;
  std::set<std::pair<float, float>> expected, got;
  for (int f = 0; f < 6; ++f) {
    for (int a = 0; a <= 2; ++a) {
      for (int b = 0; b <= 2; ++b) expected.insert({static_cast<float>(f + 0.5 * a), static_cast<float>(0.5 * b)});
    }
  }
  for (const Vec2f& uv : fine->uvSets[0].uvs) got.insert({uv.x, uv.y});
  EXPECT_EQ(got, expected);
  // Each new face lies in one coarse face's UV square and keeps its winding (area > 0).
  for (std::size_t f = 0; f < fine->numFaces(); ++f) {
    const Vec2f* t = &fine->uvSets[0].uvs[fine->faceStart[f]];
    const double area = 0.5 * ((t[1].x - t[0].x) * (t[2].y - t[0].y) -
                               (t[2].x - t[0].x) * (t[1].y - t[0].y));
    EXPECT_NEAR(area, 0.125, 1e-6) << "face " << f;
  }
}

TEST(Subdivide, CornersWithNearlyEqualUvsShareTheLastCornersUv) {
  // Two quads side by side; the second gives the shared vertices 1 and 4 UVs 1e-5 away from the
  // first's (within Blender's 1e-4 connect limit): one face-varying value per vertex, whose
  // value is the UV of the later corner (Blender writes each corner's UV in turn). With UV
  // Smooth none, a corner at a coarse vertex gets exactly that value.
  Mesh mesh = meshOf({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}},
                     {{0, 1, 4, 3}, {1, 2, 5, 4}});
  const float shifted = 0.5f + 1e-5f;
  mesh.uvSets[0].uvs = {{0, 0}, {0.5f, 0}, {0.5f, 1}, {0, 1},
                        {shifted, 0}, {1, 0}, {1, 1}, {shifted, 1}};
  Result<Mesh> fine = subdivideMesh(mesh, {1, SubdivisionUvSmooth::kNone});
  ASSERT_TRUE(fine) << fine.error().message;
  int atShared = 0;
  for (std::size_t c = 0; c < fine->numCorners(); ++c) {
    const std::uint32_t v = fine->cornerVertex[c];
    if (v != 1 && v != 4) continue;  // coarse vertices keep their index
    ++atShared;
    EXPECT_EQ(fine->uvSets[0].uvs[c].x, shifted) << "corner " << c;
  }
  EXPECT_EQ(atShared, 4);  // one sub-face of each quad at each shared vertex
}

TEST(Subdivide, KeepsEveryUvSetAndComputesSmoothNormals) {
  Mesh coarse = prism(5);
  coarse.uvSets.push_back({"second", coarse.uvSets[0].uvs});
  // Turned by 180°: the same UV winding (which decides which corners share a value, as in
  // Blender), and every value negated exactly.
  for (Vec2f& uv : coarse.uvSets[1].uvs) uv = {-uv.x, -uv.y};
  Result<Mesh> fine = subdivideMesh(coarse, {2});
  ASSERT_TRUE(fine) << fine.error().message;
  ASSERT_EQ(fine->uvSets.size(), 2u);
  EXPECT_EQ(fine->uvSets[1].name, "second");
  for (std::size_t c = 0; c < fine->numCorners(); ++c) {
    const Vec2f a = fine->uvSets[0].uvs[c], b = fine->uvSets[1].uvs[c];
    ASSERT_EQ(a.x, -b.x);
    ASSERT_EQ(a.y, -b.y);
  }
  Mesh renormalized = *fine;
  computeSmoothNormals(renormalized);
  EXPECT_EQ(fine->cornerNormals, renormalized.cornerNormals);
  EXPECT_EQ(fine->normalSource, NormalSource::kComputed);
}

TEST(Subdivide, LevelZeroIsTheMeshAndBadLevelsAreNamed) {
  const Mesh coarse = cube();
  Result<Mesh> same = subdivideMesh(coarse, {0});
  ASSERT_TRUE(same);
  EXPECT_EQ(same->positions, coarse.positions);
  EXPECT_EQ(same->cornerVertex, coarse.cornerVertex);
  for (int level : {-1, kMaxSubdivisionLevel + 1}) {
    Result<Mesh> bad = subdivideMesh(coarse, {level});
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().code, ErrorCode::kBadInput);
    EXPECT_EQ(bad.error().message.rfind("test.obj: subdivision level", 0), 0u)
        << bad.error().message;
  }
  Mesh repeated = cube();
  repeated.cornerVertex[1] = repeated.cornerVertex[0];
  Result<Mesh> bad = subdivideMesh(repeated, {1});
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, "test.obj: face 0 uses a vertex twice and cannot be subdivided");
}

TEST(Subdivide, AResultTooLargeForAMeshIsAnErrorNotAnOverflow) {
  // 520² quads at level 6: 1.1e9 faces, 4.4e9 corners, more than 32-bit corner indices reach.
  std::vector<Vec3f> positions;
  const int n = 520;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) positions.push_back({static_cast<float>(i), static_cast<float>(j), 0});
  }
  std::vector<std::vector<std::uint32_t>> faces;
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  }
  const Mesh plane = meshOf(std::move(positions), faces);
  Result<Mesh> huge = subdivideMesh(plane, {6});
  ASSERT_FALSE(huge);
  EXPECT_EQ(huge.error().code, ErrorCode::kBadInput);
  EXPECT_EQ(huge.error().message,
            "test.obj: subdivision level 6 would make 1107558400 faces, more than a mesh holds "
            "(1073741823)");
}



TEST(LimitSurface, RegularFacesAreTheBicubicBSplineWithItsDerivatives) {
  const int nu = 10, nv = 7;
  const Mesh coarse = torusGrid(nu, nv);
  Result<LimitSurface> limit = LimitSurface::create(coarse, {1});
  ASSERT_TRUE(limit) << limit.error().message;
  EXPECT_EQ(limit->numFaces(), static_cast<std::size_t>(nu * nv));
  LimitSurface::Evaluator evaluator(*limit);
  double worst = 0;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      for (const Vec2d st : {Vec2d{0.25, 0.6}, Vec2d{0, 1}, Vec2d{0.9, 0.05}}) {
        Vec3d P, Ps, Pt;
        torusGridLimit(coarse, nu, nv, i, j, st.x, st.y, P, Ps, Pt);
        LimitPoint p;
        ASSERT_TRUE(evaluator.evaluate(static_cast<std::uint32_t>(j * nu + i), 0, st, p));
        worst = std::max({worst, length(p.position - P), length(p.dPds - Ps), length(p.dPdt - Pt)});
      }
    }
  }
  EXPECT_LT(worst, 1e-12);
  LimitPoint unused;
  EXPECT_FALSE(evaluator.evaluate(static_cast<std::uint32_t>(nu * nv), 0, {0.5, 0.5}, unused));
  EXPECT_FALSE(evaluator.evaluate(0, 1, {0.5, 0.5}, unused));  // a quad has one sub-face
}

TEST(LimitSurface, LocateFindsWhereTheUvsTakeAValue) {
  const int nu = 8, nv = 6;
  const Mesh coarse = torusGridWithUvs(nu, nv);
  for (const SubdivisionUvSmooth uvSmooth : {SubdivisionUvSmooth::kNone, SubdivisionUvSmooth::kAll}) {
    Result<LimitSurface> limit = LimitSurface::create(coarse, {1, uvSmooth});
    ASSERT_TRUE(limit) << limit.error().message;
    LimitSurface::Evaluator evaluator(*limit);
    for (int f = 0; f < nu * nv; ++f) {
      const double i = f % nu, j = f / nu;
      const Vec2d target{(i + 0.3) / nu, (j + 0.8) / nv};
      LimitPoint p;
      ASSERT_TRUE(evaluator.locate(static_cast<std::uint32_t>(f), 0, {0.5, 0.5}, 0, target, p));
      EXPECT_LT(std::sqrt(lengthSquared(p.uv[0] - target)), 1e-12) << "face " << f;
      if (uvSmooth == SubdivisionUvSmooth::kNone) {
        // Linear UVs: the point is where the face's bilinear UVs reach the target.
        LimitPoint expected;
        ASSERT_TRUE(evaluator.evaluate(static_cast<std::uint32_t>(f), 0, {0.3, 0.8}, expected));
        EXPECT_LT(length(p.position - expected.position), 1e-7) << "face " << f;  // float UVs
      }
    }
  }
}

TEST(LimitSurface, SubdividedVerticesAndUvsAreTheSurfaceAtTheirParameters) {
  for (const Mesh& coarse : {cube(), prism(3), prism(5), torusGridWithUvs(6, 5)}) {
    for (const SubdivisionUvSmooth uvSmooth :
         {SubdivisionUvSmooth::kKeepBoundaries, SubdivisionUvSmooth::kAll}) {
      SurfaceParameters parameters;
      Result<Mesh> fine = subdivideMesh(coarse, {2, uvSmooth}, &parameters);
      ASSERT_TRUE(fine) << fine.error().message;
      ASSERT_EQ(parameters.faceOrigin.size(), fine->numFaces());
      ASSERT_EQ(parameters.cornerCoord.size(), fine->numCorners());
      Result<LimitSurface> limit = LimitSurface::create(coarse, {2, uvSmooth});
      ASSERT_TRUE(limit) << limit.error().message;
      LimitSurface::Evaluator evaluator(*limit);
      double worstPosition = 0, worstUv = 0;
      for (std::size_t c = 0; c < fine->numCorners(); ++c) {
        LimitPoint p;
        ASSERT_TRUE(evaluator.evaluate(parameters.faceOrigin[c / 4], parameters.cornerSubFace[c],
                                       cast<double>(parameters.cornerCoord[c]), p));
        worstPosition = std::max(worstPosition,
                                 length(p.position - at(*fine, fine->cornerVertex[c])));
        worstUv = std::max(worstUv, std::sqrt(lengthSquared(p.uv[0] - cast<double>(fine->uvSets[0].uvs[c]))));
      }
      // subdivideMesh evaluates Blender's patches: exact where the surface is regular, within
      // float rounding of the limit where it is isolated to Quality 3. Smoothed UVs ("all")
      // around an irregular UV vertex are approximated more coarsely by Blender's face-varying
      // patches (measured: up to 7.8e-3 on these meshes; Blender's own modifier gives the same
      // floats, BlenderSubdivisionOracle).
      const double uvTolerance = uvSmooth == SubdivisionUvSmooth::kAll ? 1e-2 : 1e-6;
      EXPECT_LT(worstPosition, 1e-6) << coarse.numFaces() << " faces";  // positions of size ~1
      EXPECT_LT(worstUv, uvTolerance) << coarse.numFaces() << " faces";
    }
  }
}

}  // namespace
}  // namespace sgbake
