# learning sources (lib/learning/): neural networks on Eigen (nn/), model blobs, replay,
# PDQN agent, FedAvg
list(APPEND PALCAS_CORE_SOURCES
  lib/learning/nn/linear.cpp
  lib/learning/nn/bf16_gemm.cpp
  lib/learning/nn/activation.cpp
  lib/learning/nn/batch_norm.cpp
  lib/learning/nn/dropout.cpp
  lib/learning/nn/network.cpp
  lib/learning/nn/folded_network.cpp
  lib/learning/nn/huber_loss.cpp
  lib/learning/nn/adamw.cpp
  lib/learning/nn/serialization.cpp
  lib/learning/model_blob.cpp
  lib/learning/replay_buffer.cpp
  lib/learning/pdqn_config.cpp
  lib/learning/pdqn_agent.cpp
  lib/learning/pdqn_agent_io.cpp
  lib/learning/fedavg.cpp
)
