/// @file convert.hpp
/// @brief Re-expressing a baked normal map between object space and tangent space with Blender's
/// per-texel frame (bake.hpp, "Per-texel frame"), texel by texel.
#pragma once

#include <string_view>

#include "sgbake/bake/bake.hpp"
#include "sgbake/core/result.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/surface_gradient.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/subdiv/limit_surface.hpp"

namespace sgbake {

/// @brief The space a normal map's colours are expressed in.
enum class NormalSpace {
  kObject,   ///< ("object") the object's local frame
  kTangent,  ///< ("tangent") MikkTSpace per texel: R = +T, G = +B (OpenGL) or −B (DirectX), B = +N
};

/// @brief Parses "object" or "tangent"; kBadInput names the unknown space.
Result<NormalSpace> parseNormalSpace(std::string_view name);
/// @brief "object" or "tangent".
std::string_view normalSpaceName(NormalSpace space);

/// @brief How convertNormalMap places the mesh in the image.
struct ConvertSettings {
  int uvSet = 0;        ///< UV set that places the mesh in the image
  int udimTile = 1001;  ///< which UDIM tile the image is
  /// Green convention of the tangent-space side (the input when converting from tangent space,
  /// the output when converting to it).
  NormalMapGreen green = NormalMapGreen::kOpenGL;
  /// Channels of the input and of the output image, as BakeSettings::swizzle (Blender's bake
  /// Swizzle; on the tangent-space side G is negated after it for a DirectX green). The input's
  /// must name each axis once. Texels outside the UV islands keep the input's values, channels
  /// as they are.
  NormalSwizzle inputSwizzle = kIdentitySwizzle;
  NormalSwizzle outputSwizzle = kIdentitySwizzle;
  int samples = 1;  ///< N×N frames per texel, results averaged (encoded), as bakeMap
  int threads = 0;  ///< 0 = all cores; the result does not depend on it
  /// Optional, as BakeInput::limit: the mesh is the tessellation of this limit surface
  /// (tessellateLimitSurface), and every sample is converted with the frame of the exact limit
  /// surface at the point whose UV is the sample's (T = ∂P/∂u of UV set 0 made orthogonal to
  /// the normal ∂P/∂s × ∂P/∂t; sign from ∂P/∂v), the frame a limit bake uses. Both must outlive
  /// the conversion.
  const LimitSurface* limit = nullptr;
  const SurfaceParameters* limitParameters = nullptr;
  /// Optional: the object's placement in the world (BakeInput::transform), whose object-space
  /// side is then the map Blender bakes for the placed object. Blender's baker brings the world
  /// normal n_w back to object space as a direction for object-space maps (M^{-1} n_w) and as a
  /// normal for tangent-space maps (M^T n_w), so a Blender object-space texel n stands for the
  /// object normal M^T M n (object → tangent), and a tangent-space one decoded to n_o is written
  /// as M^{-1} M^{-T} n_o (tangent → object); both normalized. Must outlive the conversion.
  const ObjectTransform* transform = nullptr;
};

/// @brief Converts the normal map @p input from space @p from to space @p to.
///
/// For every texel a triangle covers (bakeMap's raster and edge rule), the texel's colour c is
/// decoded as n = 2c − 1 (G negated for DirectX on the tangent side) and, at each covered
/// sample, re-expressed in the per-texel frame (T, B = sign·N×T, N interpolated as Blender's
/// baker does):
///  - object → tangent: normalize(inverse([T B N]) · n) (the inverse, not the transpose), the
///    flat (0, 0, 1) where the frame is degenerate;
///  - tangent → object: normalize(x·T + y·B + z·N);
///  - same space: normalize(n) (a renormalization pass);
/// then encoded n/2 + 0.5 and averaged over the texel's covered samples. A zero input normal
/// converts to the flat normal of the target space. Texels no triangle covers keep the input's
/// values; channels after the first three are copied unchanged. The output's coverage is the
/// raster's (the input's coverage is not read).
///
/// @param[in] tangents MikkTSpace frames per corner of UV set 0 (see BakeInput::tangents); empty
///            with settings.limit: the limit surface's own frames
/// @param[in] input    W×H image with ≥ 3 channels, rows top first; it defines the output size
/// @return W×H image with input.channels channels; kBadInput when the input is empty or has fewer
///         than 3 channels, pixel storage does not match its size, the mesh has no UV set
///         settings.uvSet, the tangents do not match the mesh, a setting is out of range, or
///         the mesh is not a tessellation of settings.limit.
Result<FloatImage> convertNormalMap(const Mesh& mesh, const CornerTangents& tangents,
                                    const FloatImage& input, NormalSpace from, NormalSpace to,
                                    const ConvertSettings& settings = {});

/// @brief convertNormalMap band by band, without holding the output image: the rows are
/// converted in bands of kBakeBandRows rows from the top of the image down into a ring of
/// bakeRingRows(height, 0) reused rows, each starting from the input's rows, and @p sink is called
/// after each band with that band's rows (as bakeMapRows calls it with keepRows 0: while the
/// next band is converted, one call at a time, in order). Every value is bit for bit the one
/// convertNormalMap gives; an error from @p sink stops the conversion and is returned.
/// @return the errors of convertNormalMap, or kBadInput when @p sink is empty
Status convertNormalMapRows(const Mesh& mesh, const CornerTangents& tangents,
                            const FloatImage& input, NormalSpace from, NormalSpace to,
                            const ConvertSettings& settings, const BakedRowsSink& sink);

}  // namespace sgbake
