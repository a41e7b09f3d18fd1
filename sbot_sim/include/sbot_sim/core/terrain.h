// Rough terrain (seed 2.4.1): a grey-scale image used as a height map, its grey values scaled to the
// height range HR. Without an image, a seeded fractal (multi-octave value noise) stands in for the
// seed's default bitmap. Row 0 of the image is the +y edge of the terrain (north up, as displayed).
#pragma once

#include <vector>

#include "sbot_sim/core/world_config.h"

namespace sbot {

struct HeightMap {
  int rows = 0, cols = 0;           ///< rows along y, cols along x
  double size_x = 0, size_y = 0;    ///< [m]
  std::vector<double> heights;      ///< row-major [m], rows*cols

  /// Bilinear height at world (x, y) [m]; terrain centred on the origin; 0 outside.
  double at(double x, double y) const;
};

/// Build the height map of a Rough terrain: load `heightmap_image` (OpenCV, any grey-scale or colour
/// image; colour is converted) or generate one from `heightmap_seed`. Heights span [0, height_range].
/// Throws ConfigError naming the image if it cannot be read.
HeightMap makeHeightMap(const TerrainConfig& terrain);

}  // namespace sbot
