// The C API (v4l2_standin.h): loading a configuration, unloading it, reading the counters.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "standin_registry.h"
#include "v4l2_standin.h"

using arpipe::standin::Registry;

extern "C" int arpipe_v4l2_standin_load(const char* config_path, char* error, size_t error_size) {
  std::string message;
  int r = -1;
  try {
    if (config_path == nullptr)
      message = "arpipe_v4l2_standin_load: no configuration path given";
    else
      r = Registry::get().load(config_path, message);
  } catch (const std::exception& e) {  // never let an exception cross the C boundary
    message = e.what();
    r = -1;
  }
  if (r != 0 && error != nullptr && error_size > 0) {
    const size_t n = std::min(message.size(), error_size - 1);
    std::memcpy(error, message.data(), n);
    error[n] = '\0';
  }
  return r;
}

extern "C" void arpipe_v4l2_standin_unload(void) { Registry::get().unload(); }

extern "C" int arpipe_v4l2_standin_stats(const char* device_path, struct arpipe_v4l2_standin_stats* out) {
  if (out == nullptr) return -1;
  return Registry::get().stats(device_path, *out);
}
