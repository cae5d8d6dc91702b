/// @file texture.hpp
/// @brief Textures as the gradient sources read them: filtered values with exact derivatives.
#pragma once

#include <cstddef>
#include <span>

#include "sgbake/core/vec.hpp"

namespace sgbake {

/// @brief A filtered scalar value and its exact derivatives with respect to the texture
/// coordinates (s, t) (of the filtered function, not finite differences).
struct ScalarSample {
  double value = 0;
  Vec2d gradient{};  ///< (∂h/∂s, ∂h/∂t)
};

/// @brief A scalar texture over texture space (s, t): s right, t up, one repeat per unit
/// (the image repeats; tiling and offset are applied by the caller, seed 001 eq. 2).
class ScalarTexture {
 public:
  virtual ~ScalarTexture() = default;
  /// Value and exact derivatives at (s, t). Thread-safe.
  virtual ScalarSample sample(Vec2d st) const = 0;
  /// sample() at every point of @p st into @p out (the same size): what the baker reads a batch
  /// of texels with. Textures that can read a batch faster override it, bit for bit.
  virtual void sampleMany(std::span<const Vec2d> st, std::span<ScalarSample> out) const {
    for (std::size_t i = 0; i < st.size(); ++i) out[i] = sample(st[i]);
  }
};

/// @brief A three-channel texture (normal maps), filtered, in the same texture space.
class VectorTexture {
 public:
  virtual ~VectorTexture() = default;
  /// The filtered channels at (s, t), as stored (a normal map's [0,1] encoding is the
  /// caller's to decode). Thread-safe.
  virtual Vec3d sample(Vec2d st) const = 0;
};

}  // namespace sgbake
