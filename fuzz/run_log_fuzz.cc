// Fuzz target: run.json as `detslam report` reads it (ReadRunLog).
#include "detslam/eval/run_log.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace detslam;
  const std::string path = fuzz::WriteInput("run.json", fuzz::Bytes(data, size));
  fuzz::Accepts([&] { ReadRunLog(path); });
  return 0;
}
