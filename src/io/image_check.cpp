/// @file image_check.cpp
/// @brief imageDamage: a walk over a PNG file's chunks (with a slicing-by-8 CRC-32) or a JPEG
/// file's markers.
#include "io/image_check.hpp"

#include <array>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

namespace sgbake::io_detail {
namespace {

/// Eight 256-entry tables: table 0 is the byte-at-a-time CRC of the reflected polynomial
/// 0xEDB88320; table k advances table k-1's entry by one more zero byte, so eight input bytes
/// fold into the CRC with eight lookups (Kounavis and Berry's slicing-by-8).
using CrcTables = std::array<std::array<std::uint32_t, 256>, 8>;

constexpr CrcTables makeCrcTables() {
  CrcTables t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (std::size_t k = 1; k < 8; ++k) {
    for (std::size_t i = 0; i < 256; ++i) {
      t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFu];
    }
  }
  return t;
}

constexpr CrcTables kCrcTables = makeCrcTables();

std::uint32_t loadLittleEndian(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

std::uint32_t loadBigEndian(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) << 24 | static_cast<std::uint32_t>(p[1]) << 16 |
         static_cast<std::uint32_t>(p[2]) << 8 | static_cast<std::uint32_t>(p[3]);
}

constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

/// A chunk type is four ASCII letters; the case of the first says whether it is critical.
bool isLetter(unsigned char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }

}  // namespace

std::uint32_t crc32(std::uint32_t crc, const unsigned char* data, std::size_t size) {
  const CrcTables& t = kCrcTables;
  std::uint32_t c = ~crc;
  for (; size >= 8; data += 8, size -= 8) {
    const std::uint32_t one = loadLittleEndian(data) ^ c;
    const std::uint32_t two = loadLittleEndian(data + 4);
    c = t[7][one & 0xFFu] ^ t[6][(one >> 8) & 0xFFu] ^ t[5][(one >> 16) & 0xFFu] ^ t[4][one >> 24] ^
        t[3][two & 0xFFu] ^ t[2][(two >> 8) & 0xFFu] ^ t[1][(two >> 16) & 0xFFu] ^ t[0][two >> 24];
  }
  for (; size > 0; ++data, --size) c = t[0][(c ^ *data) & 0xFFu] ^ (c >> 8);
  return ~c;
}

namespace {

using File = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

/// The PNG file's chunks after its signature (see image_check.hpp).
std::string pngDamage(std::FILE* file) {
  std::vector<unsigned char> buffer(std::size_t{1} << 20);
  std::uint64_t offset = 8;  // of the chunk being read
  for (;;) {
    unsigned char head[8];  // length, type
    const std::size_t got = std::fread(head, 1, 8, file);
    if (got < 8) {
      return "truncated PNG: the file ends at byte " + std::to_string(offset + got) +
             ", before its IEND chunk";
    }
    const std::uint32_t length = loadBigEndian(head);
    if (!isLetter(head[4]) || !isLetter(head[5]) || !isLetter(head[6]) || !isLetter(head[7]) ||
        length > 0x7FFFFFFFu) {
      return "corrupt PNG: no valid chunk at byte " + std::to_string(offset);
    }
    const std::string type(reinterpret_cast<const char*>(head + 4), 4);
    const std::string ends = "truncated PNG: the file ends inside its " + type +
                             " chunk (at byte " + std::to_string(offset) + ")";
    std::uint32_t crc = crc32(0, head + 4, 4);
    for (std::uint64_t left = length; left > 0;) {
      const auto want = static_cast<std::size_t>(std::min<std::uint64_t>(left, buffer.size()));
      const std::size_t read = std::fread(buffer.data(), 1, want, file);
      crc = crc32(crc, buffer.data(), read);
      if (read < want) return ends;
      left -= read;
    }
    unsigned char stored[4];
    if (std::fread(stored, 1, 4, file) != 4) return ends;
    const bool critical = head[4] >= 'A' && head[4] <= 'Z';
    if (critical && loadBigEndian(stored) != crc) {
      return "corrupt PNG: its " + type + " chunk at byte " + std::to_string(offset) +
             " fails its CRC check";
    }
    if (type == "IEND") return "";
    offset += 12 + std::uint64_t{length};
  }
}

/// The JPEG file's markers after SOI, read from @p bytes (the whole file; see
/// image_check.hpp).
std::string jpegDamage(const std::vector<unsigned char>& bytes) {
  const std::size_t size = bytes.size();
  const std::string truncated = "truncated JPEG: the file ends ";
  std::size_t at = 2;  // after SOI
  for (;;) {
    // The next marker: stray bytes, then any number of 0xFF fill bytes, then its code.
    while (at < size && bytes[at] != 0xFF) ++at;
    while (at < size && bytes[at] == 0xFF) ++at;
    if (at >= size) return truncated + "before its EOI marker";
    const unsigned char code = bytes[at++];
    if (code == 0xD9) return "";                                   // EOI
    if (code == 0x01 || (code >= 0xD0 && code <= 0xD7)) continue;  // TEM, RSTn: no length
    if (at + 2 > size) return truncated + "inside a segment, before its EOI marker";
    const std::size_t length = std::size_t{bytes[at]} << 8 | bytes[at + 1];
    if (length < 2)
      return "corrupt JPEG: a segment at byte " + std::to_string(at - 2) + " is empty";
    if (at + length > size) return truncated + "inside a segment, before its EOI marker";
    at += length;
    if (code != 0xDA) continue;
    // SOS: entropy-coded data up to the next marker that is not a stuffed 0xFF00 or RSTn.
    for (;;) {
      while (at < size && bytes[at] != 0xFF) ++at;
      if (at + 1 >= size) return truncated + "inside its image data, before its EOI marker";
      const unsigned char next = bytes[at + 1];
      if (next == 0x00 || (next >= 0xD0 && next <= 0xD7)) {
        at += 2;
      } else if (next == 0xFF) {
        ++at;  // fill byte
      } else {
        break;  // a marker: the scan has ended
      }
    }
  }
}

}  // namespace

std::string imageDamage(const std::filesystem::path& path) {
  const File file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) return "";  // the decoder says why it cannot open it
  unsigned char signature[8];
  const std::size_t got = std::fread(signature, 1, 8, file.get());
  if (got == 8 && std::memcmp(signature, kPngSignature, sizeof kPngSignature) == 0) {
    return pngDamage(file.get());
  }
  if (got >= 3 && signature[0] == 0xFF && signature[1] == 0xD8 && signature[2] == 0xFF) {
    std::vector<unsigned char> bytes(signature, signature + got);
    unsigned char buffer[1 << 16];
    for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, file.get())) > 0;) {
      bytes.insert(bytes.end(), buffer, buffer + n);
    }
    return jpegDamage(bytes);
  }
  return "";
}

}  // namespace sgbake::io_detail
