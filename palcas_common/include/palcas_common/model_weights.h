#pragma once
// palcas_msgs/ModelWeights <-> palcas_core's ModelBlob: how a model travels between the RSUs
// and the federation server. A round trip keeps every field bit for bit; non-finite values
// pass through for the server's checks to refuse.

#include <palcas_core/learning/model_blob.h>
#include <palcas_msgs/ModelWeights.h>

#include <cstdint>
#include <string>

namespace palcas::common {

ModelBlob toModelBlob(const palcas_msgs::ModelWeights& msg);
/// The message without an authentication tag; signMessage (message_auth.h) adds it.
palcas_msgs::ModelWeights toWeightsMsg(const ModelBlob& blob, const std::string& sender,
                                       uint32_t round, uint32_t model_version,
                                       uint64_t sample_count);

}  // namespace palcas::common
