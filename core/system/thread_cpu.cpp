#include "core/system/thread_cpu.h"

#include <dirent.h>
#include <pthread.h>
#include <sys/resource.h>

#include <charconv>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace arpipe {
namespace {

std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace

// Fields 14 and 15, counted after the ")" that ends the name.
double cpu_seconds_from_stat_line(std::string_view stat) {
  const size_t end_of_name = stat.rfind(')');
  if (end_of_name == std::string_view::npos) return 0;
  std::istringstream fields{std::string(stat.substr(end_of_name + 1))};
  std::string field;
  double ticks = 0;
  int i = 3;
  for (; i <= 15 && fields >> field; ++i) {
    double value = 0;
    if (i >= 14 && std::from_chars(field.data(), field.data() + field.size(), value).ec != std::errc()) return 0;
    ticks += i >= 14 ? value : 0;
  }
  if (i <= 15) return 0;  // too few fields
  const long per_second = sysconf(_SC_CLK_TCK);
  return per_second > 0 ? ticks / double(per_second) : 0;
}

void name_this_thread(std::string_view name) {
  const std::string cut(name.substr(0, 15));
  pthread_setname_np(pthread_self(), cut.c_str());
}

std::vector<ThreadCpu> threads_cpu() {
  std::vector<ThreadCpu> out;
  DIR* tasks = opendir("/proc/self/task");
  if (!tasks) return out;
  while (const dirent* entry = readdir(tasks)) {
    int tid = 0;
    const std::string_view id(entry->d_name);
    if (std::from_chars(id.data(), id.data() + id.size(), tid).ec != std::errc() || tid <= 0) continue;
    const std::string dir = "/proc/self/task/" + std::string(id) + "/";
    ThreadCpu thread{tid, first_line(dir + "comm"), 0};
    const std::string schedstat = first_line(dir + "schedstat");
    double ns = 0;
    if (std::from_chars(schedstat.data(), schedstat.data() + schedstat.size(), ns).ec == std::errc()) {
      thread.cpu_seconds = ns * 1e-9;
    } else {
      const std::string stat = first_line(dir + "stat");
      if (stat.empty()) continue;  // ended while listed
      thread.cpu_seconds = cpu_seconds_from_stat_line(stat);
    }
    out.push_back(std::move(thread));
  }
  closedir(tasks);
  return out;
}

double process_cpu_seconds() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  const auto seconds = [](const timeval& t) { return double(t.tv_sec) + double(t.tv_usec) * 1e-6; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

std::string thread_part(std::string_view name) {
  if (name == "arp-process") return "processing";
  if (name == "arp-helper") return "helper";
  if (name.starts_with("llvmpipe")) return "gl";
  if (name == "arp-capture") return "capture";
  if (name == "arp-sinks" || name.starts_with("arp-sink ")) return "sinks";
  return "other";
}

std::map<std::string, double> CpuByPart::update() {
  // The snapshot under the lock: two scrapes at once must not apply an older one after a newer
  // one (its smaller counters would read as reused tids and count whole).
  std::lock_guard lock(mutex_);
  std::vector<ThreadCpu> now = threads_cpu();
  for (const auto& [part, seconds] : cpu_seconds_between(last_, now, thread_part)) totals_[part] += seconds;
  last_ = std::move(now);
  return totals_;
}

std::map<std::string, double> cpu_seconds_between(const std::vector<ThreadCpu>& before,
                                                  const std::vector<ThreadCpu>& after,
                                                  std::string (*group_of)(std::string_view name)) {
  std::map<int, double> at_start;
  for (const ThreadCpu& thread : before) at_start[thread.tid] = thread.cpu_seconds;
  std::map<std::string, double> out;
  for (const ThreadCpu& thread : after) {
    const auto it = at_start.find(thread.tid);
    // A tid used again by a thread started since has a smaller counter: it counts whole.
    const double before = it != at_start.end() && it->second <= thread.cpu_seconds ? it->second : 0.0;
    out[group_of(thread.name)] += thread.cpu_seconds - before;
  }
  return out;
}

}  // namespace arpipe
