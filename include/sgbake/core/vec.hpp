/// @file vec.hpp
/// @brief Small fixed-size vectors used by every sgbake kernel.
///
/// Deliberately tiny and transparent: element-wise arithmetic in the precision of the template
/// argument, no hidden fused operations (the library is built with -ffp-contract=off), so that a
/// float computation here rounds exactly like the same expression written out by hand.
#pragma once

#include <cmath>
#include <cstddef>

namespace sgbake {

template <class T>
struct Vec2T {
  T x{}, y{};

  constexpr T& operator[](std::size_t i) { return i == 0 ? x : y; }
  constexpr const T& operator[](std::size_t i) const { return i == 0 ? x : y; }
  friend constexpr Vec2T operator+(Vec2T a, Vec2T b) { return {a.x + b.x, a.y + b.y}; }
  friend constexpr Vec2T operator-(Vec2T a, Vec2T b) { return {a.x - b.x, a.y - b.y}; }
  friend constexpr Vec2T operator*(T s, Vec2T a) { return {s * a.x, s * a.y}; }
  friend constexpr bool operator==(Vec2T a, Vec2T b) { return a.x == b.x && a.y == b.y; }
};

template <class T>
struct Vec3T {
  T x{}, y{}, z{};

  constexpr T& operator[](std::size_t i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr const T& operator[](std::size_t i) const { return i == 0 ? x : (i == 1 ? y : z); }
  friend constexpr Vec3T operator+(Vec3T a, Vec3T b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Vec3T operator-(Vec3T a, Vec3T b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend constexpr Vec3T operator-(Vec3T a) { return {-a.x, -a.y, -a.z}; }
  friend constexpr Vec3T operator*(T s, Vec3T a) { return {s * a.x, s * a.y, s * a.z}; }
  friend constexpr Vec3T operator*(Vec3T a, T s) { return {a.x * s, a.y * s, a.z * s}; }
  friend constexpr bool operator==(Vec3T a, Vec3T b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  }
  constexpr Vec3T& operator+=(Vec3T b) {
    x += b.x;
    y += b.y;
    z += b.z;
    return *this;
  }
};

using Vec2f = Vec2T<float>;
using Vec2d = Vec2T<double>;
using Vec3f = Vec3T<float>;
using Vec3d = Vec3T<double>;

template <class T>
constexpr T dot(Vec3T<T> a, Vec3T<T> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <class T>
constexpr Vec3T<T> cross(Vec3T<T> a, Vec3T<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <class T>
constexpr T lengthSquared(Vec3T<T> a) {
  return dot(a, a);
}

template <class T>
T length(Vec3T<T> a) {
  return std::sqrt(dot(a, a));
}

template <class T>
constexpr T lengthSquared(Vec2T<T> a) {
  return a.x * a.x + a.y * a.y;
}

template <class To, class From>
constexpr Vec3T<To> cast(Vec3T<From> a) {
  return {static_cast<To>(a.x), static_cast<To>(a.y), static_cast<To>(a.z)};
}

template <class To, class From>
constexpr Vec2T<To> cast(Vec2T<From> a) {
  return {static_cast<To>(a.x), static_cast<To>(a.y)};
}

}  // namespace sgbake
