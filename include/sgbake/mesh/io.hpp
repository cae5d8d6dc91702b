/// @file io.hpp
/// @brief Reading meshes: OBJ, PLY and OFF, validated before OpenMesh parses them.
#pragma once

#include <filesystem>
#include <string_view>

#include "sgbake/core/result.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake {

/// @brief Options for loadMesh.
struct LoadOptions {
  /// Fail with a clear error when the file has no texture coordinates (for work that needs UVs).
  bool requireUvs = false;
};

/// @brief Reads an OBJ, PLY or OFF file (chosen by extension, case-insensitive).
///
/// The file is read into memory once and validated completely by sgbake's own checker before
/// OpenMesh parses the same bytes: out-of-range or zero indices, faces with fewer than three
/// corners or a repeated vertex, NaN/Inf numbers, truncated or binary-garbage content and empty
/// files are reported as ErrorCode::kBadInput with a one-line message naming the file (and the
/// line, for text formats).
///
/// - OBJ: triangles, quads and n-gons; per-corner `vt` and `vn` (seams and flat faces survive);
///   negative (relative) indices; faces without `vt` in a file that has UVs get (0, 0).
/// - PLY (ASCII and binary, either endianness) and OFF (ASCII; NOFF/STOFF variants): per-vertex
///   normals and UVs, copied to every corner of the vertex.
/// - Files without normals get smooth, angle-weighted vertex normals (computeSmoothNormals).
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

}  // namespace sgbake
