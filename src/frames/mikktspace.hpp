/// @file mikktspace.hpp
/// @brief MikkTSpace (Mikkelsen, "Simulation of Wrinkled Surfaces Revisited", 2008), written from
/// the algorithm's description, over any mesh through a small adapter.
///
/// The algorithm, in the order the implementation runs it:
///  1. Faces (triangles or quads) are gathered into flat per-corner arrays ("slots").
///  2. Slots are welded: two slots are the same vertex only when position, normal and UV are
///     exactly equal (float ==, so -0 equals +0). When the adapter names each corner's mesh
///     vertex, positions are compared once per vertex and slots only against the slots of
///     vertices at the same position; the result is the same as comparing all slots.
///  3. Quads are split on the shorter UV diagonal (ties: the shorter position diagonal, then 0-2).
///  4. Triangles with two coincident positions are degenerate: they take no part and inherit their
///     frames afterwards from welded neighbours (or from the other half of their quad).
///  5. Per triangle: the UV-derivative directions dP/ds, dP/dt (normalized, sign-corrected) and
///     their magnitudes; a triangle with zero UV area or zero derivative is "group with any".
///     Both halves of a healthy quad are forced to one orientation (that of the larger UV area).
///  6. Around each welded vertex, triangles connected across shared edges and having the same
///     orientation (sign of their UV area) form a group; "group with any" triangles join the first
///     group that reaches them and adopt its orientation.
///  7. Each group's tangent is the angle-weighted average of its triangles' dP/ds projected into
///     the vertex's tangent plane (sub-groups split only on opposite directions, i.e. the
///     algorithm's default 180 degree threshold).
///  8. A corner shared by both halves of a quad averages the two frames.
///
/// Precision: the algorithm runs in float, as MikkTSpace implementations do, so that every
/// comparison that picks a branch (the quad diagonal, the sign of a UV area, exact welding) makes
/// the same decision as Blender's. The result does not depend on the number of threads.
#pragma once

#include <concepts>
#include <cstdint>
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
/// `position(f, v)` a function of `vertex(f, v)` alone. Optional: it only makes welding cheaper.
template <class A>
concept VertexAdapter = Adapter<A> && requires(const A& a, int f, int v) {
  { a.numVertices() } -> std::convertible_to<std::uint32_t>;
  { a.vertex(f, v) } -> std::convertible_to<std::uint32_t>;  ///< < numVertices()
};

/// @brief The algorithm's input as flat per-slot arrays (one slot per face corner).
struct Input {
  std::vector<std::uint32_t> faceStart{0};  ///< #faces+1, face f owns slots [faceStart[f], faceStart[f+1])
  std::vector<Vec3f> position;              ///< #slots
  std::vector<Vec3f> normal;                ///< #slots, unit
  std::vector<Vec2f> uv;                    ///< #slots
  /// #slots, or empty: a vertex id per slot, slots with the same id having bit-identical positions
  std::vector<std::uint32_t> vertex;
  std::uint32_t numVertices = 0;  ///< ids in `vertex` are below this
};

/// @brief Per slot: the unit tangent and whether the frame preserves orientation (sign +1).
struct Output {
  std::vector<Vec3f> tangent;                      ///< #slots
  std::vector<std::uint8_t> orientationPreserving;  ///< #slots, 1 → sign +1, 0 → sign -1
};

/// @brief Runs the algorithm on gathered input, on the calling thread's TBB arena.
void generate(const Input& input, Output& output);

/// @brief Gathers an adapter's faces into flat input (faces of another size are skipped).
/// The adapter is read from several threads at once.
template <Adapter A>
Input gather(const A& adapter) {
  Input in;
  const int nf = adapter.numFaces();
  in.faceStart.resize(static_cast<std::size_t>(nf) + 1);
  in.faceStart[0] = 0;
  for (int f = 0; f < nf; ++f) {
    const int n = adapter.faceSize(f);
    const bool supported = n == 3 || n == 4;
    in.faceStart[f + 1] = in.faceStart[f] + static_cast<std::uint32_t>(supported ? n : 0);
  }
  const std::size_t slots = in.faceStart.back();
  in.position.resize(slots);
  in.normal.resize(slots);
  in.uv.resize(slots);
  constexpr bool kHasVertices = VertexAdapter<A>;
  if constexpr (kHasVertices) {
    in.vertex.resize(slots);
    in.numVertices = static_cast<std::uint32_t>(adapter.numVertices());
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, nf, 1024), [&](const tbb::blocked_range<int>& r) {
    for (int f = r.begin(); f != r.end(); ++f) {
      const std::uint32_t s0 = in.faceStart[static_cast<std::size_t>(f)];
      const int n = static_cast<int>(in.faceStart[static_cast<std::size_t>(f) + 1] - s0);
      for (int v = 0; v < n; ++v) {
        in.position[s0 + v] = adapter.position(f, v);
        in.normal[s0 + v] = adapter.normal(f, v);
        in.uv[s0 + v] = adapter.uv(f, v);
        if constexpr (kHasVertices) in.vertex[s0 + v] = static_cast<std::uint32_t>(adapter.vertex(f, v));
      }
    }
  });
  return in;
}

}  // namespace sgbake::mikk
