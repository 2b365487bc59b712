#include "palcas_core/learning/nn/bf16_gemm.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#if defined(__AVX512BF16__) && defined(__AVX512BW__)
#include <immintrin.h>
#define PALCAS_BF16_GEMM 1
#endif

namespace palcas::nn {

namespace {

constexpr Index TILE_ROWS = 32;  // two 16-float vectors of outputs
constexpr Index TILE_COLS = 8;   // 2 x 8 accumulators + 2 weight vectors + a broadcast

std::string shape(Index r, Index c) { return std::to_string(r) + " x " + std::to_string(c); }

void requireAvailable(const char* what) {
  if (!bf16GemmAvailable())
    throw std::logic_error(std::string(what) + ": this build has no AVX-512 BF16 (built for a CPU without it)");
}

uint16_t bf16Bits(float x) {
  uint32_t u;
  std::memcpy(&u, &x, sizeof u);
  if (std::isnan(x)) return static_cast<uint16_t>((u >> 16) | 0x40);  // stays a (quiet) NaN
  u += 0x7fff + ((u >> 16) & 1);  // round to nearest, ties to even
  return static_cast<uint16_t>(u >> 16);
}

}  // namespace

bool bf16GemmAvailable() {
#ifdef PALCAS_BF16_GEMM
  return true;
#else
  return false;
#endif
}

float roundToBf16(float x) {
  const uint32_t u = static_cast<uint32_t>(bf16Bits(x)) << 16;
  float out;
  std::memcpy(&out, &u, sizeof out);
  return out;
}

static void requirePackShape(const char* what, Index rows, Index cols) {
  if (rows <= 0 || rows % TILE_ROWS != 0 || cols <= 0 || cols % 2 != 0)
    throw std::invalid_argument(std::string(what) + ": weights " + shape(rows, cols) +
                                ": rows must be a positive multiple of 32 and columns of 2");
}

void packBf16Into(const Scalar* data, Index rows, Index cols, Index row_stride, Index col_stride, Bf16Weights& out) {
  requireAvailable("packBf16Into");
  requirePackShape("packBf16Into", rows, cols);
  out.rows = rows;
  out.cols = cols;
  out.pairs.resize(static_cast<size_t>(rows * cols / 2));
  // Panel p (rows 16p..16p+15), column pair k/2: 16 words, word l = (W(16p+l, k), W(16p+l, k+1)).
  uint32_t* dst = out.pairs.data();
  for (Index p = 0; p < rows; p += 16) {
    for (Index k = 0; k < cols; k += 2) {
      const Scalar* c0 = data + p * row_stride + k * col_stride;
      const Scalar* c1 = c0 + col_stride;
      for (Index l = 0; l < 16; ++l)
        *dst++ = static_cast<uint32_t>(bf16Bits(c0[l * row_stride])) |
                 (static_cast<uint32_t>(bf16Bits(c1[l * row_stride])) << 16);
    }
  }
}

Bf16Weights packBf16(const Matrix& w) {
  requireAvailable("packBf16");
  requirePackShape("packBf16", w.rows(), w.cols());
  if (!w.allFinite()) throw std::invalid_argument("packBf16: weights " + shape(w.rows(), w.cols()) + " are not finite");
  Bf16Weights out;
  packBf16Into(w.data(), w.rows(), w.cols(), 1, w.rows(), out);
  return out;
}

void bf16Gemm(const Bf16Weights& w, const Matrix& x, Matrix& out, std::vector<uint16_t>& x_scratch) {
  requireAvailable("bf16Gemm");
  if (x.rows() != w.cols || x.cols() == 0 || x.cols() % TILE_COLS != 0 ||
      w.pairs.size() != static_cast<size_t>(w.rows * w.cols / 2))
    throw std::invalid_argument("bf16Gemm: weights " + shape(w.rows, w.cols) + " times input " +
                                shape(x.rows(), x.cols()) +
                                ": the input needs as many rows as the weights have columns and a "
                                "positive multiple of 8 columns");
#ifdef PALCAS_BF16_GEMM
  const Index depth = w.cols, batch = x.cols();
  x_scratch.resize(static_cast<size_t>(depth * batch));
  // x column-major in bf16: each column's pairs (k, k+1) are one 32-bit word.
  const float* src = x.data();
  uint16_t* xs = x_scratch.data();
  const Index n = depth * batch;
  Index i = 0;
  for (; i + 16 <= n; i += 16)
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(xs + i),
                        reinterpret_cast<__m256i>(_mm512_cvtneps_pbh(_mm512_loadu_ps(src + i))));
  for (; i < n; ++i) xs[i] = bf16Bits(src[i]);

  out.resize(w.rows, batch);
  const Index pairs = depth / 2;
  for (Index r = 0; r < w.rows; r += TILE_ROWS) {
    const uint32_t* panel0 = w.pairs.data() + static_cast<size_t>(r / 16) * pairs * 16;
    const uint32_t* panel1 = panel0 + pairs * 16;
    for (Index c = 0; c < batch; c += TILE_COLS) {
      __m512 acc0[TILE_COLS], acc1[TILE_COLS];
      for (Index j = 0; j < TILE_COLS; ++j) acc0[j] = acc1[j] = _mm512_setzero_ps();
      const uint32_t* col = reinterpret_cast<const uint32_t*>(xs + c * depth);
      for (Index k = 0; k < pairs; ++k) {
        const __m512bh a0 = reinterpret_cast<__m512bh>(_mm512_loadu_si512(panel0 + k * 16));
        const __m512bh a1 = reinterpret_cast<__m512bh>(_mm512_loadu_si512(panel1 + k * 16));
        for (Index j = 0; j < TILE_COLS; ++j) {
          const __m512bh b = reinterpret_cast<__m512bh>(_mm512_set1_epi32(static_cast<int>(col[j * pairs + k])));
          acc0[j] = _mm512_dpbf16_ps(acc0[j], a0, b);
          acc1[j] = _mm512_dpbf16_ps(acc1[j], a1, b);
        }
      }
      for (Index j = 0; j < TILE_COLS; ++j) {
        float* dst = out.data() + (c + j) * w.rows + r;
        _mm512_storeu_ps(dst, acc0[j]);
        _mm512_storeu_ps(dst + 16, acc1[j]);
      }
    }
  }
#else
  (void)out;
  (void)x_scratch;
#endif
}

}  // namespace palcas::nn
