// The library constructor: loads $ARPIPE_V4L2_STANDIN when the library is preloaded. Linked after
// arpipe's static libraries (see CMakeLists.txt) so that their static objects exist when it runs.
#include <cstdio>
#include <cstdlib>

#include "v4l2_standin.h"

namespace {
// A bad file is one line on stderr and nothing served; the host keeps running.
__attribute__((constructor)) void load_from_environment() {
  const char* path = std::getenv("ARPIPE_V4L2_STANDIN");
  if (path == nullptr || *path == '\0') return;
  char error[1024];
  if (arpipe_v4l2_standin_load(path, error, sizeof error) != 0) std::fprintf(stderr, "arpipe-v4l2-standin: %s\n", error);
}
}  // namespace
