/// @file sgbake_c.cpp
/// @brief The C ABI (sgbake.h): validates the caller's flat arrays, copies them into the C++
/// types and calls the C++ API. No math lives here; nothing escapes as an exception.
#include "sgbake/sgbake.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake {
namespace {

/// How far from 1 a corner normal's length may be. Blender's normals are unit to float
/// precision (~1e-7); decoded custom normals are a little less exact. Anything further off is a
/// caller mistake (unnormalized or garbage data) that would silently skew every tangent.
constexpr double kUnitNormalTolerance = 1e-3;

/// Messages name the function, as a file-based error names the file.
constexpr std::string_view kWhere = "sgbake_compute_tangents: ";

/// Copies @p message into the caller's buffer, truncated and always NUL-terminated.
void writeError(char* buffer, std::size_t size, std::string_view message) noexcept {
  if (buffer == nullptr || size == 0) return;
  const std::size_t n = std::min(message.size(), size - 1);
  std::memcpy(buffer, message.data(), n);
  buffer[n] = '\0';
}

int statusFor(ErrorCode code) {
  return code == ErrorCode::kBadInput ? SGBAKE_ERROR_BAD_INPUT : SGBAKE_ERROR_INTERNAL;
}

Error badArgument(const std::string& what) {
  return Error::badInput(std::string(kWhere) + what);
}

/// `name[i] = (x, y, z)` for messages about one element of a float array.
std::string describeElement(const char* name, std::size_t index, const float* values,
                            std::size_t width) {
  std::string text = std::string(name) + "[" + std::to_string(index) + "] = (";
  for (std::size_t k = 0; k < width; ++k) {
    char number[32];
    std::snprintf(number, sizeof number, "%s%.9g", k == 0 ? "" : ", ",
                  static_cast<double>(values[index * width + k]));
    text += number;
  }
  return text + ")";
}

/// The index of the first non-finite element of a #n × width float array, or n if none.
std::size_t firstNonFinite(const float* values, std::size_t n, std::size_t width) {
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < width; ++k) {
      if (!std::isfinite(values[i * width + k])) return i;
    }
  }
  return n;
}

/// The raw arguments of sgbake_compute_tangents, grouped so they can be validated and converted
/// in one place.
struct TangentArguments {
  const float* positions;
  std::size_t numVertices;
  const std::uint32_t* faceStart;
  std::size_t numFaces;
  const std::uint32_t* cornerVertex;
  const float* cornerNormals;
  const float* cornerUvs;
  std::size_t numCorners;
  int threads;
  float* outTangents;
  float* outSigns;
};

/// Everything sgbake.h promises to check, before a single value is computed.
Status validate(const TangentArguments& a) {
  if (a.threads < 0) {
    return badArgument("threads = " + std::to_string(a.threads) + " (must be >= 0)");
  }
  if (a.numCorners > std::numeric_limits<std::uint32_t>::max()) {
    return badArgument("num_corners = " + std::to_string(a.numCorners) +
                       " does not fit in 32 bits");
  }
  // Every face needs 3 corners: this bound also keeps num_faces + 1 from overflowing.
  if (a.numFaces > a.numCorners / 3) {
    return badArgument("num_faces = " + std::to_string(a.numFaces) + " with num_corners = " +
                       std::to_string(a.numCorners) + " (each face needs at least 3 corners)");
  }
  if (a.numFaces == 0 && a.numCorners == 0) return Ok{};

  const struct {
    const void* pointer;
    bool needed;
    const char* name;
  } arrays[] = {
      {a.positions, a.numVertices > 0, "positions"},
      {a.faceStart, true, "face_start"},
      {a.cornerVertex, true, "corner_vertex"},
      {a.cornerNormals, true, "corner_normals"},
      {a.cornerUvs, true, "corner_uvs"},
      {a.outTangents, true, "out_tangents"},
      {a.outSigns, true, "out_signs"},
  };
  for (const auto& array : arrays) {
    if (array.needed && array.pointer == nullptr) {
      return badArgument(std::string(array.name) + " is NULL");
    }
  }

  if (a.faceStart[0] != 0) {
    return badArgument("face_start[0] = " + std::to_string(a.faceStart[0]) + " (must be 0)");
  }
  for (std::size_t f = 0; f < a.numFaces; ++f) {
    const std::uint32_t begin = a.faceStart[f];
    const std::uint32_t end = a.faceStart[f + 1];
    if (end < begin) {
      return badArgument("face_start is not increasing: face_start[" + std::to_string(f) +
                         "] = " + std::to_string(begin) + ", face_start[" +
                         std::to_string(f + 1) + "] = " + std::to_string(end));
    }
    if (end - begin < 3) {
      return badArgument("face " + std::to_string(f) + " has " + std::to_string(end - begin) +
                         " corners (faces need at least 3)");
    }
  }
  if (a.faceStart[a.numFaces] != a.numCorners) {
    return badArgument("face_start[" + std::to_string(a.numFaces) +
                       "] = " + std::to_string(a.faceStart[a.numFaces]) +
                       " (must equal num_corners = " + std::to_string(a.numCorners) + ")");
  }

  for (std::size_t c = 0; c < a.numCorners; ++c) {
    if (a.cornerVertex[c] >= a.numVertices) {
      return badArgument("corner_vertex[" + std::to_string(c) +
                         "] = " + std::to_string(a.cornerVertex[c]) +
                         " is out of range (num_vertices = " + std::to_string(a.numVertices) +
                         ")");
    }
  }

  if (const std::size_t v = firstNonFinite(a.positions, a.numVertices, 3); v < a.numVertices) {
    return badArgument(describeElement("positions", v, a.positions, 3) + " is not finite");
  }
  if (const std::size_t c = firstNonFinite(a.cornerNormals, a.numCorners, 3); c < a.numCorners) {
    return badArgument(describeElement("corner_normals", c, a.cornerNormals, 3) +
                       " is not finite");
  }
  if (const std::size_t c = firstNonFinite(a.cornerUvs, a.numCorners, 2); c < a.numCorners) {
    return badArgument(describeElement("corner_uvs", c, a.cornerUvs, 2) + " is not finite");
  }
  for (std::size_t c = 0; c < a.numCorners; ++c) {
    const float* n = a.cornerNormals + 3 * c;
    const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    if (!(std::abs(len - 1.0) <= kUnitNormalTolerance)) {
      char length[32];
      std::snprintf(length, sizeof length, "%.6g", len);
      return badArgument(describeElement("corner_normals", c, a.cornerNormals, 3) +
                         " has length " + length + " (normals must be unit length)");
    }
  }
  return Ok{};
}

/// Copies #n × 3 floats into Vec3f (a copy, not a cast: the caller's buffer is a float array).
std::vector<Vec3f> toVec3(const float* values, std::size_t n) {
  std::vector<Vec3f> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = {values[3 * i], values[3 * i + 1], values[3 * i + 2]};
  return out;
}

std::vector<Vec2f> toVec2(const float* values, std::size_t n) {
  std::vector<Vec2f> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = {values[2 * i], values[2 * i + 1]};
  return out;
}

Status computeTangentsFromArrays(const TangentArguments& a) {
  if (Status valid = validate(a); !valid) return valid;
  if (a.numCorners == 0) return Ok{};

  const std::vector<Vec3f> positions = toVec3(a.positions, a.numVertices);
  const std::vector<Vec3f> normals = toVec3(a.cornerNormals, a.numCorners);
  const std::vector<Vec2f> uvs = toVec2(a.cornerUvs, a.numCorners);
  MeshView mesh;
  mesh.positions = positions;
  mesh.faceStart = {a.faceStart, a.numFaces + 1};
  mesh.cornerVertex = {a.cornerVertex, a.numCorners};
  mesh.cornerNormals = normals;
  mesh.cornerUvs = uvs;

  TangentOptions options;
  options.threads = a.threads;
  Result<CornerTangents> frames = computeTangents(mesh, options);
  if (!frames) return Error{frames.error().code, std::string(kWhere) + frames.error().message};
  if (frames->tangent.size() != a.numCorners || frames->sign.size() != a.numCorners) {
    return Error::internal(std::string(kWhere) + "computeTangents returned " +
                           std::to_string(frames->tangent.size()) + " tangents for " +
                           std::to_string(a.numCorners) + " corners");
  }
  for (std::size_t c = 0; c < a.numCorners; ++c) {
    const Vec3f t = frames->tangent[c];
    a.outTangents[3 * c] = t.x;
    a.outTangents[3 * c + 1] = t.y;
    a.outTangents[3 * c + 2] = t.z;
    a.outSigns[c] = frames->sign[c];
  }
  return Ok{};
}

}  // namespace
}  // namespace sgbake

extern "C" {

const char* sgbake_version(void) { return SGBAKE_VERSION_STRING; }

int sgbake_compute_tangents(const float* positions, size_t num_vertices,
                            const uint32_t* face_start, size_t num_faces,
                            const uint32_t* corner_vertex, const float* corner_normals,
                            const float* corner_uvs, size_t num_corners, int threads,
                            float* out_tangents, float* out_signs, char* error_buf,
                            size_t error_buf_size) {
  using sgbake::writeError;
  try {
    const sgbake::TangentArguments arguments{positions,     num_vertices,   face_start,
                                             num_faces,     corner_vertex,  corner_normals,
                                             corner_uvs,    num_corners,    threads,
                                             out_tangents,  out_signs};
    const sgbake::Status status = sgbake::computeTangentsFromArrays(arguments);
    if (status) return SGBAKE_OK;
    writeError(error_buf, error_buf_size, status.error().message);
    return sgbake::statusFor(status.error().code);
  } catch (const std::bad_alloc&) {
    writeError(error_buf, error_buf_size, "sgbake_compute_tangents: out of memory");
  } catch (const std::exception& e) {
    writeError(error_buf, error_buf_size, "sgbake_compute_tangents: internal error: ");
    if (error_buf != nullptr && error_buf_size > 0) {
      const std::size_t used = std::strlen(error_buf);
      writeError(error_buf + used, error_buf_size - used, e.what());
    }
  } catch (...) {
    writeError(error_buf, error_buf_size, "sgbake_compute_tangents: unknown internal error");
  }
  return SGBAKE_ERROR_INTERNAL;
}

}  // extern "C"
