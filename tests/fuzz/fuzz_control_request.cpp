// libFuzzer target: the two parsers behind arpiped's sockets. Each input is read as a control
// request line (apps/common/control_request: what `arpipe ctl` sends over the control socket) and
// as a listen address (core/config/listen_address: [sinks.http] listen, control.socket). A request
// that parses must survive its own round trip through control_request_line; an address must read
// back from its own text.
#include <cstddef>
#include <cstdint>
#include <string>

#include "apps/common/control_request.h"
#include "core/config/listen_address.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::string why;
  if (const auto request = arpipe::parse_control_request(text, why)) {
    const auto again = arpipe::parse_control_request(arpipe::control_request_line(*request), why);
    ARPIPE_FUZZ_CHECK(again, "a parsed request reads back from its own line");
    ARPIPE_FUZZ_CHECK(again->kind == request->kind && again->assignments == request->assignments &&
                          again->format == request->format && again->path == request->path,
                      "a request's round trip keeps every field");
  } else {
    ARPIPE_FUZZ_CHECK(!why.empty(), "a refused request says why");
  }
  why.clear();
  if (const auto address = arpipe::parse_listen_address(text, why)) {
    const auto again = arpipe::parse_listen_address(address->text(), why);
    ARPIPE_FUZZ_CHECK(again && again->kind == address->kind && again->host == address->host &&
                          again->port == address->port && again->path == address->path,
                      "a listen address reads back from its own text");
  } else {
    ARPIPE_FUZZ_CHECK(!why.empty(), "a refused address says why");
  }
  return 0;
}
