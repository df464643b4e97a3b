#include "detslam/core/cpu_load.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace detslam {
namespace {

TEST(CpuLoadTest, ParsesTheAggregateLine) {
  // user nice system idle iowait irq softirq steal guest guest_nice
  const auto t = ParseCpuTimes("cpu  100 20 30 800 50 5 5 0 40 0");
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->idle, 850u);
  EXPECT_EQ(t->total, 1010u);  // guest time is already in user: not counted twice
  EXPECT_FALSE(ParseCpuTimes("cpu0 1 2 3 4 5").has_value());  // one core's line
  EXPECT_FALSE(ParseCpuTimes("intr 1 2 3").has_value());
  EXPECT_FALSE(ParseCpuTimes("cpu 1 2").has_value());
  EXPECT_FALSE(ParseCpuTimes("").has_value());
}

TEST(CpuLoadTest, BusyFractionBetweenTwoReadings) {
  EXPECT_DOUBLE_EQ(BusyFraction({800, 1000}, {810, 1100}), 0.9);
  EXPECT_DOUBLE_EQ(BusyFraction({800, 1000}, {900, 1100}), 0.0);
  EXPECT_EQ(BusyFraction({800, 1000}, {800, 1000}), -1.0);  // no tick passed
  EXPECT_EQ(BusyFraction({800, 1000}, {700, 1100}), -1.0);  // not a later reading
}

TEST(CpuLoadTest, ReadsThisMachinesLoadOnLinux) {
  if (!std::filesystem::exists("/proc/stat")) GTEST_SKIP() << "no /proc/stat";
  const auto t = ReadCpuTimes();
  ASSERT_TRUE(t.has_value());
  EXPECT_GT(t->total, 0u);
  EXPECT_LE(t->idle, t->total);
}

class CpuHeadroomTest : public ::testing::Test {
 protected:
  void Write(const std::string& line) {
    std::ofstream(path_) << line << "\ncpu0 1 2 3 4\n";
  }
  CpuHeadroom::Options Options(double max_busy, int max_wait_ms) const {
    CpuHeadroom::Options o;
    o.max_busy = max_busy;
    o.window = std::chrono::milliseconds(50);
    o.poll = std::chrono::milliseconds(2);
    o.max_wait = std::chrono::milliseconds(max_wait_ms);
    o.stat_path = path_;
    return o;
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::string path_ = (std::filesystem::temp_directory_path() /
                       ("detslam_cpu_load_" + std::to_string(::getpid()) + ".txt"))
                          .string();
};

TEST_F(CpuHeadroomTest, WaitsWhileBusyAndGoesOnWhenIdle) {
  Write("cpu 100 0 100 800 0 0 0 0");
  CpuHeadroom headroom(Options(0.5, 10000));
  CpuHeadroom bounded(Options(0.5, 30));
  EXPECT_EQ(headroom.Wait(), 0.0);  // the first call only takes a reading
  EXPECT_EQ(bounded.Wait(), 0.0);
  // 90 % busy since: it waits, and as the file does not change, no tick passes and it waits until
  // max_wait.
  Write("cpu 190 0 100 810 0 0 0 0");
  EXPECT_GE(bounded.Wait(), 30.0);
  // 1010 of 1100 ticks idle since the first reading: goes on without reaching max_wait.
  Write("cpu 190 0 100 1810 0 0 0 0");
  EXPECT_LT(headroom.Wait(), 10000.0);
}

TEST_F(CpuHeadroomTest, StopEndsTheWait) {
  Write("cpu 100 0 100 800 0 0 0 0");
  CpuHeadroom headroom(Options(0.5, 100000));
  headroom.Wait();
  Write("cpu 190 0 100 810 0 0 0 0");
  const std::atomic<bool> stop{true};
  EXPECT_LT(headroom.Wait(&stop), 100000.0);
}

TEST_F(CpuHeadroomTest, NeverWaitsWhenOffOrUnreadable) {
  CpuHeadroom off(Options(1.0, 100000));
  EXPECT_EQ(off.Wait(), 0.0);
  EXPECT_EQ(off.Wait(), 0.0);
  CpuHeadroom unreadable(Options(0.5, 100000));  // path_ not written
  EXPECT_EQ(unreadable.Wait(), 0.0);
  EXPECT_EQ(unreadable.Wait(), 0.0);
}

}  // namespace
}  // namespace detslam
