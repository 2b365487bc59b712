#include "palcas_core/learning/nn/bf16_gemm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <stdexcept>

#include "common/throws_naming.h"
#include "nn_test_util.h"
#include "palcas_core/learning/nn/linear.h"

using namespace palcas::nn;
using palcas::nn::test::randomMatrix;

namespace {

Matrix roundedToBf16(const Matrix& m) { return m.unaryExpr([](float v) { return roundToBf16(v); }); }

}  // namespace

TEST(Bf16, RoundsToTheNearestBfloat16TiesToEven) {
  EXPECT_EQ(roundToBf16(1.0f), 1.0f);
  // bfloat16 keeps 8 significant bits: between 1 and 2 its step is 2^-7.
  EXPECT_EQ(roundToBf16(1.0f + 0.4f / 128), 1.0f);
  EXPECT_EQ(roundToBf16(1.0f + 0.6f / 128), 1.0f + 1.0f / 128);
  EXPECT_EQ(roundToBf16(1.0f + 0.5f / 128), 1.0f);                      // tie: to the even 1.0
  EXPECT_EQ(roundToBf16(1.0f + 1.5f / 128), 1.0f + 2.0f / 128);         // tie: to the even 1 + 2/128
  EXPECT_EQ(roundToBf16(-3.0f), -3.0f);
  EXPECT_TRUE(std::isinf(roundToBf16(std::numeric_limits<float>::infinity())));
  EXPECT_TRUE(std::isnan(roundToBf16(std::numeric_limits<float>::quiet_NaN())));
}

TEST(Bf16Gemm, EqualsTheFloatProductOfTheRoundedInputs) {
  if (!bf16GemmAvailable()) GTEST_SKIP() << "built for a CPU without AVX-512 BF16";
  // The network's largest layer (512 x 256) times a batch of 24, and a small odd-sized one.
  for (const auto& [rows, depth, batch] : {std::tuple<Index, Index, Index>{512, 256, 24}, {32, 6, 8}}) {
    palcas::Rng rng(1);
    const Matrix w = randomMatrix(rows, depth, rng), x = randomMatrix(depth, batch, rng);
    Matrix out;
    std::vector<uint16_t> scratch;
    bf16Gemm(packBf16(w), x, out, scratch);
    ASSERT_EQ(out.rows(), rows);
    ASSERT_EQ(out.cols(), batch);
    // What it must compute: the product of the rounded inputs (here in double; left are only
    // float sums in another order); and what that costs against the product of the inputs
    // as given: bfloat16's ~3 significant digits. (Loops, not Eigen products: GCC 12 warns
    // inside Eigen's AVX-512 kernels, so the library keeps them out of the tests.)
    const Matrix wr = roundedToBf16(w), xr = roundedToBf16(x);
    double worst_rounded = 0.0, worst_plain = 0.0;
    for (Index j = 0; j < batch; ++j) {
      for (Index i = 0; i < rows; ++i) {
        double rounded = 0.0, plain = 0.0;
        for (Index k = 0; k < depth; ++k) {
          rounded += static_cast<double>(wr(i, k)) * xr(k, j);
          plain += static_cast<double>(w(i, k)) * x(k, j);
        }
        worst_rounded = std::max(worst_rounded, std::abs(out(i, j) - rounded));
        worst_plain = std::max(worst_plain, std::abs(out(i, j) - plain));
      }
    }
    const double scale = std::sqrt(static_cast<double>(depth));  // the sums' size
    EXPECT_LT(worst_rounded, 1e-5 * scale) << rows << " x " << depth;
    EXPECT_GT(worst_plain, 1e-4 * scale) << "bfloat16 inputs: not the float product";
    EXPECT_LT(worst_plain, 0.02 * scale);
  }
}

TEST(Bf16Gemm, RefusesShapesItCannotRunNamingThem) {
  if (!bf16GemmAvailable()) {
    palcas_test::expectThrowNaming<std::logic_error>([] { packBf16(Matrix::Zero(32, 2)); }, "AVX-512 BF16");
    return;
  }
  palcas_test::expectThrowNaming<std::invalid_argument>([] { packBf16(Matrix::Zero(30, 2)); }, "30 x 2");
  palcas_test::expectThrowNaming<std::invalid_argument>([] { packBf16(Matrix::Zero(32, 3)); }, "32 x 3");
  Matrix nan = Matrix::Zero(32, 2);
  nan(3, 1) = std::numeric_limits<float>::quiet_NaN();
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { packBf16(nan); }, "not finite");
  const Bf16Weights w = packBf16(Matrix::Ones(32, 4));
  Matrix out = Matrix::Constant(2, 2, 7.0f);
  std::vector<uint16_t> scratch;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { bf16Gemm(w, Matrix::Ones(6, 8), out, scratch); },
                                                        "input 6 x 8");
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { bf16Gemm(w, Matrix::Ones(4, 5), out, scratch); },
                                                        "input 4 x 5");
  EXPECT_EQ(out, Matrix::Constant(2, 2, 7.0f)) << "a refused product leaves its output alone";
}

namespace {

// Largest |a - b| over two equally shaped matrices.
float worstDifference(const Matrix& a, const Matrix& b) { return (a - b).cwiseAbs().maxCoeff(); }

}  // namespace

TEST(Bf16Linear, ComputesItsThreeProductsFromBfloat16InputsWithFloatSums) {
  if (!bf16GemmAvailable()) GTEST_SKIP() << "built for a CPU without AVX-512 BF16";
  palcas::Rng rng(3);
  Linear plain(256, 64, rng);
  Linear low = plain;
  low.setBf16Products(true);
  const Matrix x = randomMatrix(256, 16, rng), g = randomMatrix(64, 16, rng);
  const Matrix y_plain = plain.forward(x, true), y_low = low.forward(x, true);
  const Matrix dx_plain = plain.backward(g, {true, 0}), dx_low = low.backward(g, {true, 0});
  // The products of the rounded inputs in double: what the bf16 path must equal to float rounding.
  const Matrix w = plain.weight();
  const auto rounded = [](const Matrix& m) { return roundedToBf16(m).cast<double>().eval(); };
  const Eigen::MatrixXd y_ref = (rounded(w) * rounded(x)).colwise() + plain.bias().cast<double>();
  const Eigen::MatrixXd dw_ref = rounded(g) * rounded(x).transpose();
  const Eigen::MatrixXd dx_ref = rounded(w).transpose() * rounded(g);
  const Eigen::Map<const Matrix> dw_low(low.gradients().data(), 64, 256);
  const Eigen::Map<const Matrix> dw_plain(plain.gradients().data(), 64, 256);
  const double tight = 1e-5 * std::sqrt(256.0);
  EXPECT_LT((y_low.cast<double>() - y_ref).cwiseAbs().maxCoeff(), tight);
  EXPECT_LT((dw_low.cast<double>() - dw_ref).cwiseAbs().maxCoeff(), 1e-5 * std::sqrt(16.0));
  EXPECT_LT((dx_low.cast<double>() - dx_ref).cwiseAbs().maxCoeff(), 1e-5 * std::sqrt(64.0));
  // ... and differ from the float products by bfloat16's precision, not more.
  for (const auto& [low_m, plain_m, depth] :
       {std::tuple<Matrix, Matrix, double>{y_low, y_plain, 256}, {dw_low, dw_plain, 16}, {dx_low, dx_plain, 64}}) {
    EXPECT_GT(worstDifference(low_m, plain_m), 1e-4 * std::sqrt(depth));
    EXPECT_LT(worstDifference(low_m, plain_m), 0.02 * std::sqrt(depth));
  }
  // The bias gradient is a sum, not a product: float either way.
  EXPECT_EQ(low.gradients().tail(64), plain.gradients().tail(64));
}

TEST(Bf16Linear, ShapesOutsideItsTilesStayFloatBitForBit) {
  if (!bf16GemmAvailable()) {
    palcas::Rng rng(1);
    Linear layer(4, 32, rng);
    palcas_test::expectThrowNaming<std::logic_error>([&] { layer.setBf16Products(true); }, "AVX-512 BF16");
    return;
  }
  // The networks' first layers (45 or 49 inputs), an odd batch, and the heads (1 or 4
  // outputs), whose input gradient (rows 256, depth 4) is the one product that fits.
  for (const auto& [in, out, batch] : {std::tuple<Index, Index, Index>{45, 256, 16}, {64, 64, 9}, {256, 4, 16}}) {
    palcas::Rng rng(5);
    Linear plain(in, out, rng);
    Linear low = plain;
    low.setBf16Products(true);
    const Matrix x = randomMatrix(in, batch, rng), g = randomMatrix(out, batch, rng);
    EXPECT_EQ(low.forward(x, true), plain.forward(x, true)) << in << " x " << out;
    const Matrix dx_low = low.backward(g, {true, 0}), dx_plain = plain.backward(g, {true, 0});
    EXPECT_EQ(low.gradients(), plain.gradients()) << in << " x " << out;
    if (out % 2 != 0 || in % 32 != 0 || batch % 8 != 0) EXPECT_EQ(dx_low, dx_plain) << in << " x " << out;
    else EXPECT_NE(dx_low, dx_plain) << "the head's input gradient fits the tiles";
  }
}
