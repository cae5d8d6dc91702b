/// @file sgbake_c.cpp
/// @brief The C ABI (sgbake.h): validates the caller's flat arrays, copies them into the C++
/// types and calls the C++ API. No math lives here; nothing escapes as an exception.
#include "sgbake/sgbake.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/bake/planner.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/mesh/normals.hpp"

namespace sgbake {
namespace {

/// How far from 1 a corner normal's length may be. Blender's normals are unit to float
/// precision (~1e-7); decoded custom normals are a little less exact. Anything further off is a
/// caller mistake (unnormalized or garbage data) that would silently skew every tangent.
constexpr double kUnitNormalTolerance = 1e-3;

/// Copies @p message into the caller's buffer, truncated and always NUL-terminated.
void writeError(char* buffer, std::size_t size, std::string_view message) noexcept {
  if (buffer == nullptr || size == 0) return;
  const std::size_t n = std::min(message.size(), size - 1);
  std::memcpy(buffer, message.data(), n);
  buffer[n] = '\0';
}

int statusFor(ErrorCode code) {
  switch (code) {
    case ErrorCode::kBadInput:
      return SGBAKE_ERROR_BAD_INPUT;
    case ErrorCode::kCancelled:
      return SGBAKE_CANCELLED;
    case ErrorCode::kInternal:
      break;
  }
  return SGBAKE_ERROR_INTERNAL;
}

/// `name[i] = (x, y, z)` for messages about one element of a float array.
std::string describeElement(const std::string& name, std::size_t index, const float* values,
                            std::size_t width) {
  std::string text = name + "[" + std::to_string(index) + "] = (";
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

/// A mesh as the caller's flat arrays (sgbake_compute_tangents' arguments, or sgbake_mesh).
struct MeshArrays {
  const float* positions = nullptr;
  std::size_t numVertices = 0;
  const std::uint32_t* faceStart = nullptr;
  std::size_t numFaces = 0;
  const std::uint32_t* cornerVertex = nullptr;
  const float* cornerNormals = nullptr;  ///< NULL only where normalsOptional
  bool normalsOptional = false;
  const std::uint8_t* faceFlat = nullptr;  ///< #F, or NULL: every face smooth
  bool autoSmooth = false;
  const std::uint32_t* faceMaterial = nullptr;  ///< #F, or NULL: every face material 0
  std::vector<const float*> uvSets;  ///< each #C × 2
  std::vector<std::string> uvNames;  ///< how messages name each UV array
  std::size_t numCorners = 0;
};

/// Everything sgbake.h promises to check about a mesh, before a single value is computed.
/// Messages start with @p where (the function's name).
Status validateMesh(const std::string& where, const MeshArrays& a) {
  const auto bad = [&where](const std::string& what) { return Error::badInput(where + what); };
  if (a.numCorners > std::numeric_limits<std::uint32_t>::max()) {
    return bad("num_corners = " + std::to_string(a.numCorners) + " does not fit in 32 bits");
  }
  // Every face needs 3 corners: this bound also keeps num_faces + 1 from overflowing.
  if (a.numFaces > a.numCorners / 3) {
    return bad("num_faces = " + std::to_string(a.numFaces) + " with num_corners = " +
               std::to_string(a.numCorners) + " (each face needs at least 3 corners)");
  }
  if (a.numFaces == 0 && a.numCorners == 0) return Ok{};

  if (a.positions == nullptr && a.numVertices > 0) return bad("positions is NULL");
  if (a.faceStart == nullptr) return bad("face_start is NULL");
  if (a.cornerVertex == nullptr) return bad("corner_vertex is NULL");
  if (a.cornerNormals == nullptr && !a.normalsOptional) return bad("corner_normals is NULL");
  for (std::size_t i = 0; i < a.uvSets.size(); ++i) {
    if (a.uvSets[i] == nullptr) return bad(a.uvNames[i] + " is NULL");
  }

  if (a.faceStart[0] != 0) {
    return bad("face_start[0] = " + std::to_string(a.faceStart[0]) + " (must be 0)");
  }
  for (std::size_t f = 0; f < a.numFaces; ++f) {
    const std::uint32_t begin = a.faceStart[f];
    const std::uint32_t end = a.faceStart[f + 1];
    if (end < begin) {
      return bad("face_start is not increasing: face_start[" + std::to_string(f) +
                 "] = " + std::to_string(begin) + ", face_start[" + std::to_string(f + 1) +
                 "] = " + std::to_string(end));
    }
    if (end - begin < 3) {
      return bad("face " + std::to_string(f) + " has " + std::to_string(end - begin) +
                 " corners (faces need at least 3)");
    }
  }
  if (a.faceStart[a.numFaces] != a.numCorners) {
    return bad("face_start[" + std::to_string(a.numFaces) +
               "] = " + std::to_string(a.faceStart[a.numFaces]) +
               " (must equal num_corners = " + std::to_string(a.numCorners) + ")");
  }

  for (std::size_t c = 0; c < a.numCorners; ++c) {
    if (a.cornerVertex[c] >= a.numVertices) {
      return bad("corner_vertex[" + std::to_string(c) + "] = " +
                 std::to_string(a.cornerVertex[c]) + " is out of range (num_vertices = " +
                 std::to_string(a.numVertices) + ")");
    }
  }

  if (const std::size_t v = firstNonFinite(a.positions, a.numVertices, 3); v < a.numVertices) {
    return bad(describeElement("positions", v, a.positions, 3) + " is not finite");
  }
  if (a.cornerNormals != nullptr) {
    if (const std::size_t c = firstNonFinite(a.cornerNormals, a.numCorners, 3);
        c < a.numCorners) {
      return bad(describeElement("corner_normals", c, a.cornerNormals, 3) + " is not finite");
    }
  }
  for (std::size_t i = 0; i < a.uvSets.size(); ++i) {
    if (const std::size_t c = firstNonFinite(a.uvSets[i], a.numCorners, 2); c < a.numCorners) {
      return bad(describeElement(a.uvNames[i], c, a.uvSets[i], 2) + " is not finite");
    }
  }
  for (std::size_t c = 0; c < a.numCorners && a.cornerNormals != nullptr; ++c) {
    const float* n = a.cornerNormals + 3 * c;
    const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    if (!(std::abs(len - 1.0) <= kUnitNormalTolerance)) {
      char length[32];
      std::snprintf(length, sizeof length, "%.6g", len);
      return bad(describeElement("corner_normals", c, a.cornerNormals, 3) + " has length " +
                 length + " (normals must be unit length)");
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

/// sgbake_loop_triangles: loopTriangles of the validated mesh.
Status loopTrianglesFromArrays(const MeshArrays& a, std::uint32_t* outTriangles) {
  const std::string where = "sgbake_loop_triangles: ";
  if (Status valid = validateMesh(where, a); !valid) return valid;
  if (a.numCorners == 0) return Ok{};
  if (outTriangles == nullptr) return Error::badInput(where + "out_triangles is NULL");
  Mesh mesh;
  mesh.positions = toVec3(a.positions, a.numVertices);
  mesh.faceStart.assign(a.faceStart, a.faceStart + a.numFaces + 1);
  mesh.cornerVertex.assign(a.cornerVertex, a.cornerVertex + a.numCorners);
  const std::vector<std::array<std::uint32_t, 3>> triangles = loopTriangles(mesh);
  if (triangles.size() != a.numCorners - 2 * a.numFaces) {
    return Error::internal(where + "loopTriangles returned " + std::to_string(triangles.size()) +
                           " triangles for " + std::to_string(a.numFaces) + " faces of " +
                           std::to_string(a.numCorners) + " corners");
  }
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t i = 0; i < 3; ++i) outTriangles[3 * t + i] = triangles[t][i];
  return Ok{};
}

Status computeTangentsFromArrays(const MeshArrays& a, int threads, float* outTangents,
                                 float* outSigns) {
  const std::string where = "sgbake_compute_tangents: ";
  if (threads < 0) {
    return Error::badInput(where + "threads = " + std::to_string(threads) + " (must be >= 0)");
  }
  if (Status valid = validateMesh(where, a); !valid) return valid;
  if (a.numCorners == 0) return Ok{};
  if (outTangents == nullptr) return Error::badInput(where + "out_tangents is NULL");
  if (outSigns == nullptr) return Error::badInput(where + "out_signs is NULL");

  const std::vector<Vec3f> positions = toVec3(a.positions, a.numVertices);
  const std::vector<Vec3f> normals = toVec3(a.cornerNormals, a.numCorners);
  const std::vector<Vec2f> uvs = toVec2(a.uvSets[0], a.numCorners);
  MeshView mesh;
  mesh.positions = positions;
  mesh.faceStart = {a.faceStart, a.numFaces + 1};
  mesh.cornerVertex = {a.cornerVertex, a.numCorners};
  mesh.cornerNormals = normals;
  mesh.cornerUvs = uvs;

  TangentOptions options;
  options.threads = threads;
  Result<CornerTangents> frames = computeTangents(mesh, options);
  if (!frames) return Error{frames.error().code, where + frames.error().message};
  if (frames->tangent.size() != a.numCorners || frames->sign.size() != a.numCorners) {
    return Error::internal(where + "computeTangents returned " +
                           std::to_string(frames->tangent.size()) + " tangents for " +
                           std::to_string(a.numCorners) + " corners");
  }
  for (std::size_t c = 0; c < a.numCorners; ++c) {
    const Vec3f t = frames->tangent[c];
    outTangents[3 * c] = t.x;
    outTangents[3 * c + 1] = t.y;
    outTangents[3 * c + 2] = t.z;
    outSigns[c] = frames->sign[c];
  }
  return Ok{};
}

// ---- sgbake_bake_map ---------------------------------------------------------------------------

/// The mesh of a validated sgbake_mesh as a Mesh: the caller's normals made unit as a file's
/// are (the C ABI accepts lengths within kUnitNormalTolerance), or smooth ones computed.
Mesh toMesh(const MeshArrays& a) {
  Mesh mesh;
  mesh.source = kInMemoryMeshName;
  mesh.positions = toVec3(a.positions, a.numVertices);
  mesh.faceStart.assign(a.faceStart, a.faceStart + a.numFaces + 1);
  mesh.cornerVertex.assign(a.cornerVertex, a.cornerVertex + a.numCorners);
  for (std::size_t i = 0; i < a.uvSets.size(); ++i) {
    mesh.uvSets.push_back({"UV" + std::to_string(i), toVec2(a.uvSets[i], a.numCorners)});
  }
  if (a.faceFlat != nullptr &&
      std::any_of(a.faceFlat, a.faceFlat + a.numFaces, [](std::uint8_t f) { return f != 0; })) {
    mesh.faceFlat.resize(a.numFaces);
    for (std::size_t f = 0; f < a.numFaces; ++f) mesh.faceFlat[f] = a.faceFlat[f] != 0 ? 1 : 0;
  }
  mesh.autoSmooth = a.autoSmooth;
  if (a.faceMaterial != nullptr && std::any_of(a.faceMaterial, a.faceMaterial + a.numFaces,
                                               [](std::uint32_t m) { return m != 0; })) {
    mesh.faceMaterial.assign(a.faceMaterial, a.faceMaterial + a.numFaces);
  }
  if (a.cornerNormals == nullptr) {
    computeSmoothNormals(mesh);
    return mesh;
  }
  mesh.cornerNormals = toVec3(a.cornerNormals, a.numCorners);
  for (Vec3f& n : mesh.cornerNormals) n = unitNormal(n);
  return mesh;
}

/// Checks the images of a call; @p where starts every message.
Status validateImages(const std::string& where, const sgbake_image* images, std::size_t count) {
  if (images == nullptr && count > 0) return Error::badInput(where + "images is NULL");
  std::set<std::string_view> names;
  for (std::size_t i = 0; i < count; ++i) {
    const sgbake_image& image = images[i];
    const std::string label = "images[" + std::to_string(i) + "]";
    if (image.name == nullptr) return Error::badInput(where + label + ".name is NULL");
    const std::string named = label + " ('" + printableText(image.name) + "')";
    if (!names.insert(image.name).second) {
      return Error::badInput(where + named + ": another image has the same name");
    }
    if (image.width < 1 || image.height < 1 || image.width > kMaxImageSide ||
        image.height > kMaxImageSide) {
      return Error::badInput(where + named + ": size " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " is out of range 1..." +
                             std::to_string(kMaxImageSide));
    }
    if (image.channels < 1 || image.channels > 4) {
      return Error::badInput(where + named + ": channels = " + std::to_string(image.channels) +
                             " (must be 1 to 4)");
    }
    if (image.pixels == nullptr) return Error::badInput(where + named + ": pixels is NULL");
    const std::size_t values = static_cast<std::size_t>(image.width) *
                               static_cast<std::size_t>(image.height) *
                               static_cast<std::size_t>(image.channels);
    for (std::size_t v = 0; v < values; ++v) {
      if (!std::isfinite(image.pixels[v])) {
        const std::size_t texel = v / static_cast<std::size_t>(image.channels);
        return Error::badInput(where + named + ": pixel " + std::to_string(texel) +
                               " (column " + std::to_string(texel % image.width) + ", row " +
                               std::to_string(texel / image.width) +
                               " from the bottom) is not a finite number");
      }
    }
  }
  return Ok{};
}

/// The channels a plan asks of an in-memory image (rows bottom first, as Image stores them).
Image selectChannels(const sgbake_image& source, ImageChannels channels) {
  Image image(source.width, source.height, source.channels);
  std::copy_n(source.pixels, image.pixels().size(), image.pixels().begin());
  return selectImageChannels(std::move(image), channels);
}

struct BakeArguments {
  const char* sceneJson;
  const sgbake_mesh* mesh;
  const sgbake_image* images;
  std::size_t numImages;
  int threads;
  sgbake_progress* progress;
  float* outRgba;
  std::size_t outFloats;
};

Status bakeMapFromArrays(const BakeArguments& a) {
  const std::string where = "sgbake_bake_map: ";
  if (a.threads < 0) {
    return Error::badInput(where + "threads = " + std::to_string(a.threads) + " (must be >= 0)");
  }
  if (a.sceneJson == nullptr) return Error::badInput(where + "scene_json is NULL");
  if (a.mesh == nullptr) return Error::badInput(where + "mesh is NULL");
  if (a.outRgba == nullptr) return Error::badInput(where + "out_rgba is NULL");

  SceneParseOptions parseOptions;
  parseOptions.inMemory = true;
  parseOptions.name = "sgbake_bake_map: scene_json";
  Result<Scene> scene = parseScene(a.sceneJson, parseOptions);
  if (!scene) return scene.error();
  if (scene->outputs.size() != 1) {
    return Error::badInput(where + "scene_json: has " + std::to_string(scene->outputs.size()) +
                           " outputs (sgbake_bake_map bakes exactly one)");
  }
  const SceneOutput output = scene->outputs[0];
  const std::size_t texels =
      static_cast<std::size_t>(output.width) * static_cast<std::size_t>(output.height);
  if (a.outFloats != 4 * texels) {
    return Error::badInput(where + "out_floats = " + std::to_string(a.outFloats) + " but the " +
                           std::to_string(output.width) + "x" + std::to_string(output.height) +
                           " output needs " + std::to_string(4 * texels) + " (width x height x 4)");
  }

  const sgbake_mesh& m = *a.mesh;
  MeshArrays arrays{m.positions,        m.num_vertices,   m.face_start, m.num_faces,
                    m.corner_vertex,    m.corner_normals, true,         m.face_flat,
                    m.auto_smooth != 0, m.face_material,  {},           {},
                    m.num_corners};
  if (m.num_uv_sets < 1 || m.num_uv_sets > static_cast<std::size_t>(kMaxUvSets)) {
    return Error::badInput(where + "num_uv_sets = " + std::to_string(m.num_uv_sets) +
                           " (must be 1 to " + std::to_string(kMaxUvSets) + ")");
  }
  if (m.corner_uvs == nullptr) return Error::badInput(where + "corner_uvs is NULL");
  for (std::size_t i = 0; i < m.num_uv_sets; ++i) {
    arrays.uvSets.push_back(m.corner_uvs[i]);
    arrays.uvNames.push_back("corner_uvs[" + std::to_string(i) + "]");
  }
  if (Status valid = validateMesh(where, arrays); !valid) return valid;
  if (m.num_faces == 0) return Error::badInput(where + "the mesh has no faces");
  if (Status valid = validateImages(where, a.images, a.numImages); !valid) return valid;

  PlanOptions planOptions{.force = true, .useManifest = false};
  for (std::size_t i = 0; i < a.numImages; ++i) planOptions.imageNames.insert(a.images[i].name);
  Result<Plan> plan = makePlan(std::move(*scene), planOptions);
  if (!plan) return Error{plan.error().code, where + plan.error().message};
  const Mesh mesh = toMesh(arrays);
  MemoryInputs inputs;
  inputs.mesh = &mesh;
  inputs.image = [&](const PlannedImage& planned) -> Result<Image> {
    const std::string name = planned.path.string();
    for (std::size_t i = 0; i < a.numImages; ++i) {
      if (name == a.images[i].name) {
        if (channelsToRead(planned.channels, a.images[i].channels) < 0) {
          return Error::badInput(where + "image '" + name + "' has " +
                                 std::to_string(a.images[i].channels) + " channel(s) but " +
                                 channelsNeeded(planned.channels) + " by " + planned.users.front());
        }
        return selectChannels(a.images[i], planned.channels);
      }
    }
    return Error::badInput(where + planned.users.front() + ": no image named '" + printableText(name) +
                           "' among the " + std::to_string(a.numImages) + " given");
  };
  BakeProgressCallback onRows;
  if (a.progress != nullptr) {
    std::atomic_ref<float>(a.progress->fraction).store(0.0f, std::memory_order_relaxed);
    onRows = [progress = a.progress](int rowsDone, int rows) {
      const float fraction = static_cast<float>(rowsDone) / static_cast<float>(rows);
      std::atomic_ref<float>(progress->fraction).store(fraction, std::memory_order_relaxed);
      return std::atomic_ref<std::int32_t>(progress->cancel).load(std::memory_order_relaxed) == 0;
    };
  }
  Result<FloatImage> baked = bakeOutputInMemory(*plan, 0, inputs, a.threads, onRows);
  if (!baked) {
    const std::string& message = baked.error().message;
    if (message.starts_with(where)) return baked.error();
    return Error{baked.error().code, where + message};
  }

  // Rows top first → Blender's bottom-first RGBA.
  const FloatImage& image = *baked;
  const int channels = image.channels;
  for (int row = 0; row < image.height; ++row) {
    const int y = image.height - 1 - row;
    for (int x = 0; x < image.width; ++x) {
      float* rgba = a.outRgba + 4 * (static_cast<std::size_t>(y) * image.width + x);
      const std::size_t texel = static_cast<std::size_t>(row) * image.width + x;
      const float* value = image.pixels.data() + texel * static_cast<std::size_t>(channels);
      rgba[0] = value[0];
      rgba[1] = channels == 1 ? value[0] : value[1];
      rgba[2] = channels == 1 ? value[0] : channels == 2 ? 0.0f : value[2];
      rgba[3] = output.alpha ? image.coverage[texel] : 1.0f;
    }
  }
  return Ok{};
}

/// Runs @p body, turning its Status into the C status and message, and any exception into
/// SGBAKE_ERROR_INTERNAL: nothing escapes into the caller's C or Python.
template <class Body>
int guarded(const char* function, char* errorBuf, std::size_t errorBufSize, const Body& body) {
  const std::string where = std::string(function) + ": ";
  try {
    const Status status = body();
    if (status) return SGBAKE_OK;
    writeError(errorBuf, errorBufSize, status.error().message);
    return statusFor(status.error().code);
  } catch (const std::bad_alloc&) {
    writeError(errorBuf, errorBufSize, where + "out of memory");
  } catch (const std::exception& e) {
    writeError(errorBuf, errorBufSize, where + "internal error: " + e.what());
  } catch (...) {
    writeError(errorBuf, errorBufSize, where + "unknown internal error");
  }
  return SGBAKE_ERROR_INTERNAL;
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
  return sgbake::guarded("sgbake_compute_tangents", error_buf, error_buf_size, [&] {
    const sgbake::MeshArrays arrays{
        positions, num_vertices, face_start, num_faces,    corner_vertex,  corner_normals, false,
        nullptr,   false,        nullptr,    {corner_uvs}, {"corner_uvs"}, num_corners};
    return sgbake::computeTangentsFromArrays(arrays, threads, out_tangents, out_signs);
  });
}

int sgbake_loop_triangles(const float* positions, size_t num_vertices, const uint32_t* face_start,
                          size_t num_faces, const uint32_t* corner_vertex, size_t num_corners,
                          uint32_t* out_triangles, char* error_buf, size_t error_buf_size) {
  return sgbake::guarded("sgbake_loop_triangles", error_buf, error_buf_size, [&] {
    sgbake::MeshArrays arrays;
    arrays.positions = positions;
    arrays.numVertices = num_vertices;
    arrays.faceStart = face_start;
    arrays.numFaces = num_faces;
    arrays.cornerVertex = corner_vertex;
    arrays.normalsOptional = true;
    arrays.numCorners = num_corners;
    return sgbake::loopTrianglesFromArrays(arrays, out_triangles);
  });
}

int sgbake_bake_map(const char* scene_json, const sgbake_mesh* mesh, const sgbake_image* images,
                    size_t num_images, int threads, sgbake_progress* progress, float* out_rgba,
                    size_t out_floats, char* error_buf, size_t error_buf_size) {
  return sgbake::guarded("sgbake_bake_map", error_buf, error_buf_size, [&] {
    return sgbake::bakeMapFromArrays(
        {scene_json, mesh, images, num_images, threads, progress, out_rgba, out_floats});
  });
}

}  // extern "C"
