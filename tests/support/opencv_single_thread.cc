// Compiled into every program of a ThreadSanitizer build only (CMakeLists.txt): OpenCV's parallel
// loops run on a TBB pool that ThreadSanitizer cannot see into, so each loop body would be reported
// as racing with the thread that started it. OpenCV's own threading is switched off before main,
// so that the reports left are about detslam's threads.
#include <opencv2/core/utility.hpp>

namespace {
const bool kOpenCvSequential = [] {
  cv::setNumThreads(0);
  return true;
}();
}  // namespace
