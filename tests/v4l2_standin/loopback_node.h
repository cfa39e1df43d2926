// What both ends of a loopback pair share: the open files, the buffer queue and its owner (vb2's
// rules), DQBUF, poll and mmap. LoopbackOutput and LoopbackCapture add what differs: the format,
// what a queued buffer means, and where the frames go or come from.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <string>
#include <vector>

#include "mmap_buffers.h"
#include "served_node.h"

namespace arpipe::standin {

class LoopbackNode : public Node {
 public:
  bool present(int64_t) override { return true; }
  void attach(OpenFile& file) override;
  void detach(OpenFile& file) override;  // the owner's close stops the stream and frees the queue
  bool open() const override { return open_count_ > 0; }
  void disconnect_all() override;
  short poll_events(const OpenFile& file, short requested) const override;
  void* mmap(void* addr, size_t length, int prot, int flags, int64_t offset) override;

 protected:
  // buffer_type: V4L2_BUF_TYPE_VIDEO_OUTPUT or _CAPTURE; ready_events: what poll reports when a
  // buffer can be dequeued; map_prot: the protection an mmap of a buffer needs.
  LoopbackNode(uint32_t buffer_type, short ready_events, int map_prot)
      : buffer_type_(buffer_type), ready_events_(ready_events), map_prot_(map_prot) {}

  bool busy(const OpenFile& file) const { return owner_ != nullptr && owner_ != &file; }
  int dqbuf(OpenFile& file, v4l2_buffer& b, const Waiter& wait);
  // STREAMOFF: queued and done buffers go back to the application, unfilled.
  void stop_streaming();
  // Stream off and the buffers freed (close of the owner, REQBUFS, unload).
  void release_queue();
  // The node's own state tied to the queue (the capture's negotiated format); nothing by default.
  virtual void queue_released() {}
  static void copy_name(uint8_t* dst, size_t size, const std::string& text);

  const uint32_t buffer_type_;
  std::vector<OpenFile*> files_;
  int open_count_ = 0;
  OpenFile* owner_ = nullptr;  // the file handle that allocated the buffers (vb2's queue owner)
  MmapBuffers buffers_;
  bool streaming_ = false;

 private:
  const short ready_events_;
  const int map_prot_;
};

}  // namespace arpipe::standin
