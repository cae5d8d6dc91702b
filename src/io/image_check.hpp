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
/// PNG: ...", "truncated JPEG: ..."), or "" when its structure is whole, it cannot be opened
/// (the decoder says why), or it is neither PNG nor JPEG (by its signature, not its name).
std::string imageDamage(const std::filesystem::path& path);

}  // namespace sgbake::io_detail
