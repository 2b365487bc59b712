#pragma once
// Scalar and matrix types of the neural-network code. Layout: ONE COLUMN PER SAMPLE
// (features x batch), column-major, so a layer's forward pass is W * X for the batch.

#include <Eigen/Core>

namespace palcas::nn {

using Scalar = float;
using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
using Index = Eigen::Index;

}  // namespace palcas::nn
