#pragma once
// What the core's arithmetic was built for. The policy's sums follow the vector width Eigen
// compiles to (-march=native unless PALCAS_NATIVE_ARCH is OFF), so the same command on the
// same traffic gives identical runs only where these agree: run manifests record them.

#include <string>

namespace palcas {

struct BuildInfo {
  std::string arch;  ///< "native" (-march=native) or "portable" (the compiler's default target)
  std::string simd;  ///< Eigen's vector instruction sets in use, e.g. "AVX512, FMA, AVX2, ..."
  std::string cpu;   ///< the running machine's CPU model ("unknown" where it cannot be read)
};

/// The core's build settings and the CPU it runs on.
BuildInfo buildInfo();

}  // namespace palcas
