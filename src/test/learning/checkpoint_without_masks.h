#pragma once
// Turns an agent checkpoint into the one the code before the valid-action masks wrote:
// checkpoint state version 1, whose replay record ends at the dones (version 2 appends one
// mask per transition there and changes nothing else), so the tests can read old files.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "palcas_core/learning/nn/adamw.h"
#include "palcas_core/learning/nn/serialization.h"

namespace palcas_test {

inline void dropMasksFromCheckpoint(const std::string& path) {
  using palcas::nn::ByteReader;
  using palcas::nn::ByteWriter;
  palcas::nn::FileContents file =
      palcas::nn::readModelFile(path, palcas::nn::FileKind::kAgentCheckpoint);
  ByteReader in(file.extra, path);
  ByteWriter out;
  auto copyFloats = [&](int arrays) {
    for (int i = 0; i < arrays; ++i) {
      const std::vector<float> values = in.floats();
      out.floats(values.data(), values.size());
    }
  };
  ASSERT_EQ(in.u32(), 2u) << path << " is not a checkpoint with masks";
  out.u32(1);
  copyFloats(2);  // target networks
  for (int i = 0; i < 2; ++i) {  // both optimisers, through their own reader and writer
    palcas::nn::AdamW optimiser;
    optimiser.read(in);
    optimiser.write(out);
  }
  for (int i = 0; i < 4; ++i) out.u64(in.u64());  // replay: state size, capacity, size, next
  copyFloats(6);                                   // s, s', action, parameter, reward, done
  in.floats();                                     // the masks: not in version 1
  out.f64(in.f64());                               // epsilon
  out.u64(in.u64());                               // gradient steps
  out.u64(in.u64());                               // decision rounds
  out.str(in.str());                               // RNG state
  ASSERT_EQ(in.remaining(), 0u);
  file.extra = out.bytes();
  palcas::nn::writeModelFile(path, file);
}

}  // namespace palcas_test
