// Fuzz target: TUM trajectory / ground-truth files as `detslam eval` reads and evaluates them:
// ReadTumTrajectory, then EvaluateFiles (sorting, duplicate check, association, ATE and RPE
// alignment on whatever values it accepts). The input is the ground truth, optionally followed by
// "\n===\n" and the estimate (default: the ground truth itself).
#include "detslam/eval/evaluate.h"
#include "detslam/io/trajectory.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace detslam;
  const std::vector<std::string> parts = fuzz::SplitParts(fuzz::Bytes(data, size));
  const std::string gt = fuzz::WriteInput("groundtruth.txt", parts[0]);
  const std::string est = parts.size() > 1 ? fuzz::WriteInput("estimate.txt", parts[1]) : gt;
  if (!fuzz::Accepts([&] { ReadTumTrajectory(gt); })) return 0;
  fuzz::Accepts([&] { EvaluateFiles(gt, est, "", EvalOptions()); });
  return 0;
}
