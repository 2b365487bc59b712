#pragma once
// A whole PDQN model as one flat array: what goes over ROS for federation
// (palcas_msgs/ModelWeights mirrors it) and what a shipped policy file holds.

#include <cstdint>
#include <string>
#include <vector>

namespace palcas {

/// Parameter network + Q-network, parameters and batch-norm statistics, in the order of
/// the layout (each network: all trainable values, then all buffers; see learning.md).
struct ModelBlob {
  std::string layout_id;         ///< names the layout; models of another layout are refused
  uint64_t layout_checksum = 0;  ///< FNV-1a 64 of layout_id
  std::vector<float> values;
};

/// What is wrong with a model blob; the one check behind the federation server's refusals,
/// FedAvg's and a model's import.
enum class BlobProblem { kNone, kLayoutMismatch, kWrongValueCount, kNonFinite };

struct BlobCheck {
  BlobProblem problem = BlobProblem::kNone;
  std::string detail;  ///< names the problem: layout ids, value counts, the bad value's index
  bool ok() const { return problem == BlobProblem::kNone; }
};

/// Checks, in this order: the layout id against `reference`'s (when given), the checksum
/// against the blob's own layout id, the value count against `reference`'s, every value
/// finite. `reference_name` names the reference in the detail ("the global model").
BlobCheck checkModelBlob(const ModelBlob& blob, const ModelBlob* reference = nullptr,
                         const std::string& reference_name = "the reference model");

/// Throws std::invalid_argument "model blob: <detail>" if checkModelBlob(blob) finds a
/// problem.
void validateModelBlob(const ModelBlob& blob);

/// Writes the blob as a model file (kind 1, atomically). Throws std::runtime_error.
void saveModelBlob(const ModelBlob& blob, const std::string& path);
/// Reads a model file written by saveModelBlob or PdqnAgent::saveModel. Throws
/// std::runtime_error if the file fails any check of nn::readModelFile or holds a
/// non-finite value.
ModelBlob loadModelBlob(const std::string& path);

}  // namespace palcas
