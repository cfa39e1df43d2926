// Controls and control events: the recording's exposure and gains while auto, the V4L2 rules for
// inactive and read-only controls, and events queued before the buffer of the frame that caused them.
#include "standin_fixture.h"

namespace arpipe::standin_test {
namespace {

using ControlsTest = StandinTest;

int get_ctrl(int fd, uint32_t id) {
  v4l2_control c{id, 0};
  EXPECT_EQ(ioctl(fd, VIDIOC_G_CTRL, &c), 0);
  return c.value;
}

TEST_F(ControlsTest, EnumerationQueriesAndAutoRules) {
  load("pacing = \"fast\"\ngain_unity = 256\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  std::vector<uint32_t> ids;
  v4l2_queryctrl q{};
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  while (ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0) {
    ids.push_back(q.id);
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  EXPECT_EQ(errno, EINVAL);
  const std::vector<uint32_t> expected = {V4L2_CID_AUTOGAIN, V4L2_CID_EXPOSURE_AUTO, V4L2_CID_EXPOSURE_ABSOLUTE,
                                          V4L2_CID_ANALOGUE_GAIN, V4L2_CID_DIGITAL_GAIN};
  EXPECT_EQ(ids, expected);

  v4l2_query_ext_ctrl e{};
  e.id = V4L2_CID_ANALOGUE_GAIN;
  ASSERT_EQ(ioctl(fd, VIDIOC_QUERY_EXT_CTRL, &e), 0);
  EXPECT_EQ(e.minimum, 256);
  EXPECT_EQ(e.maximum, 16 * 256);
  EXPECT_TRUE(e.flags & V4L2_CTRL_FLAG_INACTIVE);  // autogain is on
  e = {};
  e.id = V4L2_CID_EXPOSURE_AUTO;
  ASSERT_EQ(ioctl(fd, VIDIOC_QUERY_EXT_CTRL, &e), 0);
  EXPECT_EQ(e.type, uint32_t(V4L2_CTRL_TYPE_MENU));
  EXPECT_EQ(e.default_value, V4L2_EXPOSURE_APERTURE_PRIORITY);
  v4l2_querymenu m{};
  m.id = V4L2_CID_EXPOSURE_AUTO;
  m.index = V4L2_EXPOSURE_MANUAL;
  EXPECT_EQ(ioctl(fd, VIDIOC_QUERYMENU, &m), 0);
  m.index = V4L2_EXPOSURE_SHUTTER_PRIORITY;
  EXPECT_EQ(ioctl(fd, VIDIOC_QUERYMENU, &m), -1);
  EXPECT_EQ(errno, EINVAL);

  // The default capture: 4 ms exposure = 40 units of 100 µs; gains 1.0 = gain_unity.
  EXPECT_EQ(get_ctrl(fd, V4L2_CID_EXPOSURE_ABSOLUTE), 40);
  EXPECT_EQ(get_ctrl(fd, V4L2_CID_ANALOGUE_GAIN), 256);
  EXPECT_EQ(get_ctrl(fd, V4L2_CID_DIGITAL_GAIN), 256);

  v4l2_control c{V4L2_CID_EXPOSURE_ABSOLUTE, 100};
  EXPECT_EQ(ioctl(fd, VIDIOC_S_CTRL, &c), -1);  // auto exposure owns it
  EXPECT_EQ(errno, EACCES);
  c = {V4L2_CID_DIGITAL_GAIN, 300};
  EXPECT_EQ(ioctl(fd, VIDIOC_S_CTRL, &c), -1);  // read-only
  EXPECT_EQ(errno, EACCES);
  c = {V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_SHUTTER_PRIORITY};
  EXPECT_EQ(ioctl(fd, VIDIOC_S_CTRL, &c), -1);
  EXPECT_EQ(errno, EINVAL);
  c = {0x00981234, 0};
  EXPECT_EQ(ioctl(fd, VIDIOC_S_CTRL, &c), -1);
  EXPECT_EQ(errno, EINVAL);

  // Manual mode and a value in one S_EXT_CTRLS: the mode in the same call governs the value,
  // which clamps to the range.
  v4l2_ext_control x[2] = {};
  x[0].id = V4L2_CID_EXPOSURE_ABSOLUTE;
  x[0].value = 20000;
  x[1].id = V4L2_CID_EXPOSURE_AUTO;
  x[1].value = V4L2_EXPOSURE_MANUAL;
  v4l2_ext_controls xs{};
  xs.which = V4L2_CTRL_WHICH_CUR_VAL;
  xs.count = 2;
  xs.controls = x;
  ASSERT_EQ(ioctl(fd, VIDIOC_S_EXT_CTRLS, &xs), 0);
  EXPECT_EQ(x[0].value, 10000);
  EXPECT_EQ(get_ctrl(fd, V4L2_CID_EXPOSURE_ABSOLUTE), 10000);
  e = {};
  e.id = V4L2_CID_EXPOSURE_ABSOLUTE;
  ASSERT_EQ(ioctl(fd, VIDIOC_QUERY_EXT_CTRL, &e), 0);
  EXPECT_FALSE(e.flags & V4L2_CTRL_FLAG_INACTIVE);
  // A batch with a read-only control fails as a whole: error_idx = count for S, the index for TRY.
  x[0].id = V4L2_CID_EXPOSURE_ABSOLUTE;
  x[0].value = 7;
  x[1].id = V4L2_CID_DIGITAL_GAIN;
  x[1].value = 1;
  EXPECT_EQ(ioctl(fd, VIDIOC_S_EXT_CTRLS, &xs), -1);
  EXPECT_EQ(errno, EACCES);
  EXPECT_EQ(xs.error_idx, 2u);
  EXPECT_EQ(ioctl(fd, VIDIOC_TRY_EXT_CTRLS, &xs), -1);
  EXPECT_EQ(xs.error_idx, 1u);
  EXPECT_EQ(get_ctrl(fd, V4L2_CID_EXPOSURE_ABSOLUTE), 10000);

  // Manual exposure stays as set while frames stream (the pixels stay the recording's).
  start(fd, 2);
  v4l2_buffer b{};
  ASSERT_TRUE(next_buffer(fd, b));
  EXPECT_EQ(get_ctrl(fd, V4L2_CID_EXPOSURE_ABSOLUTE), 10000);
}

TEST_F(ControlsTest, EventsComeBeforeTheBufferOfTheirFrame) {
  const auto rec_dir = synthetic_recording(5);
  load("pacing = \"fast\"\n", rec_dir);
  RecordingReader rec(rec_dir);
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  v4l2_event_subscription sub{};
  sub.type = V4L2_EVENT_CTRL;
  sub.id = V4L2_CID_EXPOSURE_ABSOLUTE;
  sub.flags = V4L2_EVENT_SUB_FL_SEND_INITIAL;
  ASSERT_EQ(ioctl(fd, VIDIOC_SUBSCRIBE_EVENT, &sub), 0);
  sub.id = V4L2_CID_ANALOGUE_GAIN;
  sub.flags = 0;
  ASSERT_EQ(ioctl(fd, VIDIOC_SUBSCRIBE_EVENT, &sub), 0);
  sub.type = V4L2_EVENT_EOS;
  EXPECT_EQ(ioctl(fd, VIDIOC_SUBSCRIBE_EVENT, &sub), -1);  // uvcvideo: control events only
  EXPECT_EQ(errno, EINVAL);

  v4l2_event ev{};
  ASSERT_EQ(ioctl(fd, VIDIOC_DQEVENT, &ev), 0);  // the initial value
  EXPECT_EQ(ev.id, uint32_t(V4L2_CID_EXPOSURE_ABSOLUTE));
  EXPECT_EQ(ev.u.ctrl.changes, uint32_t(V4L2_EVENT_CTRL_CH_VALUE | V4L2_EVENT_CTRL_CH_FLAGS));
  EXPECT_EQ(ev.u.ctrl.value, 10);  // frame 0: 1 ms
  EXPECT_EQ(ev.pending, 0u);
  EXPECT_EQ(ioctl(fd, VIDIOC_DQEVENT, &ev), -1);
  EXPECT_EQ(errno, ENOENT);

  // One buffer at a time: each frame's new exposure (i+1 ms) and gain (1 + i/4) arrive as events
  // that are pending when its buffer is done.
  start(fd, 1);
  for (uint32_t i = 0; i < 5; ++i) {
    pollfd p{fd, POLLIN | POLLPRI, 0};
    ASSERT_EQ(poll(&p, 1, 1000), 1);
    EXPECT_EQ(p.revents & POLLIN, POLLIN);
    int32_t exposure = -1, gain = -1;
    while (ioctl(fd, VIDIOC_DQEVENT, &ev) == 0) {
      EXPECT_EQ(ev.type, uint32_t(V4L2_EVENT_CTRL));
      if (ev.id == V4L2_CID_EXPOSURE_ABSOLUTE) exposure = ev.u.ctrl.value;
      if (ev.id == V4L2_CID_ANALOGUE_GAIN) gain = ev.u.ctrl.value;
    }
    if (i > 0) {
      EXPECT_EQ(exposure, int32_t(rec.metadata(i).exposure_ns / 100000)) << i;
      EXPECT_EQ(gain, int32_t(std::lround(rec.metadata(i).analogue_gain * 100))) << i;
    }
    v4l2_buffer b{};
    ASSERT_EQ(dqbuf(fd, b), 0);
    EXPECT_EQ(b.sequence, i);
    ASSERT_EQ(qbuf(fd, b.index), 0);
  }
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kDevice, &stats), 0);
  EXPECT_EQ(stats.control_events, 1u + 4 + 4);  // initial, then exposure and gain changes of frames 1..4

  // Another file handle hears of a value set here; the setter does not (no ALLOW_FEEDBACK).
  const int other = open_device();
  sub = {};
  sub.type = V4L2_EVENT_CTRL;
  sub.id = V4L2_CID_AUTOGAIN;
  ASSERT_EQ(ioctl(other, VIDIOC_SUBSCRIBE_EVENT, &sub), 0);
  ASSERT_EQ(ioctl(fd, VIDIOC_SUBSCRIBE_EVENT, &sub), 0);
  v4l2_control c{V4L2_CID_AUTOGAIN, 0};
  ASSERT_EQ(ioctl(fd, VIDIOC_S_CTRL, &c), 0);
  ASSERT_EQ(ioctl(other, VIDIOC_DQEVENT, &ev), 0);
  EXPECT_EQ(ev.id, uint32_t(V4L2_CID_AUTOGAIN));
  EXPECT_EQ(ev.u.ctrl.value, 0);
  while (ioctl(fd, VIDIOC_DQEVENT, &ev) == 0) EXPECT_NE(ev.id, uint32_t(V4L2_CID_AUTOGAIN));
  // Unsubscribing everything drops what was pending.
  ASSERT_EQ(ioctl(fd, VIDIOC_SUBSCRIBE_EVENT, &sub), 0);
  c.value = 1;
  ASSERT_EQ(ioctl(other, VIDIOC_S_CTRL, &c), 0);
  sub.type = V4L2_EVENT_ALL;
  ASSERT_EQ(ioctl(fd, VIDIOC_UNSUBSCRIBE_EVENT, &sub), 0);
  EXPECT_EQ(ioctl(fd, VIDIOC_DQEVENT, &ev), -1);
  EXPECT_EQ(errno, ENOENT);
}

}  // namespace
}  // namespace arpipe::standin_test
