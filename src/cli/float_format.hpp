/// @file float_format.hpp
/// @brief printf("%.9g") for floats, several times faster than printf or std::to_chars with a
/// precision, and byte-identical to both.
///
/// Nine significant digits are what it takes to read any float back exactly, so CSV output uses
/// `%.9g`. Writing half a million tangent rows spends most of its time there; this formats the
/// usual magnitudes with one 128-bit multiplication and shift instead of arbitrary-precision
/// arithmetic, and hands everything else (zero excepted) to std::to_chars, which the C++ standard
/// defines to produce exactly printf's output.
///
/// How: a float is m·2^e with an integer m < 2^24. For the decimal exponent p of the value
/// (10^p <= |x| < 10^(p+1)), q = |x|·10^(8-p) = m·10^(8-p)·2^e lies in [10^8, 10^9); its integer
/// part and remainder are exact in 128 bits while 2^-66 <= |x| < 2^27, and rounding q half to
/// even gives the same nine digits as printf (glibc rounds the exact binary value, to nearest,
/// ties to even). The digits are then laid out as `%g` does: fixed notation for exponents -4..8,
/// scientific otherwise, trailing zeros removed.
#pragma once

#include <bit>
#include <cstddef>
#include <charconv>
#include <cstdint>
#include <cstring>

namespace sgbake::cli {

/// @brief The longest text formatFloatG9 writes: `-1.23456789e-38`.
inline constexpr std::size_t kMaxFloatG9Chars = 15;

namespace detail {

__extension__ typedef unsigned __int128 UInt128;  // GCC/Clang; __extension__ for -Wpedantic

/// 10^k for k in [0, 29], exact in 128 bits.
inline constexpr auto kPowersOf10 = [] {
  struct Table {
    UInt128 value[30];
  } table{};
  UInt128 p = 1;
  for (int k = 0; k < 30; ++k, p *= 10) table.value[k] = p;
  return table;
}();

/// Writes the @p count digits of @p digits (most significant first) to @p out.
inline char* writeDigits(char* out, const char* digits, int count) {
  std::memcpy(out, digits, static_cast<std::size_t>(count));
  return out + count;
}

/// `e+05`, `e-38`: printf's exponent, at least two digits.
inline char* writeExponent(char* out, int exponent) {
  *out++ = 'e';
  *out++ = exponent < 0 ? '-' : '+';
  const int magnitude = exponent < 0 ? -exponent : exponent;
  if (magnitude >= 100) *out++ = static_cast<char>('0' + magnitude / 100);
  *out++ = static_cast<char>('0' + magnitude / 10 % 10);
  *out++ = static_cast<char>('0' + magnitude % 10);
  return out;
}

}  // namespace detail

/// @brief Writes @p value exactly as `printf("%.9g", value)` would (C locale) and returns the
/// end of the text; @p out needs room for kMaxFloatG9Chars characters.
inline char* formatFloatG9(char* out, float value) {
  using detail::UInt128;
  constexpr std::uint32_t kMin9Digits = 100'000'000;    // 10^8
  constexpr std::uint32_t kOver9Digits = 1'000'000'000;  // 10^9

  const auto bits = std::bit_cast<std::uint32_t>(value);
  const bool negative = (bits >> 31) != 0;
  const int biasedExponent = static_cast<int>((bits >> 23) & 0xFF);
  const int e2 = biasedExponent - 127;  // 2^e2 <= |value| < 2^(e2+1) for normal values
  if ((bits & 0x7FFF'FFFF) == 0) {      // ±0
    if (negative) *out++ = '-';
    *out++ = '0';
    return out;
  }
  if (biasedExponent == 0 || e2 < -66 || e2 > 26) {  // denormal, huge, tiny, inf, nan
    return std::to_chars(out, out + kMaxFloatG9Chars, value, std::chars_format::general, 9).ptr;
  }

  const std::uint64_t m = (bits & 0x7F'FFFF) | 0x80'0000;
  const int e = e2 - 23;  // |value| = m·2^e, e in [-89, 3]
  // Decimal exponent: floor(e2·log10(2)) or one more (Ryu's integer approximation of log10(2)).
  int p = (e2 * 78913) >> 18;
  std::uint64_t q = 0;      // floor(|value|·10^(8-p)), made to have nine digits
  UInt128 remainder = 0;    // the part of |value|·10^(8-p)·2^-e below the integer q, scaled
  UInt128 half = 0;         // one half in the same scale (0: q is exact)
  for (int attempt = 0; attempt < 3; ++attempt) {
    const UInt128 scaled = m * detail::kPowersOf10.value[8 - p];
    if (e >= 0) {
      q = static_cast<std::uint64_t>(scaled << e);
      remainder = half = 0;
    } else {
      q = static_cast<std::uint64_t>(scaled >> -e);
      remainder = scaled & ((UInt128{1} << -e) - 1);
      half = UInt128{1} << (-e - 1);
    }
    if (q >= kOver9Digits) {
      ++p;
    } else if (q < kMin9Digits) {
      --p;
    } else {
      break;
    }
  }
  // Round to nearest, ties to even; 999999999.5 rounds up to the next power of ten.
  if (half != 0 && (remainder > half || (remainder == half && (q & 1) != 0))) ++q;
  if (q == kOver9Digits) {
    q = kMin9Digits;
    ++p;
  }

  char digits[9];
  for (int i = 8; i >= 0; --i, q /= 10) digits[i] = static_cast<char>('0' + q % 10);
  int significant = 9;
  while (significant > 1 && digits[significant - 1] == '0') --significant;

  if (negative) *out++ = '-';
  if (p < -4 || p >= 9) {  // scientific: d.dddde±XX
    *out++ = digits[0];
    if (significant > 1) {
      *out++ = '.';
      out = detail::writeDigits(out, digits + 1, significant - 1);
    }
    return detail::writeExponent(out, p);
  }
  if (p < 0) {  // 0.000ddd
    *out++ = '0';
    *out++ = '.';
    for (int i = -1; i > p; --i) *out++ = '0';
    return detail::writeDigits(out, digits, significant);
  }
  out = detail::writeDigits(out, digits, p + 1);  // integer part
  if (significant > p + 1) {
    *out++ = '.';
    out = detail::writeDigits(out, digits + p + 1, significant - p - 1);
  }
  return out;
}

}  // namespace sgbake::cli
