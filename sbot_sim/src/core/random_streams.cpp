#include "sbot_sim/core/random_streams.h"

namespace sbot {

std::uint64_t stableHash(std::uint64_t seed, const std::string& text) {
  std::uint64_t h = 1469598103934665603ULL ^ seed;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  // splitmix64 finaliser: spreads nearby seeds apart.
  h += 0x9E3779B97F4A7C15ULL;
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ULL;
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBULL;
  return h ^ (h >> 31);
}

std::mt19937_64& RandomStreams::stream(const std::string& name) {
  auto it = streams_.find(name);
  if (it == streams_.end()) {
    it = streams_.emplace(name, std::mt19937_64(stableHash(seed_, owner_ + "/" + name))).first;
  }
  return it->second;
}

double RandomStreams::uniform(const std::string& name, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(stream(name));
}

double RandomStreams::normal(const std::string& name, double mean, double sigma) {
  return std::normal_distribution<double>(mean, sigma)(stream(name));
}

}  // namespace sbot
