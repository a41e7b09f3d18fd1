#include "sbot_sim/core/terrain.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/input_file.h"
#include "sbot_sim/core/random_streams.h"

namespace sbot {

double HeightMap::at(double x, double y) const {
  if (rows < 2 || cols < 2) return 0;
  const double fx = (x + size_x / 2) / size_x * (cols - 1);
  const double fy = (size_y / 2 - y) / size_y * (rows - 1);
  if (fx < 0 || fy < 0 || fx > cols - 1 || fy > rows - 1) return 0;
  const int i = std::min(static_cast<int>(fx), cols - 2);
  const int j = std::min(static_cast<int>(fy), rows - 2);
  const double u = fx - i, v = fy - j;
  auto h = [this](int r, int c) { return heights[static_cast<std::size_t>(r) * cols + c]; };
  return (1 - u) * (1 - v) * h(j, i) + u * (1 - v) * h(j, i + 1) + (1 - u) * v * h(j + 1, i) +
         u * v * h(j + 1, i + 1);
}

namespace {

// Multi-octave value noise in [0,1): each octave doubles the frequency and halves the amplitude.
std::vector<double> fractalNoise(int n, std::uint64_t seed) {
  std::mt19937_64 rng(stableHash(seed, "terrain"));
  std::uniform_real_distribution<double> uni(0, 1);
  std::vector<double> out(static_cast<std::size_t>(n) * n, 0.0);
  double amplitude = 1.0;
  for (int cells = 4; cells <= n / 2; cells *= 2, amplitude *= 0.5) {
    std::vector<double> lattice(static_cast<std::size_t>(cells + 1) * (cells + 1));
    for (double& v : lattice) v = uni(rng);
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        const double fy = static_cast<double>(r) / (n - 1) * cells;
        const double fx = static_cast<double>(c) / (n - 1) * cells;
        const int i = std::min(static_cast<int>(fx), cells - 1), j = std::min(static_cast<int>(fy), cells - 1);
        double u = fx - i, v = fy - j;
        u = u * u * (3 - 2 * u);  // smoothstep: no creases along lattice lines
        v = v * v * (3 - 2 * v);
        auto L = [&](int rr, int cc) { return lattice[static_cast<std::size_t>(rr) * (cells + 1) + cc]; };
        out[static_cast<std::size_t>(r) * n + c] +=
            amplitude * ((1 - u) * (1 - v) * L(j, i) + u * (1 - v) * L(j, i + 1) + (1 - u) * v * L(j + 1, i) +
                         u * v * L(j + 1, i + 1));
      }
    }
  }
  return out;
}

}  // namespace

HeightMap makeHeightMap(const TerrainConfig& t) {
  HeightMap map;
  map.size_x = t.size_x;
  map.size_y = t.size_y;
  std::vector<double> raw;
  if (!t.heightmap_image.empty()) {
    if (const std::string problem = inputFileProblem(t.heightmap_image, "image"); !problem.empty())
      throw ConfigError(t.heightmap_image, "terrain.heightmap_image", problem);
    cv::Mat img = cv::imread(t.heightmap_image, cv::IMREAD_GRAYSCALE);
    if (img.empty()) throw ConfigError(t.heightmap_image, "terrain.heightmap_image", "cannot read image");
    if (img.rows < 2 || img.cols < 2) throw ConfigError(t.heightmap_image, "terrain.heightmap_image", "image smaller than 2x2");
    map.rows = img.rows;
    map.cols = img.cols;
    raw.resize(static_cast<std::size_t>(img.rows) * img.cols);
    for (int r = 0; r < img.rows; ++r)
      for (int c = 0; c < img.cols; ++c) raw[static_cast<std::size_t>(r) * img.cols + c] = img.at<unsigned char>(r, c) / 255.0;
  } else {
    const int n = std::max(8, t.resolution);
    map.rows = map.cols = n;
    raw = fractalNoise(n, t.heightmap_seed);
  }
  const double cell = std::min(map.size_x / (map.cols - 1), map.size_y / (map.rows - 1));
  if (!(cell >= kMinTerrainCell)) {
    std::ostringstream why;
    why << map.cols << " x " << map.rows << " samples over " << map.size_x << " x " << map.size_y << " m make cells of "
        << cell * 1000 << " mm; at least " << kMinTerrainCell * 1000 << " mm (a larger size or fewer samples)";
    throw ConfigError(t.heightmap_image.empty() ? "(generated height map)" : t.heightmap_image, "terrain.size", why.str());
  }
  // An image's grey levels are absolute (0 -> 0 m, 255 -> height_range); generated noise is
  // stretched to span the whole range.
  double lo = 0, span = 1;
  if (t.heightmap_image.empty()) {
    const auto [mn, mx] = std::minmax_element(raw.begin(), raw.end());
    lo = *mn;
    span = *mx - *mn;
  }
  map.heights.resize(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    map.heights[i] = span > 0 ? (raw[i] - lo) / span * t.height_range : 0.0;
  }
  return map;
}

}  // namespace sbot
