// A Y4M sink on a FIFO whose reader leaves (issue 18, finding 7): no SIGPIPE (it would end the
// process), the broken pipe logged once and counted, and a reader that opens the FIFO later gets a
// stream of its own, header first.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>

#include "capture/sinks/y4m_sink.h"
#include "capture_test_support.h"
#include "sink_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

// Everything the FIFO holds now (the reader is non-blocking).
std::string drain(int fd) {
  std::string bytes;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;) bytes.append(buffer, size_t(n));
  return bytes;
}

bool sigpipe_pending() {
  sigset_t pending;
  sigpending(&pending);
  return sigismember(&pending, SIGPIPE) == 1;
}

bool sigpipe_blocked() {
  sigset_t mask;
  pthread_sigmask(SIG_SETMASK, nullptr, &mask);
  return sigismember(&mask, SIGPIPE) == 1;
}

TEST(SinkBrokenPipe, Y4mOnAFifoSurvivesItsReaderLeavingAndServesTheNextReader) {
  const fs::path fifo = scratch_dir("y4m-fifo") / "video.y4m";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  constexpr int kWidth = 32, kHeight = 24;  // a frame fits in the pipe's buffer
  const std::string header = "YUV4MPEG2 W32 H24 F25:1 Ip A1:1 C420jpeg\n";
  // SIGPIPE at its default: a write that raised it would end this test program.
  const auto previous_handler = std::signal(SIGPIPE, SIG_DFL);

  int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  testing::internal::CaptureStderr();
  std::string first, second;
  {
    Y4mSink sink(Y4mSinkConfig{true, fifo});  // opens the FIFO itself: no temporary for a FIFO
    sink.consume(sink_context(kWidth, kHeight, 0));
    first = drain(reader);
    ::close(reader);  // the player quits
    sink.consume(sink_context(kWidth, kHeight, 1));
    sink.consume(sink_context(kWidth, kHeight, 2));
    EXPECT_FALSE(sigpipe_pending());
    EXPECT_FALSE(sigpipe_blocked()) << "the signal mask must be as it was";
    reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // another player
    ASSERT_GE(reader, 0);
    sink.consume(sink_context(kWidth, kHeight, 3));
    second = drain(reader);
    ::close(reader);
    EXPECT_EQ(sink.frames_written(), 2u);
    EXPECT_EQ(sink.failures(), 2u);
  }
  const std::string log = testing::internal::GetCapturedStderr();
  std::signal(SIGPIPE, previous_handler);

  EXPECT_TRUE(fs::is_fifo(fifo));
  for (const auto& [stream, index] : {std::pair{first, 0}, std::pair{second, 3}}) {
    const Y4mStream y4m = parse_y4m_stream(stream, kWidth, kHeight);
    EXPECT_EQ(y4m.header, header) << "frame " << index;
    ASSERT_EQ(y4m.frames.size(), 1u);
    EXPECT_EQ(y4m.torn_tail_bytes, 0u);
  }
  EXPECT_EQ(occurrences(log, "cannot write"), 1u) << log;
  EXPECT_NE(log.find(fmt::format("{}: cannot write frame 1: {}", fifo.string(), std::strerror(EPIPE))),
            std::string::npos)
      << log;
  EXPECT_NE(log.find(fmt::format("{}: writing resumed at frame 3; 2 frames were lost", fifo.string())),
            std::string::npos)
      << log;
}

}  // namespace
}  // namespace arpipe
