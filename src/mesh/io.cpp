/// @file io.cpp
/// @brief loadMesh: read the file once, validate it completely, let OpenMesh parse the validated
/// bytes, verify OpenMesh's result against the validator's, build the Mesh.
///
/// What comes from where:
/// - positions, faces and their corner order, per-corner OBJ UVs and per-vertex PLY/OFF normals
///   and UVs: OpenMesh, each value checked bit for bit against sgbake's own parse (a mismatch is
///   ErrorCode::kInternal: the two parsers disagree, which must never happen silently);
/// - OBJ per-corner normals: sgbake's parse (OpenMesh's importer keeps one normal per vertex).
///
/// OpenMesh facts this file relies on (9.0, verified by tests/mesh):
/// - after add_face, halfedge_handle(face) is the halfedge that points to the face's first
///   vertex; next_halfedge_handle walks the corners in the order they were given;
/// - a face that would make the mesh non-manifold is added on fresh copies of its vertices
///   (positions copied, nothing else); faces keep file order. sgbake maps the copies back to the
///   file's vertices, so the Mesh has exactly the file's vertices (as Blender would);
/// - for such a face, ImporterT::add_face_texcoords looks for the face's first *file* vertex,
///   does not find it among the copies, and stores the UVs starting one halfedge early (rotated
///   by one corner). sgbake reads them from where OpenMesh put them (and verifies them);
/// - halfedge texcoords of faces without `vt` are left uninitialised: such corners get (0, 0)
///   from sgbake, never from OpenMesh;
/// - the readers are global singletons with per-file state, and they print to omerr()/omlog():
///   reads are serialised by a mutex and the streams are silenced while a read runs.
// OpenMesh's VectorT has a default constructor that leaves its components uninitialised on
// purpose, and PropertyT::push_back() appends `T()`: with sanitizers GCC 12 reports that (in
// standard-library code inlined from OpenMesh's headers) as -Wmaybe-uninitialized. sgbake never
// reads such a value (see "halfedge texcoords" above). The pragma must precede every include.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "sgbake/mesh/io.hpp"
#include "sgbake/subdiv/subdivide.hpp"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <system_error>

#include "mesh/validate.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/core/text.hpp"
#include "sgbake/mesh/normals.hpp"

namespace sgbake {
namespace {

using OmMesh = OpenMesh::PolyMesh_ArrayKernelT<>;
using detail::Binding;
using detail::ParsedMesh;
using detail::ValidatedFile;

enum class Format { kObj, kPly, kOff };

/// "obj" / ".OBJ" → Format; empty when unknown.
std::optional<Format> formatOf(std::string_view extension) {
  if (!extension.empty() && extension.front() == '.') extension.remove_prefix(1);
  const std::string lower = toLowerAscii(extension);
  if (lower == "obj") return Format::kObj;
  if (lower == "ply") return Format::kPly;
  if (lower == "off") return Format::kOff;
  return std::nullopt;
}

/// Serialises OpenMesh reads (its readers keep per-file state in global singletons) and
/// silences its log streams for the duration, restoring their previous state afterwards.
class OpenMeshReadSession {
 public:
  OpenMeshReadSession() : lock_(mutex()) {
    for (std::size_t i = 0; i < kNumStreams; ++i) {
      OpenMesh::mostream& s = stream(i);
      wasEnabled_[i] = s.is_enabled();
      s.disable();
    }
  }
  ~OpenMeshReadSession() {
    for (std::size_t i = 0; i < kNumStreams; ++i) {
      if (wasEnabled_[i]) stream(i).enable();
    }
  }
  OpenMeshReadSession(const OpenMeshReadSession&) = delete;
  OpenMeshReadSession& operator=(const OpenMeshReadSession&) = delete;

 private:
  static constexpr std::size_t kNumStreams = 3;
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static OpenMesh::mostream& stream(std::size_t i) {
    return i == 0 ? ::omerr() : i == 1 ? ::omlog() : ::omout();
  }
  std::scoped_lock<std::mutex> lock_;
  bool wasEnabled_[kNumStreams] = {};
};

Error disagreement(std::string_view name, const std::string& what) {
  return Error::internal(std::string(name) + ": OpenMesh and sgbake's validator disagree: " + what);
}

/// Lets OpenMesh read the validated bytes and builds the Mesh, verifying every value OpenMesh
/// produced against the validator's parse.
Result<Mesh> readWithOpenMesh(const ValidatedFile& file, std::string_view name) {
  const ParsedMesh& parsed = file.parsed;
  const bool isObj = file.openMeshExtension == ".obj";
  const bool perVertexUvs = parsed.uvBinding == Binding::kPerVertex;
  const bool perVertexNormals = parsed.normalBinding == Binding::kPerVertex;

  OmMesh om;
  OpenMesh::IO::Options options;
  if (isObj) {
    // Per-corner UVs only: requesting vertex normals or texcoords would enable the OBJ reader's
    // per-vertex paths (last write wins), which sgbake does not use.
    om.request_halfedge_texcoords2D();
    options += OpenMesh::IO::Options::FaceTexCoord;
  } else {
    if (perVertexUvs) {
      om.request_vertex_texcoords2D();
      options += OpenMesh::IO::Options::VertexTexCoord;
    }
    if (perVertexNormals) {
      om.request_vertex_normals();
      options += OpenMesh::IO::Options::VertexNormal;
    }
  }
  bool ok = false;
  {
    std::istringstream in(file.openMeshBytes, std::ios::in | std::ios::binary);
    OpenMeshReadSession session;
    ok = OpenMesh::IO::read_mesh(om, in, file.openMeshExtension, options);
  }
  if (!ok)
    return Error::internal(std::string(name) + ": OpenMesh could not read the validated file");
  if ((perVertexUvs && !options.vertex_has_texcoord()) ||
      (perVertexNormals && !options.vertex_has_normal())) {
    return disagreement(name, "OpenMesh did not find the normals or UVs");
  }

  const std::size_t numVertices = parsed.positions.size();
  const std::size_t numFaces = parsed.numFaces();
  if (om.n_vertices() < numVertices || om.n_faces() != numFaces) {
    return disagreement(name, "OpenMesh read " + std::to_string(om.n_vertices()) +
                                  " vertices and " + std::to_string(om.n_faces()) +
                                  " faces, the validator " + std::to_string(numVertices) + " and " +
                                  std::to_string(numFaces));
  }

  Mesh mesh;
  mesh.source = std::string(name);
  mesh.positions.resize(numVertices);
  for (std::size_t v = 0; v < numVertices; ++v) {
    const OmMesh::Point& p = om.point(OmMesh::VertexHandle(static_cast<int>(v)));
    mesh.positions[v] = {p[0], p[1], p[2]};
    if (!detail::sameBits(mesh.positions[v], parsed.positions[v])) {
      return disagreement(name, "position of vertex " + std::to_string(v));
    }
  }

  mesh.faceStart = parsed.faceStart;
  mesh.faceFlat = parsed.faceFlat;
  mesh.faceMaterial = parsed.faceMaterial;
  mesh.materialNames = parsed.materialNames;
  mesh.cornerVertex.resize(parsed.cornerVertex.size());
  const bool hasUvs = parsed.uvBinding != Binding::kNone;
  std::vector<Vec2f> uvs(hasUvs ? parsed.cornerVertex.size() : 0);

  for (std::size_t f = 0; f < numFaces; ++f) {
    const auto fh = OmMesh::FaceHandle(static_cast<int>(f));
    const std::uint32_t begin = parsed.faceStart[f];
    const std::uint32_t size = parsed.faceStart[f + 1] - begin;
    const auto first = om.halfedge_handle(fh);

    // Where OpenMesh put this face's first per-corner UV (see the file comment).
    auto uvHalfedge = first;
    if (isObj && hasUvs) {
      const auto target = OmMesh::VertexHandle(static_cast<int>(parsed.cornerVertex[begin]));
      const auto last = om.prev_halfedge_handle(first);
      while (om.to_vertex_handle(uvHalfedge) != target && uvHalfedge != last) {
        uvHalfedge = om.next_halfedge_handle(uvHalfedge);
      }
    }

    auto h = first;
    for (std::uint32_t i = 0; i < size; ++i) {
      const std::uint32_t c = begin + i;
      const std::uint32_t fileVertex = parsed.cornerVertex[c];
      const auto omVertex = om.to_vertex_handle(h);
      // Either the file's vertex or OpenMesh's copy of it for a non-manifold face.
      const bool same = static_cast<std::size_t>(omVertex.idx()) == fileVertex;
      const OmMesh::Point& p = om.point(omVertex);
      const bool copy = static_cast<std::size_t>(omVertex.idx()) >= numVertices &&
                        detail::sameBits(Vec3f{p[0], p[1], p[2]}, parsed.positions[fileVertex]);
      if (!same && !copy) {
        return disagreement(name, "corner " + std::to_string(i) + " of face " + std::to_string(f));
      }
      mesh.cornerVertex[c] = fileVertex;

      if (isObj && hasUvs && parsed.cornerUv[c] >= 0) {
        const auto& t = om.texcoord2D(uvHalfedge);
        uvs[c] = {t[0], t[1]};
        if (!detail::sameBits(uvs[c], parsed.uvs[static_cast<std::size_t>(parsed.cornerUv[c])])) {
          return disagreement(
              name, "UV of corner " + std::to_string(i) + " of face " + std::to_string(f));
        }
      } else if (perVertexUvs) {
        const auto& t = om.texcoord2D(OmMesh::VertexHandle(static_cast<int>(fileVertex)));
        uvs[c] = {t[0], t[1]};
        if (!detail::sameBits(uvs[c], parsed.uvs[fileVertex])) {
          return disagreement(name, "UV of vertex " + std::to_string(fileVertex));
        }
      }  // else: an OBJ face without `vt` in a file with UVs: (0, 0)
      h = om.next_halfedge_handle(h);
      uvHalfedge = om.next_halfedge_handle(uvHalfedge);
    }
    if (h != first) {
      return disagreement(name, "face " + std::to_string(f) + " has a different number of corners");
    }
  }
  if (hasUvs) mesh.uvSets.push_back({"UVMap", std::move(uvs)});

  if (parsed.normalBinding == Binding::kPerCorner) {
    mesh.cornerNormals.resize(mesh.cornerVertex.size());
    for (std::size_t c = 0; c < mesh.cornerNormals.size(); ++c) {
      mesh.cornerNormals[c] =
          unitNormal(parsed.normals[static_cast<std::size_t>(parsed.cornerNormal[c])]);
    }
    mesh.normalSource = NormalSource::kFile;
    mesh.autoSmooth = normalsShowAutoSmooth(mesh);
  } else if (perVertexNormals) {
    std::vector<Vec3f> vertexNormals(numVertices);
    for (std::size_t v = 0; v < numVertices; ++v) {
      const auto& n = om.normal(OmMesh::VertexHandle(static_cast<int>(v)));
      const Vec3f normal{n[0], n[1], n[2]};
      if (!detail::sameBits(normal, parsed.normals[v])) {
        return disagreement(name, "normal of vertex " + std::to_string(v));
      }
      vertexNormals[v] = unitNormal(normal);
    }
    mesh.cornerNormals.resize(mesh.cornerVertex.size());
    for (std::size_t c = 0; c < mesh.cornerNormals.size(); ++c) {
      mesh.cornerNormals[c] = vertexNormals[mesh.cornerVertex[c]];
    }
    mesh.normalSource = NormalSource::kFile;
  } else {
    computeSmoothNormals(mesh);
  }
  return mesh;
}

}  // namespace

Result<Mesh> loadMeshFromMemory(std::string_view bytes, std::string_view extension,
                                std::string_view name, const LoadOptions& options) {
  const std::string shownName = detail::displayName(name);
  const std::optional<Format> format = formatOf(extension);
  if (!format) {
    return detail::errorIn(shownName, "unsupported file extension " + detail::quoted(extension) +
                                          " (expected .obj, .ply or .off)");
  }
  if (bytes.empty()) return detail::errorIn(shownName, "file is empty");

  Result<ValidatedFile> validated = *format == Format::kObj   ? detail::validateObj(bytes, name)
                                    : *format == Format::kPly ? detail::validatePly(bytes, name)
                                                              : detail::validateOff(bytes, name);
  if (!validated) return validated.error();
  if (options.requireUvs && validated->parsed.uvBinding == Binding::kNone) {
    return detail::errorIn(shownName,
                           "mesh has no texture coordinates (UVs are required for tangents)");
  }

  Result<Mesh> mesh = readWithOpenMesh(*validated, shownName);
  if (!mesh) return mesh;
  if (Status s = validate(*mesh); !s) {
    return Error::internal("loaded mesh breaks an invariant: " + s.error().message);
  }
  if (options.subdivision.changesMesh()) return subdivideMesh(*mesh, options.subdivision);
  return mesh;
}

Result<Mesh> loadMesh(const std::filesystem::path& path, const LoadOptions& options) {
  const std::string name = path.string();
  const std::string shownName = detail::displayName(name);
  if (!formatOf(path.extension().string())) {
    return detail::errorIn(shownName, "unsupported file extension " +
                                          detail::quoted(path.extension().string()) +
                                          " (expected .obj, .ply or .off)");
  }

  // Read the whole file once; everything after works on these bytes.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(name.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) {
    return detail::errorIn(shownName,
                           "cannot open file: " + std::generic_category().message(errno));
  }
  std::string bytes;
  std::error_code sizeError;
  const std::uintmax_t expectedSize = std::filesystem::file_size(path, sizeError);
  constexpr std::size_t kChunk = std::size_t{1} << 20;
  if (!sizeError) bytes.reserve(static_cast<std::size_t>(expectedSize) + kChunk);
  std::size_t got = 0;
  do {
    const std::size_t old = bytes.size();
    bytes.resize(old + kChunk);
    got = std::fread(bytes.data() + old, 1, kChunk, file.get());
    bytes.resize(old + got);
  } while (got == kChunk);
  if (std::ferror(file.get())) {
    return detail::errorIn(shownName,
                           "cannot read file: " + std::generic_category().message(errno));
  }
  return loadMeshFromMemory(bytes, path.extension().string(), name, options);
}

}  // namespace sgbake
