// A small blocking HTTP/1.1 client over real sockets (TCP or Unix), for the live outputs' tests
// and benchmarks: whole responses, MJPEG parts one by one, and misbehaving clients (stalled, slow).
#pragma once

#include <chrono>
#include <map>
#include <optional>
#include <string>

namespace arpipe {

struct HttpResponse {
  int status = 0;
  std::map<std::string, std::string> headers;  // names lower-cased
  std::string body;
};

class HttpConnection {
 public:
  // address: "HOST:PORT" or a Unix socket path; every read waits at most `timeout`.
  explicit HttpConnection(const std::string& address, std::chrono::milliseconds timeout = std::chrono::seconds(10),
                          int receive_buffer_bytes = 0);
  ~HttpConnection();
  HttpConnection(const HttpConnection&) = delete;
  HttpConnection& operator=(const HttpConnection&) = delete;

  bool connected() const { return fd_ >= 0; }
  bool send_all(const std::string& bytes);
  // The status line and headers; nullopt on a closed connection or timeout.
  std::optional<HttpResponse> read_head();
  // The rest of the body until the server closes (or content-length bytes).
  std::string read_body(const HttpResponse& head);
  // The next MJPEG part: its headers and its JPEG bytes.
  std::optional<HttpResponse> read_part();
  // True once the server has closed the connection (reads 0 or fails), within the timeout.
  bool closed_by_server();

 private:
  bool fill();  // reads more into buffer_; false on close/timeout
  std::optional<std::string> read_line();
  // Header lines up to the empty one, names lower-cased; false on a closed connection or timeout.
  bool read_headers(std::map<std::string, std::string>& headers);
  int fd_ = -1;
  std::string buffer_;
};

// One GET (or HEAD, or another method) on a new connection, the whole response.
std::optional<HttpResponse> http_request(const std::string& address, const std::string& path,
                                         const std::string& method = "GET");

}  // namespace arpipe
