/// @file limit_surface.hpp
/// @brief The exact Catmull-Clark limit surface of a mesh and of its UVs, evaluated anywhere on a
/// face with OpenSubdiv's Bfr: what a scene's "subdivision": {"level": "limit"} bakes from.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/subdiv/subdivide.hpp"

namespace sgbake {

/// @brief The level of the tessellation a limit-surface bake rasterizes (to find which texels a
/// face covers, and where to start looking for each sample's point): Newton's method then
/// starts within a few thousandths of a face of its answer.
inline constexpr int kLimitTessellationLevel = 3;

/// @brief The limit surface and its UV sets at one point, with first derivatives along the
/// normalized coordinates (s, t) ∈ [0,1]² of the (sub-)face (see SurfaceParameters).
struct LimitPoint {
  static constexpr int kMaxUvSets = 8;  ///< UV sets evaluated (further ones are not)
  Vec3d position, dPds, dPdt;
  int numUvSets = 0;
  std::array<Vec2d, kMaxUvSets> uv{}, dUVds{}, dUVdt{};
};

/// @brief The limit surface of a coarse mesh under Blender's subdivision options (the same
/// topology, UV welding and options as subdivideMesh, so that subdivideMesh's vertices and UVs
/// are this surface's values at their grid points). Immutable; evaluate through an Evaluator
/// per thread.
class LimitSurface {
 public:
  /// @return kBadInput naming coarse.source as subdivideMesh reports it (a face using a vertex
  ///         twice, a crease that does not fit the mesh, a topology OpenSubdiv rejects)
  static Result<LimitSurface> create(const Mesh& coarse, const SubdivisionOptions& options);

  LimitSurface(LimitSurface&&) noexcept;
  LimitSurface& operator=(LimitSurface&&) noexcept;
  ~LimitSurface();

  std::size_t numFaces() const;
  int numUvSets() const;

  /// @brief Evaluates one coarse face at a time and keeps its patch points, so that the points
  /// of one face cost one Bfr set-up. Not thread-safe: one per thread.
  class Evaluator {
   public:
    explicit Evaluator(const LimitSurface& surface);
    Evaluator(Evaluator&&) noexcept;
    Evaluator& operator=(Evaluator&&) noexcept;
    ~Evaluator();

    /// @brief The surface at (s, t) of sub-face @p subFace of coarse face @p face.
    /// @return false when the face or sub-face does not exist (out is then unchanged)
    bool evaluate(std::uint32_t face, std::uint32_t subFace, Vec2d st, LimitPoint& out);

    /// @brief The point of the sub-face whose UV set @p uvSet is @p target: Newton's method on
    /// the UVs from @p start, (s, t) kept in [0,1]², until the UV is within 1e-12 of the
    /// target's size or 8 steps. @p out is the surface there.
    /// @return false as evaluate(), or when @p uvSet does not exist
    bool locate(std::uint32_t face, std::uint32_t subFace, Vec2d start, int uvSet, Vec2d target,
                LimitPoint& out);

   private:
    struct State;
    std::unique_ptr<State> state_;
  };

 private:
  struct Data;
  explicit LimitSurface(std::unique_ptr<Data> data);
  std::unique_ptr<Data> data_;
};

/// @brief A limit surface together with the mesh a bake rasterizes to find it: what bakes and
/// conversions from the limit surface read (BakeInput::limit, ConvertSettings::limit).
struct LimitTessellation {
  LimitSurface surface;
  Mesh mesh;                     ///< subdivideMesh of the coarse mesh at kLimitTessellationLevel
  SurfaceParameters parameters;  ///< where mesh's corners lie on surface
};

/// @brief The limit surface of @p coarse under @p options (their level is ignored) and its
/// tessellation at kLimitTessellationLevel.
/// @return the errors of LimitSurface::create and subdivideMesh
Result<LimitTessellation> tessellateLimitSurface(const Mesh& coarse,
                                                 const SubdivisionOptions& options);

/// @brief Whether @p mesh is a tessellation of @p surface with @p parameters (all quads, face f
/// owning corners 4f … 4f+3, one parameter per face and corner, every face on a face of the
/// surface): what a bake or conversion from the limit surface checks before it reads them.
bool isTessellationOf(const Mesh& mesh, const LimitSurface& surface,
                      const SurfaceParameters& parameters);

}  // namespace sgbake
