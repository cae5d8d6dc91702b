/// @file sgbake.h
/// @brief sgbake's C ABI: flat arrays in, flat arrays out, status codes, no exceptions.
///
/// Meant for callers that cannot use C++ — above all the Blender add-on, through Python's ctypes.
/// Every function validates its arguments completely before computing, never throws, never
/// prints and never exits; failures are a status code plus a one-line message written into a
/// caller-provided buffer.
///
/// Conventions shared by every array below (the same as the C++ `sgbake::MeshView`):
/// - `#V` vertices, `#F` faces, `#C` face corners (Blender's "loops"). Corners are stored face
///   after face, each face's corners in winding order.
/// - Arrays are dense, row-major, C order: "#C × 3" means `3 * #C` values, corner `c` occupying
///   elements `[3c, 3c+3)` (a contiguous numpy array of shape (#C, 3)).
/// - Positions, normals and tangents are in object space, right-handed, unitless (whatever unit
///   the positions use). UVs have their origin at the bottom left, u to the right, v up (Blender).
/// - The library copies what it needs: no pointer is kept after a call returns.
/// - Functions are thread-safe: concurrent calls on different output arrays are fine.
#ifndef SGBAKE_SGBAKE_H
#define SGBAKE_SGBAKE_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#define SGBAKE_C_API
#else
/// Exported even if the library is ever built with hidden visibility: ctypes looks these up.
#define SGBAKE_C_API __attribute__((visibility("default")))
#endif

/// The version of this header, as "MAJOR.MINOR.PATCH"; sgbake_version() reports the library's.
/// 0.2.0 appended sgbake_mesh::face_flat and sgbake_mesh::auto_smooth: a caller built against
/// 0.1.0's header passes a shorter struct, so rebuild (and set both fields). 0.3.0 changes no
/// C declaration: normal-map layers and steep bumps bake as Cycles shades them (manifests of
/// 0.2.0 re-bake). 0.4.0 changes none either: the scene gains a height layer's "base"
/// ("above": it bumps the normal of the layers before it, as chained Bump nodes do) and
/// "channel" (one channel of a packed map), a tangent-space normal layer's "tangent_uv", and
/// the corners table decodes tangent-space layers with the loop triangles' frames. 0.5.0
/// changes none: the scene gains "transform" (the object's matrix_world), with which normal
/// maps, derivative, surface-gradient and corners outputs are shaded in world space as Cycles
/// shades the placed object (height scales then in world units; docs/baker.md). 0.6.0
/// appends sgbake_mesh::face_material (rebuild, and set it or NULL) for a layer's "material".
#define SGBAKE_VERSION_STRING "0.6.0"

#ifdef __cplusplus
extern "C" {
#endif

/// @brief Status codes returned by every sgbake_* function (the same as the CLI's exit codes).
enum sgbake_status {
  SGBAKE_OK = 0,             ///< success; every output array has been written
  SGBAKE_ERROR_INTERNAL = 1, ///< a bug or a resource failure (e.g. out of memory) in sgbake
  SGBAKE_ERROR_BAD_INPUT = 2, ///< the arguments are inconsistent or the data is invalid
  SGBAKE_CANCELLED = 3        ///< the caller asked the call to stop (sgbake_progress::cancel)
};

/// @brief The library's version, "MAJOR.MINOR.PATCH" (a static string; never NULL).
SGBAKE_C_API const char* sgbake_version(void);

/// @brief MikkTSpace tangent frames per face corner, identical to Blender's (see the C++
/// `sgbake::computeTangents` for the algorithm: triangles and quads as they are, n-gons by ear
/// clipping, corners welded only where position, normal and UV are exactly equal).
///
/// @param[in]  positions       #V × 3 floats: vertex positions (x, y, z), object space.
/// @param[in]  num_vertices    #V.
/// @param[in]  face_start      #F + 1 offsets into the corner arrays: face f owns corners
///                             [face_start[f], face_start[f+1]). face_start[0] must be 0,
///                             face_start[#F] must be #C, and every face needs at least 3 corners.
///                             (Blender: `polygons.loop_start` with #C appended.)
/// @param[in]  num_faces       #F.
/// @param[in]  corner_vertex   #C vertex indices, each < #V (Blender: `loops.vertex_index`).
/// @param[in]  corner_normals  #C × 3 floats: unit normal of each corner, object space (the split
///                             or custom normal; the face normal on flat faces).
/// @param[in]  corner_uvs      #C × 2 floats: texture coordinates (u, v) of each corner.
/// @param[in]  num_corners     #C (must fit in 32 bits).
/// @param[in]  threads         maximum number of threads; 0 = all cores. The result is
///                             bit-identical for every value.
/// @param[out] out_tangents    #C × 3 floats: unit tangent of each corner, object space.
/// @param[out] out_signs       #C floats, each +1 or -1: the bitangent is
///                             `sign * cross(normal, tangent)`.
/// @param[out] error_buf       receives a NUL-terminated one-line message when the call fails
///                             (truncated to fit); may be NULL. Untouched on success.
/// @param[in]  error_buf_size  size of error_buf in bytes, terminating NUL included; may be 0.
///
/// @return SGBAKE_OK, SGBAKE_ERROR_BAD_INPUT or SGBAKE_ERROR_INTERNAL. On failure the output
///         arrays may have been partly written and must not be used.
///
/// @note Validated before anything is computed (failures are SGBAKE_ERROR_BAD_INPUT): pointers
///       are non-NULL wherever their array is non-empty; face_start is as described above;
///       every corner_vertex is < #V; every position, normal and UV is finite; every normal has
///       unit length to within 1e-3; threads >= 0. A mesh with no faces and no corners succeeds
///       and writes nothing (face_start may then be NULL).
SGBAKE_C_API int sgbake_compute_tangents(const float* positions, size_t num_vertices,
                                         const uint32_t* face_start, size_t num_faces,
                                         const uint32_t* corner_vertex,
                                         const float* corner_normals, const float* corner_uvs,
                                         size_t num_corners, int threads, float* out_tangents,
                                         float* out_signs, char* error_buf,
                                         size_t error_buf_size);

/// @brief The triangles Blender 3.4 tessellates a mesh into (its loop triangles,
/// `Mesh.loop_triangles`): a triangle as it is, a quad split as Blender splits it, a k-gon cut into
/// k − 2 triangles by Blender's ear clipping. These are the triangles sgbake bakes and computes the
/// tangent frames of n-gons on.
///
/// @param[in]  positions, num_vertices, face_start, num_faces, corner_vertex, num_corners
///             the mesh, as for sgbake_compute_tangents.
/// @param[out] out_triangles (#C − 2·#F) × 3 corner indices (Blender: `loop_triangles[i].loops`),
///             face after face, in Blender's order and corner order.
/// @param[out] error_buf, error_buf_size as for sgbake_compute_tangents.
///
/// @return SGBAKE_OK, SGBAKE_ERROR_BAD_INPUT (the mesh fails the checks of
///         sgbake_compute_tangents that concern these arrays, or out_triangles is NULL for a
///         non-empty mesh) or SGBAKE_ERROR_INTERNAL.
SGBAKE_C_API int sgbake_loop_triangles(const float* positions, size_t num_vertices,
                                       const uint32_t* face_start, size_t num_faces,
                                       const uint32_t* corner_vertex, size_t num_corners,
                                       uint32_t* out_triangles, char* error_buf,
                                       size_t error_buf_size);

/// @brief A mesh as flat arrays, for sgbake_bake_map (conventions at the top of this file).
///
/// Blender: positions from `vertices.foreach_get("co")`, face_start from
/// `polygons.foreach_get("loop_start")` with #C appended, corner_vertex from
/// `loops.foreach_get("vertex_index")`, corner_normals from `loops.foreach_get("normal")` after
/// `calc_normals_split()`, one corner_uvs array per `uv_layers[i].data.foreach_get("uv")`.
typedef struct sgbake_mesh {
  const float* positions;         ///< #V × 3 vertex positions, object space
  size_t num_vertices;            ///< #V
  const uint32_t* face_start;     ///< #F + 1 offsets, as in sgbake_compute_tangents
  size_t num_faces;               ///< #F
  const uint32_t* corner_vertex;  ///< #C vertex indices, each < #V
  /// #C × 3 unit corner normals (split normals: the face normal on flat faces), or NULL for
  /// angle-weighted smooth vertex normals computed by sgbake (every face smooth).
  const float* corner_normals;
  /// num_uv_sets pointers, each to #C × 2 floats (u, v); UV set 0 is the one MikkTSpace frames
  /// are computed on, as Blender does for its first UV map. A scene's "uv": N reads set N.
  const float* const* corner_uvs;
  size_t num_uv_sets;  ///< at least 1, at most 4 (the UV sets a scene's "uv" keys can name)
  size_t num_corners;  ///< #C (must fit in 32 bits)
  /// #F flags, nonzero for a flat-shaded face (Blender: `not polygons[f].use_smooth`), or NULL:
  /// every face smooth. Without auto_smooth a flat face is shaded with each of its triangles'
  /// own normal, as Cycles shades it; its tangent frame uses its polygon normal. With
  /// corner_normals NULL it gets the polygon normal at its corners, and subdivision keeps it flat.
  const uint8_t* face_flat;
  /// Nonzero when Blender's Auto Smooth is on (`mesh.use_auto_smooth`; custom normals need it):
  /// Cycles then shades every face, flat ones included, with its corner normals.
  int auto_smooth;
  /// #F material indices (Blender: `polygons.foreach_get("material_index")`), or NULL: every
  /// face material 0. A scene layer's "material": N applies to the faces of material N only.
  const uint32_t* face_material;
} sgbake_mesh;

/// @brief An image in memory, laid out as Blender's `Image.pixels`: width × height × channels
/// floats, rows **bottom first**, channels interleaved. Values are used as given (no colour-space
/// conversion: like a file image, they are data, "Non-Color").
typedef struct sgbake_image {
  /// The name a scene's "image" keys use to refer to it (Blender: `Image.name`); unique among
  /// the images of a call.
  const char* name;
  const float* pixels;  ///< width × height × channels floats, every one finite
  int32_t width;        ///< ≥ 1
  int32_t height;       ///< ≥ 1
  int32_t channels;     ///< 1 to 4 (Blender: 4). Heights read the Rec. 709 luminance of RGB.
} sgbake_image;

/// @brief Progress of a long call, shared with the caller while it runs: the library writes
/// `fraction`, the caller may set `cancel` from another thread (e.g. a UI's, while a worker
/// thread is in the call). The library reads and writes both fields atomically (relaxed).
typedef struct sgbake_progress {
  float fraction;  ///< written by the library: 0 at the start, rising to 1 when the map is baked
  int32_t cancel;  ///< set to non-zero by the caller to stop: the call returns SGBAKE_CANCELLED
} sgbake_progress;

/// @brief Bakes one map of a mesh given as arrays, into a caller-provided RGBA float buffer laid
/// out as Blender's `Image.pixels` (rows bottom first), so a Blender image takes it with
/// `pixels.foreach_set`.
///
/// @param[in] scene_json  A scene in the format of `sgbake bake SCENE.json` (docs/baker.md),
///                        without "mesh" (the mesh is @p mesh) and with exactly one output,
///                        which has no "file", "format" or "bit_depth" ("tile" picks the UDIM
///                        tile, 1001 by default) — e.g.
///                        `{"layers": [{"type": "height", "image": "Bumps", "scale": 0.1}],
///                          "outputs": [{"map": "tangent-normal", "size": 1024, "margin": 16}]}`.
///                        "image" keys name entries of @p images instead of files; a name
///                        with `<UDIM>` in it ("Bumps.<UDIM>") is a UDIM image whose tiles are
///                        the entries named with a tile number in its place ("Bumps.1001",
///                        "Bumps.1002", …), each read where the UVs lie in its tile. The planner
///                        runs as for a scene file: only what the output needs is computed.
///                        "subdivision" subdivides @p mesh first, as Blender's modifier would.
/// @param[in]  mesh        the mesh (see sgbake_mesh).
/// @param[in]  images      the images the scene's layers name; may be NULL when num_images is 0.
/// @param[in]  num_images  number of entries in images.
/// @param[in]  threads     maximum number of threads; 0 = all cores. The result is
///                         bit-identical for every value.
/// @param[in,out] progress may be NULL. Its `fraction` rises with the rows baked (band by band);
///                         a non-zero `cancel` stops the bake within two bands of 256 rows, and
///                         the call returns SGBAKE_CANCELLED (out_rgba is then unusable).
/// @param[out] out_rgba    width × height × 4 floats (the output's "size", or "width" and
///                         "height"), rows bottom first. RGB hold the map's values as a float
///                         file would store them: normal, tangent and bitangent maps encoded as
///                         n/2 + 0.5; height, mask and signed maps (derivative, surface-gradient)
///                         raw. One-channel maps fill R, G and B alike; two-channel maps leave B
///                         at 0. A is the coverage when the output has "alpha": true, else 1.
///                         Texels outside the UV islands hold the map's background, padded by
///                         the output's "margin" and "padding" as in a file.
/// @param[in]  out_floats  number of floats out_rgba holds: must be width × height × 4.
/// @param[out] error_buf   receives a NUL-terminated one-line message when the call fails; may
///                         be NULL. Untouched on success.
/// @param[in]  error_buf_size size of error_buf in bytes; may be 0.
///
/// @return SGBAKE_OK, SGBAKE_CANCELLED, SGBAKE_ERROR_BAD_INPUT (bad scene text — the message names
/// the key as
///         for a scene file —, a bad mesh array as in sgbake_compute_tangents, an image a layer
///         names that is not among @p images, a UV set the mesh lacks, a wrong out_floats) or
///         SGBAKE_ERROR_INTERNAL. Everything is validated before anything is baked; on failure
///         out_rgba may have been partly written and must not be used.
SGBAKE_C_API int sgbake_bake_map(const char* scene_json, const sgbake_mesh* mesh,
                                 const sgbake_image* images, size_t num_images, int threads,
                                 sgbake_progress* progress, float* out_rgba, size_t out_floats,
                                 char* error_buf, size_t error_buf_size);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* SGBAKE_SGBAKE_H */
