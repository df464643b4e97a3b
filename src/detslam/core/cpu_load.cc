#include "detslam/core/cpu_load.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

namespace detslam {

std::optional<CpuTimes> ParseCpuTimes(const std::string& line) {
  std::istringstream in(line);
  std::string name;
  if (!(in >> name) || name != "cpu") return std::nullopt;
  std::vector<uint64_t> v;
  uint64_t x = 0;
  while (in >> x) v.push_back(x);
  // user nice system idle iowait irq softirq steal [guest guest_nice]: guest time is already in
  // user and nice, so only the first 8 fields are summed.
  if (v.size() < 4) return std::nullopt;
  CpuTimes t;
  t.idle = v[3] + (v.size() > 4 ? v[4] : 0);
  for (size_t i = 0; i < v.size() && i < 8; ++i) t.total += v[i];
  return t;
}

std::optional<CpuTimes> ReadCpuTimes(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) return std::nullopt;
  return ParseCpuTimes(line);
}

double BusyFraction(const CpuTimes& before, const CpuTimes& after) {
  if (after.total <= before.total || after.idle < before.idle) return -1.0;
  const double total = static_cast<double>(after.total - before.total);
  const double idle = static_cast<double>(after.idle - before.idle);
  return std::min(1.0, std::max(0.0, 1.0 - idle / total));
}

CpuHeadroom::CpuHeadroom(Options options) : options_(std::move(options)) {}

bool CpuHeadroom::Sample() {
  const std::optional<CpuTimes> t = ReadCpuTimes(options_.stat_path);
  if (!t) return false;
  const Clock::time_point now = Clock::now();
  samples_.emplace_back(now, *t);
  // Keep one reading at least a window old, and none older than that one.
  while (samples_.size() > 2 && samples_[1].first <= now - options_.window) samples_.pop_front();
  return true;
}

double CpuHeadroom::RecentBusy() const {
  if (samples_.size() < 2) return -1.0;
  return BusyFraction(samples_.front().second, samples_.back().second);
}

double CpuHeadroom::Wait(const std::atomic<bool>* stop) {
  if (options_.max_busy >= 1.0) return 0.0;
  const Clock::time_point start = Clock::now();
  const bool first = samples_.empty();
  if (!Sample() || first) return 0.0;
  while (true) {
    const double busy = RecentBusy();
    if (busy >= 0.0 && busy <= options_.max_busy) break;
    if (Clock::now() - start >= options_.max_wait) break;
    if (stop != nullptr && stop->load()) break;
    std::this_thread::sleep_for(options_.poll);
    if (!Sample()) break;
  }
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace detslam
