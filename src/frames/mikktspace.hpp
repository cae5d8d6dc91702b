/// @file mikktspace.hpp
/// @brief MikkTSpace (Mikkelsen, "Simulation of Wrinkled Surfaces Revisited", 2008), written from
/// the algorithm's description, over any mesh through a small adapter.
///
/// The algorithm, in the order the implementation runs it:
///  1. The input is viewed as flat per-corner arrays ("slots") of faces (triangles or quads), with
///     positions shared through per-slot vertex ids; a mesh of triangles and quads is read in
///     place, other meshes are gathered first.
///  2. Slots are welded: two slots are the same vertex only when position, normal and UV are
///     exactly equal (float ==, so -0 equals +0). When vertices are shared by several slots,
///     positions are compared once per vertex and slots only against the slots of vertices at
///     the same position; the result is the same as comparing all slots.
///  3. Quads are split on the shorter UV diagonal (ties: the shorter position diagonal, then 0-2).
///  4. Triangles with two coincident positions are degenerate: they take no part and inherit their
///     frames afterwards from welded neighbours (or from the other half of their quad).
///  5. Per triangle: the UV-derivative directions dP/ds, dP/dt (normalized, sign-corrected) and
///     their magnitudes; a triangle with zero UV area or zero derivative is "group with any".
///     Both halves of a healthy quad are forced to one orientation (that of the larger UV area).
///     Per triangle corner: the derivatives projected into the tangent plane of the corner's
///     normal, and the interior angle in that plane.
///  6. Around each welded vertex, triangles connected across shared edges and having the same
///     orientation (sign of their UV area) form a group; "group with any" triangles join the first
///     group that reaches them and adopt its orientation. Without such triangles the groups do
///     not depend on the order they are found in, and every vertex finds its own in parallel;
///     with them, one depth-first walk in triangle order finds all groups.
///  7. Each group's tangent is the angle-weighted average of its triangles' projected dP/ds
///     (sub-groups split only on opposite directions, i.e. the algorithm's default 180 degree
///     threshold).
///  8. A corner shared by both halves of a quad averages the two frames.
///
/// Precision: the algorithm runs in float, as MikkTSpace implementations do, so that every
/// comparison that picks a branch (the quad diagonal, the sign of a UV area, exact welding) makes
/// the same decision as Blender's. The result does not depend on the number of threads.
#pragma once

#include <concepts>
#include <cstdint>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "sgbake/core/vec.hpp"

namespace sgbake::mikk {

/// @brief What the algorithm reads from a mesh: faces of 3 or 4 corners with per-corner data.
template <class A>
concept Adapter = requires(const A& a, int f, int v) {
  { a.numFaces() } -> std::convertible_to<int>;
  { a.faceSize(f) } -> std::convertible_to<int>;  ///< 3 or 4
  { a.position(f, v) } -> std::convertible_to<Vec3f>;
  { a.normal(f, v) } -> std::convertible_to<Vec3f>;  ///< unit
  { a.uv(f, v) } -> std::convertible_to<Vec2f>;
};

/// @brief An adapter that also names the mesh vertex of each corner, with
/// `position(f, v)` equal to `vertexPosition(vertex(f, v))`. Optional: it makes welding cheaper.
template <class A>
concept VertexAdapter = Adapter<A> && requires(const A& a, int f, int v, std::uint32_t u) {
  { a.numVertices() } -> std::convertible_to<std::uint32_t>;
  { a.vertex(f, v) } -> std::convertible_to<std::uint32_t>;  ///< < numVertices()
  { a.vertexPosition(u) } -> std::convertible_to<Vec3f>;
};

/// @brief The algorithm's input as flat arrays, viewed, not owned: faces of 3 or 4 corners, one
/// "slot" per face corner, positions shared through per-slot vertex ids.
struct Input {
  std::span<const std::uint32_t> faceStart;  ///< #faces+1, face f owns slots [faceStart[f], faceStart[f+1])
  std::span<const std::uint32_t> vertex;     ///< #slots: the vertex of each slot
  std::span<const Vec3f> position;           ///< #vertices
  std::span<const Vec3f> normal;             ///< #slots, unit
  std::span<const Vec2f> uv;                 ///< #slots

  std::size_t numSlots() const { return vertex.size(); }
};

/// @brief Where the algorithm writes, per slot: the unit tangent and the bitangent sign (+1 when
/// the frame preserves orientation, else -1). Both #slots long.
struct Output {
  std::span<Vec3f> tangent;
  std::span<float> sign;
};

/// @brief Runs the algorithm, on the calling thread's TBB arena. Faces must have 3 or 4 corners.
void generate(const Input& input, const Output& output);

/// @brief Input gathered from an adapter into arrays of its own.
struct GatheredInput {
  std::vector<std::uint32_t> faceStart{0}, vertex;
  std::vector<Vec3f> position, normal;
  std::vector<Vec2f> uv;

  Input view() const { return {faceStart, vertex, position, normal, uv}; }
};

/// @brief Gathers an adapter's faces (faces of another size than 3 or 4 are skipped). Without
/// vertex ids, each slot is a vertex of its own. The adapter is read from several threads at once.
template <Adapter A>
GatheredInput gather(const A& adapter) {
  GatheredInput in;
  const int nf = adapter.numFaces();
  in.faceStart.resize(static_cast<std::size_t>(nf) + 1);
  in.faceStart[0] = 0;
  for (int f = 0; f < nf; ++f) {
    const int n = adapter.faceSize(f);
    const bool supported = n == 3 || n == 4;
    in.faceStart[f + 1] = in.faceStart[f] + static_cast<std::uint32_t>(supported ? n : 0);
  }
  const std::size_t slots = in.faceStart.back();
  in.vertex.resize(slots);
  in.normal.resize(slots);
  in.uv.resize(slots);
  constexpr bool kHasVertices = VertexAdapter<A>;
  if constexpr (kHasVertices) {
    in.position.resize(adapter.numVertices());
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, static_cast<std::uint32_t>(in.position.size()), 4096),
                      [&](const tbb::blocked_range<std::uint32_t>& r) {
                        for (std::uint32_t u = r.begin(); u != r.end(); ++u) in.position[u] = adapter.vertexPosition(u);
                      });
  } else {
    in.position.resize(slots);
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, nf, 1024), [&](const tbb::blocked_range<int>& r) {
    for (int f = r.begin(); f != r.end(); ++f) {
      const std::uint32_t s0 = in.faceStart[static_cast<std::size_t>(f)];
      const int n = static_cast<int>(in.faceStart[static_cast<std::size_t>(f) + 1] - s0);
      for (int v = 0; v < n; ++v) {
        if constexpr (kHasVertices) {
          in.vertex[s0 + v] = static_cast<std::uint32_t>(adapter.vertex(f, v));
        } else {
          in.vertex[s0 + v] = s0 + static_cast<std::uint32_t>(v);
          in.position[s0 + v] = adapter.position(f, v);
        }
        in.normal[s0 + v] = adapter.normal(f, v);
        in.uv[s0 + v] = adapter.uv(f, v);
      }
    }
  });
  return in;
}

}  // namespace sgbake::mikk
