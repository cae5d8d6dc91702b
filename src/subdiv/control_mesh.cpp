/// @file control_mesh.cpp
/// @brief buildControlMesh: Far topology and face-varying channels of a Mesh, as Blender's
/// mesh converter makes them.
#include "subdiv/control_mesh.hpp"

#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <cmath>
#include <functional>
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
  std::vector<std::uint32_t> cornerFace(mesh.numCorners());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
      cornerFace[c] = static_cast<std::uint32_t>(f);
    }
  }
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

}  // namespace

SurfaceFactory::Options surfaceFactoryOptions() {
  SurfaceFactory::Options options;
  options.SetApproxLevelSmooth(kApproxLevel).SetApproxLevelSharp(kApproxLevel);
  return options;
}

Result<ControlMesh> buildControlMesh(const Mesh& coarse, const SubdivisionOptions& options) {
  const std::string& name = coarse.source;
  const std::size_t nf = coarse.numFaces();
  for (std::size_t f = 0; f < nf; ++f) {
    const auto first = coarse.cornerVertex.begin() + coarse.faceStart[f];
    const auto last = coarse.cornerVertex.begin() + coarse.faceStart[f + 1];
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
  using RefinerFactory = osd::Far::TopologyRefinerFactory<osd::Far::TopologyDescriptor>;
  ControlMesh control;
  control.refiner.reset(RefinerFactory::Create(
      descriptor, RefinerFactory::Options(osd::Sdc::SCHEME_CATMARK, sdcOptions(options))));
  if (!control.refiner) return Error::badInput(name + ": OpenSubdiv cannot subdivide this topology");

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
