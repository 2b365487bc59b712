#pragma once
// Shape checks shared by the layers (private to the library).

#include <stdexcept>
#include <string>

#include "palcas_core/learning/nn/types.h"

namespace palcas::nn::detail {

/// Throws std::invalid_argument naming `who` unless m has `rows` rows and >= 1 column.
inline void checkBatch(const Matrix& m, Index rows, const std::string& who) {
  if (m.rows() != rows || m.cols() < 1)
    throw std::invalid_argument(who + ": expected " + std::to_string(rows) +
                                " x batch (batch >= 1), got " + std::to_string(m.rows()) +
                                " x " + std::to_string(m.cols()));
}

/// Throws std::invalid_argument unless grad has exactly rows x cols.
inline void checkGrad(const Matrix& grad, Index rows, Index cols, const std::string& who) {
  if (grad.rows() != rows || grad.cols() != cols)
    throw std::invalid_argument(who + ": gradient must be " + std::to_string(rows) + " x " +
                                std::to_string(cols) + ", got " + std::to_string(grad.rows()) +
                                " x " + std::to_string(grad.cols()));
}

}  // namespace palcas::nn::detail
