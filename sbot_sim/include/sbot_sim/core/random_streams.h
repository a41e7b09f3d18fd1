// Reproducible randomness: every consumer (a robot's IR noise, a terrain generator, ...) draws from
// its own named stream derived from (scenario seed, owner, stream name). Adding a robot or a sensor
// therefore never shifts the numbers another one sees, and the same seed gives the same run.
#pragma once

#include <cstdint>
#include <map>
#include <random>
#include <string>

namespace sbot {

class RandomStreams {
 public:
  RandomStreams(std::uint64_t seed, std::string owner) : seed_(seed), owner_(std::move(owner)) {}

  /// The named stream, created on first use from a hash of (seed, owner, name).
  std::mt19937_64& stream(const std::string& name);
  /// Uniform in [lo, hi) from the named stream.
  double uniform(const std::string& name, double lo, double hi);
  /// Normal(mean, sigma) from the named stream.
  double normal(const std::string& name, double mean, double sigma);
  /// Forget every stream: the next draws repeat from the start (used by World::reset).
  void reset() { streams_.clear(); }
  std::uint64_t seed() const { return seed_; }

 private:
  std::uint64_t seed_;
  std::string owner_;
  std::map<std::string, std::mt19937_64> streams_;
};

/// Stable 64-bit hash (FNV-1a + splitmix finaliser); std::hash is not stable across builds.
std::uint64_t stableHash(std::uint64_t seed, const std::string& text);

}  // namespace sbot
