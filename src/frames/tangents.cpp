#include "sgbake/frames/tangents.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>


#include <tbb/info.h>
#include <tbb/task_arena.h>

#include "frames/mikktspace.hpp"
#include "sgbake/mesh/triangulate.hpp"

namespace sgbake {
namespace {

/// MikkTSpace's view of a MeshView: triangles and quads as they are; each n-gon becomes the
/// triangles of its ear-clipping triangulation (faces of their own to the algorithm).
class MeshViewAdapter {
 public:
  explicit MeshViewAdapter(const MeshView& mesh) : mesh_(mesh) {
    const std::size_t nf = mesh.numFaces();
    bool hasNgons = false;
    for (std::size_t f = 0; f < nf && !hasNgons; ++f) hasNgons = mesh.faceSize(f) > 4;
    if (!hasNgons) return;  // faces map one to one: no tables needed
    faceStart_.assign(1, 0);
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<Vec3f> points;
    for (std::size_t f = 0; f < nf; ++f) {
      const std::uint32_t c0 = mesh.faceStart[f], n = mesh.faceSize(f);
      if (n <= 4) {
        for (std::uint32_t i = 0; i < n; ++i) corner_.push_back(c0 + i);
        faceStart_.push_back(static_cast<std::uint32_t>(corner_.size()));
        continue;
      }
      points.resize(n);
      for (std::uint32_t i = 0; i < n; ++i) points[i] = mesh.positions[mesh.cornerVertex[c0 + i]];
      triangulatePolygon(points, triangles);
      for (const auto& tri : triangles) {
        for (const std::uint32_t i : tri) corner_.push_back(c0 + i);
        faceStart_.push_back(static_cast<std::uint32_t>(corner_.size()));
      }
    }
  }

  int numFaces() const {
    return static_cast<int>(faceStart_.empty() ? mesh_.numFaces() : faceStart_.size() - 1);
  }
  int faceSize(int f) const {
    return static_cast<int>(faceStart_.empty() ? mesh_.faceSize(static_cast<std::size_t>(f))
                                               : faceStart_[f + 1] - faceStart_[f]);
  }
  /// The mesh corner behind corner @p v of algorithm face @p f.
  std::uint32_t meshCorner(int f, int v) const {
    return faceStart_.empty() ? mesh_.faceStart[static_cast<std::size_t>(f)] + static_cast<std::uint32_t>(v)
                              : corner_[faceStart_[static_cast<std::size_t>(f)] + static_cast<std::uint32_t>(v)];
  }
  std::uint32_t numVertices() const { return static_cast<std::uint32_t>(mesh_.positions.size()); }
  std::uint32_t vertex(int f, int v) const { return mesh_.cornerVertex[meshCorner(f, v)]; }
  Vec3f vertexPosition(std::uint32_t u) const { return mesh_.positions[u]; }
  Vec3f position(int f, int v) const { return mesh_.positions[vertex(f, v)]; }
  Vec3f normal(int f, int v) const { return mesh_.cornerNormals[meshCorner(f, v)]; }
  Vec2f uv(int f, int v) const { return mesh_.cornerUvs[meshCorner(f, v)]; }
  bool identity() const { return faceStart_.empty(); }

 private:
  const MeshView& mesh_;
  std::vector<std::uint32_t> faceStart_;  // empty when faces map one to one
  std::vector<std::uint32_t> corner_;
};
static_assert(mikk::VertexAdapter<MeshViewAdapter>);


}  // namespace

Result<CornerTangents> computeTangents(const MeshView& mesh, const TangentOptions& options) {
  const std::size_t nc = mesh.numCorners();
  if (mesh.cornerUvs.size() != nc || nc == 0)
    return Error::badInput("mesh has no texture coordinates (tangents need UVs)");
  if (mesh.cornerNormals.size() != nc)
    return Error::badInput("mesh has " + std::to_string(mesh.cornerNormals.size()) +
                           " corner normals for " + std::to_string(nc) + " corners");

  CornerTangents result;
  auto work = [&] {
    result.tangent.resize(nc);
    result.sign.resize(nc);
    const MeshViewAdapter adapter(mesh);
    if (adapter.identity()) {
      // Triangles and quads only: slots are corners, and the algorithm reads and writes the
      // mesh's and the result's arrays directly.
      const mikk::Input input{mesh.faceStart, mesh.cornerVertex, mesh.positions, mesh.cornerNormals,
                              mesh.cornerUvs};
      mikk::generate(input, {result.tangent, result.sign});
      return;
    }
    const mikk::GatheredInput input = mikk::gather(adapter);
    std::vector<Vec3f> tangent(input.vertex.size());
    std::vector<float> sign(input.vertex.size());
    mikk::generate(input.view(), {tangent, sign});
    // N-gon corners may appear in several triangles: the last one wins.
    for (int f = 0, slot = 0; f < adapter.numFaces(); ++f) {
      for (int v = 0; v < adapter.faceSize(f); ++v, ++slot) {
        const std::uint32_t c = adapter.meshCorner(f, v);
        result.tangent[c] = tangent[static_cast<std::size_t>(slot)];
        result.sign[c] = sign[static_cast<std::size_t>(slot)];
      }
    }
  };
  if (options.threads > 0) {
    // More threads than cores only adds contention (and a TBB warning); the result is the same.
    tbb::task_arena arena(std::min(options.threads, tbb::info::default_concurrency()));
    arena.execute(work);
  } else {
    work();
  }
  return result;
}

std::string missingTangentsWarning(const CornerTangents& tangents, const std::string& meshName) {
  const auto missing = static_cast<std::size_t>(
      std::count_if(tangents.tangent.begin(), tangents.tangent.end(),
                    [](const Vec3f& t) { return !(t.x != 0 || t.y != 0 || t.z != 0); }));
  if (missing == 0) return "";
  return meshName + ": " + std::to_string(missing) + " of " +
         std::to_string(tangents.tangent.size()) +
         " face corners have no tangent (MikkTSpace found no usable position and UV differences "
         "there: triangles of zero area in space or in UV, as a large polygon's slivers or "
         "coordinates beyond ~1e19 that overflow single precision make them): tangent-space "
         "values there mean nothing";
}

}  // namespace sgbake
