#pragma once
// Shared helpers of the neural-network tests: a finite-difference gradient check and a
// save/load round trip. The check runs in float (the library's only scalar): central
// differences with step h = 1e-2 on a smooth scalar loss L = sum_ij w_ij y_ij (accumulated
// in double), asserting a relative error < 1e-2 per checked value.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "palcas_core/common/rng.h"
#include "palcas_core/learning/nn/layer.h"
#include "palcas_core/learning/nn/network.h"
#include "palcas_core/learning/nn/serialization.h"

namespace palcas::nn::test {

inline Matrix randomMatrix(Index rows, Index cols, Rng& rng, float low = -1, float high = 1) {
  Matrix m(rows, cols);
  for (Index i = 0; i < m.size(); ++i) m.data()[i] = rng.uniform(low, high);
  return m;
}

/// Runs a forward pass and returns L = sum w .* y in double. `reset` runs first (e.g. to
/// replay the same dropout mask).
using ForwardFn = std::function<const Matrix&(const Matrix&)>;

inline double weightedLoss(const ForwardFn& forward, const Matrix& input, const Matrix& w) {
  const Matrix& y = forward(input);
  return (y.cast<double>().array() * w.cast<double>().array()).sum();
}

inline double relativeError(double numeric, double analytic) {
  return std::abs(numeric - analytic) / std::max(1e-2, std::abs(numeric) + std::abs(analytic));
}

constexpr double GRAD_STEP = 1e-2;
constexpr double GRAD_TOLERANCE = 1e-2;

/// Checks d L / d input of `layer` (all rows) against central differences.
inline void expectInputGradient(Layer& layer, const Matrix& input, const Matrix& w, bool training,
                                const std::function<void()>& reset = [] {}) {
  ForwardFn fwd = [&](const Matrix& x) -> const Matrix& {
    reset();
    return layer.forward(x, training);
  };
  Matrix x = input;
  fwd(x);
  const Matrix analytic = layer.backward(w, BackwardOptions{true, 0});
  ASSERT_EQ(analytic.rows(), input.rows());
  for (Index i = 0; i < x.size(); ++i) {
    const float original = x.data()[i];
    x.data()[i] = original + static_cast<float>(GRAD_STEP);
    const double plus = weightedLoss(fwd, x, w);
    x.data()[i] = original - static_cast<float>(GRAD_STEP);
    const double minus = weightedLoss(fwd, x, w);
    x.data()[i] = original;
    const double numeric = (plus - minus) / (2 * GRAD_STEP);
    EXPECT_LT(relativeError(numeric, analytic.data()[i]), GRAD_TOLERANCE)
        << "input " << i << ": numeric " << numeric << " analytic " << analytic.data()[i];
  }
}

/// Checks d L / d parameters of `layer` against central differences.
inline void expectParameterGradient(Layer& layer, const Matrix& input, const Matrix& w,
                                    bool training, const std::function<void()>& reset = [] {}) {
  ForwardFn fwd = [&](const Matrix& x) -> const Matrix& {
    reset();
    return layer.forward(x, training);
  };
  const Vector saved_buffers = layer.buffers();  // BN running stats move in training mode
  fwd(input);
  layer.backward(w, BackwardOptions{true, 0});
  const Vector analytic = layer.gradients();
  ASSERT_EQ(analytic.size(), layer.parameters().size());
  for (Index i = 0; i < layer.parameters().size(); ++i) {
    float& p = layer.parameters()[i];
    const float original = p;
    p = original + static_cast<float>(GRAD_STEP);
    const double plus = weightedLoss(fwd, input, w);
    p = original - static_cast<float>(GRAD_STEP);
    const double minus = weightedLoss(fwd, input, w);
    p = original;
    const double numeric = (plus - minus) / (2 * GRAD_STEP);
    EXPECT_LT(relativeError(numeric, analytic[i]), GRAD_TOLERANCE)
        << "parameter " << i << ": numeric " << numeric << " analytic " << analytic[i];
  }
  layer.buffers() = saved_buffers;
}

/// Saves `source`, loads the file into `target` (built differently), and expects equal
/// state values and equal eval-mode outputs on `input`.
inline void expectSaveLoadRoundTrip(Network& source, Network& target, const Matrix& input) {
  const std::string path = ::testing::TempDir() + "palcas_roundtrip_" +
                           ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                           ".model";
  saveNetwork(source, path);
  loadNetwork(target, path);
  std::remove(path.c_str());
  EXPECT_EQ(source.getState(), target.getState());
  source.eval();
  target.eval();
  const Matrix expected = source.forward(input);
  EXPECT_EQ(expected, target.forward(input));
}

}  // namespace palcas::nn::test
