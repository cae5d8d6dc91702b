/// @file named.hpp
/// @brief Named: one row of a table that spells enum values as scene files and the CLI write them.
#pragma once

namespace sgbake {

/// @brief The name @p name stands for @p value (e.g. {"keep-boundaries", kKeepBoundaries}).
template <class E>
struct Named {
  const char* name;
  E value;
};

}  // namespace sgbake
