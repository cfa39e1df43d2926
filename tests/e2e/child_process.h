// Runs a program of the build (arpiped, arpipe) as a real child process for end-to-end tests,
// with stdout and stderr captured to files, and lets the test signal it and wait for it.
#pragma once

#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace arpipe::test {

inline std::filesystem::path build_program(const std::string& name) {
  return std::filesystem::path(ARPIPE_BINARY_DIR) / "apps" / name;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Lines in a text file (0 when it does not exist): results.jsonl has one per output frame.
inline size_t count_lines(const std::filesystem::path& path) {
  std::ifstream in(path);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

class ChildProcess {
 public:
  // env: extra "NAME=value" entries for the child's environment.
  ChildProcess(const std::filesystem::path& program, const std::vector<std::string>& args,
               const std::filesystem::path& log_dir, const std::vector<std::string>& env = {})
      : stdout_path_(log_dir / "stdout.txt"), stderr_path_(log_dir / "stderr.txt") {
    std::filesystem::create_directories(log_dir);
    pid_ = fork();
    if (pid_ == 0) {
      for (const auto& entry : env) putenv(const_cast<char*>(entry.c_str()));
      if (!freopen(stdout_path_.c_str(), "w", stdout) || !freopen(stderr_path_.c_str(), "w", stderr)) _exit(127);
      std::vector<char*> argv;
      std::string prog = program.string();
      argv.push_back(prog.data());
      std::vector<std::string> copy = args;
      for (auto& a : copy) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(prog.c_str(), argv.data());
      _exit(127);
    }
  }
  ~ChildProcess() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }

  void signal(int sig) { kill(pid_, sig); }

  // Waits up to timeout; returns the wait status (or -1 on timeout, after killing the child).
  int wait(std::chrono::seconds timeout = std::chrono::seconds(120)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return status;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

  std::string stderr_text() const { return read_text(stderr_path_); }
  // Polls stderr until it holds `text`: how long the daemon takes depends on the machine (a
  // sanitizer build is several times slower), so tests wait for what they look for, not a fixed time.
  bool wait_for_stderr(const std::string& text, std::chrono::seconds timeout = std::chrono::seconds(30)) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (stderr_text().find(text) == std::string::npos) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return true;
  }
  std::string stdout_text() const { return read_text(stdout_path_); }

 private:
  std::filesystem::path stdout_path_, stderr_path_;
  pid_t pid_ = -1;
  bool exited_ = false;
};

// Runs to completion; returns the exit code, or -(signal) if it died of a signal, or -1000 on timeout.
inline int run_to_exit(const std::filesystem::path& program, const std::vector<std::string>& args,
                       const std::filesystem::path& log_dir, std::string* stderr_text = nullptr,
                       const std::vector<std::string>& env = {}) {
  ChildProcess child(program, args, log_dir, env);
  const int status = child.wait();
  if (stderr_text) *stderr_text = child.stderr_text();
  if (status == -1) return -1000;
  if (WIFSIGNALED(status)) return -WTERMSIG(status);
  return WEXITSTATUS(status);
}

}  // namespace arpipe::test
