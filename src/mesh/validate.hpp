/// @file validate.hpp
/// @brief sgbake's own validating parsers for OBJ, PLY and OFF (private to src/mesh).
///
/// OpenMesh 9.0's readers trust their input: an out-of-range OBJ index overflows the heap, a
/// face corner without a vertex index aborts, unparseable numbers silently drop vertices and
/// shift every later index. So every file is parsed completely by the checkers declared here
/// before OpenMesh sees a byte. A checker returns
/// - the mesh as it read it (ParsedMesh): the reference OpenMesh's result is verified against,
///   and the only source of what OpenMesh cannot express (OBJ per-corner normals);
/// - the exact bytes to hand OpenMesh (ValidatedFile::openMeshBytes): the validated file with
///   what OpenMesh must not see neutralised (see each checker).
///
/// Messages are one line: `<name>:<line>: <problem>` for text, `<name>: <problem>` otherwise.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"

namespace sgbake::detail {

/// Largest number of vertices, faces or corners a file may declare. OpenMesh's handles are
/// `int`, and OpenMesh may add one vertex per corner of a non-manifold face.
inline constexpr std::uint64_t kMaxElements = std::numeric_limits<std::int32_t>::max() / 2;

/// A normal read from a file is renormalized when its length differs from 1 by more than this.
/// Eight float ulps at 1 (about 9.5e-7): a normal that was normalized in float and printed with
/// 9 significant digits is kept bit-exact; Blender's 4-decimal OBJ normals (off by up to ~1e-4)
/// are renormalized. Also the tolerance of validate(const Mesh&) for unit normals.
inline constexpr double kUnitLengthTolerance = 8.0 * std::numeric_limits<float>::epsilon();

/// How an attribute is attached to the mesh.
enum class Binding {
  kNone,       ///< the file has none
  kPerVertex,  ///< one value per vertex (PLY, OFF): `values[cornerVertex[c]]`
  kPerCorner,  ///< one index per corner into a pool (OBJ `vt`/`vn`): `values[cornerIndex[c]]`
};

/// The mesh exactly as sgbake's checker read it.
struct ParsedMesh {
  std::vector<Vec3f> positions;             ///< #V, each number parsed straight to float
  std::vector<std::uint32_t> faceStart{0};  ///< #F+1, file order
  std::vector<std::uint32_t> cornerVertex;  ///< #C, 0-based, each face in file order

  Binding uvBinding = Binding::kNone;
  std::vector<Vec2f> uvs;              ///< per vertex, or the OBJ `vt` pool
  std::vector<std::int32_t> cornerUv;  ///< kPerCorner: #C indices into uvs, -1 = UV (0, 0)

  Binding normalBinding = Binding::kNone;
  std::vector<Vec3f> normals;              ///< per vertex, or the OBJ `vn` pool (finite, non-zero)
  std::vector<std::int32_t> cornerNormal;  ///< kPerCorner: #C indices into normals (all valid)

  /// #F, 1 for a flat-shaded face (OBJ: Blender's reading of `s` statements), or empty when the
  /// file does not say (no `s` statement at all; PLY, OFF): every face smooth.
  std::vector<std::uint8_t> faceFlat;
  /// #F material indices (OBJ: `usemtl` names numbered in order of first use, faces before the
  /// first `usemtl` 0 with the name ""), or empty when the file names none.
  std::vector<std::uint32_t> faceMaterial;
  std::vector<std::string> materialNames;  ///< per material index (faceMaterial)

  std::size_t numFaces() const { return faceStart.size() - 1; }
};

/// A checked file: the reference mesh and what OpenMesh is given to read.
struct ValidatedFile {
  ParsedMesh parsed;
  std::string openMeshBytes;      ///< the validated content, in the format of openMeshExtension
  std::string openMeshExtension;  ///< ".obj" or ".ply"
};

/// OBJ: keeps `v`, `vt`, `vn` and `f` statements for OpenMesh, each on its original line;
/// every other statement (mtllib included: OpenMesh would open the file it names), comments,
/// a UTF-8 byte-order mark and line continuations are blanked out.
Result<ValidatedFile> validateObj(std::string_view bytes, std::string_view name);

/// PLY (ASCII, binary little and big endian): the body is kept byte for byte; the header is
/// rewritten in the canonical form OpenMesh 9.0 parses correctly (see validate_ply.cpp).
Result<ValidatedFile> validatePly(std::string_view bytes, std::string_view name);

/// OFF (ASCII; [ST][C][N]OFF): handed to OpenMesh as an equivalent ASCII PLY made of the
/// file's own number tokens, because OpenMesh's OFF reader ignores the header of a stream (see
/// validate_off.cpp).
Result<ValidatedFile> validateOff(std::string_view bytes, std::string_view name);

// ---------------------------------------------------------------------------------------------
// Helpers shared by the three checkers.

/// @p name made safe for a one-line message: control characters become '?'.
inline std::string displayName(std::string_view name) { return printableText(name); }

/// A token from the file, quoted for a message: at most 40 characters, non-printable bytes
/// written as \xNN, so that a message stays one printable line whatever the file contains.
inline std::string quoted(std::string_view token) {
  constexpr std::size_t kMaxShown = 40;
  constexpr char kHex[] = "0123456789abcdef";
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c < 0x20 || c >= 0x7f) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xf];
    } else {
      out += static_cast<char>(c);
    }
  }
  if (token.size() > kMaxShown) out += "...";
  out += "'";
  return out;
}

/// `<name>:<line>: <what>` (name already passed through displayName).
inline Error errorAt(std::string_view name, std::size_t line, std::string_view what) {
  std::string msg(name);
  msg += ':';
  msg += std::to_string(line);
  msg += ": ";
  msg += what;
  return Error::badInput(std::move(msg));
}

/// `<name>: <what>` (name already passed through displayName).
inline Error errorIn(std::string_view name, std::string_view what) {
  std::string msg(name);
  msg += ": ";
  msg += what;
  return Error::badInput(std::move(msg));
}

/// Checks that @p text is text: no NUL or other control bytes except tab, line feed and a
/// carriage return that ends a line. Bytes >= 0x80 (UTF-8 names, comments) are allowed; they
/// fail later if they stand where a number must be.
/// @param[in] firstLine line number of text's first line in the file (for the message)
inline Status checkTextBytes(std::string_view text, std::string_view name, std::size_t firstLine) {
  std::size_t line = firstLine;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++line;
    } else if (c == '\r') {
      if (i + 1 < text.size() && text[i + 1] != '\n') {
        return errorAt(name, line, "carriage return inside a line (only \\n or \\r\\n line ends)");
      }
    } else if ((c < 0x20 && c != '\t') || c == 0x7f) {
      return errorAt(name, line,
                     "binary data in a text file (byte " + quoted(text.substr(i, 1)) + ")");
    }
  }
  return Ok{};
}

/// Splits @p text into lines: each call yields the next line without its `\n` or `\r\n`.
class LineReader {
 public:
  explicit LineReader(std::string_view text, std::size_t firstLine = 1)
      : text_(text), nextLine_(firstLine) {}

  /// @param[out] line the line's content; @return false at the end of the text
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const std::size_t end = text_.find('\n', pos_);
    const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = stop + 1;
    lineNumber_ = nextLine_++;
    return true;
  }
  /// Number of the line last returned by next().
  std::size_t lineNumber() const { return lineNumber_; }
  /// Offset in the text just past the line last returned by next() (and its line end).
  std::size_t offset() const { return std::min(pos_, text_.size()); }
  bool atEnd() const { return pos_ >= text_.size(); }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t nextLine_;
  std::size_t lineNumber_ = 0;
};

/// Splits a line into tokens separated by spaces and tabs.
class Tokenizer {
 public:
  explicit Tokenizer(std::string_view line) : rest_(line) {}

  bool next(std::string_view& token) {
    std::size_t b = 0;
    while (b < rest_.size() && (rest_[b] == ' ' || rest_[b] == '\t')) ++b;
    if (b == rest_.size()) return false;
    std::size_t e = b;
    while (e < rest_.size() && rest_[e] != ' ' && rest_[e] != '\t') ++e;
    token = rest_.substr(b, e - b);
    rest_.remove_prefix(e);
    return true;
  }

  /// The rest of the line without its leading and trailing blanks (a name with spaces).
  std::string_view rest() const {
    std::size_t b = 0, e = rest_.size();
    while (b < e && (rest_[b] == ' ' || rest_[b] == '\t')) ++b;
    while (e > b && (rest_[e - 1] == ' ' || rest_[e - 1] == '\t')) --e;
    return rest_.substr(b, e - b);
  }

 private:
  std::string_view rest_;
};

/// Outcome of parsing one number token.
enum class NumberStatus {
  kOk,
  kSyntax,     ///< not a complete decimal number
  kNotFinite,  ///< spelled NaN or infinity
  kOverflow,   ///< finite in decimal but too large for the type
};

namespace number_detail {

/// Decimal exponent of the leading non-zero digit of a syntactically valid decimal number
/// (e.g. 0.002 → -3, 1.5e7 → 7), saturated to ±1e6. Used only to tell an underflow (rounds to
/// zero) from an overflow when from_chars reports result_out_of_range.
inline long leadingDecimalExponent(std::string_view s) {
  constexpr long kSaturation = 1000000;
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
  long intDigits = 0;  // significant digits before the point
  long leadingFractionZeros = 0;
  bool seenNonZero = false;
  for (; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i) {
    if (s[i] != '0') seenNonZero = true;
    if (seenNonZero) ++intDigits;
  }
  if (i < s.size() && s[i] == '.') {
    for (++i; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i) {
      if (!seenNonZero && s[i] == '0') ++leadingFractionZeros;
      if (s[i] != '0') seenNonZero = true;
    }
  }
  long exponent = 0;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    const bool negative = i < s.size() && s[i] == '-';
    if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
    for (; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i) {
      exponent = std::min(kSaturation, exponent * 10 + (s[i] - '0'));
    }
    if (negative) exponent = -exponent;
  }
  const long lead = intDigits > 0 ? intDigits - 1 : -(leadingFractionZeros + 1);
  return lead + exponent;
}

/// Removes a leading '+' that introduces a number (iostreams accept it, from_chars does not).
inline std::string_view stripPlus(std::string_view s) {
  if (s.size() >= 2 && s[0] == '+' && ((s[1] >= '0' && s[1] <= '9') || s[1] == '.')) {
    s.remove_prefix(1);
  }
  return s;
}

}  // namespace number_detail

/// Parses a whole token as a decimal floating-point number of type T (float or double):
/// `[+-]digits[.digits][(e|E)[+-]digits]`, correctly rounded. A magnitude too small for T
/// rounds to ±0 (as strtod and iostreams do); one too large is kOverflow; "nan"/"inf" spellings
/// are kNotFinite; anything else that does not consume the whole token is kSyntax.
template <class T>
NumberStatus parseReal(std::string_view token, T& out) {
  const std::string_view s = number_detail::stripPlus(token);
  if (s.empty()) return NumberStatus::kSyntax;
  T value{};
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ptr != s.data() + s.size() || ec == std::errc::invalid_argument) return NumberStatus::kSyntax;
  if (ec == std::errc::result_out_of_range) {
    if (number_detail::leadingDecimalExponent(s) >= 0) return NumberStatus::kOverflow;
    out = s[0] == '-' ? -T(0) : T(0);
    return NumberStatus::kOk;
  }
  if (!std::isfinite(value)) return NumberStatus::kNotFinite;
  out = value;
  return NumberStatus::kOk;
}

/// Parses a whole token as a decimal integer with optional sign. kOverflow beyond int64.
inline NumberStatus parseInteger(std::string_view token, std::int64_t& out) {
  const std::string_view s = number_detail::stripPlus(token);
  if (s.empty()) return NumberStatus::kSyntax;
  std::int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ptr != s.data() + s.size() || ec == std::errc::invalid_argument) return NumberStatus::kSyntax;
  if (ec == std::errc::result_out_of_range) return NumberStatus::kOverflow;
  out = value;
  return NumberStatus::kOk;
}

/// Why @p token (what the file calls @p what, e.g. "coordinate") is not an acceptable number.
inline std::string describeBadNumber(NumberStatus status, std::string_view what,
                                     std::string_view token, std::string_view type = "float") {
  std::string msg(what);
  msg += ' ';
  msg += quoted(token);
  switch (status) {
    case NumberStatus::kNotFinite:
      msg += " is not a finite number";
      break;
    case NumberStatus::kOverflow:
      msg += " is out of range for a ";
      msg += type;
      break;
    default:
      msg += " is not a number";
      break;
  }
  return msg;
}

/// True when the two floats have the same bits (the verification of OpenMesh's values).
inline bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }
inline bool sameBits(Vec3f a, Vec3f b) {
  return sameBits(a.x, b.x) && sameBits(a.y, b.y) && sameBits(a.z, b.z);
}
inline bool sameBits(Vec2f a, Vec2f b) { return sameBits(a.x, b.x) && sameBits(a.y, b.y); }

/// True when a face's vertex indices contain a repeat; @p repeated receives it.
/// Quadratic for the usual small faces, sorting for large n-gons.
inline bool findRepeatedVertex(const std::uint32_t* indices, std::size_t count,
                               std::uint32_t& repeated) {
  constexpr std::size_t kQuadraticLimit = 16;
  if (count <= kQuadraticLimit) {
    for (std::size_t i = 0; i < count; ++i) {
      for (std::size_t j = i + 1; j < count; ++j) {
        if (indices[i] == indices[j]) {
          repeated = indices[i];
          return true;
        }
      }
    }
    return false;
  }
  std::vector<std::uint32_t> sorted(indices, indices + count);
  std::sort(sorted.begin(), sorted.end());
  const auto it = std::adjacent_find(sorted.begin(), sorted.end());
  if (it == sorted.end()) return false;
  repeated = *it;
  return true;
}

}  // namespace sgbake::detail
