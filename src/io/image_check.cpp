/// @file image_check.cpp
/// @brief imageDamage: a walk over a PNG file's chunks (with a slicing-by-8 CRC-32), a JPEG
/// file's markers, an SGI file's RLE scanlines or an EXR file's chunks, or a Cineon or DPX
/// file's sizes against its header.
#include "io/image_check.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string_view>
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

/// The whole file: the @p got bytes of @p first already read, then the rest of @p file.
std::vector<unsigned char> wholeFile(std::FILE* file, const unsigned char* first, std::size_t got) {
  std::vector<unsigned char> bytes(first, first + got);
  unsigned char buffer[1 << 16];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, file)) > 0;) {
    bytes.insert(bytes.end(), buffer, buffer + n);
  }
  return bytes;
}

/// Reads @p size bytes at @p offset of @p file into @p out; false where the file ends first.
bool readAt(std::FILE* file, std::uint64_t offset, unsigned char* out, std::size_t size) {
  if (offset > static_cast<std::uint64_t>(std::numeric_limits<long>::max()) ||
      std::fseek(file, static_cast<long>(offset), SEEK_SET) != 0) {
    return false;
  }
  return std::fread(out, 1, size, file) == size;
}

std::uint64_t fileSize(std::FILE* file) {
  if (std::fseek(file, 0, SEEK_END) != 0) return 0;
  const long size = std::ftell(file);
  return size < 0 ? 0 : static_cast<std::uint64_t>(size);
}

std::uint32_t loadBigEndian16(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) << 8 | static_cast<std::uint32_t>(p[1]);
}

/// The SGI (IRIS) file (see image_check.hpp). Its 512-byte header: magic 474, storage (0
/// verbatim, 1 RLE), bytes per channel, dimension, xsize, ysize, zsize, all big-endian. An RLE
/// file has a table of ysize·zsize scanline offsets and one of their lengths after the header;
/// each scanline is runs of a count c (its high bit set: c values follow; clear: one value
/// repeated c times), ended by a count of 0, and must fill its length and xsize values exactly,
/// as OpenImageIO's reader wants them to.
std::string sgiDamage(const std::vector<unsigned char>& bytes) {
  const std::uint64_t size = bytes.size();
  if (size < 512) return "truncated SGI image: the file ends inside its 512-byte header";
  const unsigned char* h = bytes.data();
  const std::uint32_t storage = h[2], bpc = h[3];
  const std::uint64_t width = loadBigEndian16(h + 6), rows = loadBigEndian16(h + 8),
                      channels = loadBigEndian16(h + 10);
  if ((storage != 0 && storage != 1) || (bpc != 1 && bpc != 2)) return "";  // the decoder says
  const std::uint64_t scanlines = rows * channels;
  if (storage == 0) {
    const std::uint64_t want = 512 + scanlines * width * bpc;
    if (size < want) {
      return "truncated SGI image: the file is " + std::to_string(size) + " bytes, its " +
             std::to_string(width) + " x " + std::to_string(rows) + " x " +
             std::to_string(channels) + " pixels need " + std::to_string(want);
    }
    return "";
  }
  if (size < 512 + 8 * scanlines) {
    return "truncated SGI image: the file ends inside its table of RLE scanlines";
  }
  const std::string corrupt = "corrupt SGI image: RLE scanline ";
  for (std::uint64_t line = 0; line < scanlines; ++line) {
    const std::uint64_t start = loadBigEndian(h + 512 + 4 * line);
    const std::uint64_t length = loadBigEndian(h + 512 + 4 * (scanlines + line));
    if (start + length > size) {
      return "truncated SGI image: the file ends inside RLE scanline " + std::to_string(line) +
             " (at byte " + std::to_string(start) + ")";
    }
    const unsigned char* data = h + start;
    std::uint64_t at = 0, values = 0;
    while (at + bpc <= length) {
      const std::uint32_t value = bpc == 1 ? data[at] : loadBigEndian16(data + at);
      at += bpc;
      const std::uint64_t count = value & 0x7Fu;
      if (count == 0) break;
      at += (value & 0x80u) != 0 ? count * bpc : bpc;  // the values copied, or the one repeated
      values += count;
      if (at > length || values > width) break;
    }
    if (at != length || values != width) {
      return corrupt + std::to_string(line) + " (at byte " + std::to_string(start) +
             ") does not decode to " + std::to_string(width) + " values";
    }
  }
  return "";
}

/// Where a Cineon or DPX header records what filmScanDamage compares: byte offsets of 32-bit
/// fields (the pixels' offset, the file size, pixels per line, lines) and of channel 0's bits
/// per component, and the components per pixel (0: unknown, or not stored plainly).
struct FilmScanLayout {
  const char* name;
  std::size_t headerBytes, dataOffset, fileSize, width, rows, bits;
  std::uint64_t (*components)(const unsigned char* header, bool bigEndian);
};

/// A Cineon image: magic 0x802A5FD7 (either byte order), channels at byte 193.
constexpr FilmScanLayout kCineon{
    "Cineon image", 208, 4, 20, 200, 204, 198, [](const unsigned char* h, bool) {
      return std::uint64_t{h[193] <= 8 ? h[193] : 0u};
    }};

/// Components per pixel of a DPX image element's descriptor, 0 when not known here.
std::uint64_t dpxComponents(unsigned descriptor) {
  if (descriptor >= 1 && descriptor <= 8) return 1;  // one channel (R, G, B, A, luma, depth…)
  switch (descriptor) {
    case 50:   // RGB
    case 102:  // CbYCr
      return 3;
    case 51:   // RGBA
    case 52:   // ABGR
    case 103:  // CbYCrA
      return 4;
    default:
      return 0;
  }
}

/// A DPX image: magic "SDPX" (either byte order), element 0's descriptor at byte 800 and its
/// encoding at 806 (0: not run-length encoded).
constexpr FilmScanLayout kDpx{
    "DPX image", 808, 4, 16, 772, 776, 803, [](const unsigned char* h, bool bigEndian) {
      const unsigned encoding = bigEndian ? h[806] << 8 | h[807] : h[807] << 8 | h[806];
      return encoding == 0 ? dpxComponents(h[800]) : 0;
    }};

/// A Cineon or DPX file against what its header says (see image_check.hpp): its pixels start
/// inside it, it is as long as the header records and as long as its pixels need at the least.
std::string filmScanDamage(std::FILE* file, bool bigEndian, const FilmScanLayout& layout) {
  const std::string what = layout.name;
  const std::uint64_t size = fileSize(file);
  unsigned char h[1024];
  if (!readAt(file, 0, h, layout.headerBytes)) {
    return "truncated " + what + ": the file ends in its header";
  }
  const auto u32 = [&](std::size_t at) {
    return std::uint64_t{bigEndian ? loadBigEndian(h + at) : loadLittleEndian(h + at)};
  };
  const std::uint64_t dataOffset = u32(layout.dataOffset), width = u32(layout.width),
                      rows = u32(layout.rows), bits = h[layout.bits],
                      components = layout.components(h, bigEndian);
  const std::string truncated =
      "truncated " + what + ": the file is " + std::to_string(size) + " bytes, ";
  if (dataOffset >= size) {
    return truncated + "its pixels would start at byte " + std::to_string(dataOffset);
  }
  if (const std::uint64_t recorded = u32(layout.fileSize); recorded > size) {
    return truncated + "its header says " + std::to_string(recorded);
  }
  if (bits <= 64 && width <= (1u << 20) && rows <= (1u << 20)) {
    const std::uint64_t pixelBytes = width * rows * components * bits / 8;
    if (dataOffset + pixelBytes > size) {
      return truncated + "its pixels need " + std::to_string(dataOffset + pixelBytes);
    }
  }
  return "";
}

/// Scanlines per chunk of an OpenEXR compression, 0 for one not known here.
std::uint64_t exrLinesPerChunk(unsigned compression) {
  switch (compression) {
    case 0:  // NONE
    case 1:  // RLE
    case 2:  // ZIPS
      return 1;
    case 3:  // ZIP
    case 5:  // PXR24
      return 16;
    case 4:  // PIZ
    case 6:  // B44
    case 7:  // B44A
    case 8:  // DWAA
      return 32;
    case 9:  // DWAB
      return 256;
    default:
      return 0;
  }
}

/// The chunks of a single-part OpenEXR file, scanline or tiled (one level or mipmapped): every
/// chunk the offset table points to within the file must hold data, all of it in the file.
/// (OpenEXR rebuilds a table with entries out of the file from the chunks themselves, and checks
/// multi-part, deep and ripmapped files further itself.)
std::string exrDamage(std::FILE* file) {
  const std::uint64_t size = fileSize(file);
  unsigned char version[4];
  if (!readAt(file, 4, version, 4)) return "";  // OpenEXR says what is wrong
  const std::uint32_t flags = loadLittleEndian(version) & ~0xFFu;
  const bool tiled = (flags & 0x200u) != 0;
  if ((flags & ~0x600u) != 0) return "";  // deep or multi-part
  // The header: attributes (name, type, size, value) up to an empty name.
  std::int64_t box[4] = {0, 0, -1, -1};
  std::uint64_t compression = 0xFF, tileWidth = 0, tileHeight = 0, levelMode = 0, roundUp = 0;
  bool haveBox = false, haveTiles = false;
  std::uint64_t at = 8;
  std::vector<unsigned char> value;
  for (;;) {
    std::string name, type;
    for (std::string* text : {&name, &type}) {
      for (int c; (c = std::fgetc(file)) != 0; ++at) {
        if (c == EOF || text->size() > 255) return "";
        text->push_back(static_cast<char>(c));
      }
      ++at;
      if (text == &name && name.empty()) break;
    }
    if (name.empty()) break;
    unsigned char length[4];
    if (std::fread(length, 1, 4, file) != 4) return "";
    const std::uint32_t bytes = loadLittleEndian(length);
    if (bytes > (1u << 24)) return "";
    value.resize(bytes);
    if (std::fread(value.data(), 1, bytes, file) != bytes) return "";
    at += 4 + std::uint64_t{bytes};
    if (name == "dataWindow" && type == "box2i" && bytes == 16) {
      for (int i = 0; i < 4; ++i) {
        box[i] = static_cast<std::int32_t>(loadLittleEndian(value.data() + 4 * i));
      }
      haveBox = true;
    } else if (name == "compression" && bytes == 1) {
      compression = value[0];
    } else if (name == "tiles" && type == "tiledesc" && bytes == 9) {
      tileWidth = loadLittleEndian(value.data());
      tileHeight = loadLittleEndian(value.data() + 4);
      levelMode = value[8] & 0x0Fu;
      roundUp = value[8] >> 4;
      haveTiles = true;
    }
  }
  const std::uint64_t linesPerChunk = exrLinesPerChunk(static_cast<unsigned>(compression));
  if (!haveBox || box[2] < box[0] || box[3] < box[1] || linesPerChunk == 0) return "";
  const auto width = static_cast<std::uint64_t>(box[2] - box[0] + 1);
  const auto height = static_cast<std::uint64_t>(box[3] - box[1] + 1);
  std::uint64_t chunks = 0;
  if (!tiled) {
    chunks = (height + linesPerChunk - 1) / linesPerChunk;
  } else {
    if (!haveTiles || tileWidth == 0 || tileHeight == 0 || levelMode > 1) return "";
    // Mipmap level l is the image's size over 2^l, rounded down or up, at least 1.
    const auto levelSize = [&](std::uint64_t full, int level) {
      const std::uint64_t scale = std::uint64_t{1} << level;
      return std::max<std::uint64_t>(roundUp != 0 ? (full + scale - 1) / scale : full / scale, 1);
    };
    const std::uint64_t largest = std::max(width, height);
    int levels = 1;
    if (levelMode == 1) {
      for (int l = 1; l < 64 && levelSize(largest, l - 1) > 1; ++l) levels = l + 1;
    }
    for (int l = 0; l < levels; ++l) {
      chunks += ((levelSize(width, l) + tileWidth - 1) / tileWidth) *
                ((levelSize(height, l) + tileHeight - 1) / tileHeight);
    }
  }
  if (chunks > (std::uint64_t{1} << 26) || at + 8 * chunks > size) return "";
  std::vector<unsigned char> table(8 * chunks);
  if (!readAt(file, at, table.data(), table.size())) return "";
  const std::uint64_t headerBytes = tiled ? 20 : 8;  // tile x, y, level x, y, or y; then size
  for (std::uint64_t k = 0; k < chunks; ++k) {
    const std::uint64_t offset = std::uint64_t{loadLittleEndian(table.data() + 8 * k)} |
                                 std::uint64_t{loadLittleEndian(table.data() + 8 * k + 4)} << 32;
    if (offset < at + 8 * chunks || offset >= size) continue;  // rebuilt by OpenEXR
    unsigned char head[20];
    const std::string where =
        "chunk " + std::to_string(k) + " (at byte " + std::to_string(offset) + ")";
    if (!readAt(file, offset, head, headerBytes)) {
      return "truncated EXR: the file ends inside " + where;
    }
    const auto bytes = static_cast<std::int32_t>(loadLittleEndian(head + headerBytes - 4));
    if (bytes <= 0) return "corrupt EXR: " + where + " holds no pixel data";
    if (offset + headerBytes + static_cast<std::uint64_t>(bytes) > size) {
      return "truncated EXR: the file ends inside " + where;
    }
  }
  return "";
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
    return jpegDamage(wholeFile(file.get(), signature, got));
  }
  if (got >= 4 && signature[0] == 0x76 && signature[1] == 0x2F && signature[2] == 0x31 &&
      signature[3] == 0x01) {
    return exrDamage(file.get());
  }
  if (got >= 2 && signature[0] == 0x01 && signature[1] == 0xDA) {
    return sgiDamage(wholeFile(file.get(), signature, got));
  }
  if (got >= 4) {
    const std::uint32_t magic = loadBigEndian(signature);
    if (magic == 0x802A5FD7u || magic == 0xD75F2A80u) {
      return filmScanDamage(file.get(), magic == 0x802A5FD7u, kCineon);
    }
    if (magic == 0x53445058u || magic == 0x58504453u) {  // "SDPX", "XPDS"
      return filmScanDamage(file.get(), magic == 0x53445058u, kDpx);
    }
  }
  return "";
}

}  // namespace sgbake::io_detail
