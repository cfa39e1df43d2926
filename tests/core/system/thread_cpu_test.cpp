#include "core/system/thread_cpu.h"

#include <gtest/gtest.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <atomic>
#include <thread>

namespace arpipe {
namespace {

double own_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

const ThreadCpu* find_named(const std::vector<ThreadCpu>& threads, std::string_view name) {
  const auto it = std::find_if(threads.begin(), threads.end(), [&](const ThreadCpu& t) { return t.name == name; });
  return it == threads.end() ? nullptr : &*it;
}

// A named thread that burns 60 ms of CPU is listed under its name with the CPU time its own
// clock gave (the kernel's schedstat and CLOCK_THREAD_CPUTIME_ID count the same run time).
TEST(ThreadCpu, ANamedThreadIsListedWithTheCpuTimeItsOwnClockGives) {
  std::atomic<int> stage{0};
  double burnt = 0;
  std::thread burner([&] {
    name_this_thread("arp-test-burner, a name longer than fifteen bytes");
    const double start = own_cpu_seconds();
    volatile double sink = 0;
    while (own_cpu_seconds() - start < 0.06) sink = sink + 1.0;
    burnt = own_cpu_seconds();
    stage = 1;
    stage.notify_all();
    stage.wait(1);  // blocked, not spinning: no CPU until it is told to end
  });
  stage.wait(0);
  const std::vector<ThreadCpu> threads = threads_cpu();
  stage = 2;
  stage.notify_all();
  burner.join();
  const ThreadCpu* found = find_named(threads, "arp-test-burner");  // cut to 15 bytes
  ASSERT_NE(found, nullptr);
  EXPECT_GT(found->tid, 0);
  // Read after the burn (at least `burnt`), while it waits: within 20 ms of its own clock, and not
  // below it by more than the counter's step (schedstat: nanoseconds; without it, the stat file's
  // clock ticks).
  const bool nanoseconds = std::filesystem::exists("/proc/thread-self/schedstat");
  const double step = nanoseconds ? 1e-6 : 1.0 / double(sysconf(_SC_CLK_TCK));
  EXPECT_GE(found->cpu_seconds, burnt - step - 1e-3);
  EXPECT_LE(found->cpu_seconds, burnt + 0.02);
}

TEST(ThreadCpu, TheDifferenceBetweenSnapshotsIsSummedByGroup) {
  const std::vector<ThreadCpu> before{{1, "llvmpipe-0", 1.0}, {2, "llvmpipe-1", 2.0}, {3, "arp-process", 0.5}};
  // Thread 4 started between the snapshots; thread 2 ended (its time is lost).
  const std::vector<ThreadCpu> after{{1, "llvmpipe-0", 1.25}, {3, "arp-process", 1.5}, {4, "llvmpipe-2", 0.125}};
  const auto groups = cpu_seconds_between(before, after, [](std::string_view name) {
    return std::string(name.starts_with("llvmpipe") ? "GL" : "other");
  });
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_DOUBLE_EQ(groups.at("GL"), 0.375);
  EXPECT_DOUBLE_EQ(groups.at("other"), 1.0);
}

TEST(ThreadCpu, AStatLineGivesUserPlusSystemTicks) {
  const double tick = 1.0 / double(sysconf(_SC_CLK_TCK));
  // proc(5): pid (comm) state ppid ... utime (14) stime (15) ...; the name holds ") (" and spaces.
  const std::string line = "4242 (a) (b c) S 1 4242 4242 0 -1 4194560 100 0 0 0 250 50 0 0 20 0 1 0 100 0 0";
  EXPECT_NEAR(cpu_seconds_from_stat_line(line), 300 * tick, 1e-12);
  EXPECT_EQ(cpu_seconds_from_stat_line("4242 (a) S 1 2 3"), 0.0);               // too few fields
  EXPECT_EQ(cpu_seconds_from_stat_line("no name field at all"), 0.0);
  EXPECT_EQ(cpu_seconds_from_stat_line("1 (a) S 1 1 1 0 -1 0 0 0 0 0 x 5 0"), 0.0);  // utime not a number
}

}  // namespace
}  // namespace arpipe
