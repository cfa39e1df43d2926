// One thread that runs one job at a time for another: the processing thread's helper that runs the
// next frame's first stage ahead (pipeline.overlap_first_stage). Started once, so each frame pays
// a hand-over between two waiting threads, not a thread's creation (with a std::async per frame
// the default capture ran at 291-315 frames/s, with this at 328-335, alternating at 4a047cc).
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace arpipe {

class HelperThread {
 public:
  HelperThread();
  ~HelperThread();  // waits for a job under way, then ends the thread
  HelperThread(const HelperThread&) = delete;
  HelperThread& operator=(const HelperThread&) = delete;

  // Runs job on the helper; the job must not throw. One at a time: wait() before the next.
  void start(std::function<void()> job);
  // Until the job given to start() has returned (at once when there is none).
  void wait();

 private:
  void loop();

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> job_;  // empty: none waiting
  bool busy_ = false;          // a job given and not yet finished
  bool stopping_ = false;
  std::thread thread_;         // last: starts once the members above exist
};

}  // namespace arpipe
