#include "detslam/core/allocator.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <vector>

namespace detslam {
namespace {

long MinorFaults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// A frame's buffers (here 16 of 1 MiB: pyramid levels, masks, blobs) allocated, written and freed
// again and again are faulted in once, not on every frame. With glibc's defaults the freed heap
// top (16 MiB) exceeds its trim threshold (twice the largest block) and goes back to the kernel.
TEST(Allocator, AFramesFreedBuffersAreReusedWithoutNewPageFaults) {
  if (!KeepFreedMemoryForReuse()) {
    GTEST_SKIP() << "this C library (or a sanitizer's allocator) has no such settings";
  }
  constexpr size_t kBlock = 1u << 20;
  constexpr int kBlocks = 16;
  constexpr long kPages = static_cast<long>(kBlocks * kBlock / 4096);
  constexpr int kRounds = 20;
  void* (*volatile allocate)(size_t) = std::malloc;  // not elided by the compiler
  void (*volatile release)(void*) = std::free;
  const long before = MinorFaults();
  for (int round = 0; round < kRounds; ++round) {
    std::vector<char*> blocks;
    for (int b = 0; b < kBlocks; ++b) {
      blocks.push_back(static_cast<char*>(allocate(kBlock)));
      ASSERT_NE(blocks.back(), nullptr);
      std::memset(blocks.back(), round + b, kBlock);
    }
    for (char* block : blocks) release(block);
  }
  const long faults = MinorFaults() - before;
  // Faulting in every round would be kRounds * kPages.
  EXPECT_LT(faults, 3 * kPages) << faults << " minor page faults in " << kRounds << " rounds of "
                                << kPages << " pages";
}

}  // namespace
}  // namespace detslam
