/// @file udim.cpp
/// @brief UDIM textures (udim.hpp).
#include "sgbake/gradient/udim.hpp"

#include <cmath>

namespace sgbake {

int udimTileOf(Vec2d st, Vec2d& within) {
  const double u = std::floor(st.x), v = std::floor(st.y);
  within = {st.x - u, st.y - v};
  // NaN fails these comparisons too; 1e5 rows of ten tiles are far beyond any tile number.
  if (!(u >= 0 && u < 10 && v >= 0 && v < 1e5)) return 0;
  return 1001 + static_cast<int>(u) + 10 * static_cast<int>(v);
}

ScalarSample UdimScalarTexture::sample(Vec2d st) const {
  Vec2d within;
  const ScalarTexture* tile = tiles_.at(st, within);
  return tile != nullptr ? tile->sample(within) : ScalarSample{};
}

Vec3d UdimVectorTexture::sample(Vec2d st) const {
  Vec2d within;
  const VectorTexture* tile = tiles_.at(st, within);
  return tile != nullptr ? tile->sample(within) : Vec3d{0.5, 0.5, 0.5};  // the zero normal
}

}  // namespace sgbake
