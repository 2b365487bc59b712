#pragma once
// The core's checks of its input: a refused value throws std::invalid_argument whose text
// names what was wrong (the suite's rule for bad input). A check takes its message in parts
// and joins them only when it fails, so a check on every vehicle of every step costs a
// comparison, not a string.

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace palcas::common {

/// The parts as an std::ostream writes them, joined: text("x_m is ", 0.5) is "x_m is 0.5"
/// (numbers in the stream's default form: "1e+06", "nan", "-inf"; integers as std::to_string).
template <typename... Parts>
std::string text(const Parts&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  return out.str();
}

/// Throws std::invalid_argument(text(parts...)) unless ok, e.g.
/// require(lanes >= 1, "RsuControllerOptions: num_lanes = ", lanes, " must be >= 1").
template <typename... Parts>
void require(bool ok, const Parts&... parts) {
  if (!ok) throw std::invalid_argument(text(parts...));
}

/// Throws std::invalid_argument("<name> must be finite and > 0") unless value is.
inline void requirePositive(double value, std::string_view name) {
  require(std::isfinite(value) && value > 0.0, name, " must be finite and > 0");
}

/// Throws std::invalid_argument("<name> must be finite and >= 0") unless value is.
inline void requireNonNegative(double value, std::string_view name) {
  require(std::isfinite(value) && value >= 0.0, name, " must be finite and >= 0");
}

}  // namespace palcas::common
