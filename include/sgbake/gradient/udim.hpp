/// @file udim.hpp
/// @brief UDIM textures: one texture per tile of texture space, each tile one unit square.
#pragma once

#include <map>
#include <memory>
#include <utility>

#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/texture.hpp"

namespace sgbake {

/// @brief The UDIM tile number of texture coordinates (s, t): 1001 + u + 10·v for the unit
/// square [u, u+1) × [v, v+1) with 0 ≤ u < 10 and v ≥ 0; 0 outside those columns (s < 0,
/// s ≥ 10, t < 0), where no tile lies. Also returns the coordinates within the tile, in [0, 1).
int udimTileOf(Vec2d st, Vec2d& within);

/// @brief Textures of type T (ScalarTexture or VectorTexture) by UDIM tile number.
template <class T>
class UdimTiles {
 public:
  /// @p tiles: tile number (1001 …) → texture; none may be null.
  explicit UdimTiles(std::map<int, std::unique_ptr<T>> tiles) : tiles_(std::move(tiles)) {}
  /// The texture of the tile (s, t) lies in, and in @p within the coordinates within the
  /// tile; null where no tile is given.
  const T* at(Vec2d st, Vec2d& within) const {
    const auto tile = tiles_.find(udimTileOf(st, within));
    return tile == tiles_.end() ? nullptr : tile->second.get();
  }

 private:
  std::map<int, std::unique_ptr<T>> tiles_;
};

/// @brief A scalar texture made of UDIM tiles (Blender's tiled images, Mari's UDIMs): where
/// (s, t) lies in tile k, the tile's texture is sampled at the coordinates within the tile,
/// so derivatives are those of the tile's texture (one tile spans one unit, as one image does).
/// Where no tile is given the value and derivatives are 0: no bump.
class UdimScalarTexture : public ScalarTexture {
 public:
  explicit UdimScalarTexture(std::map<int, std::unique_ptr<ScalarTexture>> tiles)
      : tiles_(std::move(tiles)) {}
  ScalarSample sample(Vec2d st) const override;

 private:
  UdimTiles<ScalarTexture> tiles_;
};

/// @brief A three-channel texture made of UDIM tiles, as UdimScalarTexture. Where no tile is
/// given the sample is (0.5, 0.5, 0.5), the encoded zero normal, which tangent-space
/// (slopesFromTangentNormal) and object-space (gradientFromObjectNormal) layers both read as
/// no bump. (0.5, 0.5, 1) would be "no bump" only in tangent space: an object-space layer
/// reads it as +Z and turns every surface there towards +Z.
class UdimVectorTexture : public VectorTexture {
 public:
  explicit UdimVectorTexture(std::map<int, std::unique_ptr<VectorTexture>> tiles)
      : tiles_(std::move(tiles)) {}
  Vec3d sample(Vec2d st) const override;

 private:
  UdimTiles<VectorTexture> tiles_;
};

}  // namespace sgbake
