#include "palcas_common/model_weights.h"

namespace palcas::common {

ModelBlob toModelBlob(const palcas_msgs::ModelWeights& msg) {
  return ModelBlob{msg.layout_id, msg.layout_checksum, msg.values};
}

palcas_msgs::ModelWeights toWeightsMsg(const ModelBlob& blob, const std::string& sender,
                                       uint32_t round, uint32_t model_version,
                                       uint64_t sample_count) {
  palcas_msgs::ModelWeights m;
  m.rsu_id = sender;
  m.round = round;
  m.model_version = model_version;
  m.sample_count = sample_count;
  m.layout_id = blob.layout_id;
  m.layout_checksum = blob.layout_checksum;
  m.values = blob.values;
  return m;
}

}  // namespace palcas::common
