#pragma once
// Register-blocked y = act(W x + b) on pre-packed weights (private to the library).
// Written with GCC/Clang vector extensions so the compiler emits AVX-512 (16 floats), AVX
// (8) or SSE (4) FMAs from one source. Each output value is accumulated in the same order
// (bias, then k = 0..in-1, one multiply-add per k) whatever block its column falls in, so a
// column's result never depends on the batch around it.

#include <algorithm>
#include <cstring>

#include "palcas_core/learning/nn/types.h"

namespace palcas::nn::detail {

#if defined(__AVX512F__)
constexpr Index VEC_FLOATS = 16;
constexpr Index PANEL_VECS = 4;      // 4 x 6 accumulators + 4 weights + 1 broadcast <= 32 zmm
constexpr Index MAX_BLOCK_COLS = 6;
#elif defined(__AVX__)
constexpr Index VEC_FLOATS = 8;
constexpr Index PANEL_VECS = 2;      // 2 x 4 + 2 + 1 <= 16 ymm
constexpr Index MAX_BLOCK_COLS = 4;
#else
constexpr Index VEC_FLOATS = 4;
constexpr Index PANEL_VECS = 2;
constexpr Index MAX_BLOCK_COLS = 4;
#endif
/// Rows per packed weight panel.
constexpr Index PANEL_ROWS = PANEL_VECS * VEC_FLOATS;
/// Inputs per pass over a panel: 64 rows x 128 x 4 B = 32 KiB stays in L1 for all columns
/// (measured on the AVX-512 Xeon: 4x6 blocks with 128-deep passes ~25 % faster than 2x12
/// blocks over the whole depth).
constexpr Index K_BLOCK = 128;
/// Layers with fewer outputs than this (the networks' heads: 1 and 4) use dot products.
constexpr Index SMALL_OUTPUT = VEC_FLOATS;

typedef Scalar VecF __attribute__((vector_size(VEC_FLOATS * sizeof(Scalar))));

inline VecF loadVec(const Scalar* p) {
  VecF v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// Rows [0, rows) of one panel for COLS columns over inputs [k0, k1). The accumulators
/// start from the bias on the first pass and from y (the partial sums) on later ones; ReLU
/// is applied on the last pass only. x: column stride `in`; y: column stride `out`.
template <int COLS, bool RELU>
inline void panelKernel(const Scalar* __restrict panel, const Scalar* __restrict bias,
                        const Scalar* __restrict x, Index in, Index k0, Index k1,
                        Scalar* __restrict y, Index out, Index rows) {
  VecF acc[PANEL_VECS][COLS];
  const bool full = rows == PANEL_ROWS;  // fixed-size copies inline; partial panels copy
  for (int j = 0; j < COLS; ++j) {
    const Scalar* from = k0 == 0 ? bias : y + j * out;
    Scalar start[PANEL_ROWS] = {};
    if (k0 == 0 || full)
      std::memcpy(start, from, sizeof start);
    else
      std::memcpy(start, from, static_cast<size_t>(rows) * sizeof(Scalar));
    for (Index v = 0; v < PANEL_VECS; ++v) acc[v][j] = loadVec(start + v * VEC_FLOATS);
  }
  // acc += W'(:, k) x(k, j): one broadcast per column, PANEL_VECS FMAs per broadcast.
  for (Index k = k0; k < k1; ++k) {
    VecF w[PANEL_VECS];
    for (Index v = 0; v < PANEL_VECS; ++v) w[v] = loadVec(panel + k * PANEL_ROWS + v * VEC_FLOATS);
    for (int j = 0; j < COLS; ++j) {
      const Scalar xv = x[j * in + k];
      for (Index v = 0; v < PANEL_VECS; ++v) acc[v][j] += w[v] * xv;
    }
  }
  const bool last = k1 == in;
  for (int j = 0; j < COLS; ++j) {
    Scalar result[PANEL_ROWS];
    for (Index v = 0; v < PANEL_VECS; ++v) {
      VecF a = acc[v][j];
      if (RELU && last) {  // y = max(0, z), fused so the pre-activation is never re-read
        const VecF zero = {};
        a = a > zero ? a : zero;
      }
      std::memcpy(result + v * VEC_FLOATS, &a, sizeof a);
    }
    if (full)
      std::memcpy(y + j * out, result, sizeof result);
    else
      std::memcpy(y + j * out, result, static_cast<size_t>(rows) * sizeof(Scalar));
  }
}

/// y(out x n) = act(W' x + b') for packed panels (see FoldedNetwork::Stage): panel by
/// panel, K_BLOCK inputs at a time, so the weights are fetched once per call and reused
/// from L1 for every column block.
template <bool RELU>
void denseForward(const Scalar* panels, const Scalar* bias, Index in, Index out, const Scalar* x,
                  Index n, Scalar* y) {
  const Index panel_count = (out + PANEL_ROWS - 1) / PANEL_ROWS;
  for (Index p = 0; p < panel_count; ++p) {
    const Scalar* panel = panels + p * in * PANEL_ROWS;
    const Scalar* b = bias + p * PANEL_ROWS;
    const Index rows = std::min(PANEL_ROWS, out - p * PANEL_ROWS);
    Scalar* yp = y + p * PANEL_ROWS;
    for (Index k0 = 0; k0 < in; k0 += K_BLOCK) {
      const Index k1 = std::min(in, k0 + K_BLOCK);
      Index j = 0;
      for (; j + MAX_BLOCK_COLS <= n; j += MAX_BLOCK_COLS)
        panelKernel<MAX_BLOCK_COLS, RELU>(panel, b, x + j * in, in, k0, k1, yp + j * out, out,
                                          rows);
      // Narrower blocks for the remaining columns (same per-value arithmetic).
      for (; j + 4 <= n; j += 4)
        panelKernel<4, RELU>(panel, b, x + j * in, in, k0, k1, yp + j * out, out, rows);
      for (; j + 2 <= n; j += 2)
        panelKernel<2, RELU>(panel, b, x + j * in, in, k0, k1, yp + j * out, out, rows);
      for (; j < n; ++j)
        panelKernel<1, RELU>(panel, b, x + j * in, in, k0, k1, yp + j * out, out, rows);
    }
  }
}

/// Heads with out < SMALL_OUTPUT: y(r, j) = b(r) + sum_k W(r, k) x(k, j) as one dot product
/// per value (vector partial sums in a fixed order, then the scalar tail). w: row-major.
inline void smallForward(const Scalar* w, const Scalar* bias, Index in, Index out,
                         const Scalar* x, Index n, Scalar* y) {
  const Index vec_end = in - in % VEC_FLOATS;
  for (Index j = 0; j < n; ++j) {
    const Scalar* xj = x + j * in;
    for (Index r = 0; r < out; ++r) {
      const Scalar* wr = w + r * in;
      VecF acc = {};
      for (Index k = 0; k < vec_end; k += VEC_FLOATS) acc += loadVec(wr + k) * loadVec(xj + k);
      Scalar sum = bias[r];
      for (Index v = 0; v < VEC_FLOATS; ++v) sum += acc[v];
      for (Index k = vec_end; k < in; ++k) sum += wr[k] * xj[k];
      y[j * out + r] = sum;
    }
  }
}

}  // namespace palcas::nn::detail
