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

// Spins until this thread has spent `seconds` of CPU; returns its CPU clock then.
double burn(double seconds) {
  const double start = own_cpu_seconds();
  volatile double sink = 0;
  while (own_cpu_seconds() - start < seconds) sink = sink + 1.0;
  return own_cpu_seconds();
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
    burnt = burn(0.06);
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

// Each part's total only grows: a thread that ends keeps what was counted of it, and a new one of
// the same part adds its own.
TEST(ThreadCpu, CpuByPartNeverFallsWhenAThreadEnds) {
  const auto burn_as_helper = [](double seconds) {
    std::thread([seconds] {
      name_this_thread("arp-helper");
      burn(seconds);
    }).join();
  };
  CpuByPart cpu;
  const double helper_before = cpu.update()["helper"];  // none yet: 0
  std::atomic<int> stage{0};
  std::thread first([&] {
    name_this_thread("arp-helper");
    burn(0.03);
    stage = 1;
    stage.notify_all();
    stage.wait(1);
  });
  stage.wait(0);
  const double while_alive = cpu.update()["helper"];
  stage = 2;
  stage.notify_all();
  first.join();
  EXPECT_EQ(helper_before, 0.0);
  EXPECT_GE(while_alive, 0.03 - 1e-3);
  const double after_end = cpu.update()["helper"];
  EXPECT_GE(after_end, while_alive);  // counted once, never taken back
  burn_as_helper(0.02);               // started and ended between two calls: its time is lost
  const double next = cpu.update()["helper"];
  EXPECT_GE(next, after_end);
  EXPECT_LT(next, after_end + 0.005);
}

TEST(ThreadCpu, EachThreadNameHasItsPart) {
  EXPECT_EQ(thread_part("arp-process"), "processing");
  EXPECT_EQ(thread_part("arp-helper"), "helper");
  EXPECT_EQ(thread_part("llvmpipe-1"), "gl");
  EXPECT_EQ(thread_part("arp-capture"), "capture");
  EXPECT_EQ(thread_part("arp-sinks"), "sinks");
  EXPECT_EQ(thread_part("arp-sink sinks."), "sinks");
  EXPECT_EQ(thread_part("arpiped"), "other");
  EXPECT_EQ(thread_part("arp-sinkhole"), "other");
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
