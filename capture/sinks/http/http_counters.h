// What the HTTP sink counts about itself, for /state and /metrics.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "core/pipeline/latency_histogram.h"

namespace arpipe {

struct HttpCounters {
  int stream_clients = 0;          // MJPEG clients connected now
  uint64_t jpeg_encodes = 0;       // frames encoded for the streams (none while nobody watches)
  double jpeg_encode_seconds = 0;  // their total encoding time, on the sink's thread
  uint64_t frames_not_encoded = 0;  // frames published while no stream client watched
  uint64_t encode_failures = 0;
  uint64_t requests = 0;
  double recent_fps = 0;           // frames published per second over the last ones
  // From the end of exposure to the frame's last byte handed to a stream client's socket.
  LatencyHistogram stream_latency_seconds;
  // The daemon's CPU by part of the pipeline (core/system/thread_cpu.h CpuByPart), and the whole
  // process's (every thread, ended ones too); filled for /metrics.
  std::map<std::string, double> cpu_seconds_by_part;
  double process_cpu_seconds = 0;
};

}  // namespace arpipe
