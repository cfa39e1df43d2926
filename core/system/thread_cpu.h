// Names this process's threads and reads each one's CPU time, so that a benchmark can say where a
// frame's CPU goes (which thread, how many cores busy) and `top -H` shows the pipeline's parts.
#pragma once

#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace arpipe {

// The calling thread's name as /proc and top show it (Linux keeps 15 bytes; the rest is cut).
void name_this_thread(std::string_view name);

struct ThreadCpu {
  int tid = 0;
  std::string name;            // /proc/self/task/TID/comm
  double cpu_seconds = 0;      // on a CPU since the thread started (user and kernel)
};

// utime + stime of a /proc stat line, in seconds (ticks of sysconf(_SC_CLK_TCK)); 0 for a line
// that does not parse. The name field may hold spaces and parentheses.
double cpu_seconds_from_stat_line(std::string_view stat);

// Every live thread of this process. From /proc/self/task/TID/schedstat (nanoseconds), else the
// stat file's utime + stime (clock ticks, 10 ms); empty when /proc does not say.
std::vector<ThreadCpu> threads_cpu();

// The part of the pipeline a thread's name puts it in: "processing" (arp-process), "helper"
// (arp-helper), "gl" (llvmpipe's rasteriser threads), "capture" (arp-capture), "sinks" (arp-sinks,
// arp-sink KEY) or "other" (the main thread, the HTTP server's, a library's).
std::string thread_part(std::string_view name);

// User and system CPU seconds of the whole process, ended threads included (getrusage).
double process_cpu_seconds();

// This process's CPU seconds by part (thread_part), summed from each thread's own counter. The
// first call counts every live thread's time since it started; each later one adds what each
// thread spent since the call before (a thread started between them counts whole). A thread
// that ends loses only its time since the last call, so the totals never fall: a Prometheus
// counter. Safe to call from any thread.
class CpuByPart {
 public:
  std::map<std::string, double> update();

 private:
  std::mutex mutex_;
  std::vector<ThreadCpu> last_;  // the threads at the call before (cpu_seconds_between from it)
  std::map<std::string, double> totals_;
};

// CPU seconds per thread between two snapshots, by tid (a thread started between them counts from
// zero, as does one whose counter is below its earlier reading: a new thread that took the tid;
// one that ended between them is missing, its time lost). Summed by the group that
// `group_of` gives each thread's name (thread_part, say).
std::map<std::string, double> cpu_seconds_between(const std::vector<ThreadCpu>& before,
                                                  const std::vector<ThreadCpu>& after,
                                                  std::string (*group_of)(std::string_view name));

}  // namespace arpipe
