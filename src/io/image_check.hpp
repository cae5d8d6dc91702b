/// @file image_check.hpp
/// @brief An image file's structure checked before it is decoded.
///
/// Some decoders behind OpenImageIO do not report a damaged file in one line, or at all:
/// - PNG: libpng prints its own "libpng error: ..." line to standard error before OpenImageIO
///   reports the failure. The check walks the chunks (length, type, data, CRC-32) up to IEND: a
///   file that ends inside a chunk or before IEND is truncated, a critical chunk (IHDR, PLTE,
///   IDAT, IEND: type starting with an upper-case letter) whose CRC does not match is corrupt.
///   Ancillary chunks with a bad CRC are left to libpng, which skips them, as Blender does.
/// - JPEG: libjpeg only warns ("Premature end of JPEG file") about a file cut short, and
///   OpenImageIO returns its rows padded with grey as if nothing happened. The check walks the
///   markers and segments from SOI, skips each scan's entropy-coded data (where 0xFF is
///   followed by 0x00 or a restart marker), and wants the EOI marker before the file ends.
///   Stray bytes between segments are skipped, as libjpeg skips them.
/// - SGI (IRIS): OpenImageIO's reader aborts the process (an assertion kept in Debian's build)
///   on RLE data that overruns its scanline, and says "Read error" once per row of a truncated
///   file. The check wants every RLE scanline inside the file and decoding to exactly xsize
///   values in exactly its recorded length, and a verbatim file long enough for its pixels.
/// - Cineon, DPX: a Cineon file cut short is decoded with its missing pixels zero or garbage,
///   a DPX one refused with no reason given. The check compares the file's size with the size
///   its header records, with where its pixels start, and with their least possible size.
/// - OpenEXR: a chunk whose size field says 0 comes back as rows of zeros or of another chunk.
///   In single-part scanline and tiled files (one level or mipmapped), every chunk the offset
///   table points to inside the file must hold data, all of it inside the file (entries pointing
///   elsewhere are left to OpenEXR, which rebuilds the table from the chunks).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace sgbake::io_detail {

/// @brief CRC-32 (ISO 3309, the polynomial of PNG and zlib) of @p size bytes, continuing
/// @p crc (0 to start).
std::uint32_t crc32(std::uint32_t crc, const unsigned char* data, std::size_t size);

/// @brief Why the image file @p path cannot be decoded whole ("truncated PNG: ...", "corrupt
/// PNG: ...", "truncated JPEG: ...", "corrupt SGI image: ...", "corrupt EXR: ..."), or "" when
/// its structure is whole, it cannot be opened (the decoder says why), or it is of a format not
/// checked here (by its signature, not its name).
std::string imageDamage(const std::filesystem::path& path);

}  // namespace sgbake::io_detail
