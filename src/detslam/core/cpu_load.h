// The machine's CPU load from Linux's /proc/stat: the share of all cores' time that was busy
// (neither idle nor waiting for I/O) between two readings, and a wait for idle time. The
// camera-rate mode's segmentation thread waits with it before each frame it takes, so that the
// detector leaves the cores some idle time (RunOptions::camera_rate_max_busy): on a virtual
// machine whose cores are all kept busy the host may stop a core for a whole scheduling period
// (about 100 ms on the machines of docs/STATUS.md), whatever thread of the frames' path is on it.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>

namespace detslam {

struct CpuTimes {
  uint64_t idle = 0;   // idle + iowait, in clock ticks summed over all cores
  uint64_t total = 0;  // the ticks of every state
};

// The aggregate "cpu " line of /proc/stat (user nice system idle iowait irq softirq steal ...);
// nothing when the line is not one.
std::optional<CpuTimes> ParseCpuTimes(const std::string& line);

// Reads the aggregate line of `path`; nothing where it cannot be read (e.g. not Linux).
std::optional<CpuTimes> ReadCpuTimes(const std::string& path = "/proc/stat");

// Busy share of the time between two readings, in [0, 1]; -1 when no tick passed between them.
double BusyFraction(const CpuTimes& before, const CpuTimes& after);

// Waits until the machine was busy at most `max_busy` of the time over the last `window`, polling
// every `poll`, for at most `max_wait` per call. Readings of earlier calls count, so the time
// spent between calls (e.g. one segmentation) is in the window.
class CpuHeadroom {
 public:
  using Clock = std::chrono::steady_clock;
  struct Options {
    double max_busy = 1.0;  // >= 1: never waits
    std::chrono::milliseconds window{100};
    std::chrono::milliseconds poll{10};
    std::chrono::milliseconds max_wait{100};
    std::string stat_path = "/proc/stat";
  };
  explicit CpuHeadroom(Options options);

  // Returns the milliseconds waited. Returns at once where the load cannot be read, when
  // max_busy >= 1, or when *stop (may be null) becomes true.
  double Wait(const std::atomic<bool>* stop = nullptr);

 private:
  // Adds a reading; false where none could be taken.
  bool Sample();
  // Busy share from the newest reading taken at least `window` before the newest one (or the
  // oldest there is) to the newest; -1 without two readings a tick apart.
  double RecentBusy() const;

  Options options_;
  std::deque<std::pair<Clock::time_point, CpuTimes>> samples_;
};

}  // namespace detslam
