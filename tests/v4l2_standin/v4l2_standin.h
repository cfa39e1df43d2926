// The V4L2 stand-in's C API: load a configuration (devices served from recordings) in-process and
// read per-device counters. See docs/V4L2_STANDIN.md; with LD_PRELOAD, ARPIPE_V4L2_STANDIN does the load.
#ifndef ARPIPE_V4L2_STANDIN_H
#define ARPIPE_V4L2_STANDIN_H

#include <stddef.h>
#include <stdint.h>

#if defined(__GNUC__)
#define ARPIPE_V4L2_STANDIN_API __attribute__((visibility("default")))
#else
#define ARPIPE_V4L2_STANDIN_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

// Replaces the configuration; 0 on success, -1 with a message (file:line:column and what was
// expected) in error[] on a bad file, or when a served device is still open ("busy").
ARPIPE_V4L2_STANDIN_API int arpipe_v4l2_standin_load(const char* config_path, char* error, size_t error_size);
// Serves nothing (open fds keep ENODEV).
ARPIPE_V4L2_STANDIN_API void arpipe_v4l2_standin_unload(void);

// Counters of one served device since its configuration was loaded.
struct arpipe_v4l2_standin_stats {
  uint64_t opens;                     // successful opens of the device path
  uint64_t streamons;                 // successful VIDIOC_STREAMON calls that started streaming
  uint64_t frames_delivered;          // buffers marked done (error buffers included); loopback capture: frames served
  uint64_t frames_dropped_no_buffer;  // frames that fell due with no buffer queued
  uint64_t frames_skipped_by_fault;   // frames skipped by "drop" faults
  uint64_t error_buffers;             // buffers marked done with V4L2_BUF_FLAG_ERROR (loopback output: frames not spooled)
  uint64_t control_events;            // V4L2_EVENT_CTRL events queued, summed over file handles
  uint64_t unplugs;                   // "unplug" faults that fired
  uint64_t frames_written;            // loopback output: frames handed to the spool
};
// 0 and *out filled, or -1 (errno ENOENT) when device_path is not a served path.
ARPIPE_V4L2_STANDIN_API int arpipe_v4l2_standin_stats(const char* device_path, struct arpipe_v4l2_standin_stats* out);

#ifdef __cplusplus
}
#endif

#endif  // ARPIPE_V4L2_STANDIN_H
