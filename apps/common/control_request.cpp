#include "apps/common/control_request.h"

#include <nlohmann/json.hpp>

namespace arpipe {

std::optional<ControlRequest> parse_control_request(std::string_view line, std::string& why) {
  using nlohmann::json;
  if (line.size() > kMaxControlRequestBytes) {
    why = "a request of at most 64 KiB";
    return std::nullopt;
  }
  const json j = json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object() || !j.contains("command") || !j["command"].is_string()) {
    why = "one JSON object with a \"command\" string";
    return std::nullopt;
  }
  const std::string command = j["command"].get<std::string>();
  ControlRequest request;
  const auto string_field = [&](const char* name, std::string& out) {
    if (!j.contains(name) || !j[name].is_string()) {
      why = std::string("\"") + name + "\": a string";
      return false;
    }
    out = j[name].get<std::string>();
    return true;
  };
  if (command == "status") {
    request.kind = ControlRequest::Kind::Status;
  } else if (command == "reload") {
    request.kind = ControlRequest::Kind::Reload;
  } else if (command == "set") {
    request.kind = ControlRequest::Kind::Set;
    const auto it = j.find("assignments");
    if (it == j.end() || !it->is_array() || it->empty() || it->size() > kMaxControlAssignments) {
      why = "\"assignments\": an array of 1 to 256 \"section.key=value\" strings";
      return std::nullopt;
    }
    for (const json& a : *it) {
      if (!a.is_string() || a.get<std::string>().find('=') == std::string::npos) {
        why = "\"assignments\": each a \"section.key=value\" string";
        return std::nullopt;
      }
      request.assignments.push_back(a.get<std::string>());
    }
  } else if (command == "snapshot") {
    request.kind = ControlRequest::Kind::Snapshot;
    if (j.contains("format")) {
      if (!string_field("format", request.format)) return std::nullopt;
      if (request.format != "png" && request.format != "jpg") {
        why = "\"format\": \"png\" or \"jpg\"";
        return std::nullopt;
      }
    }
  } else if (command == "record") {
    std::string action;
    if (!string_field("action", action)) return std::nullopt;
    if (action == "start") {
      request.kind = ControlRequest::Kind::RecordStart;
      if (!string_field("path", request.path)) return std::nullopt;
      if (request.path.empty()) {
        why = "\"path\": a directory";
        return std::nullopt;
      }
    } else if (action == "stop") {
      request.kind = ControlRequest::Kind::RecordStop;
    } else {
      why = "\"action\": \"start\" or \"stop\"";
      return std::nullopt;
    }
  } else {
    why = "\"command\": one of \"status\", \"reload\", \"set\", \"snapshot\", \"record\"";
    return std::nullopt;
  }
  return request;
}

std::string control_request_line(const ControlRequest& request) {
  nlohmann::json j;
  switch (request.kind) {
    case ControlRequest::Kind::Status: j["command"] = "status"; break;
    case ControlRequest::Kind::Reload: j["command"] = "reload"; break;
    case ControlRequest::Kind::Set:
      j["command"] = "set";
      j["assignments"] = request.assignments;
      break;
    case ControlRequest::Kind::Snapshot:
      j["command"] = "snapshot";
      j["format"] = request.format;
      break;
    case ControlRequest::Kind::RecordStart:
      j["command"] = "record";
      j["action"] = "start";
      j["path"] = request.path;
      break;
    case ControlRequest::Kind::RecordStop:
      j["command"] = "record";
      j["action"] = "stop";
      break;
  }
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace arpipe
