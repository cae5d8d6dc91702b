/// @file validate_obj.cpp
/// @brief The OBJ checker: parses the whole file with from_chars, reports the first problem as
/// `<file>:<line>: <what>`, and prepares the buffer OpenMesh 9.0 can read safely.
///
/// Accepted: `v x y z [w | r g b [a]]`, `vt u v [w]`, `vn x y z`, `f` with 3 or more corners of
/// the forms `v`, `v/vt`, `v//vn`, `v/vt/vn` (positive indices count from 1 over the whole file,
/// negative ones back from the last element defined before the face). Ignored: comments (also
/// after a statement), blank lines, `\r\n` line ends, `\` line continuations (except of comment
/// lines), a UTF-8 BOM and the statements OpenMesh does not need (groups, objects, smoothing,
/// materials, lines, points, free-form geometry: kIgnoredStatements). Anything else is an error.
#include <algorithm>
#include <iterator>

#include "mesh/validate.hpp"

namespace sgbake::detail {
namespace {

/// Statements of the OBJ format (and common extensions such as `vc` vertex colours) that carry
/// nothing sgbake reads.
constexpr std::string_view kIgnoredStatements[] = {
    "o",      "g",          "s",         "usemtl",   "mtllib",   "l",    "p",
    "vp",     "cstype",     "deg",       "bmat",     "step",     "curv", "curv2",
    "surf",   "parm",       "trim",      "hole",     "scrv",     "sp",   "end",
    "con",    "mg",         "bevel",     "c_interp", "d_interp", "lod",  "usemap",
    "maplib", "shadow_obj", "trace_obj", "ctech",    "stech",    "vc"};

/// Keywords whose lines OpenMesh reads (everything else is blanked in its copy).
bool isDataStatement(std::string_view keyword) {
  return keyword == "v" || keyword == "vt" || keyword == "vn" || keyword == "f";
}

bool isIgnoredStatement(std::string_view keyword) {
  return std::find(std::begin(kIgnoredStatements), std::end(kIgnoredStatements), keyword) !=
         std::end(kIgnoredStatements);
}

/// The three element kinds a face corner refers to, for messages.
struct ElementKind {
  std::string_view singular;  ///< "vertex"
  std::string_view plural;    ///< "vertices"
};
constexpr ElementKind kVertexKind{"vertex", "vertices"};
constexpr ElementKind kUvKind{"texture coordinate", "texture coordinates"};
constexpr ElementKind kNormalKind{"normal", "normals"};

/// The `vt` or `vn` index of a corner that has none.
constexpr std::int64_t kNoIndex = -1;

/// True for a line whose first non-blank character is '#': a comment, which never continues
/// onto the next line even when it ends with a backslash (a Windows path, say).
bool isCommentLine(std::string_view line) {
  const std::size_t first = line.find_first_not_of(" \t");
  return first != std::string_view::npos && line[first] == '#';
}

class ObjChecker {
 public:
  ObjChecker(std::string_view bytes, std::string_view name) : bytes_(bytes), name_(name) {}

  Result<ValidatedFile> run();

 private:
  Status statement(std::string_view keyword, Tokenizer& tokens, std::size_t line);
  Status vertex(Tokenizer& tokens, std::size_t line);
  Status texcoord(Tokenizer& tokens, std::size_t line);
  Status normal(Tokenizer& tokens, std::size_t line);
  Status face(Tokenizer& tokens, std::size_t line);
  Status useMaterial(Tokenizer& tokens, std::size_t line);
  /// The index of material @p name, numbered in order of first use.
  std::uint32_t materialIndex(std::string_view name);
  /// Resolves one index of a corner: OBJ's 1-based or negative relative index → 0-based.
  /// Positive indices are checked against the final count at the end (forward references are
  /// legal OBJ); negative ones against the count defined so far.
  Status resolveIndex(std::string_view digits, std::string_view corner, std::size_t definedSoFar,
                      const ElementKind& kind, std::size_t line, std::int64_t& index);
  Status checkDeferredIndices();

  std::string_view bytes_;
  std::string name_;
  ValidatedFile out_;
  std::vector<std::size_t> faceLine_;  ///< #F, line of each face (for deferred messages)
  bool anyCornerWithUv_ = false;
  bool everyCornerWithNormal_ = true;
  bool anySmoothing_ = false;  ///< the file has an `s` statement
  bool smooth_ = false;        ///< the state `s` statements set: Blender's importer starts flat
  bool anyMaterial_ = false;   ///< the file has a `usemtl` statement
  /// The state `usemtl` statements set (index into materialNames); before the first, kNoMaterial
  /// (faces there get the name "").
  static constexpr std::uint32_t kNoMaterial = 0xffffffffu;
  std::uint32_t material_ = kNoMaterial;
};

/// Whether the argument of an `s` statement makes the faces that follow smooth, as Blender 3.4's
/// importer reads it: a smoothing group number > 0 does; 0, "off", and anything that is not a
/// number (even "on") do not.
bool smoothingGroupIsSmooth(Tokenizer& tokens) {
  std::string_view token;
  if (!tokens.next(token) || token.empty()) return false;
  long long group = 0;
  for (const char ch : token) {
    if (ch < '0' || ch > '9') return false;
    group = std::min<long long>(group * 10 + (ch - '0'), 1LL << 40);
  }
  return group > 0;
}

Result<ValidatedFile> ObjChecker::run() {
  std::string_view text = bytes_;
  constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
  if (text.substr(0, kUtf8Bom.size()) == kUtf8Bom) text.remove_prefix(kUtf8Bom.size());
  if (Status s = checkTextBytes(text, name_, 1); !s) return s.error();

  std::string& om = out_.openMeshBytes;
  om.reserve(text.size() + 1);
  LineReader lines(text);
  std::string_view physical;
  std::string joined;  // a logical line assembled from `\`-continued physical lines
  while (lines.next(physical)) {
    const std::size_t line = lines.lineNumber();
    std::size_t physicalLines = 1;
    std::string_view logical = physical;
    if (!physical.empty() && physical.back() == '\\' && !isCommentLine(physical)) {
      joined.assign(physical.substr(0, physical.size() - 1));
      std::string_view more;
      while (lines.next(more)) {
        ++physicalLines;
        joined += ' ';
        const bool continues = !more.empty() && more.back() == '\\';
        joined += continues ? more.substr(0, more.size() - 1) : more;
        if (!continues) break;
      }
      logical = joined;
    }
    if (const std::size_t hash = logical.find('#'); hash != std::string_view::npos) {
      logical = logical.substr(0, hash);
    }

    Tokenizer tokens(logical);
    std::string_view keyword;
    if (tokens.next(keyword)) {
      if (Status s = statement(keyword, tokens, line); !s) return s.error();
      if (isDataStatement(keyword)) om += logical;
    }
    om.append(physicalLines, '\n');
  }

  if (out_.parsed.numFaces() == 0) return errorIn(name_, "mesh has no faces");
  if (Status s = checkDeferredIndices(); !s) return s.error();

  ParsedMesh& mesh = out_.parsed;
  if (anyCornerWithUv_) {
    mesh.uvBinding = Binding::kPerCorner;
  } else {
    mesh.cornerUv.clear();  // `vt` lines no face uses: the mesh has no UVs
    mesh.uvs.clear();
  }
  if (!anySmoothing_) mesh.faceFlat.clear();  // the file does not say: smooth, as before
  if (!anyMaterial_) {
    mesh.faceMaterial.clear();
    mesh.materialNames.clear();
  }
  if (everyCornerWithNormal_) {
    mesh.normalBinding = Binding::kPerCorner;
  } else {
    mesh.cornerNormal.clear();  // file normals are used only when every corner has one
    mesh.normals.clear();
  }
  out_.openMeshExtension = ".obj";
  return std::move(out_);
}

Status ObjChecker::useMaterial(Tokenizer& tokens, std::size_t line) {
  const std::string_view name = tokens.rest();  // as Blender's importer, spaces and all
  if (name.empty()) return errorAt(name_, line, "usemtl without a material name");
  anyMaterial_ = true;
  material_ = materialIndex(name);
  return Ok{};
}

std::uint32_t ObjChecker::materialIndex(std::string_view name) {
  std::vector<std::string>& names = out_.parsed.materialNames;
  const auto found = std::find(names.begin(), names.end(), name);
  if (found != names.end()) return static_cast<std::uint32_t>(found - names.begin());
  names.emplace_back(name);
  return static_cast<std::uint32_t>(names.size() - 1);
}

Status ObjChecker::statement(std::string_view keyword, Tokenizer& tokens, std::size_t line) {
  if (keyword == "v") return vertex(tokens, line);
  if (keyword == "vt") return texcoord(tokens, line);
  if (keyword == "vn") return normal(tokens, line);
  if (keyword == "f") return face(tokens, line);
  if (keyword == "s") {
    anySmoothing_ = true;
    smooth_ = smoothingGroupIsSmooth(tokens);
    return Ok{};
  }
  if (keyword == "usemtl") return useMaterial(tokens, line);
  if (isIgnoredStatement(keyword)) return Ok{};
  return errorAt(name_, line, "unknown OBJ statement " + quoted(keyword));
}

/// Reads up to @p maxCount numbers; fewer than @p minCount or more than @p maxCount is an error.
/// @return the count read, or an error naming @p what.
Result<int> readFloats(Tokenizer& tokens, float* values, int minCount, int maxCount,
                       std::string_view what, std::string_view name, std::size_t line,
                       std::string_view needs) {
  int count = 0;
  std::string_view token;
  while (tokens.next(token)) {
    if (count == maxCount) return errorAt(name, line, "too many values for " + std::string(what));
    float value = 0;
    const NumberStatus status = parseReal(token, value);  // OpenMesh 9.0 reads `>> float`
    if (status != NumberStatus::kOk) {
      return errorAt(name, line, describeBadNumber(status, "coordinate", token));
    }
    values[count++] = value;
  }
  if (count < minCount)
    return errorAt(name, line, std::string(what) + " needs " + std::string(needs));
  return count;
}

Status ObjChecker::vertex(Tokenizer& tokens, std::size_t line) {
  // x y z, optionally w or an r g b [a] colour (which OpenMesh would read as a colour).
  constexpr int kMaxVertexValues = 7;
  float v[kMaxVertexValues] = {};
  Result<int> n = readFloats(tokens, v, 3, kMaxVertexValues, "vertex", name_, line, "x, y and z");
  if (!n) return n.error();
  if (out_.parsed.positions.size() >= kMaxElements)
    return errorAt(name_, line, "too many vertices");
  out_.parsed.positions.push_back({v[0], v[1], v[2]});
  return Ok{};
}

Status ObjChecker::texcoord(Tokenizer& tokens, std::size_t line) {
  // OpenMesh rejects the whole file on a one-component `vt`, so u and v are both required.
  float t[3] = {};
  Result<int> n = readFloats(tokens, t, 2, 3, "texture coordinate", name_, line, "u and v");
  if (!n) return n.error();
  if (out_.parsed.uvs.size() >= kMaxElements) {
    return errorAt(name_, line, "too many texture coordinates");
  }
  out_.parsed.uvs.push_back({t[0], t[1]});
  return Ok{};
}

Status ObjChecker::normal(Tokenizer& tokens, std::size_t line) {
  float n[3] = {};
  Result<int> count = readFloats(tokens, n, 3, 3, "normal", name_, line, "x, y and z");
  if (!count) return count.error();
  const Vec3f normal{n[0], n[1], n[2]};
  if (!(lengthSquared(cast<double>(normal)) > 0)) {
    return errorAt(name_, line, "normal has zero length");
  }
  if (out_.parsed.normals.size() >= kMaxElements) return errorAt(name_, line, "too many normals");
  out_.parsed.normals.push_back(normal);
  return Ok{};
}

Status ObjChecker::resolveIndex(std::string_view digits, std::string_view corner,
                                std::size_t definedSoFar, const ElementKind& kind, std::size_t line,
                                std::int64_t& index) {
  std::int64_t raw = 0;
  const NumberStatus status = parseInteger(digits, raw);
  if (status == NumberStatus::kSyntax) {
    return errorAt(name_, line,
                   "face corner " + quoted(corner) + " has an invalid " +
                       std::string(kind.singular) + " index");
  }
  if (status != NumberStatus::kOk || raw > static_cast<std::int64_t>(kMaxElements) ||
      raw < -static_cast<std::int64_t>(kMaxElements)) {
    return errorAt(name_, line,
                   "face corner " + quoted(corner) + " has an out-of-range " +
                       std::string(kind.singular) + " index");
  }
  if (raw == 0) {
    return errorAt(name_, line,
                   "face corner " + quoted(corner) + " uses " + std::string(kind.singular) +
                       " index 0 (OBJ indices start at 1)");
  }
  if (raw < 0) {
    index = static_cast<std::int64_t>(definedSoFar) + raw;
    if (index < 0) {
      return errorAt(name_, line,
                     "face corner refers to " + std::string(kind.singular) + " " +
                         std::to_string(raw) + " but only " + std::to_string(definedSoFar) + " " +
                         std::string(kind.plural) + " are defined before this line");
    }
  } else {
    index = raw - 1;  // checked in checkDeferredIndices once the whole file is read
  }
  return Ok{};
}

Status ObjChecker::face(Tokenizer& tokens, std::size_t line) {
  ParsedMesh& mesh = out_.parsed;
  const std::size_t first = mesh.cornerVertex.size();
  std::size_t withUv = 0;
  std::string_view corner;
  while (tokens.next(corner)) {
    // Split "v/vt/vn" into at most three fields.
    std::string_view fields[3];
    std::size_t numFields = 0;
    std::string_view rest = corner;
    for (;;) {
      if (numFields == 3) {
        return errorAt(name_, line, "face corner " + quoted(corner) + " has more than 3 indices");
      }
      const std::size_t slash = rest.find('/');
      fields[numFields++] = rest.substr(0, slash);
      if (slash == std::string_view::npos) break;
      rest.remove_prefix(slash + 1);
    }
    if (fields[0].empty()) {
      return errorAt(name_, line, "face corner " + quoted(corner) + " has no vertex index");
    }
    if ((numFields == 2 && fields[1].empty()) || (numFields == 3 && fields[2].empty())) {
      return errorAt(name_, line, "face corner " + quoted(corner) + " ends with an empty index");
    }
    if (mesh.cornerVertex.size() >= kMaxElements) return errorAt(name_, line, "too many corners");

    std::int64_t v = kNoIndex, vt = kNoIndex, vn = kNoIndex;
    if (Status s = resolveIndex(fields[0], corner, mesh.positions.size(), kVertexKind, line, v);
        !s) {
      return s;
    }
    if (numFields >= 2 && !fields[1].empty()) {
      if (Status s = resolveIndex(fields[1], corner, mesh.uvs.size(), kUvKind, line, vt); !s) {
        return s;
      }
      ++withUv;
    }
    if (numFields == 3) {
      if (Status s = resolveIndex(fields[2], corner, mesh.normals.size(), kNormalKind, line, vn);
          !s) {
        return s;
      }
    }
    mesh.cornerVertex.push_back(static_cast<std::uint32_t>(v));
    mesh.cornerUv.push_back(static_cast<std::int32_t>(vt));
    mesh.cornerNormal.push_back(static_cast<std::int32_t>(vn));
    if (vn == kNoIndex) everyCornerWithNormal_ = false;
  }

  const std::size_t count = mesh.cornerVertex.size() - first;
  if (count < 3) {
    return errorAt(name_, line,
                   "face has " + std::to_string(count) + (count == 1 ? " corner" : " corners") +
                       " (at least 3 are needed)");
  }
  // OpenMesh stores a face's UVs in order and skips corners without one: a face that gives UVs
  // to some corners only would get them on the wrong corners.
  if (withUv != 0 && withUv != count) {
    return errorAt(name_, line, "face gives texture coordinates to only some of its corners");
  }
  if (withUv != 0) anyCornerWithUv_ = true;
  std::uint32_t repeated = 0;
  if (findRepeatedVertex(mesh.cornerVertex.data() + first, count, repeated)) {
    return errorAt(name_, line, "face uses vertex " + std::to_string(repeated + 1ull) + " twice");
  }
  mesh.faceStart.push_back(static_cast<std::uint32_t>(mesh.cornerVertex.size()));
  mesh.faceFlat.push_back(smooth_ ? 0 : 1);
  mesh.faceMaterial.push_back(material_ != kNoMaterial ? material_ : materialIndex(""));
  faceLine_.push_back(line);
  return Ok{};
}

Status ObjChecker::checkDeferredIndices() {
  const ParsedMesh& mesh = out_.parsed;
  auto outOfRange = [&](std::size_t f, const ElementKind& kind, std::int64_t index,
                        std::size_t defined) {
    return errorAt(name_, faceLine_[f],
                   "face corner refers to " + std::string(kind.singular) + " " +
                       std::to_string(index + 1) + " but only " + std::to_string(defined) + " " +
                       std::string(defined == 1 ? kind.singular : kind.plural) +
                       (defined == 1 ? " is" : " are") + " defined");
  };
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
      if (mesh.cornerVertex[c] >= mesh.positions.size()) {
        return outOfRange(f, kVertexKind, mesh.cornerVertex[c], mesh.positions.size());
      }
      if (mesh.cornerUv[c] != kNoIndex &&
          static_cast<std::size_t>(mesh.cornerUv[c]) >= mesh.uvs.size()) {
        return outOfRange(f, kUvKind, mesh.cornerUv[c], mesh.uvs.size());
      }
      if (mesh.cornerNormal[c] != kNoIndex &&
          static_cast<std::size_t>(mesh.cornerNormal[c]) >= mesh.normals.size()) {
        return outOfRange(f, kNormalKind, mesh.cornerNormal[c], mesh.normals.size());
      }
    }
  }
  return Ok{};
}

}  // namespace

Result<ValidatedFile> validateObj(std::string_view bytes, std::string_view name) {
  return ObjChecker(bytes, displayName(name)).run();
}

}  // namespace sgbake::detail
