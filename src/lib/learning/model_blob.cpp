#include "palcas_core/learning/model_blob.h"

#include <Eigen/Core>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "palcas_core/learning/nn/serialization.h"

namespace palcas {

BlobCheck checkModelBlob(const ModelBlob& blob, const ModelBlob* reference,
                         const std::string& reference_name) {
  if (reference && blob.layout_id != reference->layout_id)
    return {BlobProblem::kLayoutMismatch, "layout '" + blob.layout_id + "' differs from " +
                                              reference_name + "'s '" + reference->layout_id + "'"};
  if (blob.layout_checksum != nn::fnv1a64(blob.layout_id))
    return {BlobProblem::kLayoutMismatch, "layout checksum " +
                                              std::to_string(blob.layout_checksum) +
                                              " does not match layout id '" + blob.layout_id + "'"};
  if (reference && blob.values.size() != reference->values.size())
    return {BlobProblem::kWrongValueCount, std::to_string(blob.values.size()) + " values, " +
                                               reference_name + " has " +
                                               std::to_string(reference->values.size())};
  const Eigen::Map<const Eigen::VectorXf> all(blob.values.data(),
                                              static_cast<Eigen::Index>(blob.values.size()));
  if (all.allFinite()) return {};
  for (size_t i = 0; i < blob.values.size(); ++i) {
    if (!std::isfinite(blob.values[i])) {
      std::ostringstream detail;
      detail << "value " << i << " is not finite (" << blob.values[i] << ")";
      return {BlobProblem::kNonFinite, detail.str()};
    }
  }
  return {};
}

void validateModelBlob(const ModelBlob& blob) {
  const BlobCheck check = checkModelBlob(blob);
  if (!check.ok()) throw std::invalid_argument("model blob: " + check.detail);
}

void saveModelBlob(const ModelBlob& blob, const std::string& path) {
  nn::FileContents c;
  c.kind = nn::FileKind::kModel;
  c.layout = blob.layout_id;
  c.layout_checksum = blob.layout_checksum;
  c.values = blob.values;
  nn::writeModelFile(path, c);
}

ModelBlob loadModelBlob(const std::string& path) {
  nn::FileContents c = nn::readModelFile(path, nn::FileKind::kModel);
  ModelBlob blob{std::move(c.layout), c.layout_checksum, std::move(c.values)};
  try {
    validateModelBlob(blob);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return blob;
}

}  // namespace palcas
