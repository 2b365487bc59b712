#pragma once
// A bfloat16 matrix product with float accumulation (AVX-512 BF16). The benchmark times it
// against Eigen's float product on the network's largest layer; Linear uses it for the
// gradient step's products when asked (learning/bf16_products, off by default: a bf16 update
// differs from the float one by bfloat16's precision, docs/journal/experiments.md, "What
// bfloat16 could buy the step").

#include <cstdint>
#include <vector>

#include "palcas_core/learning/nn/types.h"

namespace palcas::nn {

/// true when this build runs bf16Gemm: compiled for a CPU with AVX-512 BF16 (the core
/// follows -march, src/CMakeLists.txt). Otherwise bf16Gemm and packBf16 throw.
bool bf16GemmAvailable();

/// The float nearest to `x` in bfloat16 (round to nearest, ties to even; NaN stays NaN).
float roundToBf16(float x);

/// Weights W (rows x cols) in bfloat16, packed for bf16Gemm: 16-row panels, each column pair
/// (k, k+1) interleaved so one 32-bit word holds W(i, k) and W(i, k + 1).
struct Bf16Weights {
  Index rows = 0, cols = 0;
  std::vector<uint32_t> pairs;
};

/// Packs W. Throws std::invalid_argument naming the shape unless rows is a multiple of 32 and
/// cols of 2 and W is finite; std::logic_error when !bf16GemmAvailable().
Bf16Weights packBf16(const Matrix& w);

/// The same packing of a rows x cols matrix read as data[i * row_stride + k * col_stride]
/// (a column-major matrix: 1, rows; its transpose: rows, 1) into `out`, reusing its storage.
/// Non-finite entries stay non-finite (no check: the float product would carry them too).
/// Throws like packBf16 on the shape.
void packBf16Into(const Scalar* data, Index rows, Index cols, Index row_stride, Index col_stride, Bf16Weights& out);

/// out = W x with W's and x's entries rounded to bfloat16 and the sums in float (out is
/// resized to W.rows x x.cols). x: W.cols x batch, batch a multiple of 8. `x_scratch` holds
/// x in bfloat16 between calls (no allocation once sized). Throws std::invalid_argument naming
/// the shapes when they do not fit, std::logic_error when !bf16GemmAvailable().
void bf16Gemm(const Bf16Weights& w, const Matrix& x, Matrix& out, std::vector<uint16_t>& x_scratch);

}  // namespace palcas::nn
