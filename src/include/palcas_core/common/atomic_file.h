#pragma once
// The one way the suite replaces a file it owns (checkpoints, model files, metrics, tables):
// readers and a crash mid-write see the old file or the new one, never half of either.

#include <string>

namespace palcas {

/// Writes `bytes` to "<path>.tmp", flushes it, then rename(2)s it over `path`. On failure
/// throws std::runtime_error naming the file and the system's reason; the tmp file is
/// removed and `path` keeps its old content.
void writeFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace palcas
