// The texel raster: Blender's looptris and nudged samples, edge functions with a tie rule,
// row-block bins, and the UDIM tiles a UV set touches. See bake.hpp and raster.hpp for the
// conventions.
#include "bake/raster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <sys/mman.h>
#include <unistd.h>

#include "sgbake/mesh/triangulate.hpp"

namespace sgbake {
namespace bake_detail {
namespace {

/// Direction (texels, y up) deciding samples exactly on an edge, rare now that samples are
/// nudged (kBakeSampleNudge): the nudge once more, taken to the limit; kTieDirection2 breaks the
/// tie of an edge parallel to it.
constexpr Vec2d kTieDirection{1, 2};
constexpr Vec2d kTieDirection2{1, 0};

/// The edge function of the directed edge p → q (positive to its left), computed with the
/// endpoints in canonical order so that q → p gives bitwise the negated function.
EdgeFunction directedEdge(Vec2d p, Vec2d q) {
  const bool swapped = (q.x < p.x) || (q.x == p.x && q.y < p.y);
  const Vec2d a = swapped ? q : p, b = swapped ? p : q;
  // E(s) = (b − a) × (s − a) = −(b.y − a.y)·s.x + (b.x − a.x)·s.y + ((b.y − a.y)·a.x − (b.x − a.x)·a.y)
  EdgeFunction e;
  e.a = -(b.y - a.y);
  e.b = b.x - a.x;
  e.c = (b.y - a.y) * a.x - (b.x - a.x) * a.y;
  if (swapped) {
    e.a = -e.a;
    e.b = -e.b;
    e.c = -e.c;
  }
  return e;
}

/// Clamps a texel-space coordinate into [lo, hi] before converting to int (UVs may be huge).
int clampedFloor(double x, int lo, int hi) {
  if (!(x >= lo)) return lo;  // also NaN
  if (x >= hi) return hi;
  return static_cast<int>(std::floor(x));
}

}  // namespace

bool setupRasterTriangle(const std::array<Vec2d, 3>& texel, int width, int height,
                         RasterTriangle& triangle) {
  // edge[i] runs from corner i+1 to corner i+2 (opposite corner i).
  for (int i = 0; i < 3; ++i) {
    triangle.edge[static_cast<std::size_t>(i)] =
        directedEdge(texel[static_cast<std::size_t>((i + 1) % 3)],
                     texel[static_cast<std::size_t>((i + 2) % 3)]);
  }
  // Twice the signed area, from the same canonical function the neighbours see.
  const double area = triangle.edge[2](texel[2].x, texel[2].y);
  if (!(area != 0) || !std::isfinite(area)) return false;
  for (EdgeFunction& e : triangle.edge) {
    if (area < 0) {  // clockwise in UV space (mirrored island): inside is to the right
      e.a = -e.a;
      e.b = -e.b;
      e.c = -e.c;
    }
    // Exactly one of the two triangles sharing an edge has the nudge pointing inside.
    const double toward = e.a * kTieDirection.x + e.b * kTieDirection.y;
    e.claimsTies = toward > 0 || (toward == 0 && e.a * kTieDirection2.x + e.b * kTieDirection2.y > 0);
  }
  const double minX = std::min({texel[0].x, texel[1].x, texel[2].x});
  const double maxX = std::max({texel[0].x, texel[1].x, texel[2].x});
  const double minY = std::min({texel[0].y, texel[1].y, texel[2].y});
  const double maxY = std::max({texel[0].y, texel[1].y, texel[2].y});
  // A sample p inside has minX ≤ p.x ≤ maxX, so its texel floor(p.x) is in [floor(minX), floor(maxX)].
  triangle.x0 = clampedFloor(minX, 0, width);
  triangle.x1 = clampedFloor(maxX, -1, width - 1);
  triangle.y0 = clampedFloor(minY, 0, height);
  triangle.y1 = clampedFloor(maxY, -1, height - 1);
  return triangle.x0 <= triangle.x1 && triangle.y0 <= triangle.y1;
}

SampleOffsets::SampleOffsets(int samples) {
  for (int i = 0; i < samples; ++i) {
    x.push_back((i + 0.5) / samples + kBakeSampleNudge.x);
    y.push_back((i + 0.5) / samples + kBakeSampleNudge.y);
  }
}

void rowSpan(const RasterTriangle& tri, int y, const SampleOffsets& offsets, int& first,
             int& last) {
  first = tri.x0;
  last = tri.x1;
  if (offsets.x.empty()) return;
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  const double maxPx = tri.x1 + 2.0;  // beyond every sample of the box (offsets < 1.002)
  // Union over the sample rows of the px interval where every edge may be ≥ 0.
  double unionLo = INFINITY, unionHi = -INFINITY;
  for (const double offsetY : offsets.y) {
    const double py = y + offsetY;
    double lo = -INFINITY, hi = INFINITY;
    bool empty = false;
    for (const EdgeFunction& e : tri.edge) {
      const double rest = e.b * py + e.c;  // E(px) = a·px + rest
      // Bound on the rounding of a·px + b·py + c, as a distance along px.
      const double slack =
          1 + 4 * kEpsilon * (std::abs(e.a) * maxPx + std::abs(e.b * py) + std::abs(e.c)) /
                  std::abs(e.a);
      if (e.a > 0) {
        lo = std::max(lo, -rest / e.a - slack);
      } else if (e.a < 0) {
        hi = std::min(hi, -rest / e.a + slack);
      } else if (rest < 0) {
        empty = true;  // a horizontal edge with the row outside (E = rest exactly)
      }
    }
    if (empty) continue;
    unionLo = std::min(unionLo, lo);
    unionHi = std::max(unionHi, hi);
  }
  if (!(unionLo <= unionHi)) {  // no sample row can be inside (NaN keeps the whole box)
    if (!std::isnan(unionLo) && !std::isnan(unionHi)) last = first - 1;
    return;
  }
  // px = x + offset ∈ [x + offsets.front(), x + offsets.back()] meets [unionLo, unionHi].
  const double xLo = std::floor(unionLo - offsets.x.back());
  const double xHi = std::floor(unionHi - offsets.x.front()) + 1;
  if (xLo > first) first = xLo > last ? last + 1 : static_cast<int>(xLo);
  if (xHi < last) last = xHi < first ? first - 1 : static_cast<int>(xHi);
}

void prefaultPages(void* data, std::size_t bytes, int pieces) {
#ifdef MADV_POPULATE_WRITE
  const long pageSize = ::sysconf(_SC_PAGESIZE);
  if (data == nullptr || bytes == 0 || pageSize <= 0 || pieces < 1) return;
  const auto page = static_cast<std::uintptr_t>(pageSize);
  // Whole pages inside the buffer only: the pages at its ends may hold other allocations.
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + page - 1) / page * page;
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) / page * page;
  if (end <= begin) return;
  const std::uintptr_t pages = (end - begin) / page;
  const auto parts = static_cast<std::uintptr_t>(pieces);
  tbb::parallel_for(std::uintptr_t{0}, parts, [&](std::uintptr_t k) {
    const std::uintptr_t first = begin + pages * k / parts * page;
    const std::uintptr_t last = begin + pages * (k + 1) / parts * page;
    // Best effort: on failure (an old kernel, no memory right now) the pages fault in later.
    if (last > first) ::madvise(reinterpret_cast<void*>(first), last - first, MADV_POPULATE_WRITE);
  });
#else
  (void)data;
  (void)bytes;
  (void)pieces;
#endif
}

TriangleBins binTriangles(const RasterJob& job) {
  const int numBlocks = (job.height + kRowsPerBlock - 1) / kRowsPerBlock;
  TriangleBins bins;
  bins.start.assign(static_cast<std::size_t>(numBlocks) + 1, 0);
  // Block range of each triangle (first, last), or first > last when outside the tile.
  std::vector<std::array<int, 2>> range(job.triangles.size());
  for (std::size_t t = 0; t < job.triangles.size(); ++t) {
    const std::array<std::uint32_t, 3>& c = job.triangles[t];
    double minY = INFINITY, maxY = -INFINITY, minX = INFINITY, maxX = -INFINITY;
    for (const std::uint32_t corner : c) {
      const Vec2d p = uvToTexel(job.uvs[corner], job.udimTile, job.width, job.height);
      minX = std::min(minX, p.x);
      maxX = std::max(maxX, p.x);
      minY = std::min(minY, p.y);
      maxY = std::max(maxY, p.y);
    }
    const int y0 = clampedFloor(minY, 0, job.height), y1 = clampedFloor(maxY, -1, job.height - 1);
    const bool outside = !(maxX >= 0) || !(minX < job.width) || y0 > y1;
    range[t] = outside ? std::array<int, 2>{1, 0}
                       : std::array<int, 2>{y0 / kRowsPerBlock, y1 / kRowsPerBlock};
    for (int b = range[t][0]; b <= range[t][1]; ++b) ++bins.start[static_cast<std::size_t>(b) + 1];
  }
  for (std::size_t b = 0; b < static_cast<std::size_t>(numBlocks); ++b) bins.start[b + 1] += bins.start[b];
  bins.index.resize(bins.start.back());
  std::vector<std::uint32_t> fill(bins.start.begin(), bins.start.end() - 1);
  for (std::size_t t = 0; t < job.triangles.size(); ++t)
    for (int b = range[t][0]; b <= range[t][1]; ++b)
      bins.index[fill[static_cast<std::size_t>(b)]++] = static_cast<std::uint32_t>(t);
  return bins;
}

std::vector<std::array<std::uint32_t, 3>> cyclesShadingTriangles(
    const Mesh& mesh, std::span<const std::array<std::uint32_t, 3>> triangles) {
  std::vector<std::array<std::uint32_t, 3>> shading;
  std::size_t t = 0;  // the first loop triangle of face f (faces are cut in order)
  for (std::size_t f = 0; f < mesh.numFaces(); t += mesh.faceSize(f) - 2, ++f) {
    if (mesh.faceSize(f) != 4 || t + 1 >= triangles.size()) continue;
    const std::uint32_t first = mesh.faceStart[f];
    const bool bakerFlips = triangles[t][2] == first + 3;  // loopTriangles' 1–3 diagonal
    // Blender's is_quad_flip_v3_first_third_fast_with_normal with the quad's normal
    // (normal_quad_v3, the cross product of its diagonals), in float as Blender computes it.
    const Vec3f v1 = mesh.positions[mesh.cornerVertex[first]];
    const Vec3f v2 = mesh.positions[mesh.cornerVertex[first + 1]];
    const Vec3f v3 = mesh.positions[mesh.cornerVertex[first + 2]];
    const Vec3f v4 = mesh.positions[mesh.cornerVertex[first + 3]];
    const Vec3f tangent = cross(v3 - v1, cross(v1 - v3, v2 - v4));
    const float d = dot(v1, tangent);
    const bool cyclesFlips = dot(v4, tangent) >= d || dot(v2, tangent) <= d;
    if (bakerFlips == cyclesFlips) continue;
    if (shading.empty()) shading.assign(triangles.begin(), triangles.end());
    shading[t] = cyclesFlips ? std::array<std::uint32_t, 3>{first, first + 1, first + 3}
                             : std::array<std::uint32_t, 3>{first, first + 1, first + 2};
    shading[t + 1] = cyclesFlips ? std::array<std::uint32_t, 3>{first + 1, first + 2, first + 3}
                                 : std::array<std::uint32_t, 3>{first, first + 2, first + 3};
  }
  return shading;
}

std::vector<std::array<std::uint32_t, 3>> cyclesTriangles(const Mesh& mesh) {
  std::vector<std::array<std::uint32_t, 3>> triangles = loopTriangles(mesh);
  std::vector<std::array<std::uint32_t, 3>> cycles = cyclesShadingTriangles(mesh, triangles);
  return cycles.empty() ? triangles : cycles;
}

}  // namespace bake_detail

std::vector<std::array<std::uint32_t, 3>> loopTriangles(const Mesh& mesh) {
  std::vector<std::array<std::uint32_t, 3>> triangles;
  triangles.reserve(mesh.numCorners() - 2 * mesh.numFaces());
  std::vector<Vec3f> points;
  std::vector<std::array<std::uint32_t, 3>> local;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const std::uint32_t first = mesh.faceStart[f];
    const std::uint32_t size = mesh.faceSize(f);
    if (size == 3) {
      triangles.push_back({first, first + 1, first + 2});
    } else if (size == 4) {
      // Blender's quad split (mesh_tessellate.cc, is_quad_flip_v3_first_third_fast), in float on
      // purpose: flip to the 1–3 diagonal when corners 1 and 3 lie on the same side of 0–2.
      const Vec3f p0 = mesh.positions[mesh.cornerVertex[first]];
      const Vec3f d1 = mesh.positions[mesh.cornerVertex[first + 1]] - p0;
      const Vec3f d2 = mesh.positions[mesh.cornerVertex[first + 2]] - p0;
      const Vec3f d3 = mesh.positions[mesh.cornerVertex[first + 3]] - p0;
      if (dot(cross(d1, d2), cross(d3, d2)) > 0.0f) {
        triangles.push_back({first, first + 1, first + 3});
        triangles.push_back({first + 1, first + 2, first + 3});
      } else {
        triangles.push_back({first, first + 1, first + 2});
        triangles.push_back({first, first + 2, first + 3});
      }
    } else {
      points.clear();
      for (std::uint32_t k = 0; k < size; ++k) points.push_back(mesh.positions[mesh.cornerVertex[first + k]]);
      triangulatePolygon(points, local);
      for (const std::array<std::uint32_t, 3>& t : local)
        triangles.push_back({first + t[0], first + t[1], first + t[2]});
    }
  }
  return triangles;
}

namespace {

/// Whether triangle @p p (any orientation, nonzero area) overlaps the open unit square with
/// lower-left corner @p origin with positive area: no separating axis among the square's two axes
/// and the triangle's three edge normals (strict: touching is not overlapping).
bool overlapsOpenSquare(const std::array<Vec2d, 3>& p, Vec2d origin) {
  const std::array<Vec2d, 4> square{origin, Vec2d{origin.x + 1, origin.y},
                                    Vec2d{origin.x + 1, origin.y + 1}, Vec2d{origin.x, origin.y + 1}};
  auto separated = [&](Vec2d axis) {
    double tMin = INFINITY, tMax = -INFINITY, sMin = INFINITY, sMax = -INFINITY;
    for (const Vec2d& q : p) {
      const double d = axis.x * q.x + axis.y * q.y;
      tMin = std::min(tMin, d);
      tMax = std::max(tMax, d);
    }
    for (const Vec2d& q : square) {
      const double d = axis.x * q.x + axis.y * q.y;
      sMin = std::min(sMin, d);
      sMax = std::max(sMax, d);
    }
    return tMax <= sMin || sMax <= tMin;
  };
  if (separated({1, 0}) || separated({0, 1})) return false;
  for (int i = 0; i < 3; ++i) {
    const Vec2d e = p[static_cast<std::size_t>((i + 1) % 3)] - p[static_cast<std::size_t>(i)];
    if (separated({-e.y, e.x})) return false;
  }
  return true;
}

}  // namespace

std::vector<int> udimTiles(const Mesh& mesh, int uvSet, std::size_t* trianglesOutside) {
  if (trianglesOutside != nullptr) *trianglesOutside = 0;
  if (uvSet < 0 || !mesh.hasUvSet(static_cast<std::size_t>(uvSet))) return {};
  const std::vector<Vec2f>& uvs = mesh.uvSets[static_cast<std::size_t>(uvSet)].uvs;
  constexpr int kTilesU = 10, kTilesV = (kLastUdimTile - kFirstUdimTile) / 10 + 1;
  std::vector<std::uint8_t> touched(std::size_t{kTilesU} * kTilesV, 0);  // by tile − 1001
  for (const std::array<std::uint32_t, 3>& t : loopTriangles(mesh)) {
    const std::array<Vec2d, 3> p{cast<double>(uvs[t[0]]), cast<double>(uvs[t[1]]),
                                 cast<double>(uvs[t[2]])};
    const double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
    if (!(area != 0) || !std::isfinite(area)) continue;
    const double minU = std::min({p[0].x, p[1].x, p[2].x}), maxU = std::max({p[0].x, p[1].x, p[2].x});
    const double minV = std::min({p[0].y, p[1].y, p[2].y}), maxV = std::max({p[0].y, p[1].y, p[2].y});
    // Candidate tiles: those the bounding box overlaps (clamped to the valid range).
    const int u0 = std::max(0, static_cast<int>(std::floor(std::max(minU, -1.0))));
    const int u1 = std::min(kTilesU - 1, static_cast<int>(std::floor(std::min(maxU, double(kTilesU)))));
    const int v0 = std::max(0, static_cast<int>(std::floor(std::max(minV, -1.0))));
    const int v1 = std::min(kTilesV - 1, static_cast<int>(std::floor(std::min(maxV, double(kTilesV)))));
    // The common case needs no test: a triangle (of nonzero area) whose bounds lie inside the
    // open square of one tile overlaps it.
    if (u0 == u1 && v0 == v1 && minU > u0 && maxU < u0 + 1 && minV > v0 && maxV < v0 + 1) {
      touched[static_cast<std::size_t>(v0 * 10 + u0)] = 1;
      continue;
    }
    bool inAnyTile = false;
    for (int tv = v0; tv <= v1; ++tv)
      for (int tu = u0; tu <= u1; ++tu)
        if (overlapsOpenSquare(p, {double(tu), double(tv)})) {
          touched[static_cast<std::size_t>(tv * 10 + tu)] = 1;
          inAnyTile = true;
        }
    if (!inAnyTile && trianglesOutside != nullptr) ++*trianglesOutside;
  }
  std::vector<int> tiles;
  for (std::size_t i = 0; i < touched.size(); ++i)
    if (touched[i] != 0) tiles.push_back(kFirstUdimTile + static_cast<int>(i));
  return tiles;
}

}  // namespace sgbake
