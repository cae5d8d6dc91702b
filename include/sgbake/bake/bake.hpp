/// @file bake.hpp
/// @brief Baking maps in UV space: the texel raster, per-texel frames as Blender's baker builds
/// them, the map kinds, and edge padding. Pure in-memory; writing files is in
/// bake/image_output.hpp.
///
/// ## Triangles (Blender's "looptris")
/// Faces are rasterized as the triangles Blender 3.4 tessellates them into (loopTriangles()):
///  - a triangle as it is;
///  - a quad (c0, c1, c2, c3) as (c0, c1, c2), (c0, c2, c3), **unless** c1 and c3 lie on the same
///    side of the diagonal c0–c2, i.e. `⟨(P1−P0)×(P2−P0), (P3−P0)×(P2−P0)⟩ > 0` in float (a quad
///    reflex at c1 or c3, or a bow-tie), where it is (c0, c1, c3), (c1, c2, c3). Ties (c1 or c3 on
///    the diagonal, degenerate quads) keep the c0–c2 split. Verified with Blender 3.4.1 headless
///    (`Mesh.calc_loop_triangles()` on convex, reflex-at-0/1/2/3, collinear, twisted and bow-tie
///    quads): identical triangles and corner order in every case.
///  - an n-gon by triangulatePolygon, which reproduces Blender's polyfill (ear clipping in the
///    plane of the Newell normal with its sweep order; e.g. a regular pentagon gives (4,0,1),
///    (1,2,3), (1,3,4)), its decisions taken in float as Blender takes them: the same
///    triangles, order and corner order as Blender 3.4.1 on 4,800 random test polygons,
///    near-ties and coincident corners included.
///
/// ## Texels and coverage
/// Texel (x, y) of a W×H bake of UDIM tile t, y counted **up** from the bottom, has its centre at
/// `u = u0 + (x + 0.5)/W`, `v = v0 + (y + 0.5)/H` with `(u0, v0) = ((t−1001) % 10, (t−1001) / 10)`;
/// it is stored in row `H − 1 − y` of FloatImage (rows top first, as files store them).
///
/// **Where a texel is sampled.** As Blender's baker samples it: at its centre moved by
/// kBakeSampleNudge = (0.001, 0.002) texel (Blender shifts the UVs by −(0.5 + 0.001,
/// 0.5 + 0.002) texel and samples whole-texel points, so that centres on pixel-aligned edges pick
/// one triangle). The nudged point both picks the triangle and is shaded: a centre less than
/// 0.002 texel from an edge goes to the triangle it is nudged into (between two materials that
/// changes the texel: 17 texels of a 256² two-material Suzanne, 5–33° off Cycles when the
/// centre picked), and shading the unmoved centre doubled the error of normal-map bakes against
/// Blender's (median 0.0034° against 0.0017°). bakeSampleUv() gives the point. With N×N
/// supersampling sample (i, j) is the point `(x + (i+0.5)/N, y + (j+0.5)/N)` of the texel grid,
/// nudged the same way. A sample belongs to the triangle containing it; where UV islands
/// overlap, to the last such triangle (in loopTriangles order), as a pixel does in Blender's
/// baker (measured: two quads with the same UVs bake to the second one's normal).
///
/// **Edge rule.** A sample exactly on an edge or vertex (rare once nudged) is treated as
/// displaced further by an infinitesimal ε·(1, 2) + ε²·(1, 0) texels. Edge functions are
/// evaluated with the two endpoints in a canonical order, so the two triangles sharing an edge
/// compute the same value with opposite signs: every sample of a watertight UV region is claimed
/// by exactly one triangle (no double counting, no gaps), whatever the rounding. Triangles with
/// zero UV area cover nothing. Triangles reaching outside the tile are clipped to it.
///
/// **Supersampling.** A texel's value is the plain average (box filter) of the values of its
/// covered samples, as stored: for normal maps the average of the *encoded* colours, i.e.
/// encode(mean of the unit normals), not renormalized. Its coverage is the fraction of its N²
/// samples that are covered. Texels no sample covers get the map's background and coverage 0.
///
/// ## Per-texel frame (CONVENTIONS.md, "Per-texel frame in Blender's baker")
/// At a sample with barycentrics (b0, b1, b2) in triangle (c0, c1, c2):
/// `T = Σ bi·Ti` (unit MikkTSpace corner tangents, not renormalized), `N = Σ bi·Ni` (corner
/// normals; flat faces carry their face normal at every corner), `sign = Σ bi·si < 0 ? −1 : +1`,
/// `B = sign·N×T`, `P = Σ bi·Pi`, UVs interpolated, and ∂P/∂u, ∂P/∂v the triangle's constant
/// derivatives. The gradient engine sees a SurfacePoint with normal = normalize(N) and tangent
/// frame (T, Σ bi·si). Tangent-space output is `normalize(inverse([T B N]) · N')`.
/// **Flat faces** (Mesh::faceFlat, OBJ `s 0`) are shaded as Cycles shades them: without Auto
/// Smooth (Mesh::autoSmooth) the shading normal (the SurfacePoint's, the unperturbed normal of
/// object-space maps, the base of the bump) is the triangle's own geometric normal, so a
/// non-planar flat quad shows two normals; with it, the corner normals as on smooth faces. The
/// frame's N on a flat face is its polygon normal (Newell) either way, as Blender's object →
/// tangent conversion uses. Checked on flat Suzanne (BlenderBakeOracle case suzanne_flat).
///
/// ## Threads
/// The image is cut into blocks of rows processed in parallel (TBB); each texel is written by one
/// task and its samples are summed in a fixed order, so 1 and N threads give identical bits.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/surface_gradient.hpp"
#include "sgbake/gradient/world_shading.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/subdiv/limit_surface.hpp"

namespace sgbake {

/// @brief The maps sgbake bakes (CLI names in parentheses).
enum class MapKind {
  kTangentNormal,    ///< ("tangent-normal") RGB = n_ts/2 + 0.5, Blender's per-texel frame
  kObjectNormal,     ///< ("object-normal") RGB = n_obj/2 + 0.5
  kHeight,           ///< ("height") R = Σ weight·mask·scale·h of the height layers (UV, volume, planar, triplanar)
  kDerivative,       ///< ("derivative") RG = (∂h/∂u, ∂h/∂v) = (⟨Γ,∂P/∂u⟩, ⟨Γ,∂P/∂v⟩) of the bake's UV set (seed 001 eq. 32)
  kSurfaceGradient,  ///< ("surface-gradient") RGB = object-space Γ, raw (not encoded)
  kTangent,          ///< ("tangent") RGB = normalize(T)/2 + 0.5 (T interpolated, unnormalized)
  kBitangent,        ///< ("bitangent") RGB = normalize(sign·N×T)/2 + 0.5
  kMask,             ///< ("mask") R = coverage in [0, 1] (fraction of samples inside a triangle)
};

/// @brief One channel of a baked normal map: which component of the normal it stores (0 x,
/// 1 y, 2 z) and whether negated. Blender's bake Swizzle setting (+X, +Y, +Z, −X, −Y, −Z per
/// channel; normal_r, normal_g, normal_b of bpy.types.BakeSettings).
struct SwizzleAxis {
  int axis = 0;
  bool negate = false;
  friend bool operator==(const SwizzleAxis&, const SwizzleAxis&) = default;
};
/// @brief R, G, B of a baked normal map: channel c stores sign·n[axis]/2 + 0.5, as Blender's
/// baker encodes it in every space.
using NormalSwizzle = std::array<SwizzleAxis, 3>;
/// @brief +X +Y +Z: the normal's x, y, z in R, G, B (Blender's default).
inline constexpr NormalSwizzle kIdentitySwizzle = {{{0, false}, {1, false}, {2, false}}};

/// @brief +X-Y+Z: a DirectX green.
inline constexpr NormalSwizzle kDirectXSwizzle = {{{0, false}, {1, true}, {2, false}}};
/// @brief The channels a tangent-space normal map stores: @p swizzle, then its G negated for a
/// DirectX @p green (the same on an object-space map, whose green is OpenGL).
inline NormalSwizzle storedChannels(NormalSwizzle swizzle, NormalMapGreen green) {
  if (green == NormalMapGreen::kDirectX) swizzle[1].negate = !swizzle[1].negate;
  return swizzle;
}
/// @brief What a normal-map file says of its channels @p stored (storedChannels): in a
/// tangent-space map whose G holds ±y, sgbake:green ("opengl" or "directx"); for any swizzle
/// other than +X+Y+Z and a tangent-space map's DirectX green, sgbake:swizzle ("-Z+X-Y"). So
/// the same channels said as a green or as a swizzle make the same file.
std::vector<std::pair<std::string, std::string>> normalChannelAttributes(
    const NormalSwizzle& stored, bool tangentSpace);

/// @brief Parses a swizzle written as three signed axes, "+X-Y+Z" (case-insensitive; commas or
/// spaces between them allowed), or Blender's names "POS_X,NEG_Y,POS_Z". kBadInput says what is
/// wrong.
Result<NormalSwizzle> parseNormalSwizzle(std::string_view text);
/// @brief "+X-Y+Z": the form parseNormalSwizzle reads and sgbake writes.
std::string normalSwizzleName(const NormalSwizzle& swizzle);

/// @brief Parses a CLI/scene map name ("tangent-normal", ...); kBadInput names the unknown map.
Result<MapKind> parseMapKind(std::string_view name);
/// @brief The CLI/scene name of @p kind.
std::string_view mapKindName(MapKind kind);
/// @brief Channels the map stores (1, 2 or 3).
int mapChannels(MapKind kind);
/// @brief Whether the map needs MikkTSpace tangent frames (besides what its layers need):
/// kTangentNormal, kTangent, kBitangent.
bool mapNeedsTangents(MapKind kind);

/// @brief Whether the map's values are signed and unbounded (derivative, surface-gradient): an
/// integer file stores them remapped by a range (SceneOutput::range), not clamped to [0, 1].
bool isSignedMap(MapKind kind);

/// @brief A float image in memory, rows top first (as files store them), channels interleaved.
///
/// Row r holds the texels with y = H − 1 − r (y counted up from the bottom, v up).
struct FloatImage {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;    ///< width·height·channels
  std::vector<float> coverage;  ///< width·height, fraction of the texel's samples inside the mesh
  float& at(int x, int row, int c) { return pixels[(static_cast<std::size_t>(row) * width + x) * channels + c]; }
  float at(int x, int row, int c) const { return pixels[(static_cast<std::size_t>(row) * width + x) * channels + c]; }
};

/// @brief View of consecutive rows [begin, end) of an image (rows top first), stored in a ring
/// of `ringRows` rows: file row r lives in slot r % ringRows. A whole FloatImage is the view
/// with ringRows == height (of()); bakeMapRows hands out views of its reused band ring.
/// @tparam T `const float` (ImageRows) or `float` (MutableImageRows)
template <class T>
struct BasicImageRows {
  int width = 0, height = 0, channels = 0;  ///< of the whole image
  int begin = 0, end = 0;                   ///< the rows that may be read
  int ringRows = 0;                         ///< rows of storage (≥ end − begin)
  T* pixels = nullptr;                      ///< ringRows·width·channels
  T* coverage = nullptr;                    ///< ringRows·width

  /// @brief The view of all rows of @p image.
  template <class Image>
  static BasicImageRows of(Image& image) {
    return {image.width, image.height, image.channels, 0, image.height, image.height,
            image.pixels.data(), image.coverage.data()};
  }
  /// A mutable view is also a read-only one.
  operator BasicImageRows<const float>() const {
    return {width, height, channels, begin, end, ringRows, pixels, coverage};
  }
  /// The width·channels values of row @p row (begin ≤ row < end).
  T* pixelRow(int row) const { return pixels + slot(row) * rowValues(); }
  /// The width coverage values of row @p row (begin ≤ row < end).
  T* coverageRow(int row) const { return coverage + slot(row) * static_cast<std::size_t>(width); }
  /// Rows from @p row on (≤ end) that follow each other in memory: up to the ring's wrap.
  int contiguousRows(int row) const { return std::min(end, row - row % ringRows + ringRows) - row; }
  std::size_t rowValues() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(channels); }

 private:
  std::size_t slot(int row) const { return static_cast<std::size_t>(row % ringRows); }
};
using ImageRows = BasicImageRows<const float>;
using MutableImageRows = BasicImageRows<float>;

/// First UDIM tile number: the tile [0,1)².
inline constexpr int kFirstUdimTile = 1001;
/// Last UDIM tile number Blender accepts (u tile 9, v tile 99).
inline constexpr int kLastUdimTile = 2000;
/// UDIM tile @p tile in words for messages: "the 0-1 UV square" (1001) or "UDIM tile N".
inline std::string describeUdimTile(int tile) {
  return tile == kFirstUdimTile ? "the 0-1 UV square" : "UDIM tile " + std::to_string(tile);
}
/// Largest N of N×N supersampling.
inline constexpr int kMaxBakeSamples = 16;
/// How far from the point it stands for a bake samples (texels, y up), as Blender's baker does
/// (see "Where a texel is sampled" above).
inline constexpr Vec2d kBakeSampleNudge{0.001, 0.002};

/// @brief The UV at which a width × height bake of UDIM tile @p udimTile samples the point
/// (tx, ty) of its texel grid (texels, y up from the tile's lower-left corner; texel (x, y) is
/// [x, x + 1) × [y, y + 1), its centre (x + 0.5, y + 0.5)): the point moved by kBakeSampleNudge.
inline Vec2d bakeSampleUv(double tx, double ty, int width, int height,
                          int udimTile = kFirstUdimTile) {
  const int index = udimTile - kFirstUdimTile;
  return {index % 10 + (tx + kBakeSampleNudge.x) / width,
          index / 10 + (ty + kBakeSampleNudge.y) / height};
}
/// Largest width or height of a bake, texels.
inline constexpr int kMaxBakeSide = 65536;

/// @brief What to bake.
struct BakeSettings {
  MapKind map = MapKind::kTangentNormal;
  int width = 1024, height = 1024;  ///< texels, 1 … kMaxBakeSide
  int samples = 1;        ///< N: N×N samples per texel (supersampling), averaged; 1 … kMaxBakeSamples
  int uvSet = 0;          ///< UV set that places the mesh in the image
  int udimTile = 1001;    ///< which UDIM tile (1001 = [0,1)²), kFirstUdimTile … kLastUdimTile
  NormalMapGreen green = NormalMapGreen::kOpenGL;  ///< kDirectX flips G of kTangentNormal
  /// Channels of kTangentNormal and kObjectNormal (Blender's bake Swizzle); with green
  /// kDirectX, G is negated after it.
  NormalSwizzle swizzle = kIdentitySwizzle;
  int threads = 0;        ///< 0 = all cores; the result does not depend on it
};

/// @brief Everything a bake reads: the mesh, its tangent frames (may be null when no map or
/// layer needs them), and the layers.
struct BakeInput {
  const Mesh* mesh = nullptr;
  /// MikkTSpace frames per corner of **UV set 0** (computeTangents(mesh.view(0))), or nullptr.
  /// They define the tangent space of kTangentNormal/kTangent/kBitangent whatever uvSet places
  /// the texels (Blender: the tangents of the active UV map), and are the SurfacePoint's tangent
  /// frame for tangent-space layers.
  const CornerTangents* tangents = nullptr;  ///< may be null with `limit` (its own frames)
  std::span<const Layer> layers;  ///< composited in order; textures must outlive the bake
  /// With a limit surface, `mesh` is its tessellation (subdivideMesh of the same coarse mesh and
  /// options, with `limitParameters`): the raster walks the tessellation, and every sample is
  /// shaded from the exact limit surface at the point whose UV is the sample's (position,
  /// normal, UVs and their derivatives; tangent frame: ∂P/∂u of UV set 0 made orthogonal to
  /// the normal). Masks are the tessellation's coverage. Null: shade the mesh as it is.
  const LimitSurface* limit = nullptr;
  const SurfaceParameters* limitParameters = nullptr;
  /// Per UV set, MikkTSpace frames of Cycles' triangles (computeLoopTriangleTangents: 3 per
  /// triangle, in loop-triangle order), or nullptr. Given, they are the SurfacePoint's tangent
  /// frames for tangent-space layers on that set, as Cycles' Normal Map node decodes with them;
  /// the map's own frame (kTangentNormal's) stays `tangents`, as Blender's baker uses the mesh's.
  std::array<const CornerTangents*, kMaxUvSets> triangleTangents{};
  /// The object's placement in the world (Blender's matrix_world), or nullptr. One whose linear
  /// part is not the identity makes the bake shade the object in world space, as Cycles does
  /// (world_shading.hpp): height layers' scales are then world distances (a Bump node's
  /// Distance), normal maps are carried to world space as normals, the guard works there, and
  /// the normal comes back to object space as Blender's baker brings it (tangent-space maps as a
  /// normal, object-space maps as a direction). Height, tangent, bitangent and mask maps do not
  /// change; derivative and surface-gradient maps hold the object-space Γ of the unguarded
  /// world normal.
  const ObjectTransform* transform = nullptr;
};

/// @brief MikkTSpace frames of Cycles' triangles of @p mesh (Blender's looptris, the triangles
/// the raster walks, but for the near-tie quads Cycles splits on the other diagonal), each
/// handed to MikkTSpace as a face of its own: the tangents Cycles computes for its Normal Map
/// node (on its triangulated mesh), which differ from the polygon mesh's (computeTangents)
/// inside quads and n-gons. Normals as Cycles gives them: a flat face without Auto Smooth its
/// triangle's normal, every other face its corner normals. UV set @p uvSet.
/// @return 3 frames per triangle, in loop-triangle order (triangle k of a quad split two ways
///         is Cycles' triangle k); kBadInput without UV set @p uvSet
Result<CornerTangents> computeLoopTriangleTangents(const Mesh& mesh, int uvSet = 0,
                                                   const TangentOptions& options = {});

/// @brief The loop-triangle frames of @p triangleFrames (computeLoopTriangleTangents of @p mesh)
/// per corner of @p mesh: each corner takes its frame in the first of those triangles through it.
/// (MikkTSpace gives a corner the same frame in every triangle of its face that it shares with
/// the same normal and UV, so which triangle is not a choice.) For per-corner evaluation
/// (CornerOptions::layerTangents) that decodes as the bake does.
/// @return #C frames in corner order
CornerTangents loopTriangleFramesAtCorners(const Mesh& mesh, const CornerTangents& triangleFrames);

/// @brief Bakes one map. Texels no triangle covers get the map's background (tangent-space
/// normal (0.5, 0.5, 1), zero elsewhere) and coverage 0.
///
/// @return width × height × mapChannels(map) image with coverage; kBadInput when the mesh is
///         null or has no UV set @p settings.uvSet, a setting is out of range, the map needs
///         tangents and none (or a wrong number) are given, or validateLayers rejects a layer;
///         kInternal when memory runs out.
Result<FloatImage> bakeMap(const BakeInput& input, const BakeSettings& settings);

/// @brief How far a bake is: @p rowsDone of the image's @p rows rows are baked. Return false to
/// stop the bake (it then fails with ErrorCode::kCancelled).
using BakeProgressCallback = std::function<bool(int rowsDone, int rows)>;

/// @brief bakeMap that reports its progress after each band of kBakeBandRows rows (from a thread
/// of the bake, one call at a time, in order; the last call has rowsDone == height) and stops
/// within two bands when @p progress returns false. The image is the one bakeMap gives, bit for
/// bit.
/// @return bakeMap's errors, or kCancelled ("bake: cancelled") when @p progress stopped it
Result<FloatImage> bakeMap(const BakeInput& input, const BakeSettings& settings,
                           const BakeProgressCallback& progress);

/// Rows per band of bakeMapRows (the last band, or the first of a height that is not a multiple
/// of 8, may have fewer).
inline constexpr int kBakeBandRows = 256;

/// @brief Called by bakeMapRows after each band with the rows that may be read (see there). It
/// may also change them (pad them in place: extendMarginRowsInPlace); the bake never reads them
/// back. Returning an error stops the bake, which then returns that error.
using BakedRowsSink = std::function<Status(const MutableImageRows& rows)>;

/// @brief bakeMap band by band, without ever holding the whole image: the map is baked in bands
/// of kBakeBandRows rows from the top of the image (file row 0) down into a ring of
/// bakeRingRows(height, keepRows) reused rows, and @p sink is called after each band while the
/// next band is baked (on one of the bake's threads, one call at a time, in order). With e the
/// end of the previous call (0 at first), a call sees rows [max(0, e − keepRows), end): the new
/// band and the @p keepRows rows above it (the halo a padding of the rows above the band
/// needs). The last call has end == height. Every value is bit for bit the one bakeMap
/// computes; memory is O(width · (2·kBakeBandRows + keepRows)) instead of O(width · height),
/// so a 4096² RGB bake holds ~36 MB instead of ~270 MB.
/// @return bakeMap's errors, or the first error of @p sink (no later band is baked)
Status bakeMapRows(const BakeInput& input, const BakeSettings& settings, int keepRows,
                   const BakedRowsSink& sink);

/// @brief Rows of the ring bakeMapRows bakes a map of @p height rows into, keeping @p keepRows
/// rows above each band: the band a sink call reads, the rows above it, and the next band,
/// baked meanwhile — min(height, 2·kBakeBandRows + keepRows).
inline int bakeRingRows(int height, int keepRows) {
  return std::min(height, 2 * kBakeBandRows + std::max(keepRows, 0));
}

/// @brief The triangles the baker rasterizes, as global corner indices, face after face (see
/// "Triangles" in the file comment): #F triangles for a triangle mesh, 2 per quad, k−2 per k-gon.
std::vector<std::array<std::uint32_t, 3>> loopTriangles(const Mesh& mesh);

/// @brief UDIM tiles (1001, 1002, ...) that UV set @p uvSet touches, ascending.
///
/// A tile is touched when a triangle with nonzero UV area overlaps the tile's open square
/// (touching its border only does not count). Parts of the UV layout outside tiles
/// 1001 … 2000 (negative u or v, u ≥ 10, v ≥ 100) are ignored; @p trianglesOutside (when not
/// null) is set to how many triangles with nonzero UV area lie wholly there, in no tile. Empty
/// when the set does not exist.
std::vector<int> udimTiles(const Mesh& mesh, int uvSet, std::size_t* trianglesOutside = nullptr);

/// @brief Edge padding as Blender's "Extend" margin (IMB_filter_extend, what Blender 3.4 runs for
/// margin type Extend): @p margin passes, each filling every not-yet-filled texel that has a
/// filled **4-neighbour** with the weighted average of its filled 8-neighbours (weight 2 for the
/// 4 edge neighbours, 1 for the 4 diagonal ones), all reading the state before the pass.
///
/// Texels with coverage > 0 are the initial filled set. The filled region therefore grows one
/// ring per pass in the **L1 (Manhattan) metric**: after the call, exactly the texels within
/// L1 distance ≤ margin of a covered texel have been written. Coverage is left unchanged (it
/// stays the geometric coverage, e.g. for an alpha channel). Parallel, deterministic.
/// @param[in] threads 0 = all cores; the result does not depend on it
void extendMargin(FloatImage& image, int margin, int threads = 0);

/// @brief Rows [rowBegin, rowEnd) of extendMargin(image, margin), bit for bit, computed from rows
/// [rowBegin − margin, rowEnd + margin) of the image alone (@p rows must hold them, clipped to
/// the image): a texel's padded value depends on nothing farther than @p margin rows. This pads
/// a strip of an image whose lower rows are still being baked (bakeMapRows).
/// @param[out] window receives those rows of the image (clipped to it), padded; its buffers are
///             reused from one call to the next
/// @param[in] threads 0 = all cores; the result does not depend on it
/// @return the row of @p window that holds row @p rowBegin of the image
int extendMarginRows(const ImageRows& rows, int margin, int rowBegin, int rowEnd,
                     FloatImage& window, int threads = 0);
/// @brief extendMarginRows without the copy: rows [rowBegin, rowEnd) of @p rows become, in
/// place, rows [rowBegin, rowEnd) of extendMargin(image, margin), bit for bit, when @p rows
/// holds rows [rowBegin − margin, rowEnd + margin) of the image (clipped to it) as they were
/// baked — except that uncovered texels may hold anything, since padding never reads them.
/// The halo rows are changed too (their uncovered texels near an island get values that are
/// final only once the halo is padded as a strip of its own), so strips padded top to bottom
/// this way, each with the rows above it already padded, give the whole image's padding: what
/// the CLI does band by band. Does nothing when @p rows does not hold those rows.
void extendMarginRowsInPlace(const MutableImageRows& rows, int margin, int rowBegin, int rowEnd,
                             int threads = 0);
/// @brief extendMarginRows of a whole image.
int extendMarginRows(const FloatImage& image, int margin, int rowBegin, int rowEnd,
                     FloatImage& window, int threads = 0);

/// @brief Edge padding as Blender's "Adjacent Faces" margin (Blender's default margin type):
/// each uncovered texel near an island takes the value the surface has on the other side of
/// the UV seam it faces, so mipmaps and filtering across a seam blend the right colours.
///
/// The margin is every uncovered texel within `margin + 1.5` texels of a covered one along
/// 8-connected steps of 1 and √2 (Blender writes margin + 1 rows beyond a straight edge). Each
/// starts at the face that covers its nearest covered texel and walks: while its point p (the
/// texel centre, in that face's UV frame) lies outside the face, it crosses the face's edge
/// nearest p into the face across it in the mesh, carrying p over with the edge — its position
/// along the edge in proportion, its distance from the edge in texels, on the far side. Where
/// p lands inside a face its value is the bilinear interpolation of the covered texels there.
/// At a boundary edge (no face across) it is the face's value at the edge's point nearest p;
/// a walk that leaves the image (the face across lies in another UDIM tile) or crosses more
/// than 8 edges gives the start face's value at its outline's point nearest the texel. Values
/// are read only from covered texels, so the result does not depend on the order.
///
/// Checked against Blender 3.4 (tests/blender/margin_oracle.py): along seams the values agree
/// to float precision; where Blender's choice is arbitrary they differ — beyond the corner of
/// an island where three or more faces meet, and around poles of triangle fans.
/// @param mesh the mesh the image was baked from, with UV set @p uvSet; the image is tile
///        @p udimTile baked with @p samples² samples per texel (its coverage must be the raster's)
/// @param[in] threads 0 = all cores; the result does not depend on it
void adjacentFacesMargin(FloatImage& image, const Mesh& mesh, int uvSet, int udimTile, int samples,
                         int margin, int threads = 0);

/// @brief How the texels outside the UV islands are filled (a scene output's "padding").
enum class PaddingMode {
  kExtend,    ///< "extend": extendMargin by the output's margin (Blender's "Extend")
  kPushPull,  ///< "push-pull": pushPullFill, every uncovered texel (the margin is ignored)
  /// "adjacent-faces": adjacentFacesMargin by the output's margin (Blender's "Adjacent Faces",
  /// its default): texels across a UV seam take the surface's values from the other side
  kAdjacentFaces,
};

/// @brief Pads the whole image @p image (tile @p udimTile of UV set @p uvSet of @p mesh, baked
/// or converted with @p samples² samples per texel) as @p mode says: extendMargin or
/// adjacentFacesMargin by @p margin texels, or pushPullFill (the margin unused).
/// @param[in] threads 0 = all cores; the result does not depend on it
void padImage(FloatImage& image, PaddingMode mode, int margin, const Mesh& mesh, int uvSet,
              int udimTile, int samples, int threads = 0);

/// @brief Fills every uncovered texel (coverage 0) by push-pull (Gortler et al. 1996): a
/// pyramid of 2×2 weighted averages of the covered texels (weights clamped to 1), then, from
/// the coarsest level down, each texel with weight w < 1 becomes w·own + (1−w)·(bilinear
/// interpolation of the coarser level). Covered texels (coverage > 0) keep their values bit for
/// bit; an image without covered texels is left unchanged. Coverage is left unchanged, so
/// texels written by extendMargin count as holes here. Parallel, deterministic.
/// @param[in] threads 0 = all cores; the result does not depend on it
void pushPullFill(FloatImage& image, int threads = 0);

}  // namespace sgbake
