/// @file validate_off.cpp
/// @brief The OFF checker (ASCII; OFF, COFF, NOFF, STOFF and their combinations [ST][C][N]OFF).
///
/// Layout accepted (Geomview's, one record per line; `#` starts a comment anywhere):
/// ```
/// [ST][C][N]OFF [nV nF [nE]]
/// nV nF [nE]                             (when not on the header line)
/// x y z [nx ny nz] [colour: 0, 1, 3 or 4 numbers] [s t]      nV times
/// n i0 i1 ... i(n-1) [colour: 0 to 4 numbers]                nF times, indices from 0
/// ```
/// Rejected with a clear message: `OFF BINARY`, 4OFF / nOFF (homogeneous or n-dimensional).
///
/// Why OpenMesh gets a PLY: OpenMesh 9.0's OFF reader takes the header flags (N, ST, C, BINARY)
/// from state that only its file-name API sets; reading a stream it reuses whatever the previous
/// OFF *file* set, so a NOFF stream loses its normals (verified) and a stale BINARY flag would
/// make it read text as binary. The checked OFF is therefore handed over as an ASCII PLY made of
/// the file's own number tokens (OpenMesh's PLY reader parses its header from the stream and
/// reads values with the same `>> float` as its OFF reader), which is independent of that state.
#include "mesh/validate.hpp"

namespace sgbake::detail {
namespace {

/// Flags of an OFF header keyword.
struct OffFlags {
  bool texcoords = false;  ///< ST: s t at the end of each vertex
  bool colours = false;    ///< C: a colour after the position (and normal)
  bool normals = false;    ///< N: nx ny nz after the position
};

class OffChecker {
 public:
  OffChecker(std::string_view bytes, std::string_view name) : bytes_(bytes), name_(name) {}

  Result<ValidatedFile> run();

 private:
  /// Next line with content (comments removed), split into tokens; false at the end.
  bool nextRecord() {
    std::string_view line;
    while (lines_.next(line)) {
      if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) {
        line = line.substr(0, hash);
      }
      tokens_.clear();
      Tokenizer tokenizer(line);
      std::string_view token;
      while (tokenizer.next(token)) tokens_.push_back(token);
      if (!tokens_.empty()) return true;
    }
    return false;
  }
  std::size_t line() const { return lines_.lineNumber(); }
  Error truncated(std::uint64_t have, std::uint64_t declared, std::string_view what) const {
    return errorAt(name_, std::max<std::size_t>(line(), 1),
                   "file is truncated: it ends after " + std::to_string(have) + " of " +
                       std::to_string(declared) + " " + std::string(what));
  }
  Status header(OffFlags& flags, std::uint64_t& numVertices, std::uint64_t& numFaces);
  Status vertex(const OffFlags& flags, std::string& ply);
  Status face(std::uint64_t numVertices, std::string& ply);
  Status readFloat(std::string_view token, std::string_view what, float& out, std::string& ply);

  std::string_view bytes_;
  std::string name_;
  LineReader lines_{{}};
  std::vector<std::string_view> tokens_;
  ParsedMesh mesh_;
  std::vector<std::uint32_t> face_;
};

Status OffChecker::header(OffFlags& flags, std::uint64_t& numVertices, std::uint64_t& numFaces) {
  if (!nextRecord()) return errorIn(name_, "file has no OFF header");
  std::string_view keyword = tokens_[0];
  if (keyword.substr(0, 2) == "ST") {
    flags.texcoords = true;
    keyword.remove_prefix(2);
  }
  if (keyword.substr(0, 1) == "C") {
    flags.colours = true;
    keyword.remove_prefix(1);
  }
  if (keyword.substr(0, 1) == "N") {
    flags.normals = true;
    keyword.remove_prefix(1);
  }
  if (keyword == "4OFF" || keyword == "nOFF" || keyword == "4nOFF") {
    return errorAt(
        name_, line(),
        "unsupported OFF variant " + quoted(tokens_[0]) + " (only 3D vertices are supported)");
  }
  if (keyword != "OFF") {
    return errorAt(name_, line(), "not an OFF file (header " + quoted(tokens_[0]) + ")");
  }
  std::size_t first = 1;  // counts may follow the keyword on the header line
  if (tokens_.size() > 1 && tokens_[1] == "BINARY") {
    return errorAt(name_, line(), "binary OFF is not supported (OFF BINARY); convert it to ASCII");
  }
  if (tokens_.size() == 1) {
    if (!nextRecord()) return errorIn(name_, "file is truncated: OFF header has no counts");
    first = 0;
  }
  const std::size_t numCounts = tokens_.size() - first;
  if (numCounts < 2 || numCounts > 3) {
    return errorAt(name_, line(),
                   std::string(first == 1 ? "OFF header has " : "OFF counts line has ") +
                       std::to_string(numCounts) + " value" + (numCounts == 1 ? "" : "s") +
                       (first == 1 ? " after the keyword" : "") +
                       "; it needs the vertex, face and edge counts alone (the vertices start "
                       "on the next line)");
  }
  std::uint64_t counts[3] = {};
  for (std::size_t i = 0; i < numCounts; ++i) {
    std::int64_t value = 0;
    const std::string_view token = tokens_[first + i];
    if (parseInteger(token, value) != NumberStatus::kOk || value < 0) {
      return errorAt(name_, line(), "OFF count " + quoted(token) + " is not a count");
    }
    if (static_cast<std::uint64_t>(value) > kMaxElements) {
      return errorAt(name_, line(), "OFF count " + quoted(token) + " is too large");
    }
    counts[i] = static_cast<std::uint64_t>(value);
  }
  numVertices = counts[0];
  numFaces = counts[1];
  return Ok{};
}

Status OffChecker::readFloat(std::string_view token, std::string_view what, float& out,
                             std::string& ply) {
  const NumberStatus status = parseReal(token, out);
  if (status != NumberStatus::kOk)
    return errorAt(name_, line(), describeBadNumber(status, what, token));
  ply += number_detail::stripPlus(token);  // the same token, so OpenMesh rounds it identically
  ply += ' ';
  return Ok{};
}

Status OffChecker::vertex(const OffFlags& flags, std::string& ply) {
  const std::size_t fixed = 3 + (flags.normals ? 3 : 0) + (flags.texcoords ? 2 : 0);
  if (tokens_.size() < fixed) {
    return errorAt(name_, line(),
                   "OFF vertex needs " + std::to_string(fixed) + " numbers, found " +
                       std::to_string(tokens_.size()));
  }
  const std::size_t colourValues = tokens_.size() - fixed;
  const bool colourOk = flags.colours ? (colourValues == 0 || colourValues == 1 ||
                                         colourValues == 3 || colourValues == 4)
                                      : colourValues == 0;
  if (!colourOk) {
    return errorAt(name_, line(),
                   "OFF vertex has " + std::to_string(tokens_.size()) +
                       " values; the header allows " + std::to_string(fixed) +
                       (flags.colours ? " plus a 1, 3 or 4 value colour" : ""));
  }
  std::size_t t = 0;
  float p[3] = {};
  for (float& c : p) {
    if (Status s = readFloat(tokens_[t++], "coordinate", c, ply); !s) return s;
  }
  mesh_.positions.push_back({p[0], p[1], p[2]});
  if (flags.normals) {
    float n[3] = {};
    for (float& c : n) {
      if (Status s = readFloat(tokens_[t++], "normal component", c, ply); !s) return s;
    }
    const Vec3f normal{n[0], n[1], n[2]};
    if (!(lengthSquared(cast<double>(normal)) > 0)) {
      return errorAt(name_, line(), "normal has zero length");
    }
    mesh_.normals.push_back(normal);
  }
  for (std::size_t i = 0; i < colourValues; ++i, ++t) {
    double ignored = 0;
    if (parseReal(tokens_[t], ignored) == NumberStatus::kSyntax) {
      return errorAt(name_, line(), "colour value " + quoted(tokens_[t]) + " is not a number");
    }
  }
  if (flags.texcoords) {
    float uv[2] = {};
    for (float& c : uv) {
      if (Status s = readFloat(tokens_[t++], "texture coordinate", c, ply); !s) return s;
    }
    mesh_.uvs.push_back({uv[0], uv[1]});
  }
  ply.back() = '\n';
  return Ok{};
}

Status OffChecker::face(std::uint64_t numVertices, std::string& ply) {
  constexpr std::size_t kMaxColourValues = 4;
  std::int64_t size = 0;
  if (parseInteger(tokens_[0], size) != NumberStatus::kOk || size < 0) {
    return errorAt(name_, line(), "OFF face size " + quoted(tokens_[0]) + " is not a count");
  }
  if (size < 3) {
    return errorAt(name_, line(),
                   "face has " + std::to_string(size) + (size == 1 ? " corner" : " corners") +
                       " (at least 3 are needed)");
  }
  const auto corners = static_cast<std::uint64_t>(size);
  if (tokens_.size() - 1 < corners) {
    return errorAt(name_, line(),
                   "face declares " + std::to_string(corners) + " corners but lists " +
                       std::to_string(tokens_.size() - 1));
  }
  if (tokens_.size() - 1 - corners > kMaxColourValues) {
    return errorAt(
        name_, line(),
        "face has more values than its " + std::to_string(corners) + " corners and a colour");
  }
  if (mesh_.cornerVertex.size() + corners > kMaxElements) {
    return errorAt(name_, line(), "too many corners");
  }
  face_.clear();
  for (std::size_t i = 1; i <= corners; ++i) {
    std::int64_t index = 0;
    const NumberStatus status = parseInteger(tokens_[i], index);
    if (status == NumberStatus::kSyntax) {
      return errorAt(name_, line(), "vertex index " + quoted(tokens_[i]) + " is not an integer");
    }
    if (status != NumberStatus::kOk || index < 0 ||
        static_cast<std::uint64_t>(index) >= numVertices) {
      return errorAt(name_, line(),
                     "face corner refers to vertex " + std::string(tokens_[i]) + " but only " +
                         std::to_string(numVertices) +
                         " vertices are defined (OFF indices start at 0)");
    }
    face_.push_back(static_cast<std::uint32_t>(index));
  }
  for (std::size_t i = 1 + corners; i < tokens_.size(); ++i) {
    double ignored = 0;
    if (parseReal(tokens_[i], ignored) == NumberStatus::kSyntax) {
      return errorAt(name_, line(), "colour value " + quoted(tokens_[i]) + " is not a number");
    }
  }
  std::uint32_t repeated = 0;
  if (findRepeatedVertex(face_.data(), face_.size(), repeated)) {
    return errorAt(name_, line(), "face uses vertex " + std::to_string(repeated) + " twice");
  }
  mesh_.cornerVertex.insert(mesh_.cornerVertex.end(), face_.begin(), face_.end());
  mesh_.faceStart.push_back(static_cast<std::uint32_t>(mesh_.cornerVertex.size()));
  ply += std::to_string(corners);
  for (const std::uint32_t v : face_) {
    ply += ' ';
    ply += std::to_string(v);
  }
  ply += '\n';
  return Ok{};
}

Result<ValidatedFile> OffChecker::run() {
  std::string_view text = bytes_;
  constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
  if (text.substr(0, kUtf8Bom.size()) == kUtf8Bom) text.remove_prefix(kUtf8Bom.size());
  if (Status s = checkTextBytes(text, name_, 1); !s) return s.error();
  lines_ = LineReader(text);

  OffFlags flags;
  std::uint64_t numVertices = 0, numFaces = 0;
  if (Status s = header(flags, numVertices, numFaces); !s) return s.error();

  std::string vertices, faces;  // the PLY body, in two parts
  vertices.reserve(text.size());
  for (std::uint64_t i = 0; i < numVertices; ++i) {
    if (!nextRecord()) return truncated(i, numVertices, "vertices");
    if (Status s = vertex(flags, vertices); !s) return s.error();
  }
  for (std::uint64_t f = 0; f < numFaces; ++f) {
    if (!nextRecord()) return truncated(f, numFaces, "faces");
    if (Status s = face(numVertices, faces); !s) return s.error();
  }
  if (nextRecord()) return errorAt(name_, line(), "unexpected data after the last face");
  if (numFaces == 0) return errorIn(name_, "mesh has no faces");

  ValidatedFile out;
  std::string& ply = out.openMeshBytes;
  ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(numVertices) +
        "\nproperty float x\nproperty float y\nproperty float z\n";
  if (flags.normals) ply += "property float nx\nproperty float ny\nproperty float nz\n";
  if (flags.texcoords) ply += "property float u\nproperty float v\n";
  ply += "element face " + std::to_string(numFaces) +
         "\nproperty list int int vertex_indices\nend_header\n";
  ply += vertices;
  ply += faces;
  out.openMeshExtension = ".ply";

  if (flags.normals) mesh_.normalBinding = Binding::kPerVertex;
  if (flags.texcoords) mesh_.uvBinding = Binding::kPerVertex;
  out.parsed = std::move(mesh_);
  return out;
}

}  // namespace

Result<ValidatedFile> validateOff(std::string_view bytes, std::string_view name) {
  return OffChecker(bytes, displayName(name)).run();
}

}  // namespace sgbake::detail
