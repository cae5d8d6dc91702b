/// @file float_format_test.cpp
/// @brief formatFloatG9 (the CLI's fast `%.9g`) against printf itself.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include "float_format.hpp"

namespace sgbake::cli {
namespace {

std::string fast(float value) {
  char buffer[kMaxFloatG9Chars + 1];
  char* end = formatFloatG9(buffer, value);
  EXPECT_LE(end - buffer, static_cast<std::ptrdiff_t>(kMaxFloatG9Chars));
  return {buffer, end};
}

std::string reference(float value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.9g", static_cast<double>(value));
  return buffer;
}

TEST(FloatFormat, MatchesPrintfOnChosenValues) {
  const float values[] = {
      0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 0.1f, 1.0f / 3.0f, 2.0f / 3.0f, 1e-4f, 1e-5f, 9.9999997e-5f,
      0.000123456789f, 123456789.0f, 99999999.0f, 999999999.0f, 1e9f, 1e10f, 16777216.0f,
      // ties: ten significant digits ending in 5, rounded to even
      1234567.125f, 1234567.375f, 1234567.625f, 8388607.5f,
      // the edges of the fast path (2^-66 and 2^27) and of float itself
      std::ldexp(1.0f, -66), std::nextafter(std::ldexp(1.0f, -66), 0.0f), std::ldexp(1.0f, 27),
      std::nextafter(std::ldexp(1.0f, 27), 0.0f), std::numeric_limits<float>::min(),
      std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max(),
      std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
      std::numeric_limits<float>::quiet_NaN()};
  for (const float v : values) {
    EXPECT_EQ(fast(v), reference(v)) << std::hexfloat << v;
    EXPECT_EQ(fast(-v), reference(-v)) << std::hexfloat << -v;
  }
}

TEST(FloatFormat, MatchesPrintfAroundEveryPowerOfTen) {
  for (int p = -38; p <= 38; ++p) {
    float v = std::pow(10.0f, static_cast<float>(p));
    for (int step = 0; step < 4; ++step) v = std::nextafter(v, 0.0f);
    for (int step = 0; step < 8; ++step, v = std::nextafter(v, INFINITY)) {
      ASSERT_EQ(fast(v), reference(v)) << std::hexfloat << v;
    }
  }
}

/// A sample of all 2^32 bit patterns (every 1021st, about four million); the whole range of the
/// fast path was checked exhaustively once, which takes minutes.
TEST(FloatFormat, MatchesPrintfOnASampleOfAllFloats) {
  constexpr std::uint64_t kStride = 1021;
  int mismatches = 0;
  for (std::uint64_t bits = 0; bits <= 0xFFFF'FFFFu && mismatches < 10; bits += kStride) {
    const float v = std::bit_cast<float>(static_cast<std::uint32_t>(bits));
    const std::string got = fast(v);
    const std::string want = reference(v);
    if (got != want) {
      ++mismatches;
      ADD_FAILURE() << std::hexfloat << v << ": " << got << " instead of " << want;
    }
  }
}

}  // namespace
}  // namespace sgbake::cli
