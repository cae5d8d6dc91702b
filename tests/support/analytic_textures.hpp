// Textures with closed-form values and exact derivatives, for tests whose reference is analytic.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <utility>

#include "sgbake/core/math.hpp"
#include "sgbake/core/result.hpp"
#include "sgbake/gradient/texture.hpp"

namespace sgbake::test {

/// Largest componentwise difference of two vectors.
inline double maxAbsDiff(Vec3d a, Vec3d b) {
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
}
inline double maxAbsDiff(Vec2d a, Vec2d b) {
  return std::max(std::abs(a.x - b.x), std::abs(a.y - b.y));
}

/// What a create() that must succeed made (its error reported as a failure otherwise).
template <class T>
T created(Result<T> made) {
  EXPECT_TRUE(made) << made.error().message;
  return std::move(made).value();
}

/// Central differences of @p f at @p p, step @p h.
template <class F>
Vec3d centralGradient(const F& f, Vec3d p, double h) {
  return {(f(p + Vec3d{h, 0, 0}) - f(p - Vec3d{h, 0, 0})) / (2 * h),
          (f(p + Vec3d{0, h, 0}) - f(p - Vec3d{0, h, 0})) / (2 * h),
          (f(p + Vec3d{0, 0, h}) - f(p - Vec3d{0, 0, h})) / (2 * h)};
}

/// One normal everywhere, encoded n/2 + 0.5 as a normal map's texel.
class ConstantNormalTexture final : public VectorTexture {
 public:
  explicit ConstantNormalTexture(Vec3d n) : encoded_(0.5 * n + Vec3d{0.5, 0.5, 0.5}) {}
  Vec3d sample(Vec2d) const override { return encoded_; }

 private:
  Vec3d encoded_;
};

/// h(s, t) = a·s + b·t + c·sin(2π s)·cos(2π t), exact derivatives; counts its samples
/// (thread-safe), so tests can check what was (not) evaluated.
class AnalyticHeight final : public ScalarTexture {
 public:
  AnalyticHeight(double a, double b, double c) : a_(a), b_(b), c_(c) {}
  ScalarSample sample(Vec2d st) const override {
    ++count;
    const double w = 2 * kPi;
    return {a_ * st.x + b_ * st.y + c_ * std::sin(w * st.x) * std::cos(w * st.y),
            {a_ + c_ * w * std::cos(w * st.x) * std::cos(w * st.y),
             b_ - c_ * w * std::sin(w * st.x) * std::sin(w * st.y)}};
  }
  mutable std::atomic<int> count{0};

 private:
  double a_, b_, c_;
};

}  // namespace sgbake::test
