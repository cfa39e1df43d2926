// A loopback's capture node (VIDEO_CAPTURE, MMAP streaming): serves the frames its output node
// wrote to the spool, from the oldest, in order, each once per stream, waiting for those not yet
// written. Its format is the writer's; there is none until a writer has set one.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loopback_spool.h"
#include "mmap_buffers.h"
#include "served_node.h"
#include "standin_config.h"

namespace arpipe::standin {

class LoopbackCapture final : public Node {
 public:
  explicit LoopbackCapture(const LoopbackConfig& config);

  const std::string& path() const override { return config_.capture; }
  bool present(int64_t) override { return true; }
  void attach(OpenFile& file) override;
  void detach(OpenFile& file) override;
  bool open() const override { return open_count_ > 0; }
  void disconnect_all() override;
  void advance(int64_t now) override;
  int64_t next_wake(int64_t now) const override;
  int ioctl(OpenFile& file, unsigned long request, void* arg, const Waiter& wait) override;
  short poll_events(const OpenFile& file, short requested) const override;
  void* mmap(void* addr, size_t length, int prot, int flags, int64_t offset) override;

 private:
  // The stream's format once buffers are allocated, else the writer's latest (nullopt: none yet).
  std::optional<SpoolFormat> current_format();
  void fill_format(const SpoolFormat& s, v4l2_format& f) const;
  int reqbufs(OpenFile& file, v4l2_requestbuffers& r);
  int qbuf(OpenFile& file, v4l2_buffer& b);
  int dqbuf(OpenFile& file, v4l2_buffer& b, const Waiter& wait);
  void stop_streaming();
  bool busy(const OpenFile& file) const { return owner_ != nullptr && owner_ != &file; }

  LoopbackConfig config_;
  SpoolReader reader_;
  std::vector<OpenFile*> files_;
  int open_count_ = 0;
  OpenFile* owner_ = nullptr;
  MmapBuffers buffers_;
  std::optional<SpoolFormat> negotiated_;  // fixed by REQBUFS
  bool streaming_ = false;
  uint64_t next_frame_ = 0;  // the spool index served next
  uint32_t sequence_ = 0;    // frames since STREAMON
  std::string format_error_; // the last complaint about the format file (said once)
};

}  // namespace arpipe::standin
