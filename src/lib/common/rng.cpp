#include "palcas_core/common/rng.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace palcas {

Rng::Rng(uint64_t seed) : engine_(seed) {}

uint64_t Rng::uniformIndex(uint64_t n) {
  if (n == 0) throw std::invalid_argument("Rng::uniformIndex: n must be > 0");
  // Rejection sampling removes the modulo bias: accept only draws below the largest
  // multiple of n that fits in 64 bits.
  const uint64_t limit = UINT64_MAX - (UINT64_MAX % n);
  uint64_t draw = engine_();
  while (draw >= limit) draw = engine_();
  return draw % n;
}

float Rng::normal() {
  // Box-Muller: z = sqrt(-2 ln u1) cos(2 pi u2), u1 in (0, 1].
  const double u1 = (static_cast<double>(engine_() >> 11) + 1.0) * (1.0 / 9007199254740992.0);
  const double u2 = static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0);
  return static_cast<float>(std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2));
}

std::string Rng::state() const {
  std::ostringstream out;
  out << engine_;
  return out.str();
}

void Rng::setState(const std::string& text) {
  std::istringstream in(text);
  std::mt19937_64 parsed;
  in >> parsed;
  if (in.fail()) throw std::invalid_argument("Rng::setState: text is not a mt19937_64 state");
  engine_ = parsed;
}

}  // namespace palcas
