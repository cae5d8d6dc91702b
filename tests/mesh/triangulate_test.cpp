// triangulatePolygon against Blender 3.4's loop triangles (Mesh.loop_triangles) for n-gons of
// every kind the rule distinguishes, and the invariants any triangulation must keep.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "sgbake/mesh/triangulate.hpp"

namespace sgbake {
namespace {

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

struct RecordedCase {
  std::string name;
  std::vector<Vec3f> points;
  Triangles blender;
};

// Recorded from Blender 3.4.1 (headless, --factory-startup): each polygon was the only face of a
// mesh built with Mesh.from_pydata-style loops, Mesh.calc_loop_triangles() was called, and
// Mesh.loop_triangles[i].loops (loop index = corner index) is listed in Blender's order. The
// positions are the float values Blender stored. Names: reg/irrconv convex, star/L/U/comb/rand
// concave, _r<n> corner order rotated by n, _rev reversed, _tilt rotated out of the xy plane,
// twist/zig/randnp/wavy non-planar, coll collinear corners, thin/spike nearly degenerate,
// rand3d/randorder self-intersecting (no ear at some step).
// One case per three lines, as recorded.
// clang-format off
const std::vector<RecordedCase>& recordedCases() {
  static const std::vector<RecordedCase> cases{
    {"star10",
     {{6.12323426e-17f, 1.0f, 0.0f}, {-0.235114098f, 0.323606789f, 0.0f}, {-0.95105654f, 0.309017003f, 0.0f}, {-0.380422592f, -0.123606801f, 0.0f}, {-0.587785244f, -0.809017003f, 0.0f}, {-7.34788112e-17f, -0.400000006f, 0.0f}, {0.587785244f, -0.809017003f, 0.0f}, {0.380422592f, -0.123606801f, 0.0f}, {0.95105654f, 0.309017003f, 0.0f}, {0.235114098f, 0.323606789f, 0.0f}},
     {{9, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 8, 9}, {9, 1, 3}, {3, 5, 7}, {3, 7, 9}}},
    {"reg5",
     {{1.0f, 0.0f, 0.0f}, {0.309017003f, 0.95105654f, 0.0f}, {-0.809017003f, 0.587785244f, 0.0f}, {-0.809017003f, -0.587785244f, 0.0f}, {0.309017003f, -0.95105654f, 0.0f}},
     {{4, 0, 1}, {1, 2, 3}, {1, 3, 4}}},
    {"reg8",
     {{1.0f, 0.0f, 0.0f}, {0.707106769f, 0.707106769f, 0.0f}, {6.12323426e-17f, 1.0f, 0.0f}, {-0.707106769f, 0.707106769f, 0.0f}, {-1.0f, 1.22464685e-16f, 0.0f}, {-0.707106769f, -0.707106769f, 0.0f}, {-1.83697015e-16f, -1.0f, 0.0f}, {0.707106769f, -0.707106769f, 0.0f}},
     {{7, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 1, 3}, {3, 5, 7}}},
    {"reg12_ph",
     {{0.955336511f, 0.295520216f, 0.0f}, {0.679585576f, 0.733596265f, 0.0f}, {0.221740231f, 0.975105762f, 0.0f}, {-0.295520216f, 0.955336511f, 0.0f}, {-0.733596265f, 0.679585576f, 0.0f}, {-0.975105762f, 0.221740231f, 0.0f}, {-0.955336511f, -0.295520216f, 0.0f}, {-0.679585576f, -0.733596265f, 0.0f}, {-0.221740231f, -0.975105762f, 0.0f}, {0.295520216f, -0.955336511f, 0.0f}, {0.733596265f, -0.679585576f, 0.0f}, {0.975105762f, -0.221740231f, 0.0f}},
     {{11, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 8, 9}, {9, 10, 11}, {11, 1, 3}, {3, 5, 7}, {7, 9, 11}, {3, 7, 11}}},
    {"irrconv9_0",
     {{0.111756742f, 0.695614934f, 0.0f}, {-0.999901056f, -0.0098453695f, 0.0f}, {-0.996258616f, -0.0604953803f, 0.0f}, {-0.96917814f, -0.172452733f, 0.0f}, {-0.882897377f, -0.328696221f, 0.0f}, {0.128593624f, -0.694188178f, 0.0f}, {0.638825834f, -0.538545966f, 0.0f}, {0.955732763f, -0.20596531f, 0.0f}, {0.993665516f, -0.0786645412f, 0.0f}},
     {{8, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 8, 1}, {1, 3, 5}, {1, 5, 7}}},
    {"star5_0.5",
     {{1.0f, 0.0f, 0.0f}, {0.404508501f, 0.293892622f, 0.0f}, {0.309017003f, 0.95105654f, 0.0f}, {-0.154508501f, 0.47552827f, 0.0f}, {-0.809017003f, 0.587785244f, 0.0f}, {-0.5f, 6.12323426e-17f, 0.0f}, {-0.809017003f, -0.587785244f, 0.0f}, {-0.154508501f, -0.47552827f, 0.0f}, {0.309017003f, -0.95105654f, 0.0f}, {0.404508501f, -0.293892622f, 0.0f}},
     {{9, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 8, 9}, {9, 1, 3}, {3, 5, 7}, {3, 7, 9}}},
    // Recorded later (a second set of 1,600 polygons): coincident corners, a comb tilted out of
    // the xy plane, collinear corners on a grid. Blender decides them in float.
    {"grid_coincident",
     {{0.25f, 0.75f, 0.0f}, {0.5f, 0.25f, 0.0f}, {0.5f, 0.25f, 0.0f}, {0.5f, 0.25f, 0.0f}, {0.75f, 0.0f, 0.0f}, {0.25f, 0.5f, 0.0f}},
     {{1, 2, 3}, {1, 3, 4}, {5, 0, 1}, {1, 4, 5}}},
    {"comb_tilt",
     {{0.0f, 0.0f, -0.0f}, {4.0f, 0.0f, -0.0f}, {4.0f, 2.67068624f, -1.36654127f}, {3.0f, 2.67068624f, -1.36654127f}, {3.0f, 0.890228748f, -0.455513775f}, {2.0f, 2.67068624f, -1.36654127f}, {1.0f, 2.67068624f, -1.36654127f}, {1.0f, 0.890228748f, -0.455513775f}},
     {{7, 0, 1}, {1, 2, 3}, {4, 5, 6}, {1, 3, 4}, {4, 6, 7}, {1, 4, 7}}},
    {"grid_collinear",
     {{0.25f, 0.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {0.0f, 0.5f, 0.0f}, {1.0f, 0.75f, 0.0f}, {0.25f, 0.75f, 0.0f}, {0.5f, 0.0f, 0.0f}, {0.0f, 0.75f, 0.0f}, {0.75f, 0.75f, 0.0f}, {1.0f, 0.25f, 0.0f}},
     {{4, 5, 6}, {7, 8, 0}, {7, 0, 1}, {4, 6, 7}, {3, 4, 7}, {3, 7, 1}, {1, 2, 3}}},
    {"L",
     {{0.0f, 0.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {2.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {1.0f, 2.0f, 0.0f}, {0.0f, 2.0f, 0.0f}},
     {{0, 1, 2}, {3, 4, 5}, {0, 2, 3}, {0, 3, 5}}},
    {"U",
     {{0.0f, 0.0f, 0.0f}, {3.0f, 0.0f, 0.0f}, {3.0f, 3.0f, 0.0f}, {2.0f, 3.0f, 0.0f}, {2.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {1.0f, 3.0f, 0.0f}, {0.0f, 3.0f, 0.0f}},
     {{1, 2, 3}, {1, 3, 4}, {6, 7, 0}, {1, 4, 5}, {5, 6, 0}, {0, 1, 5}}},
    {"comb",
     {{0.0f, 0.0f, 0.0f}, {5.0f, 0.0f, 0.0f}, {5.0f, 2.0f, 0.0f}, {4.0f, 2.0f, 0.0f}, {4.0f, 1.0f, 0.0f}, {3.0f, 1.0f, 0.0f}, {3.0f, 2.0f, 0.0f}, {2.0f, 2.0f, 0.0f}, {2.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {1.0f, 2.0f, 0.0f}, {0.0f, 2.0f, 0.0f}},
     {{1, 2, 3}, {1, 3, 4}, {10, 11, 0}, {9, 10, 0}, {0, 1, 4}, {5, 6, 7}, {0, 4, 5}, {8, 9, 0}, {5, 7, 8}, {0, 5, 8}}},
    {"U_r2",
     {{3.0f, 3.0f, 0.0f}, {2.0f, 3.0f, 0.0f}, {2.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {1.0f, 3.0f, 0.0f}, {0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {3.0f, 0.0f, 0.0f}},
     {{7, 0, 1}, {7, 1, 2}, {4, 5, 6}, {7, 2, 3}, {3, 4, 6}, {3, 6, 7}}},
    {"star10_rev",
     {{0.235114098f, 0.323606789f, 0.0f}, {0.95105654f, 0.309017003f, 0.0f}, {0.380422592f, -0.123606801f, 0.0f}, {0.587785244f, -0.809017003f, 0.0f}, {-7.34788112e-17f, -0.400000006f, 0.0f}, {-0.587785244f, -0.809017003f, 0.0f}, {-0.380422592f, -0.123606801f, 0.0f}, {-0.95105654f, 0.309017003f, 0.0f}, {-0.235114098f, 0.323606789f, 0.0f}, {6.12323426e-17f, 1.0f, 0.0f}},
     {{0, 1, 2}, {2, 3, 4}, {4, 5, 6}, {6, 7, 8}, {8, 9, 0}, {0, 2, 4}, {4, 6, 8}, {0, 4, 8}}},
    {"rand9_1",
     {{0.900024414f, 0.235363752f, 0.0f}, {0.493579388f, 0.83218658f, 0.0f}, {-0.0342114158f, 0.30941534f, 0.0f}, {-0.473881662f, 0.669947803f, 0.0f}, {-0.869638979f, -0.0825127438f, 0.0f}, {-0.503343463f, -0.525642633f, 0.0f}, {-0.0957863256f, -0.754268467f, 0.0f}, {0.197998062f, -0.519600809f, 0.0f}, {0.932914317f, -0.110589713f, 0.0f}},
     {{8, 0, 1}, {2, 3, 4}, {8, 1, 2}, {5, 6, 7}, {7, 8, 2}, {2, 4, 5}, {2, 5, 7}}},
    {"rand12_2",
     {{0.501194596f, 0.1991079f, 0.0f}, {0.677284658f, 0.272124887f, 0.0f}, {0.24110949f, 0.732158542f, 0.0f}, {-0.465512186f, 0.643995047f, 0.0f}, {-0.469296962f, 0.619129956f, 0.0f}, {-0.684013188f, 0.418277413f, 0.0f}, {-0.397377163f, -0.055719275f, 0.0f}, {-0.911639273f, -0.362651438f, 0.0f}, {-0.270330518f, -0.172739878f, 0.0f}, {-0.737458229f, -0.574653685f, 0.0f}, {0.644556582f, -0.604477465f, 0.0f}, {0.809577882f, -0.349333584f, 0.0f}},
     {{0, 1, 2}, {2, 3, 4}, {4, 5, 6}, {6, 7, 8}, {8, 9, 10}, {10, 11, 0}, {0, 2, 4}, {4, 6, 8}, {8, 10, 0}, {0, 4, 8}}},
    {"U_tilt",
     {{0.0f, 0.0f, 0.0f}, {2.76318288f, 0.0f, -1.16825497f}, {3.51579356f, 2.29452658f, 0.611836314f}, {2.59473252f, 2.29452658f, 1.00125468f}, {2.09299207f, 0.764842212f, -0.185472906f}, {1.17193115f, 0.764842212f, 0.203945443f}, {1.6736716f, 2.29452658f, 1.39067304f}, {0.752610564f, 2.29452658f, 1.7800914f}},
     {{1, 2, 3}, {1, 3, 4}, {6, 7, 0}, {1, 4, 5}, {5, 6, 0}, {0, 1, 5}}},
    {"twist8_1.2",
     {{1.0f, 0.0f, 0.0f}, {0.707106769f, 0.707106769f, 1.20000005f}, {6.12323426e-17f, 1.0f, 1.46957622e-16f}, {-0.707106769f, 0.707106769f, -1.20000005f}, {-1.0f, 1.22464685e-16f, -2.93915245e-16f}, {-0.707106769f, -0.707106769f, 1.20000005f}, {-1.83697015e-16f, -1.0f, 4.4087284e-16f}, {0.707106769f, -0.707106769f, -1.20000005f}},
     {{7, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 1, 3}, {3, 5, 7}}},
    {"zig7_1.0",
     {{1.0f, 0.0f, 0.0f}, {0.623489797f, 0.781831503f, 1.0f}, {-0.222520933f, 0.974927902f, 0.0f}, {-0.90096885f, 0.433883727f, 1.0f}, {-0.90096885f, -0.433883727f, 0.0f}, {-0.222520933f, -0.974927902f, 1.0f}, {0.623489797f, -0.781831503f, 0.0f}},
     {{6, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 1}, {1, 3, 5}}},
    {"randnp9_2_r2",
     {{-0.645329177f, -0.383579671f, -0.113012686f}, {-0.394120961f, -0.568767428f, 0.141436338f}, {-0.231567562f, -0.591535747f, 0.478094101f}, {-0.143590793f, -0.444833994f, -0.487831652f}, {-0.153789982f, -0.956394672f, -0.187992275f}, {0.136213526f, -0.475526333f, -0.084440954f}, {0.658940673f, -0.281311363f, 0.486114562f}, {-0.60668236f, 0.297564358f, -0.252084285f}, {-0.842763007f, -0.0696220696f, -0.380906552f}},
     {{8, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 8, 1}, {1, 3, 5}, {1, 5, 7}}},
    {"coll6_r1",
     {{1.0f, 0.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {2.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 0.0f}},
     {{5, 0, 1}, {1, 2, 3}, {3, 4, 5}, {1, 3, 5}}},
    {"coll8",
     {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {3.0f, 0.0f, 0.0f}, {3.0f, 1.0f, 0.0f}, {2.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}},
     {{7, 0, 1}, {2, 3, 4}, {7, 1, 2}, {4, 5, 6}, {6, 7, 2}, {2, 4, 6}}},
    {"coll5_r1",
     {{1.0f, 0.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {2.0f, 2.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, 0.0f}},
     {{4, 0, 1}, {1, 2, 3}, {1, 3, 4}}},
    {"thin6",
     {{0.0f, 0.0f, 0.0f}, {1.0f, 0.00100000005f, 0.0f}, {2.0f, 0.0f, 0.0f}, {3.0f, 0.00100000005f, 0.0f}, {4.0f, 0.0f, 0.0f}, {2.0f, 0.00200000009f, 0.0f}},
     {{5, 0, 1}, {1, 2, 3}, {3, 4, 5}, {1, 3, 5}}},
    {"spike7",
     {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {0.5f, 1.0f, 0.0f}, {0.5f, 5.0f, 0.0f}, {0.49000001f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}},
     {{6, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 1}, {1, 3, 5}}},
    {"wavy9_3",
     {{0.343710959f, 0.300716251f, 0.66739887f}, {0.391623706f, 0.698464751f, -0.87582314f}, {0.538288176f, 0.54245156f, -0.818181038f}, {-0.0760379955f, 0.388674676f, 0.619419515f}, {-0.452242374f, 0.324213594f, 0.262691259f}, {-0.152631491f, -0.454333693f, 0.324610859f}, {0.151858419f, -0.856951952f, -1.13163328f}, {0.335547447f, -0.585128069f, -0.688772619f}, {0.433669001f, -0.487670928f, 0.472564399f}},
     {{8, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 8, 1}, {1, 3, 5}, {1, 5, 7}}},
    {"rand3d8_1",
     {{0.553215027f, 0.619144797f, 0.268596888f}, {-0.0616827495f, 0.12410783f, -0.548026383f}, {0.927728415f, -0.293736577f, 0.277592957f}, {0.637478292f, 0.632358313f, -0.0637982339f}, {-0.411315352f, 0.0965354219f, -0.749667823f}, {0.667488933f, -0.290507674f, 0.701339245f}, {-0.465151042f, -0.247703001f, -0.492901683f}, {-0.147791058f, -0.628220558f, -0.994609892f}},
     {{7, 0, 1}, {1, 2, 3}, {3, 4, 5}, {5, 6, 7}, {7, 1, 3}, {3, 5, 7}}},
    {"randorder7_0",
     {{-0.166318744f, 0.240615293f, 0.0f}, {0.348217249f, 0.495954096f, 0.0f}, {0.693974137f, 0.328850448f, 0.0f}, {-0.757670522f, 0.68174237f, 0.0f}, {-0.41243571f, 0.133768409f, 0.0f}, {-0.254057914f, 0.476134866f, 0.0f}, {-0.60161984f, -0.505141735f, 0.0f}},
     {{3, 4, 5}, {5, 6, 0}, {5, 0, 1}, {2, 3, 5}, {1, 2, 5}}},
  };
  return cases;
}
// clang-format on

TEST(TriangulatePolygon, MatchesBlenderLoopTriangles) {
  for (const RecordedCase& c : recordedCases()) {
    Triangles triangles;
    triangulatePolygon(c.points, triangles);
    // Same triangles, in the same order, each starting at the same corner.
    EXPECT_EQ(triangles, c.blender) << c.name;
  }
}

double signedArea2(const std::vector<std::array<double, 2>>& p, std::uint32_t a, std::uint32_t b,
                   std::uint32_t c) {
  return (p[b][0] - p[a][0]) * (p[c][1] - p[a][1]) - (p[b][1] - p[a][1]) * (p[c][0] - p[a][0]);
}

/// k-2 triangles over valid, distinct corners, every corner used; for a simple polygon in the
/// xy plane (either winding), triangles that keep its winding and whose areas add up to the
/// polygon's, i.e. that tile it.
void expectTiles(const std::vector<Vec3f>& points, const std::string& name) {
  const std::size_t k = points.size();
  Triangles triangles;
  triangulatePolygon(points, triangles);
  ASSERT_EQ(triangles.size(), k - 2) << name;
  std::vector<bool> used(k, false);
  std::vector<std::array<double, 2>> p(k);
  for (std::size_t i = 0; i < k; ++i) p[i] = {points[i].x, points[i].y};
  double polygonArea = 0, sum = 0;
  for (std::size_t i = 0; i < k; ++i)
    polygonArea += p[i][0] * p[(i + 1) % k][1] - p[(i + 1) % k][0] * p[i][1];
  const double winding = polygonArea < 0 ? -1.0 : 1.0;
  polygonArea *= winding;
  for (const auto& t : triangles) {
    for (const std::uint32_t i : t) {
      ASSERT_LT(i, k) << name;
      used[i] = true;
    }
    EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) << name;
    const double area = winding * signedArea2(p, t[0], t[1], t[2]);
    EXPECT_GE(area, -1e-9 * std::abs(polygonArea)) << name;
    sum += area;
  }
  EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](bool u) { return u; })) << name;
  EXPECT_NEAR(sum, polygonArea, 1e-9 * std::abs(polygonArea)) << name;
}

TEST(TriangulatePolygon, TilesSimplePolygons) {
  // The recorded planar simple polygons in the xy plane (stars, L, U, comb, random).
  for (const RecordedCase& c : recordedCases()) {
    const bool planarXy = std::all_of(c.points.begin(), c.points.end(),
                                      [](const Vec3f& q) { return q.z == 0.0f; });
    const bool simple = c.name.rfind("randorder", 0) != 0 && c.name.rfind("thin", 0) != 0 &&
                        c.name.rfind("spike", 0) != 0 && c.name.rfind("grid", 0) != 0;
    if (planarXy && simple) expectTiles(c.points, c.name);
  }
  // Random polygons star-shaped around the origin (corners by increasing angle, no angular gap of
  // half a turn or more, so the origin is inside and the polygon simple), often very concave,
  // 5 to 40 corners.
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> radius(0.05f, 1.0f), unit(0.0f, 1.0f);
  for (int n = 0; n < 300; ++n) {
    const int k = 5 + n % 36;
    std::vector<float> angles(static_cast<std::size_t>(k));
    for (float& a : angles) a = 6.2831853f * unit(rng);
    std::sort(angles.begin(), angles.end());
    angles.erase(std::unique(angles.begin(), angles.end()), angles.end());
    float gap = angles.front() + 6.2831853f - angles.back();
    for (std::size_t i = 1; i < angles.size(); ++i) gap = std::max(gap, angles[i] - angles[i - 1]);
    std::vector<Vec3f> points;
    for (const float a : angles) {
      const float r = radius(rng);
      points.push_back({r * std::cos(a), r * std::sin(a), 0.0f});
    }
    if (points.size() >= 5 && gap < 3.1f) expectTiles(points, "random star " + std::to_string(n));
  }
}

TEST(TriangulatePolygon, TilesPolygonsOfManyCorners) {
  // A circle (its corners nearly straight in float) and a wavy, very concave ring of 20,000
  // corners: the candidate ears are tested against the non-convex corners near them only.
  for (const double waves : {0.0, 200.0}) {
    std::vector<Vec3f> points;
    const int k = 20000;
    for (int i = 0; i < k; ++i) {
      const double a = 2 * 3.14159265358979 * i / k, r = 1 + 0.3 * std::sin(waves * a);
      points.push_back(
          {static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)), 0.0f});
    }
    expectTiles(points, waves == 0 ? "circle" : "wavy ring");
  }
}

TEST(TriangulatePolygon, UsesEveryCornerOnNonPlanarAndSelfIntersectingPolygons) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coord(-1.0f, 1.0f);
  for (int n = 0; n < 200; ++n) {
    const std::size_t k = 5 + static_cast<std::size_t>(n % 20);
    std::vector<Vec3f> points(k);
    for (Vec3f& q : points) q = {coord(rng), coord(rng), n % 2 ? coord(rng) : 0.0f};
    Triangles triangles;
    triangulatePolygon(points, triangles);
    ASSERT_EQ(triangles.size(), k - 2);
    std::vector<bool> used(k, false);
    for (const auto& t : triangles)
      for (const std::uint32_t i : t) {
        ASSERT_LT(i, k);
        used[i] = true;
      }
    EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](bool u) { return u; }));
  }
}

}  // namespace
}  // namespace sgbake
