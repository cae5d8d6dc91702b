/// @file subdivide.cpp
/// @brief subdivideMesh: OpenSubdiv's Far topology plus Blender's patch evaluation on each coarse face's
/// grid of new vertices, numbered and connected as Blender's Subdivision Surface modifier does.
#include "sgbake/subdiv/subdivide.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/mesh/normals.hpp"
#include "subdiv/control_mesh.hpp"
#include "subdiv/patch_evaluator.hpp"

namespace sgbake {
namespace {

using namespace subdiv_detail;

/// The grid of new vertices on one coarse face. A quad has one grid of R×R points (R = 2^level
/// + 1) on its own [0,1]² parameterization, point (i, j) at (i, j)/(R-1), corner k of the face at
/// the k-th corner of the square counter-clockwise from (0, 0). Any other face of n corners has
/// n grids of r×r points (r = 2^(level-1) + 1), one per corner k: Ptex sub-face k (Bfr's normalized sub-face k),
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

/// A cell of a face's grids: grid g, cell (i, j) between points (i, j) and (i+1, j+1).
struct GridCell {
  int g = 0, i = 0, j = 0;
};

/// The cells of a face in the order Blender's modifier makes its new faces (measured in Blender
/// 3.4 on quads, triangles and 5- to 8-gons at levels 1 to 3). With M cells per grid side:
/// a quad's cells off its border row by row, then its border ring side by side, each side from
/// its corner (side 0 along j = 0, side 1 along i = M−1, side 2 back along j = M−1, side 3 down
/// along i = 0); any other face's cells off the two grid lines shared with the neighbours
/// (i = 0 and j = 0 stay outside) grid by grid, then the cells along each grid's j = M−1 line
/// (grid k+1's, for each k), then each grid's centre cell, then each grid's cells along its
/// face edges (j = 0 outwards from the corner, then i = 0).
std::vector<GridCell> blenderCellOrder(const FaceGrid& grid) {
  const int m = grid.side - 1;
  std::vector<GridCell> cells;
  cells.reserve(static_cast<std::size_t>(grid.grids() * grid.cellsPerGrid()));
  if (grid.corners == 4) {
    for (int j = 1; j + 1 < m; ++j) {
      for (int i = 1; i + 1 < m; ++i) cells.push_back({0, i, j});
    }
    for (int t = 0; t + 1 < m; ++t) cells.push_back({0, t, 0});  // (m ≥ 2: level ≥ 1)
    for (int t = 0; t + 1 < m; ++t) cells.push_back({0, m - 1, t});
    for (int t = 0; t + 1 < m; ++t) cells.push_back({0, m - 1 - t, m - 1});
    for (int t = 0; t + 1 < m; ++t) cells.push_back({0, 0, m - 1 - t});
    return cells;
  }
  const int n = grid.corners;
  for (int k = 0; k < n; ++k) {
    for (int j = 1; j + 1 < m; ++j) {
      for (int i = 1; i < m; ++i) cells.push_back({k, i, j});
    }
  }
  for (int k = 0; k < n; ++k) {
    for (int i = 1; i + 1 < m; ++i) cells.push_back({(k + 1) % n, i, m - 1});
  }
  if (m >= 2) {
    for (int k = 0; k < n; ++k) cells.push_back({k, m - 1, m - 1});
  }
  for (int k = 0; k < n; ++k) {
    for (int t = 0; t < m; ++t) cells.push_back({k, t, 0});
    for (int t = 1; t < m; ++t) cells.push_back({k, 0, t});
  }
  return cells;
}

/// The edges of @p mesh in the order Blender gives a mesh built from its faces (an imported OBJ:
/// BKE_mesh_calc_edges), each as (lower vertex, higher vertex), which is how Blender stores
/// them. Blender collects the edges in open-addressing hash tables and keeps their slot order:
/// hash (lo << 8) ^ hi as a 32-bit int widened to 64 bits, probing h, then h = 5h + 1 + perturb
/// with perturb shifted right by 5 before each step, tables of a power of two ≥ 8 slots at
/// most half full (grown to fit before each insertion, the keys re-inserted in slot order),
/// first sized for 2·faces / tables keys. Meshes of 1000 faces or more are split over
/// 2^⌊log2 min(8, threads)⌋ tables by the low bits of lo, threads being the logical CPUs, as
/// Blender counts them by default (so there Blender's own order depends on the machine).
/// Measured against Blender 3.4 on the cube, Suzanne, grids, meshes of triangles and n-gons
/// and meshes of over 1000 faces with 1, 2 and 8 threads.
std::vector<std::pair<std::uint32_t, std::uint32_t>> blenderEdgeOrder(const Mesh& mesh) {
  using Key = std::pair<std::uint32_t, std::uint32_t>;
  struct Table {
    std::vector<std::optional<Key>> slots = std::vector<std::optional<Key>>(1);
    std::size_t usable = 0, occupied = 0;
  };
  const auto hash = [](const Key& key) {
    const auto h32 = static_cast<std::int32_t>((key.first << 8) ^ key.second);
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(h32));
  };
  // Calls @p visit with each slot index the probe for @p key reaches until it returns true.
  const auto probe = [&](const Key& key, std::size_t mask, auto&& visit) {
    std::uint64_t h = hash(key), perturb = h;
    while (!visit(static_cast<std::size_t>(h & mask))) {
      perturb >>= 5;
      h = 5 * h + 1 + perturb;
    }
  };
  const auto grow = [&](Table& table, std::size_t minUsable) {
    std::size_t total = 8;
    while (total < 2 * minUsable) total *= 2;
    std::vector<std::optional<Key>> slots(total);
    for (const std::optional<Key>& key : table.slots) {
      if (!key) continue;
      probe(*key, total - 1, [&](std::size_t s) {
        if (slots[s]) return false;
        slots[s] = key;
        return true;
      });
    }
    table.slots = std::move(slots);
    table.usable = total / 2;
  };
  const std::size_t faces = mesh.numFaces();
  std::size_t tables = 1;
  if (faces >= 1000) {
    const std::size_t threads =
        std::min<std::size_t>(8, std::max(1u, std::thread::hardware_concurrency()));
    while (tables * 2 <= threads) tables *= 2;
  }
  std::vector<Table> maps(tables);
  for (Table& table : maps) {
    if (table.usable < 2 * faces / tables) grow(table, 2 * faces / tables);
  }
  for (std::size_t f = 0; f < faces; ++f) {
    const std::uint32_t begin = mesh.faceStart[f], end = mesh.faceStart[f + 1];
    std::uint32_t previous = mesh.cornerVertex[end - 1];
    for (std::uint32_t c = begin; c < end; ++c) {
      const std::uint32_t v = mesh.cornerVertex[c];
      if (v != previous) {
        const Key key{std::min(previous, v), std::max(previous, v)};
        Table& table = maps[key.first & (tables - 1)];
        if (table.occupied >= table.usable) grow(table, table.occupied + 1);
        probe(key, table.slots.size() - 1, [&](std::size_t s) {
          if (!table.slots[s]) {
            table.slots[s] = key;
            ++table.occupied;
            return true;
          }
          return *table.slots[s] == key;
        });
      }
      previous = v;
    }
  }
  std::vector<Key> edges;
  for (const Table& table : maps) {
    for (const std::optional<Key>& key : table.slots) {
      if (key) edges.push_back(*key);
    }
  }
  return edges;
}

/// Numbers the new vertices as Blender's modifier does: coarse vertex v keeps index v; point t
/// (1..R-2, from the edge's lower vertex) inside the coarse edge Blender numbers e
/// (blenderEdgeOrder) is edgeBase + e·(R-2) + t-1; points inside face f follow from faceBase[f].
class VertexNumbering {
 public:
  VertexNumbering(const Mesh& mesh, const Refiner& refiner, int level) : level_(level) {
    const auto& base = refiner.GetLevel(0);
    edgeSide_ = (1 << level) + 1;
    edgeBase_ = static_cast<std::uint32_t>(mesh.numVertices());
    const auto edges = static_cast<std::uint32_t>(base.GetNumEdges());
    // OpenSubdiv's edges ↔ Blender's.
    blenderEdge_.assign(edges, 0);
    osdEdge_.assign(edges, 0);
    const std::vector<std::pair<std::uint32_t, std::uint32_t>> order = blenderEdgeOrder(mesh);
    for (std::size_t e = 0; e < order.size() && e < edges; ++e) {
      const int osd =
          base.FindEdge(static_cast<int>(order[e].first), static_cast<int>(order[e].second));
      if (osd < 0) continue;
      blenderEdge_[static_cast<std::size_t>(osd)] = static_cast<std::uint32_t>(e);
      osdEdge_[e] = static_cast<std::uint32_t>(osd);
    }
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

  /// The coarse edge (OpenSubdiv's base-level index) whose inside new vertex @p v lies on, or -1
  /// (a coarse vertex, or inside a face).
  int edgeOf(std::uint32_t v) const {
    const std::uint32_t perEdge = static_cast<std::uint32_t>(edgeSide_ - 2);
    if (v < edgeBase_ || (faceBase_.empty() ? v >= count_ : v >= faceBase_[0])) return -1;
    return static_cast<int>(osdEdge_[(v - edgeBase_) / perEdge]);
  }

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
    // Blender's order inside an n-gon: the centre, then grid by grid the rows j = 1 … last−1,
    // each of points i = 1 … last (its last point on the line from the middle of edge k to the
    // centre); point (i, last) of grid k is point (last, i) of grid k−1.
    const int k = g, inner = last - 1;
    const auto interior = [&](int sub, int x, int y) {
      return faceBase_[f] +
             static_cast<std::uint32_t>(1 + sub * inner * last + (y - 1) * last + (x - 1));
    };
    if (i == 0 && j == 0) return corner(k);
    if (j == 0) return onEdge(refiner, f, k, corner(k), i);
    if (i == 0) return onEdge(refiner, f, (k + n - 1) % n, corner(k - 1), full - j);
    if (i == last && j == last) return faceBase_[f];
    if (j == last) return interior((k + n - 1) % n, last, i);
    return interior(k, i, j);
  }

 private:
  /// Point t (0..R-1) of face @p f's edge @p k counted from @p from, its first corner's vertex.
  std::uint32_t onEdge(const Refiner& refiner, std::size_t f, int k, std::uint32_t from,
                       int t) const {
    const auto& base = refiner.GetLevel(0);
    const int e = base.GetFaceEdges(static_cast<int>(f))[k];
    const auto ends = base.GetEdgeVertices(e);
    const bool forward = static_cast<std::uint32_t>(std::min(ends[0], ends[1])) == from;
    const int along = forward ? t : edgeSide_ - 1 - t;
    return edgeBase_ +
           blenderEdge_[static_cast<std::size_t>(e)] * static_cast<std::uint32_t>(edgeSide_ - 2) +
           static_cast<std::uint32_t>(along - 1);
  }

  int level_;
  std::vector<std::uint32_t> blenderEdge_;  ///< OpenSubdiv's base edge → Blender's edge index
  std::vector<std::uint32_t> osdEdge_;      ///< Blender's edge index → OpenSubdiv's base edge
  int edgeSide_ = 0;
  std::uint32_t edgeBase_ = 0;
  std::vector<std::uint32_t> faceBase_;
  std::uint32_t count_ = 0;
};

using SharpPairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

/// Shades @p mesh with the Auto Smooth of @p options (set): Blender's split normals, split also
/// along @p sharp (vertex pairs, lower index first, in any order).
void shadeAutoSmooth(Mesh& mesh, const SubdivisionOptions& options, SharpPairs sharp) {
  std::sort(sharp.begin(), sharp.end());
  sharp.erase(std::unique(sharp.begin(), sharp.end()), sharp.end());
  computeSplitNormals(mesh, *options.autoSmoothDegrees * (kPi / 180), sharp);
}

/// The edges of @p fine along coarse edges marked sharp (as Blender copies a coarse edge's
/// flags to the new edges along it), as vertex pairs, lower index first.
SharpPairs sharpAlongMarkedEdges(const Mesh& fine, const Refiner& refiner,
                                 const VertexNumbering& numbering,
                                 const std::vector<SharpEdge>& marked) {
  SharpPairs sharp;
  if (marked.empty()) return sharp;
  const auto& base = refiner.GetLevel(0);
  std::vector<std::uint8_t> isMarked(static_cast<std::size_t>(base.GetNumEdges()), 0);
  for (const SharpEdge& e : marked) {
    const int edge = base.FindEdge(static_cast<int>(e.v0), static_cast<int>(e.v1));
    if (edge >= 0) isMarked[static_cast<std::size_t>(edge)] = 1;
  }
  // A new edge lies along coarse edge e when both its ends are inside e, or one is inside e and
  // the other is one of e's ends.
  const auto endsAt = [&](int edge, std::uint32_t v) {
    const auto ends = base.GetEdgeVertices(edge);
    return static_cast<std::uint32_t>(ends[0]) == v || static_cast<std::uint32_t>(ends[1]) == v;
  };
  for (std::size_t f = 0; f < fine.numFaces(); ++f) {
    const std::uint32_t b = fine.faceStart[f], n = fine.faceStart[f + 1] - b;
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t u = fine.cornerVertex[b + k], v = fine.cornerVertex[b + (k + 1) % n];
      const int eu = numbering.edgeOf(u), ev = numbering.edgeOf(v);
      int edge = -1;
      if (eu >= 0 && (eu == ev || (ev < 0 && endsAt(eu, v)))) edge = eu;
      if (ev >= 0 && eu < 0 && endsAt(ev, u)) edge = ev;
      if (edge >= 0 && isMarked[static_cast<std::size_t>(edge)]) {
        sharp.emplace_back(std::min(u, v), std::max(u, v));
      }
    }
  }
  return sharp;
}

/// subdivideGrids could not evaluate a face's limit surface.
struct EvaluationFailed {};

/// The most corners a subdivided mesh may have: corner indices are 32-bit.
constexpr std::uint64_t kMaxSubdividedCorners = std::numeric_limits<std::uint32_t>::max();

/// The subdivided mesh (see subdivideMesh) of @p coarse as OpenSubdiv sees it (@p control),
/// and where its corners lie on the limit surface when @p parameters is not null. Throws
/// std::bad_alloc, or EvaluationFailed when no patch covers a point.
Mesh subdivideGrids(const Mesh& coarse, ControlMesh& control, const SubdivisionOptions& options,
                    PatchEvaluator::Refinement refinement, SurfaceParameters* parameters);

}  // namespace

SubdivisionConflict findSubdivisionConflict(const SubdivisionOptions& options, bool limit) {
  using C = SubdivisionConflict;
  if (limit) {
    if (!options.useLimitSurface) return C::kLimitWithoutLimitSurface;
    if (options.type == SubdivisionType::kSimple) return C::kLimitSimple;
    if (options.autoSmoothDegrees) return C::kLimitAutoSmooth;
    if (!options.sharpEdges.empty()) return C::kLimitSharpEdges;
    return C::kNone;
  }
  if (!options.sharpEdges.empty() && !options.autoSmoothDegrees) {
    return C::kSharpEdgesWithoutAutoSmooth;  // at any level: they split nothing
  }
  if (options.level != 0) return C::kNone;
  if (!options.edgeCreases.empty()) return C::kEdgeCreasesUnsubdivided;
  if (!options.vertexCreases.empty()) return C::kVertexCreasesUnsubdivided;
  if (!options.useLimitSurface) return C::kNoLimitSurfaceUnsubdivided;
  if (options.type == SubdivisionType::kSimple) return C::kSimpleUnsubdivided;
  return C::kNone;
}

Result<Mesh> subdivideMesh(const Mesh& coarse, const SubdivisionOptions& options,
                           SurfaceParameters* parameters) {
  const std::string& name = coarse.source;
  if (options.level < 0 || options.level > kMaxSubdivisionLevel) {
    return Error::badInput(name + ": subdivision level " + std::to_string(options.level) +
                           " is out of range (0.." + std::to_string(kMaxSubdivisionLevel) + ")");
  }
  if (options.quality < kMinSubdivisionQuality || options.quality > kMaxSubdivisionQuality) {
    return Error::badInput(name + ": subdivision quality " + std::to_string(options.quality) +
                           " is out of range (" + std::to_string(kMinSubdivisionQuality) + ".." +
                           std::to_string(kMaxSubdivisionQuality) + ")");
  }
  if (options.autoSmoothDegrees &&
      !(*options.autoSmoothDegrees >= 0 && *options.autoSmoothDegrees <= 180)) {
    std::ostringstream angle;
    angle << *options.autoSmoothDegrees;
    return Error::badInput(name + ": Auto Smooth angle " + angle.str() +
                           " is out of range (0..180 degrees)");
  }
  if (options.level == 0) {
    if (parameters != nullptr) {  // each corner at its own corner of its face
      *parameters = {};
      for (std::size_t f = 0; f < coarse.numFaces(); ++f) {
        parameters->faceOrigin.push_back(static_cast<std::uint32_t>(f));
      }
    }
    if (!options.autoSmoothDegrees) return coarse;
    // The modifier at level 0 returns the mesh as it is, and the mesh's Auto Smooth splits its
    // normals, along its own edges marked sharp.
    if (Status ok = checkCreases(coarse, options); !ok) return ok.error();
    Mesh shaded = coarse;
    SharpPairs sharp;
    for (const SharpEdge& e : options.sharpEdges) {
      sharp.emplace_back(std::min(e.v0, e.v1), std::max(e.v0, e.v1));
    }
    shadeAutoSmooth(shaded, options, std::move(sharp));
    return shaded;
  }
  Result<ControlMesh> control = buildControlMesh(coarse, options);
  if (!control) return control.error();
  const std::size_t nf = coarse.numFaces();
  const std::vector<int>& faceSizes = control->faceSizes;
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
    // Blender's SubdivSettings: adaptive to the Quality on the limit surface, else uniform.
    // (Simple: refined to level 1, whichever way.)
    const int refinementLevel =
        options.type == SubdivisionType::kSimple ? 1 : (options.useLimitSurface ? options.quality : level);
    const PatchEvaluator::Refinement refinement{options.useLimitSurface, refinementLevel};
    return subdivideGrids(coarse, *control, options, refinement, parameters);
  } catch (const EvaluationFailed&) {
    return Error::badInput(name + ": OpenSubdiv cannot evaluate the limit surface of a face");
  } catch (const std::bad_alloc&) {
    return Error::internal(name + ": out of memory subdividing to level " +
                           std::to_string(level) + " (" + std::to_string(newFaces) + " faces)");
  }
}

namespace {

Mesh subdivideGrids(const Mesh& coarse, ControlMesh& control, const SubdivisionOptions& options,
                    PatchEvaluator::Refinement refinement, SurfaceParameters* parameters) {
  const int level = options.level;
  const Refiner* const refiner = control.refiner.get();
  const std::vector<FVarChannel>& channels = control.channels;
  const std::vector<int>& faceSizes = control.faceSizes;
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
    // Faces in order. Within an n-gon, as Blender evaluates the points grids share: first
    // every grid's row j = 0 (corner k and edge k up to its middle), then every grid's column
    // i = last (the line from the middle of edge k to the centre, the centre from grid 0),
    // then the rest grid by grid; so grid k evaluates the middle of edge k and the line to the
    // centre for every k, including the last.
    std::vector<std::uint8_t> seen(numbering.count(), 0);
    for (std::size_t f = 0; f < nf; ++f) {
      const FaceGrid grid = faceGrid(faceSizes[f], level);
      const auto visit = [&](int g, int i, int j) {
        const std::size_t p =
            gridStart[f] + static_cast<std::size_t>(g * grid.pointsPerGrid() + j * grid.side + i);
        const std::uint32_t v = numbering.vertex(coarse, *refiner, f, g, i, j);
        pointVertex[p] = v;
        if (!seen[v]) seen[v] = pointEvaluates[p] = 1;
      };
      for (int g = 0; g < grid.grids(); ++g) {
        for (int i = 0; i < grid.side; ++i) visit(g, i, 0);
      }
      const int last = grid.side - 1;
      for (int g = 0; g < grid.grids(); ++g) {
        for (int j = 1; j <= last; ++j) visit(g, last, j);
      }
      for (int g = 0; g < grid.grids(); ++g) {
        for (int j = 1; j <= last; ++j) {
          for (int i = 0; i < last; ++i) visit(g, i, j);
        }
      }
    }
  }

  // The new faces: per coarse face, its cells in Blender's order (blenderCellOrder), cell (i, j)
  // as (i,j) (i+1,j) (i+1,j+1) (i,j+1).
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

  // Limit positions and UVs as Blender evaluates them (PatchEvaluator: Osd's patches in
  // float at each grid point's Ptex coordinates), face by face in parallel.
  if (parameters != nullptr) {
    parameters->faceOrigin.resize(fineFaces);
    parameters->cornerSubFace.resize(4 * fineFaces);
    parameters->cornerCoord.resize(4 * fineFaces);
  }
  const PatchEvaluator patches(control, refinement);
  tbb::enumerable_thread_specific<std::vector<Vec2f>> gridUvsTls;
  std::atomic<bool> failed{false};
  tbb::parallel_for(std::size_t{0}, nf, [&](std::size_t f) {
    std::vector<Vec2f>& gridUvs = gridUvsTls.local();
    const FaceGrid grid = faceGrid(faceSizes[f], level);
    const std::size_t first = gridStart[f];
    const auto pointIndex = [&](int g, int i, int j) {
      return first + static_cast<std::size_t>(g * grid.pointsPerGrid() + j * grid.side + i);
    };
    // Grid g is Ptex face ptexFace(f) + g; point (i, j) lies at (i, j) / (side − 1), a power of
    // two: exact in float, as Blender's coordinates are.
    const float step = 1.0f / static_cast<float>(grid.side - 1);
    const auto ptex = [&](int g) { return patches.ptexFace(static_cast<int>(f)) + g; };
    // Cells.
    const std::vector<GridCell> cells = blenderCellOrder(grid);
    std::size_t cell = cellStart[f];
    for (const auto& [g, i, j] : cells) {
      std::uint32_t* out = &fine.cornerVertex[4 * cell];
      out[0] = pointVertex[pointIndex(g, i, j)];
      out[1] = pointVertex[pointIndex(g, i + 1, j)];
      out[2] = pointVertex[pointIndex(g, i + 1, j + 1)];
      out[3] = pointVertex[pointIndex(g, i, j + 1)];
      if (parameters != nullptr) {
        parameters->faceOrigin[cell] = static_cast<std::uint32_t>(f);
        const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
        for (std::size_t k = 0; k < 4; ++k) {
          parameters->cornerSubFace[4 * cell + k] = static_cast<std::uint32_t>(g);
          parameters->cornerCoord[4 * cell + k] =
              Vec2f{static_cast<float>(i + di[k]) * step, static_cast<float>(j + dj[k]) * step};
        }
      }
      ++cell;
    }
    // Positions of the points this face evaluates.
    for (int g = 0; g < grid.grids(); ++g) {
      for (int j = 0; j < grid.side; ++j) {
        for (int i = 0; i < grid.side; ++i) {
          const std::size_t p = pointIndex(g, i, j);
          if (!pointEvaluates[p]) continue;
          float P[3];
          if (!patches.position(ptex(g), static_cast<float>(i) * step,
                                static_cast<float>(j) * step, P)) {
            failed = true;
            return;
          }
          fine.positions[pointVertex[p]] = Vec3f{P[0], P[1], P[2]};
        }
      }
    }
    // UVs: each set's face-varying limit at every grid point, then copied to the cells' corners.
    for (std::size_t s = 0; s < channels.size(); ++s) {
      gridUvs.resize(static_cast<std::size_t>(grid.points()));
      for (int g = 0; g < grid.grids(); ++g) {
        for (int j = 0; j < grid.side; ++j) {
          for (int i = 0; i < grid.side; ++i) {
            float T[2];
            if (!patches.faceVarying(static_cast<int>(s), ptex(g), static_cast<float>(i) * step,
                                     static_cast<float>(j) * step, T)) {
              failed = true;
              return;
            }
            gridUvs[pointIndex(g, i, j) - first] = Vec2f{T[0], T[1]};
          }
        }
      }
      std::vector<Vec2f>& uvs = fine.uvSets[s].uvs;
      std::size_t c = cellStart[f];
      for (const auto& [g, i, j] : cells) {
        uvs[4 * c] = gridUvs[pointIndex(g, i, j) - first];
        uvs[4 * c + 1] = gridUvs[pointIndex(g, i + 1, j) - first];
        uvs[4 * c + 2] = gridUvs[pointIndex(g, i + 1, j + 1) - first];
        uvs[4 * c + 3] = gridUvs[pointIndex(g, i, j + 1) - first];
        ++c;
      }
    }
  });
  if (failed) throw EvaluationFailed{};
  // Vertices no face uses keep their index and their place, as in Blender (no grid has them).
  std::vector<std::uint8_t> used(coarse.numVertices(), 0);
  for (const std::uint32_t v : coarse.cornerVertex) used[v] = 1;
  for (std::size_t v = 0; v < coarse.numVertices(); ++v) {
    if (!used[v]) fine.positions[v] = coarse.positions[v];
  }

  // Normals as Blender 3.4 computes them on the modified mesh (Auto Smooth off): each new face
  // keeps its coarse face's flat/smooth flag; corners of smooth faces get the vertex normal
  // (angle-weighted over every face at the vertex, flat ones included), corners of flat faces
  // their own face's normal.
  // With Auto Smooth, Blender's split normals of the new mesh instead.
  const bool anyFlat = std::any_of(coarse.faceFlat.begin(), coarse.faceFlat.end(),
                                   [](std::uint8_t flat) { return flat != 0; });
  if (anyFlat) {
    fine.faceFlat.resize(fineFaces);
    for (std::size_t f = 0; f < nf; ++f) {
      std::fill(fine.faceFlat.begin() + static_cast<std::ptrdiff_t>(cellStart[f]),
                fine.faceFlat.begin() + static_cast<std::ptrdiff_t>(cellStart[f + 1]),
                coarse.isFlat(f) ? 1 : 0);
    }
  }
  // Each new face keeps its coarse face's material, as the modifier does.
  fine.materialNames = coarse.materialNames;
  if (!coarse.faceMaterial.empty()) {
    fine.faceMaterial.resize(fineFaces);
    for (std::size_t f = 0; f < nf; ++f) {
      std::fill(fine.faceMaterial.begin() + static_cast<std::ptrdiff_t>(cellStart[f]),
                fine.faceMaterial.begin() + static_cast<std::ptrdiff_t>(cellStart[f + 1]),
                coarse.material(f));
    }
  }
  if (options.autoSmoothDegrees) {
    shadeAutoSmooth(fine, options,
                    sharpAlongMarkedEdges(fine, *refiner, numbering, options.sharpEdges));
    return fine;
  }
  computeSmoothNormals(fine);
  return fine;
}

}  // namespace

}  // namespace sgbake
