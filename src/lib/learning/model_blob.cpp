#include "palcas_core/learning/model_blob.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "palcas_core/learning/nn/serialization.h"

namespace palcas {

void validateModelBlob(const ModelBlob& blob) {
  if (blob.layout_checksum != nn::fnv1a64(blob.layout_id))
    throw std::invalid_argument("model blob: layout checksum " +
                                std::to_string(blob.layout_checksum) +
                                " does not match layout id '" + blob.layout_id + "'");
  for (size_t i = 0; i < blob.values.size(); ++i) {
    if (!std::isfinite(blob.values[i])) {
      std::ostringstream msg;
      msg << "model blob: value " << i << " is not finite (" << blob.values[i] << ")";
      throw std::invalid_argument(msg.str());
    }
  }
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
