// Compiled into every program of a ThreadSanitizer build only (CMakeLists.txt): OpenCV's parallel
// loops run on a TBB pool that ThreadSanitizer cannot see into, so each loop body would be reported
// as racing with the thread that started it. OpenCV's own threading is switched off before main,
// so that the reports left are about detslam's threads. One thread rather than 0: both run the
// loops in the calling thread, but after setNumThreads(0) OpenCV 4.6 (TBB) still reports its pool's
// size from getNumThreads(), and code that saves and restores the count (pipeline/runner.cc) would
// then turn the pool back on.
#include <opencv2/core/utility.hpp>

namespace {
const bool kOpenCvSequential = [] {
  cv::setNumThreads(1);
  return true;
}();
}  // namespace
