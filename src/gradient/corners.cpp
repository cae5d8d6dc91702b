#include "sgbake/gradient/corners.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <ostream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "sgbake/core/math.hpp"
#include "sgbake/mesh/normals.hpp"
#include "sgbake/mesh/triangulate.hpp"

namespace sgbake {
namespace {

/// Sine of the angle between @p a and @p b (0 when either is zero).
double sineBetween(Vec2d a, Vec2d b) {
  const double la = std::sqrt(lengthSquared(a)), lb = std::sqrt(lengthSquared(b));
  if (!(la > 0) || !(lb > 0)) return 0;
  return std::abs(a.x * b.y - a.y * b.x) / (la * lb);
}

double sineBetween(Vec3d a, Vec3d b) {
  const double la = length(a), lb = length(b);
  if (!(la > 0) || !(lb > 0)) return 0;
  return length(cross(a, b)) / (la * lb);
}

/// The affine map of one triangle of a face, seen from one of its corners.
struct CornerTriangle {
  double quality = 0;  ///< min of the UV-space and object-space sines at the corner
  Vec3d dPdu{}, dPdv{};
};

/// ∂P/∂u, ∂P/∂v of the triangle (corner, a, b) with the corner at @p c: solves
/// [e1 e2] = [∂P/∂u ∂P/∂v] · [d1 d2] for edges e_i (object space) and d_i (UV space).
CornerTriangle cornerTriangle(const Mesh& mesh, const std::vector<Vec2f>& uvs, std::uint32_t c,
                              std::uint32_t a, std::uint32_t b) {
  const Vec3d p = cast<double>(mesh.positions[mesh.cornerVertex[c]]);
  const Vec3d e1 = cast<double>(mesh.positions[mesh.cornerVertex[a]]) - p;
  const Vec3d e2 = cast<double>(mesh.positions[mesh.cornerVertex[b]]) - p;
  const Vec2d t = cast<double>(uvs[c]);
  const Vec2d d1 = cast<double>(uvs[a]) - t, d2 = cast<double>(uvs[b]) - t;
  CornerTriangle result;
  result.quality = std::min(sineBetween(d1, d2), sineBetween(e1, e2));
  const double det = d1.x * d2.y - d1.y * d2.x;
  if (!(result.quality > 0) || det == 0) return {};
  result.dPdu = (1 / det) * (d2.y * e1 - d1.y * e2);
  result.dPdv = (1 / det) * (d1.x * e2 - d2.x * e1);
  return result;
}

/// The UV frame of corner @p c (index @p i in face @p face) for UV set @p set (see
/// cornerSurfacePoint for the choice of triangle).
UvFrame cornerUvFrame(const Mesh& mesh, std::size_t face, std::uint32_t i, std::size_t set,
                      double minSine) {
  const std::vector<Vec2f>& uvs = mesh.uvSets[set].uvs;
  const std::uint32_t first = mesh.faceStart[face], n = mesh.faceSize(face);
  const std::uint32_t c = first + i;
  UvFrame frame;
  frame.uv = cast<double>(uvs[c]);

  CornerTriangle best = cornerTriangle(mesh, uvs, c, first + (i + n - 1) % n, first + (i + 1) % n);
  if (!(best.quality >= minSine) && n > 3) {
    // Fallback: the face's triangulation, the best triangle through this corner.
    std::vector<Vec3f> points(n);
    for (std::uint32_t k = 0; k < n; ++k) points[k] = mesh.positions[mesh.cornerVertex[first + k]];
    std::vector<std::array<std::uint32_t, 3>> triangles;
    triangulatePolygon(points, triangles);
    for (const auto& tri : triangles) {
      for (std::size_t k = 0; k < 3; ++k) {
        if (tri[k] != i) continue;
        const CornerTriangle candidate =
            cornerTriangle(mesh, uvs, c, first + tri[(k + 1) % 3], first + tri[(k + 2) % 3]);
        if (candidate.quality > best.quality) best = candidate;
      }
    }
  }
  if (best.quality >= minSine) {
    frame.dPdu = best.dPdu;
    frame.dPdv = best.dPdv;
  }
  return frame;
}

/// Appends @p x with 9 significant digits ("%.9g"), −0 as 0.
void appendNumber(std::string& out, double x) {
  std::array<char, 32> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x + 0.0,
                                       std::chars_format::general, 9);
  out.append(buffer.data(), ec == std::errc() ? end : buffer.data());
}

void appendVec(std::string& out, Vec3d v) {
  for (std::size_t k = 0; k < 3; ++k) {
    out += ',';
    appendNumber(out, v[k]);
  }
}

/// Makes @p layerTangents (CornerOptions::layerTangents) corner @p c's frames for the layers of
/// @p point: set 0's is its `tangent`, another set's its `uvTangent`.
void useLayerTangents(const std::array<const CornerTangents*, kMaxUvSets>& layerTangents,
                      std::uint32_t c, SurfacePoint& point) {
  for (std::size_t set = 0; set < kMaxUvSets; ++set) {
    const CornerTangents* frames = layerTangents[set];
    if (frames == nullptr || c >= frames->tangent.size()) continue;
    const Vec3d tangent = cast<double>(frames->tangent[c]);
    const double sign = frames->sign[c] < 0 ? -1.0 : 1.0;
    if (set == 0) {
      point.tangent = tangent;
      point.bitangentSign = sign;
      point.hasTangentFrame = true;
    } else {
      point.uvTangent[set] = tangent;
      point.uvBitangentSign[set] = sign;
      point.hasUvTangentFrame[set] = true;
    }
  }
}

}  // namespace

SurfacePoint cornerSurfacePoint(const Mesh& mesh, const CornerTangents* tangents, std::size_t face,
                                std::uint32_t corner, double minCornerSine) {
  SurfacePoint point;
  point.position = cast<double>(mesh.positions[mesh.cornerVertex[corner]]);
  point.normal = normalizeOr(cast<double>(mesh.cornerNormals[corner]), Vec3d{0, 0, 1});
  const std::uint32_t i = corner - mesh.faceStart[face];
  point.numUvSets = static_cast<int>(std::min<std::size_t>(mesh.uvSets.size(), kMaxUvSets));
  for (std::size_t set = 0; set < static_cast<std::size_t>(point.numUvSets); ++set)
    point.uv[set] = cornerUvFrame(mesh, face, i, set, minCornerSine);
  if (tangents != nullptr && corner < tangents->tangent.size()) {
    point.tangent = cast<double>(tangents->tangent[corner]);
    point.bitangentSign = tangents->sign[corner] < 0 ? -1.0 : 1.0;
    point.hasTangentFrame = true;
  }
  return point;
}

Result<std::vector<CornerSample>> evaluateCorners(const Mesh& mesh, std::span<const Layer> layers,
                                                  const CornerOptions& options) {
  if (Status valid = validate(mesh); !valid) return valid.error();
  const int numUvSets = static_cast<int>(std::min<std::size_t>(mesh.uvSets.size(), kMaxUvSets));
  if (Status valid = validateLayers(layers, numUvSets); !valid) return valid.error();

  CornerTangents tangents;
  const bool haveTangents = mesh.hasUvSet(0) && mesh.numCorners() > 0;
  if (haveTangents) {
    auto computed = computeTangents(mesh.view(0), {options.threads});
    if (!computed) return computed.error();
    tangents = std::move(computed).value();
  }

  // Layers of one material: each face takes its material's.
  const std::vector<std::vector<Layer>> byMaterial = layersByMaterial(layers);
  const auto faceLayers = [&](std::size_t f) -> std::span<const Layer> {
    if (byMaterial.empty()) return layers;
    return byMaterial[std::min<std::size_t>(mesh.material(f), byMaterial.size() - 1)];
  };

  std::vector<CornerSample> samples(mesh.numCorners());
  auto work = [&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, mesh.numFaces()),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t f = range.begin(); f != range.end(); ++f) {
            const std::span<const Layer> shading = faceLayers(f);
            for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
              SurfacePoint point = cornerSurfacePoint(mesh, haveTangents ? &tangents : nullptr, f,
                                                      c, options.minCornerSine);
              CornerSample& s = samples[c];
              s.tangent = haveTangents ? point.tangent : Vec3d{};
              s.sign = haveTangents ? point.bitangentSign : 1.0;
              useLayerTangents(options.layerTangents, c, point);
              s.face = static_cast<std::uint32_t>(f);
              s.corner = c;
              s.position = point.position;
              s.normal = point.normal;
              s.uv = point.numUvSets > 0 ? point.uv[0].uv : Vec2d{};
              if (options.world != nullptr) {
                // A corner has no triangle: its own normal is its Ng (planeNormal).
                const SurfacePoint world = worldSurfacePoint(point, *options.world);
                s.gradient =
                    objectSpaceGradient(shadeLayersInWorld(shading, point, world, *options.world),
                                        point, *options.world);
                s.perturbed = resolveNormal(point.normal, s.gradient);
              } else {
                s.gradient = compositeGradient(shading, point);
                s.perturbed = resolveNormal(point.normal, s.gradient, options.objectScaleCofactor);
              }
            }
          }
        });
  };
  if (options.threads > 0) {
    tbb::task_arena arena(options.threads);
    arena.execute(work);
  } else {
    work();
  }
  return samples;
}

std::string formatCornerTable(std::span<const CornerSample> samples) {
  std::string out = kCornerTableHeader;
  out += '\n';
  out.reserve(out.size() + samples.size() * 200);
  for (const CornerSample& s : samples) {
    out += std::to_string(s.face);
    out += ',';
    out += std::to_string(s.corner);
    appendVec(out, s.position);
    appendVec(out, s.normal);
    appendVec(out, s.tangent);
    out += ',';
    appendNumber(out, s.sign);
    out += ',';
    appendNumber(out, s.uv.x);
    out += ',';
    appendNumber(out, s.uv.y);
    appendVec(out, s.gradient);
    appendVec(out, s.perturbed);
    out += '\n';
  }
  return out;
}

void writeCornerTable(std::ostream& out, std::span<const CornerSample> samples) {
  const std::string text = formatCornerTable(samples);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

}  // namespace sgbake
