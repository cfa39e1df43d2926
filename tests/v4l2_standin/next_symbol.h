// The next definition of an interposed libc function (libc's own, or another preloaded library's),
// looked up once per name: what the stand-in forwards to for everything that is not one of its own.
#pragma once

#include <dlfcn.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace arpipe::standin {

// dlsym before any constructor has run is fine; a missing symbol is a broken libc: abort loudly.
template <typename F>
F next_symbol(std::atomic<F>& slot, const char* name) {
  F f = slot.load(std::memory_order_acquire);
  if (f == nullptr) {
    f = reinterpret_cast<F>(::dlsym(RTLD_NEXT, name));
    if (f == nullptr) {
      std::fprintf(stderr, "arpipe-v4l2-standin: cannot find the next %s: %s\n", name, ::dlerror());
      std::abort();
    }
    slot.store(f, std::memory_order_release);
  }
  return f;
}

}  // namespace arpipe::standin

#define ARPIPE_REAL(type, name)                                 \
  [] {                                                          \
    static std::atomic<type> slot{nullptr};                     \
    return ::arpipe::standin::next_symbol<type>(slot, #name);   \
  }()
