#pragma once
// The core's tests' one way to say "this call is refused, and the error names what was
// wrong" (the suite's rule for bad input): the exception's type and a piece of its text.

#include <gtest/gtest.h>

#include <exception>
#include <string>

namespace palcas_test {

/// Expects `call()` to throw an E whose what() contains `needle`; reports the text otherwise.
template <typename E = std::exception, typename F>
void expectThrowNaming(F&& call, const std::string& needle) {
  try {
    call();
    ADD_FAILURE() << "no exception; expected one naming '" << needle << "'";
  } catch (const E& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << "'" << e.what() << "' does not name '" << needle << "'";
  }
}

}  // namespace palcas_test
