/// @file text.hpp
/// @brief Small text helpers shared by the parsers (file extensions, option and format names).
#pragma once

#include <cctype>
#include <string>
#include <string_view>

namespace sgbake {

/// @brief @p text with its ASCII letters in lower case (other bytes as they are), for
/// comparing names and file extensions without regard to case.
inline std::string toLowerAscii(std::string_view text) {
  std::string lower(text);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower;
}

}  // namespace sgbake
