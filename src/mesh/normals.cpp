/// @file normals.cpp
/// @brief Face and smooth vertex normals as Blender computes them, and the Mesh invariant check.
///
/// Precision: positions are float; every normal is computed and accumulated in double and
/// rounded to float once at the end. Degenerate policy (as Blender):
/// - a face whose normal direction is exactly zero (collinear or coincident points; computed in
///   double from float positions, where the differences and products are exact, so "exactly
///   zero" means "degenerate in the file's own numbers") gets (0, 0, 1) and still takes part in
///   vertex normals with that direction, like Blender's Newell fallback;
/// - a corner with a zero-length edge has weight π/2: Blender normalizes the edge vectors, its
///   normalize() leaves a zero vector as is, and acos(-dot(0, e)) = π/2;
/// - a vertex whose weighted sum is zero gets its normalized position, (0, 0, 1) at the origin.
#include "sgbake/mesh/normals.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>
#include <string>
#include <tuple>

#include "mesh/validate.hpp"
#include "sgbake/core/math.hpp"

namespace sgbake {
namespace {

/// Blender's normal for a face of zero area.
constexpr Vec3d kZeroAreaNormal{0, 0, 1};
/// Normal of a vertex at the origin whose incident face normals cancel (Blender would leave a
/// zero vector; sgbake keeps normals unit).
constexpr Vec3d kOriginVertexNormal{0, 0, 1};
/// Blender's angle weight of a corner with a zero-length edge (see the file comment).
constexpr double kZeroEdgeCornerAngle = kPi / 2;

Vec3d cornerPosition(const MeshView& mesh, std::uint32_t corner) {
  return cast<double>(mesh.positions[mesh.cornerVertex[corner]]);
}

/// Interior angle between the edges from a corner to its previous and next corners, from their
/// normalized directions: atan2(|a×b|, a·b), accurate also for nearly straight corners.
double cornerAngle(Vec3d toPrev, Vec3d toNext) {
  const Vec3d a = normalizeOr(toPrev, Vec3d{});
  const Vec3d b = normalizeOr(toNext, Vec3d{});
  if (lengthSquared(a) == 0 || lengthSquared(b) == 0) return kZeroEdgeCornerAngle;
  return angleBetween(a, b);
}

/// Each corner's face normal weighted by the face's interior angle there (in parallel).
std::vector<Vec3d> weightedCornerNormals(const MeshView& view) {
  std::vector<Vec3d> weighted(view.cornerVertex.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, view.numFaces(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& faces) {
    for (std::size_t f = faces.begin(); f != faces.end(); ++f) {
      const Vec3d normal = normalizeOr(faceNormalDirection(view, f), kZeroAreaNormal);
      const std::uint32_t b = view.faceStart[f];
      const std::uint32_t n = view.faceSize(f);
      for (std::uint32_t i = 0; i < n; ++i) {
        const Vec3d prev = cornerPosition(view, b + (i + n - 1) % n);
        const Vec3d curr = cornerPosition(view, b + i);
        const Vec3d next = cornerPosition(view, b + (i + 1) % n);
        weighted[b + i] = cornerAngle(prev - curr, next - curr) * normal;
      }
    }
  });
  return weighted;
}

/// The normalized sum, or Blender's fallback for a vanishing one: the vertex's normalized
/// position, (0, 0, 1) at the origin.
Vec3f normalOfSum(const Vec3d& sum, const Vec3f& position) {
  return cast<float>(normalizeOr(sum, normalizeOr(cast<double>(position), kOriginVertexNormal)));
}

/// Union-find over corners, with path halving.
struct CornerSets {
  std::vector<std::uint32_t> parent;
  explicit CornerSets(std::size_t n) : parent(n) {
    for (std::uint32_t c = 0; c < n; ++c) parent[c] = c;
  }
  std::uint32_t find(std::uint32_t c) {
    while (parent[c] != c) c = parent[c] = parent[parent[c]];
    return c;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

Vec3d faceNormalDirection(const MeshView& mesh, std::size_t f) {
  const std::uint32_t b = mesh.faceStart[f];
  const std::uint32_t n = mesh.faceSize(f);
  if (n == 3) {
    const Vec3d p0 = cornerPosition(mesh, b), p1 = cornerPosition(mesh, b + 1),
                p2 = cornerPosition(mesh, b + 2);
    return cross(p0 - p1, p1 - p2);
  }
  if (n == 4) {
    const Vec3d p0 = cornerPosition(mesh, b), p1 = cornerPosition(mesh, b + 1),
                p2 = cornerPosition(mesh, b + 2), p3 = cornerPosition(mesh, b + 3);
    return cross(p0 - p2, p1 - p3);
  }
  // Newell: for each edge prev → curr, the projected areas under the edge on the three axis
  // planes.
  Vec3d sum{};
  Vec3d prev = cornerPosition(mesh, b + n - 1);
  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec3d curr = cornerPosition(mesh, b + i);
    sum.x += (prev.y - curr.y) * (prev.z + curr.z);
    sum.y += (prev.z - curr.z) * (prev.x + curr.x);
    sum.z += (prev.x - curr.x) * (prev.y + curr.y);
    prev = curr;
  }
  return sum;
}

std::vector<Vec3f> computeFaceNormals(const MeshView& mesh) {
  std::vector<Vec3f> normals(mesh.numFaces());
  for (std::size_t f = 0; f < normals.size(); ++f) {
    normals[f] = cast<float>(normalizeOr(faceNormalDirection(mesh, f), kZeroAreaNormal));
  }
  return normals;
}

std::vector<std::uint32_t> cornerFaces(std::span<const std::uint32_t> faceStart) {
  std::vector<std::uint32_t> faces(faceStart.empty() ? 0 : faceStart.back());
  for (std::size_t f = 0; f + 1 < faceStart.size(); ++f) {
    std::fill(faces.begin() + faceStart[f], faces.begin() + faceStart[f + 1],
              static_cast<std::uint32_t>(f));
  }
  return faces;
}

VertexCorners cornersByVertex(std::span<const std::uint32_t> cornerVertex,
                              std::size_t numVertices) {
  VertexCorners result;
  result.start.assign(numVertices + 1, 0);
  result.corners.resize(cornerVertex.size());
  for (const std::uint32_t v : cornerVertex) ++result.start[v + 1];
  for (std::size_t v = 0; v < numVertices; ++v) result.start[v + 1] += result.start[v];
  std::vector<std::uint32_t> fill(result.start.begin(), result.start.end() - 1);
  for (std::uint32_t c = 0; c < cornerVertex.size(); ++c) result.corners[fill[cornerVertex[c]]++] = c;
  return result;
}

void computeSmoothNormals(Mesh& mesh) {
  const MeshView view = mesh.view();
  const std::size_t numCorners = mesh.numCorners(), numVertices = mesh.numVertices();
  const std::vector<Vec3d> weighted = weightedCornerNormals(view);
  // Each vertex's corners in corner order (a counting sort), so that its sum adds them in the
  // same order whatever the threads: the normals do not depend on the number of threads.
  const VertexCorners byVertex = cornersByVertex(mesh.cornerVertex, numVertices);
  std::vector<Vec3f> vertexNormals(numVertices);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, numVertices, 4096),
                    [&](const tbb::blocked_range<std::size_t>& vertices) {
    for (std::size_t v = vertices.begin(); v != vertices.end(); ++v) {
      Vec3d sum{0, 0, 0};
      for (const std::uint32_t c : byVertex.of(v)) sum += weighted[c];
      vertexNormals[v] = normalOfSum(sum, mesh.positions[v]);
    }
  });
  mesh.cornerNormals.resize(numCorners);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, numCorners, 16384),
                    [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t c = range.begin(); c != range.end(); ++c) {
      mesh.cornerNormals[c] = vertexNormals[mesh.cornerVertex[c]];
    }
  });
  // Flat faces: their corners take the face's own normal (the vertex normals above still sum
  // over them, as Blender's do).
  if (std::any_of(mesh.faceFlat.begin(), mesh.faceFlat.end(),
                  [](std::uint8_t flat) { return flat != 0; })) {
    const std::vector<Vec3f> faceNormals = computeFaceNormals(view);
    for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
      if (!mesh.isFlat(f)) continue;
      for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
        mesh.cornerNormals[c] = faceNormals[f];
      }
    }
  }
  mesh.normalSource = NormalSource::kComputed;
}

void computeSplitNormals(Mesh& mesh, double angle,
                         std::span<const std::pair<std::uint32_t, std::uint32_t>> sharpEdges) {
  const MeshView view = mesh.view();
  const std::size_t numCorners = mesh.numCorners();
  const std::vector<Vec3d> weighted = weightedCornerNormals(view);
  const std::vector<Vec3f> faceNormals = computeFaceNormals(view);
  const std::vector<std::uint32_t> cornerFace = cornerFaces(view.faceStart);
  const auto nextCorner = [&](std::uint32_t c) {
    const std::uint32_t f = cornerFace[c];
    return c + 1 < view.faceStart[f + 1] ? c + 1 : view.faceStart[f];
  };
  // Every edge as (lower vertex, higher vertex, the corner it starts at), sorted: the corners
  // that run along one edge are then neighbours.
  struct EdgeCorner {
    std::uint32_t a, b, corner;
  };
  std::vector<EdgeCorner> edges(numCorners);
  for (std::uint32_t c = 0; c < numCorners; ++c) {
    const std::uint32_t v0 = mesh.cornerVertex[c], v1 = mesh.cornerVertex[nextCorner(c)];
    edges[c] = {std::min(v0, v1), std::max(v0, v1), c};
  }
  std::sort(edges.begin(), edges.end(), [](const EdgeCorner& x, const EdgeCorner& y) {
    return std::tie(x.a, x.b, x.corner) < std::tie(y.a, y.b, y.corner);
  });
  // A smooth edge joins, at each of its ends, the corners of its two faces there. The test is
  // Blender's, in float: the float normals' dot product against cosf of the float angle (so
  // that faces at right angles stay smooth at 90 degrees, cosf(90°) being just below 0).
  const float cosAngle = std::cos(static_cast<float>(angle));
  CornerSets fans(numCorners);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    if (j - i == 2) {
      const std::uint32_t c1 = edges[i].corner, c2 = edges[i + 1].corner;
      const std::uint32_t f1 = cornerFace[c1], f2 = cornerFace[c2];
      const bool opposite = mesh.cornerVertex[c1] != mesh.cornerVertex[c2];
      const bool marked = std::binary_search(sharpEdges.begin(), sharpEdges.end(),
                                             std::make_pair(edges[i].a, edges[i].b));
      const bool smooth =
          opposite && !marked && !mesh.isFlat(f1) && !mesh.isFlat(f2) &&
          !(dot(faceNormals[f1], faceNormals[f2]) < cosAngle);
      if (smooth) {  // c1 runs u→v, c2 v→u: c1 pairs with c2's next corner and vice versa
        fans.join(c1, nextCorner(c2));
        fans.join(nextCorner(c1), c2);
      }
    }
    i = j;
  }
  std::vector<Vec3d> fanSum(numCorners, Vec3d{0, 0, 0});
  for (std::uint32_t c = 0; c < numCorners; ++c) fanSum[fans.find(c)] += weighted[c];
  mesh.cornerNormals.resize(numCorners);
  for (std::uint32_t c = 0; c < numCorners; ++c) {
    mesh.cornerNormals[c] =
        normalOfSum(fanSum[fans.find(c)], mesh.positions[mesh.cornerVertex[c]]);
  }
  mesh.normalSource = NormalSource::kComputed;
  mesh.autoSmooth = true;
}

Status validate(const Mesh& mesh) {
  const std::string name = mesh.source.empty() ? "mesh" : detail::displayName(mesh.source);
  auto fail = [&](const std::string& what) -> Status { return detail::errorIn(name, what); };
  const std::size_t numCorners = mesh.numCorners();
  const std::size_t numVertices = mesh.numVertices();

  if (mesh.faceStart.empty() || mesh.faceStart[0] != 0)
    return fail("faceStart does not start at 0");
  for (std::size_t f = 0; f + 1 < mesh.faceStart.size(); ++f) {
    const std::uint64_t begin = mesh.faceStart[f], end = mesh.faceStart[f + 1];
    if (end < begin + 3) {
      return fail("face " + std::to_string(f) + " has " +
                  (end < begin ? "a negative number of" : std::to_string(end - begin)) +
                  " corners (at least 3 are needed)");
    }
  }
  if (mesh.faceStart.back() != numCorners) {
    return fail("faceStart ends at " + std::to_string(mesh.faceStart.back()) + " but there are " +
                std::to_string(numCorners) + " corners");
  }
  if (!mesh.faceFlat.empty() && mesh.faceFlat.size() != mesh.numFaces()) {
    return fail("faceFlat has " + std::to_string(mesh.faceFlat.size()) + " entries for " +
                std::to_string(mesh.numFaces()) + " faces");
  }
  if (!mesh.faceMaterial.empty() && mesh.faceMaterial.size() != mesh.numFaces()) {
    return fail("faceMaterial has " + std::to_string(mesh.faceMaterial.size()) + " entries for " +
                std::to_string(mesh.numFaces()) + " faces");
  }
  for (std::size_t c = 0; c < numCorners; ++c) {
    if (mesh.cornerVertex[c] >= numVertices) {
      return fail("corner " + std::to_string(c) + " refers to vertex " +
                  std::to_string(mesh.cornerVertex[c]) + " but there are " +
                  std::to_string(numVertices) + " vertices");
    }
  }
  for (std::size_t v = 0; v < numVertices; ++v) {
    if (!isFinite(mesh.positions[v])) {
      return fail("position of vertex " + std::to_string(v) + " is not finite");
    }
  }
  if (mesh.cornerNormals.size() != numCorners) {
    return fail("there are " + std::to_string(mesh.cornerNormals.size()) + " corner normals for " +
                std::to_string(numCorners) + " corners");
  }
  for (std::size_t c = 0; c < numCorners; ++c) {
    const Vec3f n = mesh.cornerNormals[c];
    const double len = length(cast<double>(n));
    if (!isFinite(n) || !(std::abs(len - 1.0) <= detail::kUnitLengthTolerance)) {
      return fail("normal of corner " + std::to_string(c) + " is not a unit vector (length " +
                  std::to_string(len) + ")");
    }
  }
  for (const UvSet& set : mesh.uvSets) {
    if (set.uvs.size() != numCorners) {
      return fail("UV set " + detail::quoted(set.name) + " has " + std::to_string(set.uvs.size()) +
                  " entries for " + std::to_string(numCorners) + " corners");
    }
    for (std::size_t c = 0; c < numCorners; ++c) {
      if (!isFinite(set.uvs[c])) {
        return fail("UV set " + detail::quoted(set.name) + " has a non-finite UV at corner " +
                    std::to_string(c));
      }
    }
  }
  return Ok{};
}

Vec3f unitNormal(Vec3f n) {
  const double len = length(cast<double>(n));
  if (std::abs(len - 1.0) <= detail::kUnitLengthTolerance) return n;
  return cast<float>(normalizeOr(cast<double>(n), Vec3d{0, 0, 1}));
}

bool normalsShowAutoSmooth(const Mesh& mesh) {
  if (mesh.cornerNormals.size() != mesh.numCorners()) return false;
  const std::vector<Vec3f> faceNormals = computeFaceNormals(mesh.view());
  const double cosTolerance = std::cos(0.1 * kPi / 180);
  // The normal of each vertex's first corner on a smooth face.
  std::vector<std::int64_t> firstSmoothCorner(mesh.numVertices(), -1);
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
      const Vec3f n = mesh.cornerNormals[c];
      if (mesh.isFlat(f)) {
        const Vec3d a = cast<double>(n), b = cast<double>(faceNormals[f]);
        if (dot(a, b) < cosTolerance * std::sqrt(dot(a, a) * dot(b, b))) return true;
        continue;
      }
      std::int64_t& first = firstSmoothCorner[mesh.cornerVertex[c]];
      if (first < 0) {
        first = c;
      } else if (!(mesh.cornerNormals[static_cast<std::size_t>(first)] == n)) {
        return true;
      }
    }
  }
  return false;
}

}  // namespace sgbake
