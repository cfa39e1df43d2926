// What a client asks arpiped over its control socket: one JSON object on one line, at most
// kMaxControlRequestBytes ({"command": "status"}, {"command": "set", "assignments": ["k=v", ...]},
// {"command": "snapshot", "format": "png"}, {"command": "record", "action": "start", "path": DIR}).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace arpipe {

constexpr size_t kMaxControlRequestBytes = 64 * 1024;
constexpr size_t kMaxControlAssignments = 256;

struct ControlRequest {
  enum class Kind { Status, Reload, Set, Snapshot, RecordStart, RecordStop };
  Kind kind = Kind::Status;
  std::vector<std::string> assignments;  // Set: "section.key=value", as --set takes them
  std::string format = "png";            // Snapshot: "png" or "jpg"
  std::string path;                      // RecordStart: the recording's directory, as the daemon sees it

  static ControlRequest of(Kind kind) {
    ControlRequest request;
    request.kind = kind;
    return request;
  }
};

// nullopt on anything else, with `why` saying what was expected.
std::optional<ControlRequest> parse_control_request(std::string_view line, std::string& why);
// The line a client sends (without the newline).
std::string control_request_line(const ControlRequest& request);

}  // namespace arpipe
