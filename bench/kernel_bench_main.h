// main() of the Google Benchmark kernel benchmarks (detslam_bench_orb, detslam_bench_dynamic).
#pragma once

#include <benchmark/benchmark.h>

#include "detslam/core/allocator.h"

namespace detslam::bench {

// Runs the registered benchmarks. Freed frame-sized buffers stay in the process for the next
// iteration, as in the pipeline's steady state (detslam/core/allocator.h).
inline int RunKernelBenchmarks(int argc, char** argv) {
  KeepFreedMemoryForReuse();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace detslam::bench
