/// @file io.hpp
/// @brief Reading meshes: OBJ, PLY and OFF, validated before OpenMesh parses them.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "sgbake/core/result.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/subdiv/subdivide.hpp"

namespace sgbake {

/// @brief Options for loadMesh.
struct LoadOptions {
  /// Fail with a clear error when the file has no texture coordinates (for work that needs UVs).
  bool requireUvs = false;
  /// Subdivide the mesh after reading it, as Blender's Subdivision Surface modifier
  /// (subdivideMesh); level 0, the default, leaves it as the file has it.
  SubdivisionOptions subdivision{.level = 0};
};

/// @brief Reads an OBJ, PLY or OFF file (chosen by extension, case-insensitive).
///
/// The file is read into memory once and validated completely by sgbake's own checker before
/// OpenMesh parses the validated bytes: out-of-range or zero indices, faces with fewer than three
/// corners or a repeated vertex, NaN/Inf or unparseable numbers (also values beyond float's range
/// such as 1e999), truncated or binary-garbage content, files without faces and empty files are
/// reported as ErrorCode::kBadInput with a one-line message naming the file and, for text formats,
/// the line: `mesh.obj:7: face corner refers to vertex 12 but only 8 vertices are defined`.
/// Everything OpenMesh returns is checked bit for bit against sgbake's own parse; a disagreement
/// is ErrorCode::kInternal. Numbers are parsed straight to float (correctly rounded), so a float
/// printed with 9 significant digits loads bit-exact. Safe to call from several threads (OpenMesh
/// reads are serialised); never prints.
///
/// - OBJ: triangles, quads and n-gons, each face's corners in file order; per-corner `vt` and
///   `vn` (seams and flat-shaded faces survive); negative (relative) indices; `\r\n` line ends,
///   `\` line continuations, comments and statements without geometry (o, g, s, usemtl, mtllib,
///   l, p, vp, ...) are accepted and ignored (material files are never opened).
///   UVs: the mesh has one UV set ("UVMap") when at least one face uses `vt`; corners of faces
///   without `vt` get (0, 0); a face giving `vt` to only some of its corners is an error.
///   Normals: the file's `vn` are used only when every corner of every face has one; if any
///   corner lacks a `vn`, all file normals are ignored and smooth normals are computed.
/// - PLY (ASCII and binary, either endianness) and OFF (ASCII; [ST][C][N]OFF: NOFF, STOFF, COFF,
///   ...): per-vertex normals (nx ny nz) and UVs (PLY u v, s t, texture_u texture_v; OFF s t),
///   copied to every corner of the vertex. Colours and other properties are ignored. Binary OFF,
///   4D/nD OFF, PLY list properties other than the faces' vertex_indices (before the faces) and
///   integer-typed binary PLY coordinates are rejected as unsupported.
/// - File normals: a zero-length normal is an error; a normal whose length differs from 1 by
///   more than eight float ulps (about 9.5e-7) is normalized, others are kept bit-exact.
/// - Files without normals get smooth, angle-weighted vertex normals (computeSmoothNormals).
/// - Vertices are the file's vertices, in file order (also for non-manifold meshes); faces are
///   in file order.
///
/// @param[in] path    the mesh file
/// @param[in] options see LoadOptions
Result<Mesh> loadMesh(const std::filesystem::path& path, const LoadOptions& options = {});

/// @brief Same as loadMesh on bytes already in memory.
/// @param[in] bytes     the whole file content
/// @param[in] extension "obj", "ply" or "off" (case-insensitive, with or without a dot)
/// @param[in] name      how messages name the source (usually its path)
Result<Mesh> loadMeshFromMemory(std::string_view bytes, std::string_view extension,
                                std::string_view name, const LoadOptions& options = {});

/// @brief The mesh as OBJ text that loadMesh reads back bit for bit: `v` per vertex in vertex
/// order, `vt` (UV set @p uvSet, when the mesh has it) and `vn` per corner in corner order, `f`
/// per face with its corners in order. Floats are written in the shortest form that reads back
/// exactly. One UV set only: OBJ has no place for more.
std::string formatObj(const Mesh& mesh, std::size_t uvSet = 0);

}  // namespace sgbake
