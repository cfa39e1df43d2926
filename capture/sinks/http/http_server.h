// A small HTTP/1.1 server over libmicrohttpd for the live outputs: GET and HEAD only, a thread
// per connection (a stalled client blocks only its own thread), limits on connections, header
// size and idle time. What each path answers is the HttpHandler's business.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <sys/types.h>
#include <utility>
#include <vector>

#include "capture/sinks/http/listen_socket.h"

struct MHD_Daemon;

namespace arpipe {

// A response body made while it is sent (an MJPEG stream). read() runs on the connection's own
// thread and may block until it has bytes.
class HttpStreamBody {
 public:
  virtual ~HttpStreamBody() = default;
  // Copies up to max bytes into buf and returns how many (at least 1), or -1 at the end.
  virtual ssize_t read(char* buf, size_t max) = 0;
};

struct HttpReply {
  unsigned status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;                                         // unless stream is set
  std::unique_ptr<HttpStreamBody> stream;                   // sent until it ends or the client goes
  std::vector<std::pair<std::string, std::string>> headers;  // extra ones
};

class HttpHandler {
 public:
  virtual ~HttpHandler() = default;
  // path: the URL's path (no query). Runs on the connection's thread; must not throw.
  virtual HttpReply get(std::string_view path) noexcept = 0;
};

struct HttpLimits {
  int max_clients = 16;          // connections at once; more are closed at once
  int idle_timeout_s = 10;       // a connection that moves no byte for this long is closed
  size_t header_bytes = 16384;   // a request's headers beyond this get 431
};

class HttpServer {
 public:
  // Starts serving on the socket (which the caller keeps open until the server is destroyed).
  // Throws std::runtime_error when libmicrohttpd cannot start.
  HttpServer(const ListenSocket& socket, const HttpLimits& limits, HttpHandler& handler);
  ~HttpServer();  // stops: closes every connection and joins their threads
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  uint64_t requests() const;

  struct Shared;  // what libmicrohttpd's callbacks are given

 private:
  MHD_Daemon* daemon_ = nullptr;
  std::unique_ptr<Shared> shared_;
};

}  // namespace arpipe
