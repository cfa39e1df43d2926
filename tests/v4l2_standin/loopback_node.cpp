#include "loopback_node.h"

#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace arpipe::standin {

void LoopbackNode::attach(OpenFile& file) {
  files_.push_back(&file);
  ++open_count_;
  ++stats.opens;
}

void LoopbackNode::detach(OpenFile& file) {
  --open_count_;
  std::erase(files_, &file);
  if (owner_ == &file) release_queue();  // vb2_fop_release
}

void LoopbackNode::disconnect_all() {
  for (OpenFile* f : files_) f->dead = true;
  files_.clear();
  release_queue();
}

void LoopbackNode::stop_streaming() {
  streaming_ = false;
  buffers_.return_all();
}

void LoopbackNode::release_queue() {
  streaming_ = false;
  buffers_.release();
  owner_ = nullptr;
  queue_released();
}

void LoopbackNode::copy_name(uint8_t* dst, size_t size, const std::string& text) {
  std::memset(dst, 0, size);
  std::memcpy(dst, text.data(), std::min(text.size(), size - 1));
}

int LoopbackNode::dqbuf(OpenFile& file, v4l2_buffer& b, const Waiter& wait) {
  if (b.type != buffer_type_ || b.memory != V4L2_MEMORY_MMAP) return EINVAL;
  if (busy(file)) return EBUSY;
  const bool may_block = blocking_file(file);
  for (;;) {
    if (file.dead) return EIO;
    if (!streaming_) return EINVAL;
    if (!buffers_.done.empty()) {
      const uint32_t index = buffers_.done.front();
      buffers_.done.pop_front();
      buffers_.state(index).done = false;
      buffers_.fill(index, buffer_type_, b);
      return 0;
    }
    if (!may_block) return EAGAIN;
    wait(next_wake(monotonic_ns()));
    advance(monotonic_ns());
  }
}

short LoopbackNode::poll_events(const OpenFile& file, short requested) const {
  if (file.dead) return POLLERR | POLLHUP;
  short r = 0;
  if (requested & ready_events_) {
    if (!streaming_)
      r |= POLLERR;  // vb2: nothing to wait for
    else if (!buffers_.done.empty())
      r |= ready_events_;
  }
  return short(r & (requested | POLLERR | POLLHUP));
}

void* LoopbackNode::mmap(void* addr, size_t length, int prot, int flags, int64_t offset) {
  return buffers_.map(addr, length, prot, flags, offset, map_prot_);
}

}  // namespace arpipe::standin
