// What tools that never call poll() see: stat() and fstat() of a character device of the
// video4linux major, select() and epoll that wake for a frame and time out when none is due, and
// dup()s that are the same open file.
#include "standin_fixture.h"

#include <sys/epoll.h>
#include <sys/select.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

namespace arpipe::standin_test {
namespace {

using ReadinessTest = StandinTest;

TEST_F(ReadinessTest, StatShowsACharacterDeviceOfTheVideoMajor) {
  load("pacing = \"fast\"\n");
  struct stat st {};
  ASSERT_EQ(stat(kDevice, &st), 0);
  EXPECT_EQ(st.st_mode, mode_t(S_IFCHR | 0660));
  EXPECT_EQ(major(st.st_rdev), 81u);
  EXPECT_EQ(minor(st.st_rdev), 42u);  // /dev/videoN keeps N
  struct stat lst {};
  ASSERT_EQ(lstat(kDevice, &lst), 0);
  EXPECT_EQ(lst.st_rdev, st.st_rdev);
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  struct stat fst {};
  ASSERT_EQ(fstat(fd, &fst), 0);
  EXPECT_TRUE(S_ISCHR(fst.st_mode));
  EXPECT_EQ(fst.st_rdev, st.st_rdev);
  EXPECT_EQ(fst.st_ino, st.st_ino);
  struct statx sx {};
  ASSERT_EQ(statx(AT_FDCWD, kDevice, 0, STATX_BASIC_STATS, &sx), 0);
  EXPECT_EQ(sx.stx_mode, S_IFCHR | 0660);
  EXPECT_EQ(sx.stx_rdev_major, 81u);
  EXPECT_EQ(sx.stx_rdev_minor, 42u);
  // Everything else is the real file system's.
  EXPECT_EQ(stat("/dev/video43", &st), -1);
  EXPECT_EQ(errno, ENOENT);
  ASSERT_EQ(stat(dir_.c_str(), &st), 0);
  EXPECT_TRUE(S_ISDIR(st.st_mode));
  arpipe_v4l2_standin_unload();
  EXPECT_EQ(stat(kDevice, &st), -1);
}

TEST_F(ReadinessTest, SelectWakesForAFrameAndTimesOutWhenNoneIsDue) {
  load("pacing = \"realtime\"\n", synthetic_recording(3));  // frames 40 ms apart
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  start(fd, 4);
  const auto wait_readable = [&](int timeout_ms) {
    fd_set r;
    FD_ZERO(&r);
    FD_SET(fd, &r);
    timeval t{timeout_ms / 1000, (timeout_ms % 1000) * 1000};
    return select(fd + 1, &r, nullptr, nullptr, &t) == 1 && FD_ISSET(fd, &r);
  };
  ASSERT_TRUE(wait_readable(1000));  // frame 0 fell due at STREAMON
  v4l2_buffer b{};
  ASSERT_EQ(dqbuf(fd, b), 0);
  EXPECT_EQ(b.sequence, 0u);
  EXPECT_FALSE(wait_readable(5));  // frame 1 is 40 ms away
  const int64_t t = now_ns();
  ASSERT_TRUE(wait_readable(1000));
  EXPECT_LT(now_ns() - t, 100000000);
  ASSERT_EQ(dqbuf(fd, b), 0);
  EXPECT_EQ(b.sequence, 1u);
  ASSERT_TRUE(wait_readable(1000));
  ASSERT_EQ(dqbuf(fd, b), 0);
  EXPECT_EQ(b.sequence, 2u);
  EXPECT_FALSE(wait_readable(100));  // the recording has ended
}

TEST_F(ReadinessTest, EpollOnTheDescriptorItselfWakesForAFrame) {
  load("pacing = \"realtime\"\n", synthetic_recording(3));
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  start(fd, 4);
  const int ep = epoll_create1(EPOLL_CLOEXEC);
  ASSERT_GE(ep, 0);
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = fd;
  ASSERT_EQ(epoll_ctl(ep, EPOLL_CTL_ADD, fd, &ev), 0);
  epoll_event out{};
  for (uint32_t i = 0; i < 3; ++i) {
    const int64_t t = now_ns();
    ASSERT_EQ(epoll_wait(ep, &out, 1, 1000), 1) << i;  // woken by the frame clock, not by a call of ours
    EXPECT_LT(now_ns() - t, 100000000);
    EXPECT_EQ(out.data.fd, fd);
    v4l2_buffer b{};
    ASSERT_EQ(dqbuf(fd, b), 0);
    EXPECT_EQ(b.sequence, i);
    if (i == 0) {
      EXPECT_EQ(epoll_wait(ep, &out, 1, 5), 0);  // drained: the next frame is 40 ms away
    }
  }
  EXPECT_EQ(epoll_wait(ep, &out, 1, 100), 0);  // the recording has ended
  ::close(ep);
}

TEST_F(ReadinessTest, DuplicatesAreTheSameOpenFile) {
  load("pacing = \"fast\"\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  const int copy = dup(fd);
  ASSERT_GE(copy, 0);
  fds_.push_back(copy);
  const int copy2 = fcntl(fd, F_DUPFD_CLOEXEC, 100);
  ASSERT_GE(copy2, 100);
  fds_.push_back(copy2);
  start(fd, 2);
  close_device(fd);  // the file stays open (and owns the queue) through its duplicates
  v4l2_buffer b{};
  ASSERT_TRUE(next_buffer(copy, b));
  EXPECT_EQ(b.sequence, 0u);
  ASSERT_EQ(qbuf(copy2, b.index), 0);
  struct stat st {};
  ASSERT_EQ(fstat(copy2, &st), 0);
  EXPECT_EQ(major(st.st_rdev), 81u);
}

}  // namespace
}  // namespace arpipe::standin_test
