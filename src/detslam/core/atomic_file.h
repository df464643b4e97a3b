// Atomic output: write to a temporary file beside the target, then rename over it, so a failed
// run never leaves a truncated file behind.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace detslam {

// Calls `write` with a stream to a temporary file in the target's folder; on success (no
// exception, stream good) renames it to `path`. Throws InputError naming `path` on failure.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// Same for binary content produced elsewhere (e.g. an encoded PNG buffer).
void WriteBytesAtomically(const std::string& path, const std::string& bytes);

}  // namespace detslam
