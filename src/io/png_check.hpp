/// @file png_check.hpp
/// @brief A PNG file's chunk structure checked before it is decoded.
///
/// OpenImageIO's PNG reader lets libpng print its own "libpng error: ..." line to standard
/// error when a file is cut short or damaged, before it reports the failure; an image loader
/// that promises one line per error checks the structure first. The check walks the chunks
/// (length, type, data, CRC-32) up to IEND: a file that ends inside a chunk or before IEND is
/// truncated, a critical chunk (IHDR, PLTE, IDAT, IEND: type starting with an upper-case
/// letter) whose CRC does not match is corrupt. Ancillary chunks with a bad CRC are left to
/// libpng, which skips them, as Blender does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace sgbake::io_detail {

/// @brief CRC-32 (ISO 3309, the polynomial of PNG and zlib) of @p size bytes, continuing
/// @p crc (0 to start).
std::uint32_t crc32(std::uint32_t crc, const unsigned char* data, std::size_t size);

/// @brief Why the PNG file @p path cannot be decoded ("truncated PNG: ..." / "corrupt PNG:
/// ..."), or "" when its chunks are whole or it is not a PNG file (no PNG signature).
std::string pngDamage(const std::filesystem::path& path);

}  // namespace sgbake::io_detail
