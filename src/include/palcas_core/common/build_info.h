#pragma once
// What the core's arithmetic was built for. The policy's sums follow the vector width Eigen
// compiles to (-march=native, the compiler's default with PALCAS_NATIVE_ARCH OFF, or
// PALCAS_MARCH), so the same command on the same traffic gives identical runs only where
// these agree: run manifests record them.

#include <string>

namespace palcas {

struct BuildInfo {
  std::string arch;  ///< "native" (-march=native), "portable" (the compiler's default target) or PALCAS_MARCH's value
  std::string simd;  ///< Eigen's vector instruction sets in use, e.g. "AVX512, FMA, AVX2, ..."
  std::string cpu;   ///< the running machine's CPU model ("unknown" where it cannot be read)
};

/// The core's build settings and the CPU it runs on.
BuildInfo buildInfo();

}  // namespace palcas
