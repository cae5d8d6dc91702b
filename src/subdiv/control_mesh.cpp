/// @file control_mesh.cpp
/// @brief buildControlMesh: Far topology and face-varying channels of a Mesh, as Blender's
/// mesh converter makes them.
#include "subdiv/control_mesh.hpp"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <mutex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sgbake::subdiv_detail {
namespace {

/// Blender's "Quality" of a new modifier: the adaptive refinement level its patches isolate
/// irregular features to; Bfr approximates the same regions to the same level.
constexpr int kApproxLevel = 3;
/// Blender's STD_UV_CONNECT_LIMIT: corners of a vertex whose UVs differ by less than this in
/// both u and v share one face-varying value.
constexpr float kUvConnectLimit = 1e-4f;

osd::Sdc::Options sdcOptions(const SubdivisionOptions& options) {
  using Sdc = osd::Sdc::Options;
  Sdc sdc;
  sdc.SetCreasingMethod(Sdc::CREASE_UNIFORM);
  sdc.SetTriangleSubdivision(Sdc::TRI_SUB_CATMARK);
  sdc.SetVtxBoundaryInterpolation(options.boundary == SubdivisionBoundary::kKeepCorners
                                      ? Sdc::VTX_BOUNDARY_EDGE_AND_CORNER
                                      : Sdc::VTX_BOUNDARY_EDGE_ONLY);
  Sdc::FVarLinearInterpolation fvar = Sdc::FVAR_LINEAR_BOUNDARIES;
  switch (options.uvSmooth) {
    case SubdivisionUvSmooth::kNone: fvar = Sdc::FVAR_LINEAR_ALL; break;
    case SubdivisionUvSmooth::kKeepCorners: fvar = Sdc::FVAR_LINEAR_CORNERS_ONLY; break;
    case SubdivisionUvSmooth::kKeepCornersJunctions: fvar = Sdc::FVAR_LINEAR_CORNERS_PLUS1; break;
    case SubdivisionUvSmooth::kKeepCornersJunctionsConcave:
      fvar = Sdc::FVAR_LINEAR_CORNERS_PLUS2;
      break;
    case SubdivisionUvSmooth::kKeepBoundaries: fvar = Sdc::FVAR_LINEAR_BOUNDARIES; break;
    case SubdivisionUvSmooth::kAll: fvar = Sdc::FVAR_LINEAR_NONE; break;
  }
  sdc.SetFVarLinearInterpolation(fvar);
  return sdc;
}

/// The winding of each face in UV space, as Blender's UV vertex map computes it (the
/// trapezium rule's signed area in float, "positive"): corners of faces of opposite winding
/// (a mirrored island) never share a face-varying value.
std::vector<bool> uvWindings(const Mesh& mesh, const std::vector<Vec2f>& uvs) {
  std::vector<bool> winding(mesh.numFaces());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const std::uint32_t first = mesh.faceStart[f], end = mesh.faceStart[f + 1];
    float cross = 0;
    Vec2f previous = uvs[end - 1];
    for (std::uint32_t c = first; c < end; ++c) {
      cross += (uvs[c].x - previous.x) * (uvs[c].y + previous.y);
      previous = uvs[c];
    }
    winding[f] = cross > 0;
  }
  return winding;
}

/// Groups each vertex's corners into face-varying values as Blender's mesh converter does (its
/// UV vertex map, then one write per corner): the corners are taken from the last to the first;
/// the first one left starts a group, which takes every other corner left whose UV is within
/// kUvConnectLimit of it in both u and v and whose face has the same UV winding. The value is
/// the UV of the group's last corner (Blender writes each corner's UV in turn, the last write
/// stays), which is the corner that started it.
FVarChannel weldUvs(const Mesh& mesh, const std::vector<Vec2f>& uvs) {
  const VertexCorners byVertex = cornersByVertex(mesh.cornerVertex, mesh.numVertices());
  const std::vector<bool> winding = uvWindings(mesh, uvs);
  const std::vector<std::uint32_t> cornerFace = cornerFaces(mesh.faceStart);
  FVarChannel channel;
  channel.cornerValue.assign(mesh.numCorners(), -1);
  std::vector<std::uint32_t> corners;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v) {
    const std::span<const std::uint32_t> of = byVertex.of(v);
    corners.assign(of.begin(), of.end());
    std::sort(corners.begin(), corners.end(), std::greater<>());
    for (std::size_t a = 0; a < corners.size(); ++a) {
      const std::uint32_t head = corners[a];
      if (channel.cornerValue[head] >= 0) continue;
      const int value = static_cast<int>(channel.values.size() / 2);
      channel.values.push_back(uvs[head].x);
      channel.values.push_back(uvs[head].y);
      channel.cornerValue[head] = value;
      for (std::size_t b = a + 1; b < corners.size(); ++b) {
        const std::uint32_t other = corners[b];
        if (channel.cornerValue[other] < 0 &&
            std::fabs(uvs[head].x - uvs[other].x) < kUvConnectLimit &&
            std::fabs(uvs[head].y - uvs[other].y) < kUvConnectLimit &&
            winding[cornerFace[head]] == winding[cornerFace[other]]) {
          channel.cornerValue[other] = value;
        }
      }
    }
  }
  return channel;
}

/// An edge as its two vertices, the smaller first.
using EdgeKey = std::pair<std::uint32_t, std::uint32_t>;

EdgeKey edgeKey(std::uint32_t a, std::uint32_t b) { return a < b ? EdgeKey{a, b} : EdgeKey{b, a}; }

/// Every edge of @p mesh (consecutive corners of a face), sorted, each once.
std::vector<EdgeKey> meshEdges(const Mesh& mesh) {
  std::vector<EdgeKey> edges;
  edges.reserve(mesh.numCorners());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const std::uint32_t first = mesh.faceStart[f], end = mesh.faceStart[f + 1];
    for (std::uint32_t c = first; c < end; ++c) {
      const std::uint32_t next = c + 1 == end ? first : c + 1;
      edges.push_back(edgeKey(mesh.cornerVertex[c], mesh.cornerVertex[next]));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

/// Why @p crease is not a crease value, or "".
std::string badCreaseValue(float crease) {
  if (std::isfinite(crease) && crease >= 0.0f && crease <= 1.0f) return {};
  std::ostringstream text;
  text << "crease " << crease << " is outside [0, 1]";
  return text.str();
}

/// The creases as the Far topology descriptor takes them: sharpness per edge (vertex pairs)
/// and per vertex, leaving out the zero ones (as good as absent).
struct Creases {
  std::vector<int> edgeVertices;  ///< 2 per creased edge
  std::vector<float> edgeSharpness;
  std::vector<int> vertices;
  std::vector<float> vertexSharpness;
};

/// Blender's "Simple" subdivision: Catmull-Clark with every edge and vertex infinitely sharp
/// (measured against Blender 3.4: not OpenSubdiv's bilinear scheme, which places the points
/// inside n-gons and triangles elsewhere), whatever the creases.
Creases allInfinitelySharp(const Mesh& coarse) {
  constexpr float kInfinitelySharp = 10.0f;  // Sdc's SHARPNESS_INFINITE
  Creases creases;
  for (const auto& [a, b] : meshEdges(coarse)) {
    creases.edgeVertices.push_back(static_cast<int>(a));
    creases.edgeVertices.push_back(static_cast<int>(b));
    creases.edgeSharpness.push_back(kInfinitelySharp);
  }
  for (std::size_t v = 0; v < coarse.numVertices(); ++v) {
    creases.vertices.push_back(static_cast<int>(v));
    creases.vertexSharpness.push_back(kInfinitelySharp);
  }
  return creases;
}

Creases farCreases(const Mesh& coarse, const SubdivisionOptions& options) {
  if (options.type == SubdivisionType::kSimple) return allInfinitelySharp(coarse);
  Creases creases;
  if (!options.useCreases) return creases;
  for (const EdgeCrease& edge : options.edgeCreases) {
    const float sharpness = creaseSharpness(edge.crease);
    if (!(sharpness > 0.0f)) continue;
    creases.edgeVertices.push_back(static_cast<int>(edge.v0));
    creases.edgeVertices.push_back(static_cast<int>(edge.v1));
    creases.edgeSharpness.push_back(sharpness);
  }
  for (const VertexCrease& vertex : options.vertexCreases) {
    const float sharpness = creaseSharpness(vertex.crease);
    if (!(sharpness > 0.0f)) continue;
    creases.vertices.push_back(static_cast<int>(vertex.vertex));
    creases.vertexSharpness.push_back(sharpness);
  }
  return creases;
}

}  // namespace

SurfaceFactory::Options surfaceFactoryOptions() {
  SurfaceFactory::Options options;
  options.SetApproxLevelSmooth(kApproxLevel).SetApproxLevelSharp(kApproxLevel);
  return options;
}

}  // namespace sgbake::subdiv_detail

namespace sgbake {

std::optional<CreaseIssue> findCreaseIssue(const Mesh& mesh, const SubdivisionOptions& options) {
  using subdiv_detail::EdgeKey;
  const std::size_t nv = mesh.numVertices();
  const auto vertexName = [](std::uint32_t v) { return "vertex " + std::to_string(v); };
  const auto outOfRange = [&](std::uint32_t v) {
    return vertexName(v) + " is out of range (the mesh has " + std::to_string(nv) +
           " vertices, numbered from 0)";
  };
  // Edge lists (creases, sharp marks): entry by entry, vertices in range, an edge of the mesh,
  // then @p entryIssue's own check; after that, the first entry naming an edge listed before.
  std::vector<EdgeKey> edges;
  if (!options.edgeCreases.empty() || !options.sharpEdges.empty()) {
    edges = subdiv_detail::meshEdges(mesh);
  }
  const auto edgeListIssue = [&](const auto& list, bool sharp, const char* listedBy,
                                 const auto& entryIssue) -> std::optional<CreaseIssue> {
    std::vector<std::pair<EdgeKey, std::size_t>> seen;  // edge, index listing it
    seen.reserve(list.size());
    for (std::size_t i = 0; i < list.size(); ++i) {
      const auto& e = list[i];
      for (const std::uint32_t v : {e.v0, e.v1}) {
        if (v >= nv) return CreaseIssue{true, i, outOfRange(v), sharp};
      }
      const EdgeKey key = subdiv_detail::edgeKey(e.v0, e.v1);
      if (!std::binary_search(edges.begin(), edges.end(), key)) {
        return CreaseIssue{true, i,
                           "vertices " + std::to_string(e.v0) + " and " + std::to_string(e.v1) +
                               " are not the ends of an edge of the mesh",
                           sharp};
      }
      if (std::string why = entryIssue(e); !why.empty()) return CreaseIssue{true, i, why, sharp};
      seen.emplace_back(key, i);
    }
    std::stable_sort(seen.begin(), seen.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::optional<CreaseIssue> first;
    for (std::size_t k = 1; k < seen.size(); ++k) {
      if (seen[k].first != seen[k - 1].first) continue;
      const std::size_t later = seen[k].second;
      if (!first || later < first->index) {
        first = CreaseIssue{true, later,
                            "the edge " + std::to_string(seen[k].first.first) + "-" +
                                std::to_string(seen[k].first.second) + " is also " + listedBy +
                                " by entry " + std::to_string(seen[k - 1].second),
                            sharp};
      }
    }
    return first;
  };
  if (auto issue = edgeListIssue(options.edgeCreases, false, "creased",
                                 [](const EdgeCrease& e) {
                                   return subdiv_detail::badCreaseValue(e.crease);
                                 })) {
    return issue;
  }
  if (auto issue = edgeListIssue(options.sharpEdges, true, "listed",
                                 [](const SharpEdge&) { return std::string(); })) {
    return issue;
  }
  std::vector<std::int64_t> listedAt(options.vertexCreases.empty() ? 0 : nv, -1);
  for (std::size_t i = 0; i < options.vertexCreases.size(); ++i) {
    const VertexCrease& c = options.vertexCreases[i];
    if (c.vertex >= nv) return CreaseIssue{false, i, outOfRange(c.vertex)};
    if (std::string why = subdiv_detail::badCreaseValue(c.crease); !why.empty()) {
      return CreaseIssue{false, i, why};
    }
    if (listedAt[c.vertex] >= 0) {
      return CreaseIssue{
          false, i,
          vertexName(c.vertex) + " is also creased by entry " + std::to_string(listedAt[c.vertex])};
    }
    listedAt[c.vertex] = static_cast<std::int64_t>(i);
  }
  return std::nullopt;
}

}  // namespace sgbake

namespace sgbake::subdiv_detail {

namespace {

/// The most corners of a face OpenSubdiv's topology takes (it counts them in 16 bits; a vertex's
/// faces too, which OpenSubdiv's own error names).
constexpr std::ptrdiff_t kMaxSubdivisionFaceSize = 65535;

/// The last error OpenSubdiv reported on this thread. OpenSubdiv prints its errors and warnings
/// to standard output unless given callbacks; they are kept here instead, for the error that
/// names the mesh (a CSV written to standard output must not get a line of OpenSubdiv's).
thread_local std::string lastOpenSubdivError;

void keepOpenSubdivErrors() {
  static std::once_flag installed;
  std::call_once(installed, [] {
    osd::Far::SetErrorCallback(
        [](osd::Far::ErrorType, const char* message) { lastOpenSubdivError = message; });
    osd::Far::SetWarningCallback([](const char*) {});
  });
}

}  // namespace

Status checkCreases(const Mesh& coarse, const SubdivisionOptions& options) {
  if (const std::optional<CreaseIssue> issue = findCreaseIssue(coarse, options)) {
    return Error::badInput(coarse.source + ": " + issue->noun() + " " +
                           std::to_string(issue->index) + ": " + issue->what);
  }
  return Ok{};
}

Result<ControlMesh> buildControlMesh(const Mesh& coarse, const SubdivisionOptions& options) {
  const std::string& name = coarse.source;
  if (Status ok = checkCreases(coarse, options); !ok) return ok.error();
  const std::size_t nf = coarse.numFaces();
  for (std::size_t f = 0; f < nf; ++f) {
    const auto first = coarse.cornerVertex.begin() + coarse.faceStart[f];
    const auto last = coarse.cornerVertex.begin() + coarse.faceStart[f + 1];
    if (last - first > kMaxSubdivisionFaceSize) {
      return Error::badInput(name + ": face " + std::to_string(f) + " has " +
                             std::to_string(last - first) +
                             " corners; OpenSubdiv subdivides faces "
                             "of at most " +
                             std::to_string(kMaxSubdivisionFaceSize));
    }
    std::vector<std::uint32_t> sorted(first, last);
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      return Error::badInput(name + ": face " + std::to_string(f) +
                             " uses a vertex twice and cannot be subdivided");
    }
  }

  // Topology, with one face-varying channel per UV set.
  std::vector<int> faceSizes(nf), faceVertices(coarse.cornerVertex.begin(),
                                              coarse.cornerVertex.end());
  for (std::size_t f = 0; f < nf; ++f) faceSizes[f] = static_cast<int>(coarse.faceSize(f));
  std::vector<FVarChannel> channels;
  for (const UvSet& set : coarse.uvSets) channels.push_back(weldUvs(coarse, set.uvs));
  std::vector<osd::Far::TopologyDescriptor::FVarChannel> fvarDescriptors(channels.size());
  for (std::size_t s = 0; s < channels.size(); ++s) {
    fvarDescriptors[s].numValues = static_cast<int>(channels[s].values.size() / 2);
    fvarDescriptors[s].valueIndices = channels[s].cornerValue.data();
  }
  osd::Far::TopologyDescriptor descriptor;
  descriptor.numVertices = static_cast<int>(coarse.numVertices());
  descriptor.numFaces = static_cast<int>(nf);
  descriptor.numVertsPerFace = faceSizes.data();
  descriptor.vertIndicesPerFace = faceVertices.data();
  descriptor.numFVarChannels = static_cast<int>(fvarDescriptors.size());
  descriptor.fvarChannels = fvarDescriptors.empty() ? nullptr : fvarDescriptors.data();
  // Creases: Blender hands OpenSubdiv the sharpness of every edge and vertex; zero is no crease.
  const Creases creases = farCreases(coarse, options);
  descriptor.numCreases = static_cast<int>(creases.edgeSharpness.size());
  descriptor.creaseVertexIndexPairs =
      creases.edgeVertices.empty() ? nullptr : creases.edgeVertices.data();
  descriptor.creaseWeights = creases.edgeSharpness.empty() ? nullptr : creases.edgeSharpness.data();
  descriptor.numCorners = static_cast<int>(creases.vertexSharpness.size());
  descriptor.cornerVertexIndices = creases.vertices.empty() ? nullptr : creases.vertices.data();
  descriptor.cornerWeights =
      creases.vertexSharpness.empty() ? nullptr : creases.vertexSharpness.data();
  using RefinerFactory = osd::Far::TopologyRefinerFactory<osd::Far::TopologyDescriptor>;
  ControlMesh control;
  keepOpenSubdivErrors();
  lastOpenSubdivError.clear();
  control.refiner.reset(RefinerFactory::Create(
      descriptor, RefinerFactory::Options(osd::Sdc::SCHEME_CATMARK, sdcOptions(options))));
  if (!control.refiner) {
    return Error::badInput(name + ": OpenSubdiv cannot subdivide this topology" +
                           (lastOpenSubdivError.empty() ? "" : " (" + lastOpenSubdivError + ")"));
  }

  control.channels = std::move(channels);
  control.faceSizes = std::move(faceSizes);
  control.points.resize(3 * coarse.numVertices());
  for (std::size_t v = 0; v < coarse.numVertices(); ++v) {
    control.points[3 * v] = coarse.positions[v].x;
    control.points[3 * v + 1] = coarse.positions[v].y;
    control.points[3 * v + 2] = coarse.positions[v].z;
  }
  return control;
}

}  // namespace sgbake::subdiv_detail
