// The core's shared input checks (common/checks.h): the exact texts they throw, since the
// modules' own tests and callers look for them.
#include "palcas_core/common/checks.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>

using palcas::common::require;
using palcas::common::requireNonNegative;
using palcas::common::requirePositive;
using palcas::common::text;

namespace {

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double INF = std::numeric_limits<double>::infinity();

/// The text `call` throws as std::invalid_argument, or "" (and a failure) when it does not.
template <typename F>
std::string thrown(F&& call) {
  try {
    call();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument";
  return "";
}

}  // namespace

TEST(Checks, TextJoinsPartsAsAStreamWritesThem) {
  EXPECT_EQ(text("x_m is ", 0.5, ", lane ", 3), "x_m is 0.5, lane 3");
  EXPECT_EQ(text(1e6, " ", NaN, " ", -INF), "1e+06 nan -inf");
  const std::uint64_t big = 18446744073709551615u;
  EXPECT_EQ(text(big, std::size_t{7}), std::to_string(big) + "7");  // integers as to_string
  EXPECT_EQ(text(std::string("a"), std::string_view("b"), 'c'), "abc");
}

TEST(Checks, RequireThrowsItsPartsOnlyWhenNotOk) {
  EXPECT_NO_THROW(require(true, "never ", NaN));
  EXPECT_EQ(thrown([] { require(false, "AdamW: eps must be > 0"); }), "AdamW: eps must be > 0");
  EXPECT_EQ(thrown([] { require(false, "RsuControllerOptions: ", "num_lanes", " = ", 0, " ",
                                "must be >= 1"); }),
            "RsuControllerOptions: num_lanes = 0 must be >= 1");
}

TEST(Checks, PositiveAndNonNegativeRefuseNonFiniteValues) {
  EXPECT_NO_THROW(requirePositive(1e-300, "a"));
  EXPECT_NO_THROW(requireNonNegative(0.0, "a"));
  for (double bad : {0.0, -1.0, NaN, INF, -INF})
    EXPECT_EQ(thrown([&] { requirePositive(bad, "StateScales.lateral_m"); }),
              "StateScales.lateral_m must be finite and > 0")
        << bad;
  for (double bad : {-1e-9, NaN, INF, -INF})
    EXPECT_EQ(thrown([&] { requireNonNegative(bad, "RSS parameter rho"); }),
              "RSS parameter rho must be finite and >= 0")
        << bad;
}
