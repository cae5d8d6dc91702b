/// @file subdivide.cpp
/// @brief subdivideMesh: OpenSubdiv's Far topology plus Bfr limit evaluation on each coarse face's
/// grid of new vertices, numbered and connected as Blender's Subdivision Surface modifier does.
#include "sgbake/subdiv/subdivide.hpp"

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "sgbake/mesh/normals.hpp"

namespace sgbake {
namespace {

namespace osd = OpenSubdiv;
using Refiner = osd::Far::TopologyRefiner;
using SurfaceFactory = osd::Bfr::RefinerSurfaceFactory<>;

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

/// One UV set as an OpenSubdiv face-varying channel: an index per corner into distinct values.
struct FVarChannel {
  std::vector<int> cornerValue;  ///< #C
  std::vector<double> values;    ///< 2 per value
};

/// Groups each vertex's corners by UV (within kUvConnectLimit of the group's first corner, in
/// both coordinates), as Blender's mesh converter does.
FVarChannel weldUvs(const Mesh& mesh, const std::vector<Vec2f>& uvs) {
  const std::size_t nv = mesh.numVertices(), nc = mesh.numCorners();
  // Corners of each vertex, in corner order (counting sort).
  std::vector<std::uint32_t> start(nv + 1, 0), corners(nc);
  for (const std::uint32_t v : mesh.cornerVertex) ++start[v + 1];
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::uint32_t c = 0; c < nc; ++c) corners[fill[mesh.cornerVertex[c]]++] = c;

  FVarChannel channel;
  channel.cornerValue.assign(nc, -1);
  for (std::size_t v = 0; v < nv; ++v) {
    for (std::uint32_t a = start[v]; a < start[v + 1]; ++a) {
      const std::uint32_t first = corners[a];
      if (channel.cornerValue[first] >= 0) continue;
      const int value = static_cast<int>(channel.values.size() / 2);
      channel.values.push_back(uvs[first].x);
      channel.values.push_back(uvs[first].y);
      channel.cornerValue[first] = value;
      for (std::uint32_t b = a + 1; b < start[v + 1]; ++b) {
        const std::uint32_t other = corners[b];
        if (channel.cornerValue[other] < 0 &&
            std::fabs(uvs[other].x - uvs[first].x) < kUvConnectLimit &&
            std::fabs(uvs[other].y - uvs[first].y) < kUvConnectLimit) {
          channel.cornerValue[other] = value;
        }
      }
    }
  }
  return channel;
}

/// The grid of new vertices on one coarse face. A quad has one grid of R×R points (R = 2^level
/// + 1) on its own [0,1]² parameterization, point (i, j) at (i, j)/(R-1), corner k of the face at
/// the k-th corner of the square counter-clockwise from (0, 0). Any other face of n corners has
/// n grids of r×r points (r = 2^(level-1) + 1), one per corner k: Bfr's normalized sub-face k,
/// whose (0, 0) is corner k, (1, 0) the middle of edge k (corner k → k+1), (0, 1) the middle of
/// edge k-1 and (1, 1) the face's centre.
struct FaceGrid {
  int corners = 4;  ///< n
  int side = 2;     ///< points per grid side: R for a quad, r otherwise
  int grids() const { return corners == 4 ? 1 : corners; }
  int pointsPerGrid() const { return side * side; }
  int points() const { return grids() * pointsPerGrid(); }
  int cellsPerGrid() const { return (side - 1) * (side - 1); }
  /// Points inside the face (not on its edges or corners).
  int interiorPoints() const {
    const int inner = side - 2;
    return corners == 4 ? inner * inner : 1 + corners * inner + corners * inner * inner;
  }
};

FaceGrid faceGrid(int corners, int level) {
  FaceGrid grid;
  grid.corners = corners;
  grid.side = corners == 4 ? (1 << level) + 1 : (1 << (level - 1)) + 1;
  return grid;
}

/// Numbers the new vertices: coarse vertex v keeps index v; point t (1..R-2, from the edge's
/// first vertex) inside coarse edge e is edgeBase + e·(R-2) + t-1; points inside face f follow
/// from faceBase[f].
class VertexNumbering {
 public:
  VertexNumbering(const Mesh& mesh, const Refiner& refiner, int level) : level_(level) {
    const auto& base = refiner.GetLevel(0);
    edgeSide_ = (1 << level) + 1;
    edgeBase_ = static_cast<std::uint32_t>(mesh.numVertices());
    const auto edges = static_cast<std::uint32_t>(base.GetNumEdges());
    std::uint32_t next = edgeBase_ + edges * static_cast<std::uint32_t>(edgeSide_ - 2);
    faceBase_.resize(mesh.numFaces());
    for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
      faceBase_[f] = next;
      next += static_cast<std::uint32_t>(faceGrid(static_cast<int>(mesh.faceSize(f)), level)
                                             .interiorPoints());
    }
    count_ = next;
  }

  std::uint32_t count() const { return count_; }

  /// The vertex of point (i, j) of grid g on face @p f (see FaceGrid).
  std::uint32_t vertex(const Mesh& mesh, const Refiner& refiner, std::size_t f, int g, int i,
                       int j) const {
    const FaceGrid grid = faceGrid(static_cast<int>(mesh.faceSize(f)), level_);
    const int n = grid.corners, last = grid.side - 1, full = edgeSide_ - 1;
    const auto corner = [&](int k) { return mesh.cornerVertex[mesh.faceStart[f] + ((k % n + n) % n)]; };
    if (n == 4) {
      if (i == 0 && j == 0) return corner(0);
      if (i == last && j == 0) return corner(1);
      if (i == last && j == last) return corner(2);
      if (i == 0 && j == last) return corner(3);
      if (j == 0) return onEdge(refiner, f, 0, corner(0), i);
      if (i == last) return onEdge(refiner, f, 1, corner(1), j);
      if (j == last) return onEdge(refiner, f, 2, corner(2), last - i);
      if (i == 0) return onEdge(refiner, f, 3, corner(3), last - j);
      return faceBase_[f] + static_cast<std::uint32_t>((j - 1) * (last - 1) + (i - 1));
    }
    const int k = g, inner = last - 1;
    if (i == 0 && j == 0) return corner(k);
    if (j == 0) return onEdge(refiner, f, k, corner(k), i);
    if (i == 0) return onEdge(refiner, f, (k + n - 1) % n, corner(k - 1), full - j);
    if (i == last && j == last) return faceBase_[f];
    if (i == last) return faceBase_[f] + static_cast<std::uint32_t>(1 + k * inner + (j - 1));
    if (j == last) {
      return faceBase_[f] + static_cast<std::uint32_t>(1 + ((k + n - 1) % n) * inner + (i - 1));
    }
    return faceBase_[f] + static_cast<std::uint32_t>(1 + n * inner + k * inner * inner +
                                                     (j - 1) * inner + (i - 1));
  }

 private:
  /// Point t (0..R-1) of face @p f's edge @p k counted from @p from, its first corner's vertex.
  std::uint32_t onEdge(const Refiner& refiner, std::size_t f, int k, std::uint32_t from,
                       int t) const {
    const auto& base = refiner.GetLevel(0);
    const int e = base.GetFaceEdges(static_cast<int>(f))[k];
    const bool forward = static_cast<std::uint32_t>(base.GetEdgeVertices(e)[0]) == from;
    const int along = forward ? t : edgeSide_ - 1 - t;
    return edgeBase_ + static_cast<std::uint32_t>(e) * static_cast<std::uint32_t>(edgeSide_ - 2) +
           static_cast<std::uint32_t>(along - 1);
  }

  int level_;
  int edgeSide_ = 0;
  std::uint32_t edgeBase_ = 0;
  std::vector<std::uint32_t> faceBase_;
  std::uint32_t count_ = 0;
};

/// Bfr's coordinate of point (i, j) of grid g on a face with parameterization @p param.
void gridCoord(const osd::Bfr::Parameterization& param, const FaceGrid& grid, int g, int i,
               int j, double uv[2]) {
  const double step = 1.0 / (grid.side - 1);
  const double normalized[2] = {i * step, j * step};
  if (grid.corners == 4) {
    uv[0] = normalized[0];
    uv[1] = normalized[1];
  } else {
    param.ConvertNormalizedSubFaceToCoord(g, normalized, uv);
  }
}

/// subdivideGrids could not evaluate a face's limit surface.
struct EvaluationFailed {};

/// The most corners a subdivided mesh may have: corner indices are 32-bit.
constexpr std::uint64_t kMaxSubdividedCorners = std::numeric_limits<std::uint32_t>::max();

/// The subdivided mesh (see subdivideMesh) of @p coarse, whose topology @p refiner and UV sets
/// @p channels hold. Throws std::bad_alloc, or EvaluationFailed when Bfr rejects a face.
Mesh subdivideGrids(const Mesh& coarse, const Refiner& refinerRef,
                    const std::vector<FVarChannel>& channels, const std::vector<int>& faceSizes,
                    int level);

}  // namespace

Result<Mesh> subdivideMesh(const Mesh& coarse, const SubdivisionOptions& options) {
  const std::string& name = coarse.source;
  if (options.level < 0 || options.level > kMaxSubdivisionLevel) {
    return Error::badInput(name + ": subdivision level " + std::to_string(options.level) +
                           " is out of range (0.." + std::to_string(kMaxSubdivisionLevel) + ")");
  }
  if (options.level == 0) return coarse;
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
  const std::unique_ptr<Refiner> refiner(RefinerFactory::Create(
      descriptor, RefinerFactory::Options(osd::Sdc::SCHEME_CATMARK, sdcOptions(options))));
  if (!refiner) return Error::badInput(name + ": OpenSubdiv cannot subdivide this topology");

  // Corners are numbered with 32 bits: refuse a result that does not fit before allocating it.
  const int level = options.level;
  std::uint64_t newFaces = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    const FaceGrid grid = faceGrid(faceSizes[f], level);
    newFaces += static_cast<std::uint64_t>(grid.grids() * grid.cellsPerGrid());
  }
  if (4 * newFaces > kMaxSubdividedCorners) {
    return Error::badInput(name + ": subdivision level " + std::to_string(level) + " would make " +
                           std::to_string(newFaces) + " faces, more than a mesh holds (" +
                           std::to_string(kMaxSubdividedCorners / 4) + ")");
  }
  try {
    return subdivideGrids(coarse, *refiner, channels, faceSizes, level);
  } catch (const EvaluationFailed&) {
    return Error::badInput(name + ": OpenSubdiv cannot evaluate the limit surface of a face");
  } catch (const std::bad_alloc&) {
    return Error::internal(name + ": out of memory subdividing to level " +
                           std::to_string(level) + " (" + std::to_string(newFaces) + " faces)");
  }
}

namespace {

Mesh subdivideGrids(const Mesh& coarse, const Refiner& refinerRef,
                    const std::vector<FVarChannel>& channels, const std::vector<int>& faceSizes,
                    int level) {
  const Refiner* const refiner = &refinerRef;
  const std::size_t nf = coarse.numFaces();
  // Every new vertex, and which face evaluates it: the first face (in order) that has it.
  const VertexNumbering numbering(coarse, *refiner, level);
  std::vector<std::size_t> gridStart(nf + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    gridStart[f + 1] = gridStart[f] +
                       static_cast<std::size_t>(faceGrid(faceSizes[f], level).points());
  }
  std::vector<std::uint32_t> pointVertex(gridStart[nf]);
  std::vector<std::uint8_t> pointEvaluates(gridStart[nf], 0);
  {
    std::vector<std::uint8_t> seen(numbering.count(), 0);
    for (std::size_t f = 0; f < nf; ++f) {
      const FaceGrid grid = faceGrid(faceSizes[f], level);
      std::size_t p = gridStart[f];
      for (int g = 0; g < grid.grids(); ++g) {
        for (int j = 0; j < grid.side; ++j) {
          for (int i = 0; i < grid.side; ++i, ++p) {
            const std::uint32_t v = numbering.vertex(coarse, *refiner, f, g, i, j);
            pointVertex[p] = v;
            if (!seen[v]) seen[v] = pointEvaluates[p] = 1;
          }
        }
      }
    }
  }

  // The new faces: per coarse face, grid by grid, cell (i, j) as (i,j) (i+1,j) (i+1,j+1) (i,j+1).
  Mesh fine;
  fine.source = coarse.source;
  fine.positions.assign(numbering.count(), Vec3f{0, 0, 0});
  std::vector<std::size_t> cellStart(nf + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    const FaceGrid grid = faceGrid(faceSizes[f], level);
    cellStart[f + 1] = cellStart[f] + static_cast<std::size_t>(grid.grids() * grid.cellsPerGrid());
  }
  const std::size_t fineFaces = cellStart[nf];
  fine.faceStart.resize(fineFaces + 1);
  for (std::size_t c = 0; c <= fineFaces; ++c) fine.faceStart[c] = static_cast<std::uint32_t>(4 * c);
  fine.cornerVertex.resize(4 * fineFaces);
  fine.uvSets.resize(coarse.uvSets.size());
  for (std::size_t s = 0; s < coarse.uvSets.size(); ++s) {
    fine.uvSets[s].name = coarse.uvSets[s].name;
    fine.uvSets[s].uvs.resize(4 * fineFaces);
  }

  // Limit positions and UVs, face by face in parallel (each thread its own Bfr factory: its
  // cache is not thread-safe).
  std::vector<double> meshPoints(3 * coarse.numVertices());
  for (std::size_t v = 0; v < coarse.numVertices(); ++v) {
    meshPoints[3 * v] = coarse.positions[v].x;
    meshPoints[3 * v + 1] = coarse.positions[v].y;
    meshPoints[3 * v + 2] = coarse.positions[v].z;
  }
  SurfaceFactory::Options factoryOptions;
  factoryOptions.SetApproxLevelSmooth(kApproxLevel).SetApproxLevelSharp(kApproxLevel);
  struct Worker {
    SurfaceFactory factory;
    osd::Bfr::Surface<double> surface;
    std::vector<double> patchPoints;
    std::vector<Vec2f> gridUvs;
  };
  tbb::enumerable_thread_specific<std::unique_ptr<Worker>> workers;
  std::atomic<bool> failed{false};
  tbb::parallel_for(std::size_t{0}, nf, [&](std::size_t f) {
    auto& slot = workers.local();
    if (!slot) slot.reset(new Worker{SurfaceFactory(*refiner, factoryOptions), {}, {}, {}});
    Worker& w = *slot;
    const FaceGrid grid = faceGrid(faceSizes[f], level);
    const int face = static_cast<int>(f);
    const std::size_t first = gridStart[f];
    const auto pointIndex = [&](int g, int i, int j) {
      return first + static_cast<std::size_t>(g * grid.pointsPerGrid() + j * grid.side + i);
    };
    // Cells.
    std::size_t cell = cellStart[f];
    for (int g = 0; g < grid.grids(); ++g) {
      for (int j = 0; j + 1 < grid.side; ++j) {
        for (int i = 0; i + 1 < grid.side; ++i, ++cell) {
          std::uint32_t* out = &fine.cornerVertex[4 * cell];
          out[0] = pointVertex[pointIndex(g, i, j)];
          out[1] = pointVertex[pointIndex(g, i + 1, j)];
          out[2] = pointVertex[pointIndex(g, i + 1, j + 1)];
          out[3] = pointVertex[pointIndex(g, i, j + 1)];
        }
      }
    }
    // Positions of the points this face evaluates.
    if (!w.factory.InitVertexSurface(face, &w.surface)) {
      failed = true;
      return;
    }
    const auto param = w.surface.GetParameterization();
    const osd::Bfr::Surface<double>::PointDescriptor xyz(3);
    w.patchPoints.resize(static_cast<std::size_t>(w.surface.GetNumPatchPoints()) * 3);
    w.surface.PreparePatchPoints(meshPoints.data(), xyz, w.patchPoints.data(), xyz);
    for (int g = 0; g < grid.grids(); ++g) {
      for (int j = 0; j < grid.side; ++j) {
        for (int i = 0; i < grid.side; ++i) {
          const std::size_t p = pointIndex(g, i, j);
          if (!pointEvaluates[p]) continue;
          double uv[2], P[3];
          gridCoord(param, grid, g, i, j, uv);
          w.surface.Evaluate(uv, w.patchPoints.data(), xyz, P);
          fine.positions[pointVertex[p]] = Vec3f{static_cast<float>(P[0]),
                                                 static_cast<float>(P[1]),
                                                 static_cast<float>(P[2])};
        }
      }
    }
    // UVs: each set's face-varying limit at every grid point, then copied to the cells' corners.
    const osd::Bfr::Surface<double>::PointDescriptor st(2);
    for (std::size_t s = 0; s < channels.size(); ++s) {
      if (!w.factory.InitFaceVaryingSurface(face, &w.surface, static_cast<int>(s))) {
        failed = true;
        return;
      }
      w.patchPoints.resize(static_cast<std::size_t>(w.surface.GetNumPatchPoints()) * 2);
      w.surface.PreparePatchPoints(channels[s].values.data(), st, w.patchPoints.data(), st);
      w.gridUvs.resize(static_cast<std::size_t>(grid.points()));
      for (int g = 0; g < grid.grids(); ++g) {
        for (int j = 0; j < grid.side; ++j) {
          for (int i = 0; i < grid.side; ++i) {
            double uv[2], T[2];
            gridCoord(param, grid, g, i, j, uv);
            w.surface.Evaluate(uv, w.patchPoints.data(), st, T);
            w.gridUvs[pointIndex(g, i, j) - first] =
                Vec2f{static_cast<float>(T[0]), static_cast<float>(T[1])};
          }
        }
      }
      std::vector<Vec2f>& uvs = fine.uvSets[s].uvs;
      std::size_t c = cellStart[f];
      for (int g = 0; g < grid.grids(); ++g) {
        for (int j = 0; j + 1 < grid.side; ++j) {
          for (int i = 0; i + 1 < grid.side; ++i, ++c) {
            uvs[4 * c] = w.gridUvs[pointIndex(g, i, j) - first];
            uvs[4 * c + 1] = w.gridUvs[pointIndex(g, i + 1, j) - first];
            uvs[4 * c + 2] = w.gridUvs[pointIndex(g, i + 1, j + 1) - first];
            uvs[4 * c + 3] = w.gridUvs[pointIndex(g, i, j + 1) - first];
          }
        }
      }
    }
  });
  if (failed) throw EvaluationFailed{};

  fine.cornerNormals.resize(fine.cornerVertex.size());
  computeSmoothNormals(fine);
  return fine;
}

}  // namespace

}  // namespace sgbake
