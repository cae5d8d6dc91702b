/// @file validate_ply.cpp
/// @brief The PLY checker (ASCII, binary little and big endian).
///
/// Reads the header, checks that OpenMesh 9.0 can read every element it will look at, then walks
/// the whole body: element counts against the data (truncation), finite positions, normals and
/// UVs, vertex indices in range, at least 3 distinct vertices per face, nothing after the last
/// element.
///
/// OpenMesh 9.0's PLY reader has limits and quirks this file works around or rejects:
/// - its binary reader reads positions, normals and UVs as float or double (rounded to float);
///   an integer type reads as 0 and is reported on std::cerr: rejected;
/// - it skips an unknown property by the size of one scalar, so a list property it does not know
///   (e.g. MeshLab's per-corner `texcoord`) misaligns everything after it: rejected, unless it
///   belongs to an element after the faces, which OpenMesh never reads;
/// - it drops face properties declared before `vertex_indices`: rejected;
/// - it finds the binary body by seeking 12 bytes past the end of the last header token, which
///   is wrong after a trailing space or a comment line; it knows list-length types uchar, uint8,
///   uint16 and int only; it reads colours and other known names with type-dependent code.
///   So OpenMesh gets a canonical header instead of the file's: same elements, counts, types and
///   order up to the face element; the positions, normals and UVs under OpenMesh's names (`u`/`v`
///   for the `s`/`t`/`texture_u`/... aliases); every other property renamed so that OpenMesh
///   skips it; list lengths re-declared with a supported type of the same size. The body bytes
///   are handed over unchanged.
#include <bit>
#include <cstring>
#include <optional>

#include "mesh/validate.hpp"

namespace sgbake::detail {
namespace {

enum class PlyType : std::uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};

struct TypeName {
  std::string_view name;
  PlyType type;
};
constexpr TypeName kTypeNames[] = {
    {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
    {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
    {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
    {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
    {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
    {"float64", PlyType::kFloat64}};

std::optional<PlyType> typeFromName(std::string_view name) {
  for (const TypeName& t : kTypeNames) {
    if (t.name == name) return t.type;
  }
  return std::nullopt;
}

/// Name of @p type in the canonical header (all of these are understood by OpenMesh 9.0).
std::string_view canonicalName(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
      return "char";
    case PlyType::kUint8:
      return "uchar";
    case PlyType::kInt16:
      return "short";
    case PlyType::kUint16:
      return "ushort";
    case PlyType::kInt32:
      return "int";
    case PlyType::kUint32:
      return "uint";
    case PlyType::kFloat32:
      return "float";
    case PlyType::kFloat64:
      return "double";
  }
  return "float";
}

std::size_t sizeOf(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

bool isInteger(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }

/// What a property means to sgbake.
enum class Role { kOther, kX, kY, kZ, kNx, kNy, kNz, kU, kV, kVertexIndices };

/// The name OpenMesh knows a role by (canonical header).
std::string_view roleName(Role role) {
  switch (role) {
    case Role::kX:
      return "x";
    case Role::kY:
      return "y";
    case Role::kZ:
      return "z";
    case Role::kNx:
      return "nx";
    case Role::kNy:
      return "ny";
    case Role::kNz:
      return "nz";
    case Role::kU:
      return "u";
    case Role::kV:
      return "v";
    case Role::kVertexIndices:
      return "vertex_indices";
    case Role::kOther:
      break;
  }
  return "";
}

/// What a value of @p role is called in messages.
std::string_view roleDescription(Role role) {
  switch (role) {
    case Role::kNx:
    case Role::kNy:
    case Role::kNz:
      return "normal component";
    case Role::kU:
    case Role::kV:
      return "texture coordinate";
    default:
      return "coordinate";
  }
}

Role vertexRole(std::string_view name) {
  if (name == "x") return Role::kX;
  if (name == "y") return Role::kY;
  if (name == "z") return Role::kZ;
  if (name == "nx") return Role::kNx;
  if (name == "ny") return Role::kNy;
  if (name == "nz") return Role::kNz;
  if (name == "u" || name == "s" || name == "texture_u" || name == "texture_s") return Role::kU;
  if (name == "v" || name == "t" || name == "texture_v" || name == "texture_t") return Role::kV;
  return Role::kOther;
}

struct Property {
  std::string name;
  PlyType type = PlyType::kFloat32;  ///< scalar type, or a list's entry type
  bool isList = false;
  PlyType countType = PlyType::kUint8;  ///< a list's length type
  Role role = Role::kOther;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t bodyOffset = 0;  ///< first byte after the end_header line
  std::size_t bodyLine = 0;    ///< line number of the body's first line (ASCII messages)
  int vertexElement = -1;
  int faceElement = -1;
  bool hasNormals = false;
  bool hasUvs = false;
};

/// Parses the header lines up to end_header.
Result<Header> parseHeader(std::string_view bytes, std::string_view name) {
  Header header;
  LineReader lines(bytes);
  std::string_view line;
  bool sawFormat = false;
  bool first = true;
  while (lines.next(line)) {
    const std::size_t n = lines.lineNumber();
    for (const char ch : line) {
      const auto c = static_cast<unsigned char>(ch);
      if ((c < 0x20 && c != '\t') || c == 0x7f) {
        return errorAt(name, n, "binary data in the PLY header (no end_header line before it?)");
      }
    }
    Tokenizer tokens(line);
    std::string_view keyword;
    if (first) {
      first = false;
      if (!tokens.next(keyword) || keyword != "ply") {
        return errorIn(name, "not a PLY file (the first line is not 'ply')");
      }
      continue;
    }
    if (!tokens.next(keyword)) continue;  // blank line
    std::vector<std::string_view> args;
    std::string_view arg;
    while (tokens.next(arg)) args.push_back(arg);

    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") {
      if (!sawFormat) return errorAt(name, n, "PLY header has no format line");
      header.bodyOffset = lines.offset();
      header.bodyLine = n + 1;
      return header;
    }
    if (keyword == "format") {
      if (sawFormat) return errorAt(name, n, "PLY header has a second format line");
      if (args.size() != 2) return errorAt(name, n, "PLY format line needs a format and a version");
      if (args[0] == "ascii") {
        header.format = Format::kAscii;
      } else if (args[0] == "binary_little_endian") {
        header.format = Format::kBinaryLittleEndian;
      } else if (args[0] == "binary_big_endian") {
        header.format = Format::kBinaryBigEndian;
      } else {
        return errorAt(name, n, "unknown PLY format " + quoted(args[0]));
      }
      if (args[1] != "1.0") return errorAt(name, n, "unsupported PLY version " + quoted(args[1]));
      sawFormat = true;
    } else if (keyword == "element") {
      std::int64_t count = 0;
      if (args.size() != 2) return errorAt(name, n, "PLY element line needs a name and a count");
      if (parseInteger(args[1], count) != NumberStatus::kOk || count < 0) {
        return errorAt(name, n, "PLY element count " + quoted(args[1]) + " is not a count");
      }
      if (static_cast<std::uint64_t>(count) > kMaxElements) {
        return errorAt(name, n, "PLY element " + quoted(args[0]) + " has too many entries");
      }
      header.elements.push_back({std::string(args[0]), static_cast<std::uint64_t>(count), {}});
    } else if (keyword == "property") {
      if (header.elements.empty()) return errorAt(name, n, "PLY property before any element");
      Property property;
      if (!args.empty() && args[0] == "list") {
        if (args.size() != 4) {
          return errorAt(name, n, "PLY list property needs a length type, a value type and a name");
        }
        const auto countType = typeFromName(args[1]);
        const auto entryType = typeFromName(args[2]);
        if (!countType) return errorAt(name, n, "unknown PLY type " + quoted(args[1]));
        if (!entryType) return errorAt(name, n, "unknown PLY type " + quoted(args[2]));
        if (!isInteger(*countType)) {
          return errorAt(name, n, "PLY list length type " + quoted(args[1]) + " is not an integer");
        }
        property = {std::string(args[3]), *entryType, true, *countType, Role::kOther};
      } else {
        if (args.size() != 2) return errorAt(name, n, "PLY property needs a type and a name");
        const auto type = typeFromName(args[0]);
        if (!type) return errorAt(name, n, "unknown PLY type " + quoted(args[0]));
        property = {std::string(args[1]), *type, false, PlyType::kUint8, Role::kOther};
      }
      header.elements.back().properties.push_back(std::move(property));
    } else {
      return errorAt(name, n, "unknown PLY header line " + quoted(line));
    }
  }
  return errorIn(name, "PLY header has no end_header line");
}

/// Assigns roles and rejects what OpenMesh 9.0 would misread (see the file comment).
Status checkStructure(Header& header, std::string_view name) {
  const bool binary = header.format != Format::kAscii;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    Element& element = header.elements[e];
    const std::string elementName = quoted(element.name);
    if (element.properties.empty() && element.count > 0) {
      return errorIn(name, "PLY element " + elementName + " has entries but no properties");
    }
    if (element.name == "vertex") {
      if (header.vertexElement >= 0) return errorIn(name, "PLY file has two vertex elements");
      header.vertexElement = static_cast<int>(e);
      bool seen[static_cast<int>(Role::kVertexIndices) + 1] = {};
      for (Property& p : element.properties) {
        p.role = vertexRole(p.name);
        if (p.role == Role::kOther) {
          if (p.isList) {
            return errorIn(name,
                           "PLY vertex list property " + quoted(p.name) + " is not supported");
          }
          continue;
        }
        if (p.isList) {
          return errorIn(name, "PLY vertex property " + quoted(p.name) + " must not be a list");
        }
        if (seen[static_cast<int>(p.role)]) {
          return errorIn(name, "PLY vertex element defines " + quoted(roleName(p.role)) +
                                   " twice (aliases s, t, texture_u, texture_v count as u, v)");
        }
        seen[static_cast<int>(p.role)] = true;
        if (binary && isInteger(p.type)) {
          return errorIn(name, "binary PLY vertex property " + quoted(p.name) + " is " +
                                   std::string(canonicalName(p.type)) +
                                   "; positions, normals and UVs must be float or double");
        }
      }
      for (const Role r : {Role::kX, Role::kY, Role::kZ}) {
        if (!seen[static_cast<int>(r)]) {
          return errorIn(name, "PLY vertex element has no " + quoted(roleName(r)) + " property");
        }
      }
      const int normals = seen[int(Role::kNx)] + seen[int(Role::kNy)] + seen[int(Role::kNz)];
      if (normals != 0 && normals != 3) {
        return errorIn(name, "PLY vertex normals need all of nx, ny and nz");
      }
      if (seen[int(Role::kU)] != seen[int(Role::kV)]) {
        return errorIn(name, "PLY texture coordinates need both u and v (or s and t)");
      }
      header.hasNormals = normals == 3;
      header.hasUvs = seen[int(Role::kU)];
    } else if (element.name == "face") {
      if (header.faceElement >= 0) return errorIn(name, "PLY file has two face elements");
      if (header.vertexElement < 0) {
        return errorIn(name, "PLY face element comes before the vertex element");
      }
      header.faceElement = static_cast<int>(e);
      for (std::size_t i = 0; i < element.properties.size(); ++i) {
        Property& p = element.properties[i];
        const bool isIndexList = p.name == "vertex_indices" || p.name == "vertex_index";
        if (isIndexList) {
          if (i != 0) {
            return errorIn(name, "PLY face properties before vertex_indices are not supported");
          }
          if (!p.isList || !isInteger(p.type)) {
            return errorIn(name, "PLY vertex_indices must be a list of integers");
          }
          p.role = Role::kVertexIndices;
        } else if (p.isList) {
          return errorIn(name, "PLY face list property " + quoted(p.name) +
                                   " is not supported (only vertex_indices)");
        } else if (i == 0) {
          return errorIn(name, "PLY face properties before vertex_indices are not supported");
        }
      }
      if (element.properties.empty() || element.properties[0].role != Role::kVertexIndices) {
        return errorIn(name, "PLY face element has no vertex_indices list");
      }
    } else if (header.faceElement < 0) {
      // OpenMesh reads (skips) elements before the faces property by property.
      for (const Property& p : element.properties) {
        if (p.isList) {
          return errorIn(name, "PLY list property " + quoted(p.name) + " of element " +
                                   elementName + " is not supported before the faces");
        }
      }
    }
  }
  if (header.vertexElement < 0) return errorIn(name, "PLY file has no vertex element");
  if (header.faceElement < 0 || header.elements[header.faceElement].count == 0) {
    return errorIn(name, "mesh has no faces");
  }
  return Ok{};
}

/// The header OpenMesh is given (see the file comment).
std::string canonicalHeader(const Header& header) {
  std::string h = "ply\nformat ";
  h += header.format == Format::kAscii                ? "ascii"
       : header.format == Format::kBinaryLittleEndian ? "binary_little_endian"
                                                      : "binary_big_endian";
  h += " 1.0\n";
  std::size_t unused = 0;
  for (int e = 0; e <= header.faceElement; ++e) {
    const Element& element = header.elements[e];
    const bool known = e == header.vertexElement || e == header.faceElement;
    h += "element ";
    h += known ? element.name : "sgbake_element_" + std::to_string(e);
    h += ' ';
    h += std::to_string(element.count);
    h += '\n';
    for (const Property& p : element.properties) {
      h += "property ";
      if (p.isList) {
        // Length types OpenMesh knows, chosen by size (lengths are checked to be small and >= 0).
        const std::size_t size = sizeOf(p.countType);
        h += "list ";
        h += size == 1 ? "uchar" : size == 2 ? "uint16" : "int";
        h += ' ';
      }
      h += canonicalName(p.type);
      h += ' ';
      h += p.role != Role::kOther ? std::string(roleName(p.role))
                                  : "sgbake_unused_" + std::to_string(unused++);
      h += '\n';
    }
  }
  h += "end_header\n";
  return h;
}

/// Where a value is read from: the two body encodings behind one interface.
class AsciiBody {
 public:
  AsciiBody(std::string_view text, std::size_t firstLine, std::string_view name)
      : text_(text), line_(firstLine), name_(name) {}

  void locate(const Element& element, std::uint64_t index) {
    element_ = &element;
    index_ = index;
    previousLine_ = tokenLine_;
    firstToken_ = true;
  }
  /// Reads a position, normal or UV component (OpenMesh parses it as float).
  Status real(const Property& p, float& out) {
    std::string_view token;
    if (Status s = nextToken(token); !s) return s;
    const NumberStatus status = parseReal(token, out);
    if (status != NumberStatus::kOk) {
      return error(describeBadNumber(status, roleDescription(p.role), token));
    }
    return Ok{};
  }
  /// Reads a list length or a vertex index.
  Status integer(PlyType, std::int64_t& out) {
    std::string_view token;
    if (Status s = nextToken(token); !s) return s;
    const NumberStatus status = parseInteger(token, out);
    if (status != NumberStatus::kOk) return error("expected an integer, found " + quoted(token));
    return Ok{};
  }
  /// Skips a value sgbake does not use (it must still be a number).
  Status skip(PlyType) {
    std::string_view token;
    if (Status s = nextToken(token); !s) return s;
    double ignored = 0;
    if (parseReal(token, ignored) == NumberStatus::kSyntax) {
      return error("expected a number, found " + quoted(token));
    }
    return Ok{};
  }
  Status finish() {
    std::string_view token;
    if (scan(token)) return errorAt(name_, line_, "unexpected data after the last PLY element");
    return Ok{};
  }
  Error error(std::string_view what) const { return errorAt(name_, tokenLine_, what); }

 private:
  bool scan(std::string_view& token) {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
      } else if (c != ' ' && c != '\t' && c != '\r') {
        break;
      }
      ++pos_;
    }
    if (pos_ == text_.size()) return false;
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && text_[pos_] != ' ' && text_[pos_] != '\t' &&
           text_[pos_] != '\r' && text_[pos_] != '\n') {
      ++pos_;
    }
    token = text_.substr(begin, pos_ - begin);
    tokenLine_ = line_;
    if (firstToken_) {
      firstToken_ = false;
      // Writers put one element on a line; one that starts where the last ended points at the
      // line with a value too many, should the body run out.
      if (previousLine_ != 0 && tokenLine_ == previousLine_ && midLine_.empty()) {
        midLine_ = "; " + element_->name + " " + std::to_string(index_) + " starts on line " +
                   std::to_string(tokenLine_) +
                   ", where the one before it ends: that line may "
                   "hold a value too many";
      }
    }
    return true;
  }
  Status nextToken(std::string_view& token) {
    if (scan(token)) return Ok{};
    return errorAt(name_, line_,
                   "file is truncated: it ends inside " + element_->name + " " +
                       std::to_string(index_) + " (the header declares " +
                       std::to_string(element_->count) + ")" + midLine_);
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_;
  std::size_t tokenLine_ = 0;
  std::size_t previousLine_ = 0;  ///< of the last value before the current element
  bool firstToken_ = false;       ///< the current element's first value is still to be read
  std::string midLine_;           ///< where an element first started mid-line, for errors
  std::string_view name_;
  const Element* element_ = nullptr;
  std::uint64_t index_ = 0;
};

class BinaryBody {
 public:
  BinaryBody(std::string_view data, bool bigEndian, std::string_view name)
      : data_(data), bigEndian_(bigEndian), name_(name) {}

  void locate(const Element& element, std::uint64_t index) {
    element_ = &element;
    index_ = index;
  }
  /// Reads a position, normal or UV component: float, or double rounded to float as OpenMesh
  /// does (checkStructure rejects other types).
  Status real(const Property& p, float& out) {
    std::uint64_t bits = 0;
    if (Status s = load(p.type, bits); !s) return s;
    const double value =
        p.type == PlyType::kFloat64
            ? std::bit_cast<double>(bits)
            : static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(bits)));
    const std::string what = std::string(roleDescription(p.role)) + " " + p.name;
    if (!std::isfinite(value))
      return error(what + " is " + (std::isnan(value) ? "NaN" : "infinite"));
    out = static_cast<float>(value);
    if (!std::isfinite(out)) return error(what + " is out of range for a float");
    return Ok{};
  }
  Status integer(PlyType type, std::int64_t& out) {
    std::uint64_t bits = 0;
    if (Status s = load(type, bits); !s) return s;
    switch (type) {
      case PlyType::kInt8:
        out = static_cast<std::int8_t>(bits);
        break;
      case PlyType::kInt16:
        out = static_cast<std::int16_t>(bits);
        break;
      case PlyType::kInt32:
        out = static_cast<std::int32_t>(bits);
        break;
      default:
        out = static_cast<std::int64_t>(bits);
        break;
    }
    return Ok{};
  }
  Status skip(PlyType type) {
    std::uint64_t ignored = 0;
    return load(type, ignored);
  }
  Status finish() {
    if (pos_ == data_.size()) return Ok{};
    return errorIn(name_, std::to_string(data_.size() - pos_) +
                              " bytes of unexpected data after the last PLY element");
  }
  Error error(std::string_view what) const {
    return errorIn(name_, element_->name + " " + std::to_string(index_) + ": " + std::string(what));
  }

 private:
  /// Reads one value's bytes in file order into the low bytes of @p bits, native order.
  Status load(PlyType type, std::uint64_t& bits) {
    const std::size_t size = sizeOf(type);
    if (data_.size() - pos_ < size) {
      return errorIn(name_, "file is truncated: it ends inside " + element_->name + " " +
                                std::to_string(index_) + " (the header declares " +
                                std::to_string(element_->count) + ")");
    }
    bits = 0;
    for (std::size_t i = 0; i < size; ++i) {
      const auto byte = static_cast<std::uint64_t>(static_cast<unsigned char>(data_[pos_ + i]));
      const std::size_t shift = 8 * (bigEndian_ ? size - 1 - i : i);
      bits |= byte << shift;
    }
    pos_ += size;
    return Ok{};
  }

  std::string_view data_;
  std::size_t pos_ = 0;
  bool bigEndian_;
  std::string_view name_;
  const Element* element_ = nullptr;
  std::uint64_t index_ = 0;
};

/// Walks every element of the body, filling @p mesh from the vertex and face elements.
template <class Body>
Status parseBody(Body& body, const Header& header, ParsedMesh& mesh) {
  const std::uint64_t numVertices = header.elements[header.vertexElement].count;
  std::vector<std::uint32_t> face;
  for (int e = 0; e < static_cast<int>(header.elements.size()); ++e) {
    const Element& element = header.elements[e];
    const bool isVertex = e == header.vertexElement;
    const bool isFace = e == header.faceElement;
    for (std::uint64_t i = 0; i < element.count; ++i) {
      body.locate(element, i);
      float value[static_cast<int>(Role::kVertexIndices)] = {};
      for (const Property& p : element.properties) {
        if (!p.isList) {
          if (isVertex && p.role != Role::kOther) {
            if (Status s = body.real(p, value[static_cast<int>(p.role)]); !s) return s;
          } else if (Status s = body.skip(p.type); !s) {
            return s;
          }
          continue;
        }
        std::int64_t length = 0;
        if (Status s = body.integer(p.countType, length); !s) return s;
        if (length < 0) return body.error("negative list length " + std::to_string(length));
        if (p.role != Role::kVertexIndices || !isFace) {
          for (std::int64_t k = 0; k < length; ++k) {
            if (Status s = body.skip(p.type); !s) return s;
          }
          continue;
        }
        if (length < 3) {
          return body.error("face has " + std::to_string(length) +
                            (length == 1 ? " corner" : " corners") + " (at least 3 are needed)");
        }
        if (mesh.cornerVertex.size() + static_cast<std::uint64_t>(length) > kMaxElements) {
          return body.error("too many corners");
        }
        face.clear();
        for (std::int64_t k = 0; k < length; ++k) {
          std::int64_t index = 0;
          if (Status s = body.integer(p.type, index); !s) return s;
          if (index < 0 || static_cast<std::uint64_t>(index) >= numVertices) {
            return body.error("face corner refers to vertex " + std::to_string(index) +
                              " but only " + std::to_string(numVertices) +
                              " vertices are defined (PLY indices start at 0)");
          }
          face.push_back(static_cast<std::uint32_t>(index));
        }
        std::uint32_t repeated = 0;
        if (findRepeatedVertex(face.data(), face.size(), repeated)) {
          return body.error("face uses vertex " + std::to_string(repeated) + " twice");
        }
        mesh.cornerVertex.insert(mesh.cornerVertex.end(), face.begin(), face.end());
        mesh.faceStart.push_back(static_cast<std::uint32_t>(mesh.cornerVertex.size()));
      }
      if (isVertex) {
        auto at = [&](Role r) { return value[static_cast<int>(r)]; };
        mesh.positions.push_back({at(Role::kX), at(Role::kY), at(Role::kZ)});
        if (header.hasNormals) {
          const Vec3f n{at(Role::kNx), at(Role::kNy), at(Role::kNz)};
          if (!(lengthSquared(cast<double>(n)) > 0)) return body.error("normal has zero length");
          mesh.normals.push_back(n);
        }
        if (header.hasUvs) mesh.uvs.push_back({at(Role::kU), at(Role::kV)});
      }
    }
  }
  return body.finish();
}

}  // namespace

Result<ValidatedFile> validatePly(std::string_view bytes, std::string_view rawName) {
  const std::string name = displayName(rawName);
  Result<Header> parsedHeader = parseHeader(bytes, name);
  if (!parsedHeader) return parsedHeader.error();
  Header& header = *parsedHeader;
  if (Status s = checkStructure(header, name); !s) return s.error();

  ValidatedFile out;
  ParsedMesh& mesh = out.parsed;
  const std::string_view body = bytes.substr(header.bodyOffset);
  if (header.format == Format::kAscii) {
    if (Status s = checkTextBytes(body, name, header.bodyLine); !s) return s.error();
    AsciiBody reader(body, header.bodyLine, name);
    if (Status s = parseBody(reader, header, mesh); !s) return s.error();
  } else {
    BinaryBody reader(body, header.format == Format::kBinaryBigEndian, name);
    if (Status s = parseBody(reader, header, mesh); !s) return s.error();
  }
  if (header.hasNormals) mesh.normalBinding = Binding::kPerVertex;
  if (header.hasUvs) mesh.uvBinding = Binding::kPerVertex;

  out.openMeshBytes = canonicalHeader(header);
  out.openMeshBytes.append(body);
  out.openMeshExtension = ".ply";
  return out;
}

}  // namespace sgbake::detail
