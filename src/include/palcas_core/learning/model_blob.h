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

/// Throws std::invalid_argument naming the problem if the checksum does not match the
/// layout id or a value is not finite (index and value in the message).
void validateModelBlob(const ModelBlob& blob);

/// Writes the blob as a model file (kind 1, atomically). Throws std::runtime_error.
void saveModelBlob(const ModelBlob& blob, const std::string& path);
/// Reads a model file written by saveModelBlob or PdqnAgent::saveModel. Throws
/// std::runtime_error if the file fails any check of nn::readModelFile or holds a
/// non-finite value.
ModelBlob loadModelBlob(const std::string& path);

}  // namespace palcas
