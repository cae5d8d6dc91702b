// Edge padding as Blender's "Adjacent Faces" margin: each texel of the margin takes the value
// the surface has on the other side of the UV seam it faces. See bake.hpp for the rules.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "bake/raster.hpp"
#include "sgbake/bake/bake.hpp"

namespace sgbake {
namespace {

using bake_detail::RasterTriangle;
using bake_detail::runWithThreads;
using bake_detail::uvToTexel;
using Point = std::complex<double>;

/// Texels of the margin lie within this many texels, along 8-connected steps of length 1 and
/// √2, of a covered texel, beyond `margin`: Blender's Adjacent Faces margin reaches one texel
/// farther than its Extend margin of the same size (9 rows beyond a straight island edge for
/// margin 8).
constexpr double kReachBeyondMargin = 1.5;
/// Seams crossed at most from a margin texel's nearest face to the face it is read from
/// (a texel near a corner of an island may have to go round the corner's vertex).
constexpr int kMaxFaceSteps = 8;

/// Per polygon edge (corner k → k+1 of a face, numbered by corner k), the corner on the other
/// side: the corner of the face across the same two vertices that starts that edge there, or
/// −1 on a boundary. Non-manifold edges: the next face round the edge.
std::vector<std::int64_t> oppositeCorners(const Mesh& mesh) {
  std::vector<std::int64_t> across(mesh.numCorners(), -1);
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> edges;
  edges.reserve(mesh.numCorners());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const std::uint32_t begin = mesh.faceStart[f], n = mesh.faceSize(f);
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t a = mesh.cornerVertex[begin + k];
      const std::uint32_t b = mesh.cornerVertex[begin + (k + 1) % n];
      if (a == b) continue;
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      edges[key].push_back(begin + k);
    }
  }
  for (const auto& [key, corners] : edges) {
    if (corners.size() < 2) continue;
    for (std::size_t k = 0; k < corners.size(); ++k) {
      across[corners[k]] = corners[(k + 1) % corners.size()];
    }
  }
  return across;
}

constexpr std::uint32_t kNoFace = std::numeric_limits<std::uint32_t>::max();

/// The face of the triangle that claims each texel (kNoFace: none), as rasterize() assigns
/// them: the last triangle covering one of the texel's samples. Rows y up. In parallel over
/// the raster's row blocks, each walking its triangles in ascending order.
std::vector<std::uint32_t> texelFaces(std::span<const Vec2f> uvs,
                                      std::span<const std::array<std::uint32_t, 3>> triangles,
                                      std::span<const std::uint32_t> cornerFace, int width,
                                      int height, int samples, int udimTile, int threads) {
  std::vector<std::uint32_t> face(static_cast<std::size_t>(width) * height, kNoFace);
  const bake_detail::SampleOffsets offsets(samples);
  bake_detail::RasterJob job;
  job.triangles = triangles;
  job.uvs = uvs;
  job.width = width;
  job.height = height;
  job.samples = samples;
  job.udimTile = udimTile;
  const bake_detail::TriangleBins bins = bake_detail::binTriangles(job);
  const int blocks = (height + bake_detail::kRowsPerBlock - 1) / bake_detail::kRowsPerBlock;
  runWithThreads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 1), [&](const tbb::blocked_range<int>& r) {
      for (int block = r.begin(); block != r.end(); ++block) {
        const int yBegin = block * bake_detail::kRowsPerBlock;
        const int yEnd = std::min(height, yBegin + bake_detail::kRowsPerBlock);
        for (std::uint32_t k = bins.start[static_cast<std::size_t>(block)];
             k < bins.start[static_cast<std::size_t>(block) + 1]; ++k) {
          const std::uint32_t t = bins.index[k];
          const std::array<Vec2d, 3> texel{
              uvToTexel(uvs[triangles[t][0]], udimTile, width, height),
              uvToTexel(uvs[triangles[t][1]], udimTile, width, height),
              uvToTexel(uvs[triangles[t][2]], udimTile, width, height)};
          RasterTriangle tri;
          if (!bake_detail::setupRasterTriangle(texel, width, height, tri)) continue;
          for (int y = std::max(tri.y0, yBegin); y <= std::min(tri.y1, yEnd - 1); ++y) {
            int first = 0, last = -1;
            bake_detail::rowSpan(tri, y, offsets, first, last);
            for (int x = first; x <= last; ++x) {
              bool inside = false;
              for (std::size_t j = 0; j < offsets.y.size() && !inside; ++j) {
                for (std::size_t i = 0; i < offsets.x.size() && !inside; ++i) {
                  const double px = x + offsets.x[i], py = y + offsets.y[j];
                  inside = tri.edge[0].inside(tri.edge[0](px, py)) &&
                           tri.edge[1].inside(tri.edge[1](px, py)) &&
                           tri.edge[2].inside(tri.edge[2](px, py));
                }
              }
              if (inside)
                face[static_cast<std::size_t>(y) * width + x] = cornerFace[triangles[t][0]];
            }
          }
        }
      }
    });
  });
  return face;
}

/// Rows per work item of the distance transform. Fixed, so ties between equally near faces
/// go the same way for any number of threads.
constexpr int kDistanceRows = 128;

/// The face of the nearest source texel (face ≠ kNoFace) of every texel less than @p reach
/// away along 8-connected paths of steps 1 and √2, and that distance (infinite beyond reach),
/// rows y up. Each block of kDistanceRows rows runs the two passes of a chamfer distance
/// transform (exact for this 3 × 3 mask) over itself and ⌈reach⌉ rows either side, which hold
/// every path shorter than reach; ties go to the first neighbour looked at.
void nearestFaces(std::vector<std::uint32_t>& face, std::vector<float>& distance, int width,
                  int height, double reach, int threads) {
  const int halo = static_cast<int>(std::ceil(reach)) + 1;
  const int blocks = (height + kDistanceRows - 1) / kDistanceRows;
  const std::vector<std::uint32_t> sources = face;  // read by every block
  const float diagonal = static_cast<float>(std::sqrt(2.0));
  runWithThreads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 1), [&](const tbb::blocked_range<int>& r) {
      std::vector<std::uint32_t> f;
      std::vector<float> d;
      for (int block = r.begin(); block != r.end(); ++block) {
        const int begin = block * kDistanceRows, end = std::min(height, begin + kDistanceRows);
        const int w0 = std::max(0, begin - halo), w1 = std::min(height, end + halo);
        const std::size_t offset = static_cast<std::size_t>(w0) * width;
        const std::size_t n = static_cast<std::size_t>(w1 - w0) * width;
        f.assign(sources.begin() + static_cast<std::ptrdiff_t>(offset),
                 sources.begin() + static_cast<std::ptrdiff_t>(offset + n));
        d.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
          d[i] = f[i] != kNoFace ? 0.0f : std::numeric_limits<float>::infinity();
        }
        const int rows = w1 - w0;
        auto relax = [&](std::size_t i, int nx, int ny, float step) {
          if (nx < 0 || ny < 0 || nx >= width || ny >= rows) return;
          const std::size_t m = static_cast<std::size_t>(ny) * width + nx;
          if (f[m] != kNoFace && d[m] + step < d[i]) {
            d[i] = d[m] + step;
            f[i] = f[m];
          }
        };
        for (int y = 0; y < rows; ++y) {  // forward: from the row below and the texel to the left
          for (int x = 0; x < width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * width + x;
            if (d[i] == 0) continue;
            relax(i, x - 1, y - 1, diagonal);
            relax(i, x, y - 1, 1);
            relax(i, x + 1, y - 1, diagonal);
            relax(i, x - 1, y, 1);
          }
        }
        for (int y = rows - 1; y >= 0; --y) {  // backward: from above and the right
          for (int x = width - 1; x >= 0; --x) {
            const std::size_t i = static_cast<std::size_t>(y) * width + x;
            if (d[i] == 0) continue;
            relax(i, x + 1, y + 1, diagonal);
            relax(i, x, y + 1, 1);
            relax(i, x - 1, y + 1, diagonal);
            relax(i, x + 1, y, 1);
          }
        }
        const std::size_t from = static_cast<std::size_t>(begin - w0) * width;
        const std::size_t count = static_cast<std::size_t>(end - begin) * width;
        const std::size_t to = static_cast<std::size_t>(begin) * width;
        for (std::size_t i = 0; i < count; ++i) {
          const bool near = d[from + i] < reach;
          face[to + i] = near ? f[from + i] : kNoFace;
          distance[to + i] = near ? d[from + i] : std::numeric_limits<float>::infinity();
        }
      }
    });
  });
}

/// The point of the segment [a, b] nearest @p p.
Point nearestOnSegment(Point p, Point a, Point b) {
  const Point ab = b - a;
  const double len2 = std::norm(ab);
  const double s = len2 > 0 ? ((p - a) * std::conj(ab)).real() / len2 : 0.0;
  if (s <= 0) return a;  // the vertices exactly, so ties between edges are exact
  if (s >= 1) return b;
  return a + s * ab;
}

/// Distance of @p p from the segment [a, b].
double segmentDistance(Point p, Point a, Point b) {
  return std::abs(p - nearestOnSegment(p, a, b));
}

/// Twice the signed area of (a, b, p): positive when p is left of a → b.
double cross(Point a, Point b, Point p) { return (std::conj(b - a) * (p - a)).imag(); }

}  // namespace

void adjacentFacesMargin(FloatImage& image, const Mesh& mesh, int uvSet, int udimTile, int samples,
                         int margin, int threads) {
  const int W = image.width, H = image.height, C = image.channels;
  if (margin <= 0 || W <= 0 || H <= 0 || !mesh.hasUvSet(static_cast<std::size_t>(uvSet))) return;
  const std::vector<std::array<std::uint32_t, 3>> triangles = loopTriangles(mesh);
  const std::vector<Vec2f>& uvs = mesh.uvSets[static_cast<std::size_t>(uvSet)].uvs;
  const std::vector<std::int64_t> across = oppositeCorners(mesh);
  const std::vector<std::uint32_t> cornerFace = cornerFaces(mesh.faceStart);
  // loopTriangles gives each face its k − 2 triangles in turn.
  std::vector<std::uint32_t> faceFirstTriangle(mesh.numFaces() + 1, 0);
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    faceFirstTriangle[f + 1] = faceFirstTriangle[f] + (mesh.faceSize(f) - 2);
  }
  auto covered = [&](int x, int y) {  // y up
    return image.coverage[static_cast<std::size_t>(H - 1 - y) * W + x] > 0;
  };

  // The face of the nearest covered texel of every texel within reach.
  std::vector<std::uint32_t> face =
      texelFaces(uvs, triangles, cornerFace, W, H, std::max(samples, 1), udimTile, threads);
  const double reach = margin + kReachBeyondMargin;
  const std::size_t texels = static_cast<std::size_t>(W) * H;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      // A sample inside but no coverage (an image not from this raster): not a source.
      if (!covered(x, y)) face[static_cast<std::size_t>(y) * W + x] = kNoFace;
    }
  }
  std::vector<float> distance(texels);
  nearestFaces(face, distance, W, H, reach, threads);
  // The margin: uncovered texels within reach, rows y up.
  std::vector<std::size_t> marginTexels;
  for (std::size_t i = 0; i < texels; ++i) {
    const int x = static_cast<int>(i % static_cast<std::size_t>(W));
    const int y = static_cast<int>(i / static_cast<std::size_t>(W));
    if (distance[i] > 0 && distance[i] < reach && !covered(x, y)) marginTexels.push_back(i);
  }
  distance = {};

  // Bilinear interpolation of the covered texels around texel-space point q (y up).
  auto sample = [&](Point q, float* out) {
    const double fx = q.real() - 0.5, fy = q.imag() - 0.5;
    const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
    const double ax = fx - x0, ay = fy - y0;
    std::array<const float*, 4> value{};
    std::array<double, 4> weight{};
    double total = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const int i = static_cast<int>(k & 1), j = static_cast<int>(k >> 1);
      const int x = x0 + i, y = y0 + j;
      if (x < 0 || y < 0 || x >= W || y >= H || !covered(x, y)) continue;
      const double w = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
      if (w <= 0) continue;
      value[k] = &image.pixels[(static_cast<std::size_t>(H - 1 - y) * W + x) * C];
      weight[k] = w;
      total += w;
    }
    if (total <= 0) return false;
    for (int c = 0; c < C; ++c) {
      double sum = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        if (value[k] != nullptr) sum += weight[k] * value[k][c];
      }
      out[c] = static_cast<float>(sum / total);
    }
    return true;
  };
  auto texelOf = [&](std::uint32_t corner) {
    const Vec2d p = uvToTexel(uvs[corner], udimTile, W, H);
    return Point(p.x, p.y);
  };

  auto inImage = [&](Point q) {
    return q.real() >= 0 && q.imag() >= 0 && q.real() < W && q.imag() < H;
  };
  // Face f's value at the point of its outline nearest p (read from the covered texels there).
  auto readOutline = [&](std::uint32_t f, Point p, float* out) {
    const std::uint32_t begin = mesh.faceStart[f], n = mesh.faceSize(f);
    Point nearest = texelOf(begin);
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t k = 0; k < n; ++k) {
      const Point q = nearestOnSegment(p, texelOf(begin + k), texelOf(begin + (k + 1) % n));
      if (std::abs(p - q) < best) {
        best = std::abs(p - q);
        nearest = q;
      }
    }
    return sample(nearest, out);  // (on the image's border, from the texels inside it)
  };
  // The value of the covered texel nearest texel (x, y) (y up): there is one within reach.
  const int searchRadius = static_cast<int>(std::ceil(reach)) + 1;
  auto readNearestCovered = [&](int x, int y, float* out) {
    int bestX = -1, bestY = -1;
    int best = std::numeric_limits<int>::max();
    for (int dy = -searchRadius; dy <= searchRadius; ++dy) {
      for (int dx = -searchRadius; dx <= searchRadius; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= W || ny >= H || !covered(nx, ny)) continue;
        if (dx * dx + dy * dy < best) {
          best = dx * dx + dy * dy;
          bestX = nx;
          bestY = ny;
        }
      }
    }
    if (bestX < 0) return false;
    std::copy_n(&image.pixels[(static_cast<std::size_t>(H - 1 - bestY) * W + bestX) * C], C, out);
    return true;
  };

  // Which side of the line a → b face f lies on (+1 left, −1 right, 0 unknown): the sign of
  // its UV area, taken as seen from that edge.
  auto faceSide = [&](std::uint32_t f, Point a, Point b) {
    const std::uint32_t begin = mesh.faceStart[f], n = mesh.faceSize(f);
    double sum = 0;
    for (std::uint32_t k = 0; k < n; ++k) sum += cross(a, b, texelOf(begin + k));
    return sum > 0 ? 1.0 : (sum < 0 ? -1.0 : 0.0);
  };
  // Whether p lies in one of face f's triangles (edges included).
  auto insideFace = [&](std::uint32_t f, Point p) {
    for (std::uint32_t t = faceFirstTriangle[f]; t < faceFirstTriangle[f + 1]; ++t) {
      const auto& c = triangles[t];
      const Point a = texelOf(c[0]), b = texelOf(c[1]), d = texelOf(c[2]);
      const double area = cross(a, b, d);
      if (area == 0) continue;
      const double s0 = cross(b, d, p) * area, s1 = cross(d, a, p) * area,
                   s2 = cross(a, b, p) * area;
      if (s0 >= 0 && s1 >= 0 && s2 >= 0) return true;
    }
    return false;
  };

  // Each margin texel, read from the covered image only (so the order does not matter).
  std::vector<float> values(marginTexels.size() * static_cast<std::size_t>(C));
  std::vector<std::uint8_t> written(marginTexels.size(), 0);
  runWithThreads(threads, [&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, marginTexels.size(), 1024),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t m = range.begin(); m != range.end(); ++m) {
            const std::size_t i = marginTexels[m];
            const int x = static_cast<int>(i % static_cast<std::size_t>(W));
            const int y = static_cast<int>(i / static_cast<std::size_t>(W));
            float* out = &values[m * static_cast<std::size_t>(C)];
            const Point start(x + 0.5, y + 0.5);
            Point p = start;
            std::uint32_t f = face[i];
            bool read = false;
            for (int step = 0; step <= kMaxFaceSteps; ++step) {
              const std::uint32_t begin = mesh.faceStart[f], n = mesh.faceSize(f);
              if (insideFace(f, p)) {  // read the image here
                read = inImage(p) && sample(p, out);
                break;
              }
              // The face's edge nearest p (the last in corner order on a tie).
              std::uint32_t edge = 0;
              double best = std::numeric_limits<double>::infinity();
              for (std::uint32_t k = 0; k < n; ++k) {
                const double d =
                    segmentDistance(p, texelOf(begin + k), texelOf(begin + (k + 1) % n));
                if (d <= best) {
                  best = d;
                  edge = k;
                }
              }
              const std::uint32_t ca = begin + edge, cb = begin + (edge + 1) % n;
              const std::int64_t other = across[ca];
              if (other < 0) {  // a boundary: no face continues p
                read = readOutline(f, p, out);
                break;
              }
              const std::uint32_t g = cornerFace[static_cast<std::size_t>(other)];
              const std::uint32_t gBegin = mesh.faceStart[g], gn = mesh.faceSize(g);
              // The corners of g on the edge's two vertices (g runs the edge either way).
              const std::uint32_t o = static_cast<std::uint32_t>(other);
              const std::uint32_t oNext = gBegin + (o - gBegin + 1) % gn;
              const bool sameWay = mesh.cornerVertex[o] == mesh.cornerVertex[ca];
              const std::uint32_t na = sameWay ? o : oNext, nb = sameWay ? oNext : o;
              const Point A = texelOf(ca), B = texelOf(cb), A2 = texelOf(na), B2 = texelOf(nb);
              if (!(A == A2 && B == B2)) {  // a seam: carry p over by the similarity A→A', B→B'
                if (A == B || A2 == B2) break;
                // p in the edge's frame: s along A → B (0 at A, 1 at B), r across it in texels.
                const Point w = (p - A) / (B - A);
                double r = w.imag() * std::abs(B - A);
                // f's side of the edge must land on the side g is not on: mirror when they agree.
                if (faceSide(f, A, B) * faceSide(g, A2, B2) > 0) r = -r;
                const Point mapped = A2 + Point(w.real(), r / std::abs(B2 - A2)) * (B2 - A2);
                p = mapped;
              }
              f = g;
            }
            // Nowhere to read (out of the image or the tile, too many seams, a degenerate
            // edge): the start face's value at the point of its outline nearest the texel.
            if (!read) read = readOutline(face[i], start, out);
            // A face with no covered texel near that point (a sliver): the nearest texel.
            if (!read) read = readNearestCovered(x, y, out);
            written[m] = read ? 1 : 0;
          }
        });
  });
  for (std::size_t m = 0; m < marginTexels.size(); ++m) {
    if (!written[m]) continue;
    const std::size_t i = marginTexels[m];
    const std::size_t x = i % static_cast<std::size_t>(W), y = i / static_cast<std::size_t>(W);
    std::copy_n(&values[m * static_cast<std::size_t>(C)], C,
                &image.pixels[((static_cast<std::size_t>(H) - 1 - y) * W + x) *
                              static_cast<std::size_t>(C)]);
  }
}

}  // namespace sgbake
