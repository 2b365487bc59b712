# learning sources: neural networks on Eigen, PDQN agent, replay, FedAvg
list(APPEND PALCAS_CORE_SOURCES
  lib/rng.cpp
  lib/nn/linear.cpp
  lib/nn/relu.cpp
  lib/nn/tanh.cpp
  lib/nn/batch_norm.cpp
  lib/nn/dropout.cpp
  lib/nn/network.cpp
  lib/nn/folded_network.cpp
  lib/nn/huber_loss.cpp
  lib/nn/adamw.cpp
  lib/nn/serialization.cpp
  lib/model_blob.cpp
  lib/replay_buffer.cpp
  lib/pdqn_config.cpp
  lib/pdqn_agent.cpp
  lib/pdqn_agent_io.cpp
  lib/fedavg.cpp
)
