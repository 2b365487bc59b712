#pragma once
// Seeded random source of the learning code: one std::mt19937_64 with hand-written
// conversions, so the same seed gives the same numbers with any standard library
// (std::uniform_real_distribution and friends are implementation-defined).

#include <cstdint>
#include <random>
#include <string>

namespace palcas {

/// Deterministic random number generator with a saveable state. Not thread-safe.
class Rng {
 public:
  explicit Rng(uint64_t seed);

  /// Raw 64 random bits.
  uint64_t nextU64() { return engine_(); }
  /// Uniform in [0, 1) with 24 random bits (exactly representable as float).
  float uniform01() { return static_cast<float>(engine_() >> 40) * (1.0f / 16777216.0f); }
  /// Uniform in [low, high). Precondition: low <= high (not checked in this hot path).
  float uniform(float low, float high) { return low + (high - low) * uniform01(); }
  /// Uniform integer in [0, n). Throws std::invalid_argument if n == 0.
  uint64_t uniformIndex(uint64_t n);
  /// Standard normal sample (Box-Muller on two uniforms; no cached second value, so the
  /// stream position depends only on the number of calls).
  float normal();

  /// Engine state as text (std::mt19937_64 stream format), for checkpoints.
  std::string state() const;
  /// Restores a state from state(). Throws std::invalid_argument (state unchanged) if the
  /// text is not a valid engine state.
  void setState(const std::string& text);

 private:
  std::mt19937_64 engine_;
};

}  // namespace palcas
