// Shared by the fuzz targets (fuzz/*_fuzz.cc, libFuzzer): detslam's parsers read files, so each
// input is written to a file in a per-process folder (in /dev/shm when it exists) and the parser
// is run on it. A parser may refuse an input only with InputError (a clear message naming the
// file); any other exception escapes LLVMFuzzerTestOneInput and libFuzzer reports it as a crash,
// as it does for sanitizer reports, timeouts and leaks.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "detslam/core/binary_io.h"
#include "detslam/core/check.h"

namespace detslam::fuzz {

// The folder the inputs are written to (created once per process).
inline const std::filesystem::path& WorkDir() {
  static const std::filesystem::path dir = [] {
    namespace fs = std::filesystem;
    const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    const fs::path d = base / ("detslam_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// Writes `bytes` to WorkDir()/name (replacing it); returns the path.
inline std::string WriteInput(const std::string& name, const std::string& bytes) {
  const std::filesystem::path p = WorkDir() / name;
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(),
                                                             static_cast<std::streamsize>(bytes.size()));
  return p.string();
}

inline std::string Bytes(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// `body` closed by the 8-byte FNV-1a 64 checksum detslam's binary files end with, so that the
// fuzzer reaches the parsing behind the checksum check.
inline std::string WithChecksum(std::string body) {
  const uint64_t sum = Fnv1a64(body.data(), body.size());
  PutLE(&body, sum, 8);
  return body;
}

// The file for a target of a binary format: the first input byte chooses (bit 0) whether the rest
// is the file as it is or a body closed by a valid checksum (WithChecksum). False for an empty
// input.
inline bool BinaryFile(const uint8_t* data, size_t size, std::string* file) {
  if (size == 0) return false;
  *file = Bytes(data + 1, size - 1);
  if (data[0] & 1) *file = WithChecksum(std::move(*file));
  return true;
}

// Splits `text` at every "\n===\n" (one input holding several files).
inline std::vector<std::string> SplitParts(const std::string& text) {
  std::vector<std::string> parts;
  const std::string sep = "\n===\n";
  size_t start = 0;
  for (size_t at; (at = text.find(sep, start)) != std::string::npos; start = at + sep.size())
    parts.push_back(text.substr(start, at - start));
  parts.push_back(text.substr(start));
  return parts;
}

// Runs f; an InputError (the parser refusing the input cleanly) is the expected outcome for most
// inputs. Returns true when f finished without one.
template <typename F>
bool Accepts(F&& f) {
  try {
    std::forward<F>(f)();
    return true;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace detslam::fuzz
