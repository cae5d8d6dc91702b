/// @file math.hpp
/// @brief Safe numeric primitives shared by all kernels.
///
/// Every function here states what it does at the edge of its domain, so that kernels never
/// produce NaN from round-off (acos of 1.0000001, sqrt of -1e-17, normalizing a zero vector).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "sgbake/core/vec.hpp"

namespace sgbake {

/// @brief sqrt clamped at zero: round-off may push a squared length slightly below 0.
template <class T>
T safeSqrt(T x) {
  return std::sqrt(std::max(x, T(0)));
}

/// @brief acos with its argument clamped to [-1, 1] (dot products of unit vectors overshoot).
template <class T>
T safeAcos(T x) {
  return std::acos(std::clamp(x, T(-1), T(1)));
}

/// @brief True when every component is finite (no NaN, no infinity).
template <class T>
bool isFinite(Vec3T<T> a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

template <class T>
bool isFinite(Vec2T<T> a) {
  return std::isfinite(a.x) && std::isfinite(a.y);
}

/// @brief True when |x| is larger than the smallest normal number of T.
///
/// This is MikkTSpace's notion of "not zero": denormal magnitudes count as zero.
template <class T>
bool notZero(T x) {
  return std::abs(x) > std::numeric_limits<T>::min();
}

template <class T>
bool notZero(Vec3T<T> a) {
  return notZero(a.x) || notZero(a.y) || notZero(a.z);
}

/// @brief Unit vector along @p a, or @p fallback when @p a has zero or non-finite length.
///
/// @note Overflow-safe: vectors longer than sqrt(max) are scaled down before squaring.
template <class T>
Vec3T<T> normalizeOr(Vec3T<T> a, Vec3T<T> fallback) {
  T len2 = lengthSquared(a);
  if (!(len2 > T(0)) || !std::isfinite(len2)) {
    // Either zero/denormal-squared or overflow: rescale by the largest component first.
    const T m = std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z)});
    if (!(m > T(0)) || !std::isfinite(m)) return fallback;
    a = (T(1) / m) * a;
    len2 = lengthSquared(a);
  }
  return (T(1) / std::sqrt(len2)) * a;
}

/// @brief MikkTSpace's normalize-if-nonzero: a zero vector stays zero.
template <class T>
Vec3T<T> normalizeIfNotZero(Vec3T<T> a) {
  if (!notZero(a)) return a;
  return (T(1) / length(a)) * a;
}

/// @brief Angle in radians between two vectors, robust for nearly parallel inputs
/// (atan2 of |a×b| and a·b instead of acos of the normalized dot product).
template <class T>
T angleBetween(Vec3T<T> a, Vec3T<T> b) {
  return std::atan2(length(cross(a, b)), dot(a, b));
}

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace sgbake
