#include "bench/http_client.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstring>

namespace arpipe {

HttpConnection::HttpConnection(const std::string& address, std::chrono::milliseconds timeout, int receive_buffer_bytes) {
  const bool unix_socket = address.starts_with('/') || address.starts_with("./");
  fd_ = ::socket(unix_socket ? AF_UNIX : AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) return;
  if (receive_buffer_bytes > 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof receive_buffer_bytes);
  timeval tv{};
  tv.tv_sec = timeout.count() / 1000;
  tv.tv_usec = (timeout.count() % 1000) * 1000;
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  ::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
  int result = -1;
  if (unix_socket) {
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, address.c_str(), sizeof a.sun_path - 1);
    result = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
  } else {
    const size_t colon = address.rfind(':');
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(std::stoi(address.substr(colon + 1))));
    ::inet_pton(AF_INET, address.substr(0, colon).c_str(), &a.sin_addr);
    result = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  if (result != 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

HttpConnection::~HttpConnection() {
  if (fd_ >= 0) ::close(fd_);
}

bool HttpConnection::send_all(const std::string& bytes) {
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return false;
    sent += size_t(n);
  }
  return true;
}

bool HttpConnection::fill() {
  char chunk[65536];
  const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
  if (n <= 0) return false;
  buffer_.append(chunk, size_t(n));
  return true;
}

std::optional<std::string> HttpConnection::read_line() {
  for (;;) {
    const size_t end = buffer_.find("\r\n");
    if (end != std::string::npos) {
      std::string line = buffer_.substr(0, end);
      buffer_.erase(0, end + 2);
      return line;
    }
    if (!fill()) return std::nullopt;
  }
}

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

}  // namespace

bool HttpConnection::read_headers(std::map<std::string, std::string>& headers) {
  for (;;) {
    std::optional<std::string> line = read_line();
    if (!line) return false;
    if (line->empty()) return true;
    const size_t colon = line->find(':');
    if (colon == std::string::npos) continue;
    std::string value = line->substr(colon + 1);
    value.erase(0, value.find_first_not_of(' '));
    headers[lower(line->substr(0, colon))] = value;
  }
}

std::optional<HttpResponse> HttpConnection::read_head() {
  std::optional<std::string> status = read_line();
  if (!status || !status->starts_with("HTTP/1.")) return std::nullopt;
  HttpResponse response;
  response.status = std::atoi(status->substr(9, 3).c_str());
  if (!read_headers(response.headers)) return std::nullopt;
  return response;
}

std::string HttpConnection::read_body(const HttpResponse& head) {
  const auto length = head.headers.find("content-length");
  if (length != head.headers.end()) {
    const size_t want = std::stoul(length->second);
    while (buffer_.size() < want && fill()) {
    }
    std::string body = buffer_.substr(0, std::min(want, buffer_.size()));
    buffer_.erase(0, body.size());
    return body;
  }
  if (head.headers.count("transfer-encoding") && lower(head.headers.at("transfer-encoding")) == "chunked") {
    std::string body;
    for (;;) {
      std::optional<std::string> size_line = read_line();
      if (!size_line) return body;
      const size_t size = std::stoul(*size_line, nullptr, 16);
      while (buffer_.size() < size + 2 && fill()) {
      }
      body += buffer_.substr(0, size);
      buffer_.erase(0, std::min(buffer_.size(), size + 2));
      if (size == 0) return body;
    }
  }
  while (fill()) {
  }
  std::string body;
  body.swap(buffer_);
  return body;
}

std::optional<HttpResponse> HttpConnection::read_part() {
  // Skips to the boundary line, then reads the part's headers and its Content-Length bytes.
  for (;;) {
    std::optional<std::string> line = read_line();
    if (!line) return std::nullopt;
    if (line->starts_with("--")) break;
  }
  HttpResponse part;
  if (!read_headers(part.headers)) return std::nullopt;
  const auto length = part.headers.find("content-length");
  if (length == part.headers.end()) return std::nullopt;
  const size_t want = std::stoul(length->second);
  while (buffer_.size() < want) {
    if (!fill()) return std::nullopt;
  }
  part.body = buffer_.substr(0, want);
  buffer_.erase(0, want);
  part.status = 200;
  return part;
}

bool HttpConnection::closed_by_server() {
  char c;
  for (;;) {
    const ssize_t n = ::recv(fd_, &c, 1, 0);
    if (n == 0) return true;
    if (n < 0) return errno == ECONNRESET;
  }
}

std::optional<HttpResponse> http_request(const std::string& address, const std::string& path, const std::string& method) {
  HttpConnection connection(address);
  if (!connection.connected()) return std::nullopt;
  if (!connection.send_all(method + " " + path + " HTTP/1.1\r\nHost: test\r\nConnection: close\r\n\r\n")) return std::nullopt;
  std::optional<HttpResponse> head = connection.read_head();
  if (!head) return std::nullopt;
  if (method != "HEAD") head->body = connection.read_body(*head);
  return head;
}

}  // namespace arpipe
