#include "capture/sinks/http/http_server.h"

#include <microhttpd.h>

#include <atomic>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "core/log.h"

namespace arpipe {

struct HttpServer::Shared {
  explicit Shared(HttpHandler& h) : handler(h) {}
  HttpHandler& handler;
  std::atomic<uint64_t> requests{0};
};

namespace {

// The largest piece of a streamed body handed to libmicrohttpd at once.
constexpr size_t kStreamBlockBytes = 64 * 1024;

ssize_t read_stream(void* cls, uint64_t, char* buf, size_t max) {
  const ssize_t n = static_cast<HttpStreamBody*>(cls)->read(buf, max);
  return n < 0 ? MHD_CONTENT_READER_END_OF_STREAM : n;
}

void free_stream(void* cls) { delete static_cast<HttpStreamBody*>(cls); }

MHD_Result queue_text(MHD_Connection* connection, unsigned status, const char* text) {
  MHD_Response* response = MHD_create_response_from_buffer(std::strlen(text), const_cast<char*>(text), MHD_RESPMEM_PERSISTENT);
  if (!response) return MHD_NO;
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, "text/plain; charset=utf-8");
  const MHD_Result result = MHD_queue_response(connection, status, response);
  MHD_destroy_response(response);
  return result;
}

MHD_Result answer(void* cls, MHD_Connection* connection, const char* url, const char* method, const char*,
                  const char*, size_t* upload_data_size, void** request_state) {
  auto& shared = *static_cast<HttpServer::Shared*>(cls);
  // The first call has only the headers; answer on the second, as libmicrohttpd advises.
  if (*request_state == nullptr) {
    *request_state = &shared;
    return MHD_YES;
  }
  if (*upload_data_size != 0) return queue_text(connection, MHD_HTTP_CONTENT_TOO_LARGE, "no request bodies\n");
  if (std::strcmp(method, MHD_HTTP_METHOD_GET) != 0 && std::strcmp(method, MHD_HTTP_METHOD_HEAD) != 0) {
    MHD_Response* response = MHD_create_response_from_buffer(0, nullptr, MHD_RESPMEM_PERSISTENT);
    MHD_add_response_header(response, MHD_HTTP_HEADER_ALLOW, "GET, HEAD");
    const MHD_Result result = MHD_queue_response(connection, MHD_HTTP_METHOD_NOT_ALLOWED, response);
    MHD_destroy_response(response);
    return result;
  }
  ++shared.requests;
  HttpReply reply = shared.handler.get(url);
  MHD_Response* response = nullptr;
  if (reply.stream) {
    HttpStreamBody* body = reply.stream.release();
    response = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, kStreamBlockBytes, read_stream, body, free_stream);
    if (!response) free_stream(body);
  } else {
    response = MHD_create_response_from_buffer(reply.body.size(), reply.body.data(), MHD_RESPMEM_MUST_COPY);
  }
  if (!response) return MHD_NO;
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, reply.content_type.c_str());
  MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
  MHD_add_response_header(response, "X-Content-Type-Options", "nosniff");
  for (const auto& [name, value] : reply.headers) MHD_add_response_header(response, name.c_str(), value.c_str());
  const MHD_Result result = MHD_queue_response(connection, reply.status, response);
  MHD_destroy_response(response);
  return result;
}

void log_from_library(void*, const char* format, va_list args) {
  char text[512];
  std::vsnprintf(text, sizeof text, format, args);
  std::string line(text);
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
  log::debug("http: {}", line);
}

}  // namespace

HttpServer::HttpServer(const ListenSocket& socket, const HttpLimits& limits, HttpHandler& handler)
    : shared_(std::make_unique<Shared>(handler)) {
  const unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION | MHD_USE_ITC | MHD_USE_ERROR_LOG;
  daemon_ = MHD_start_daemon(
      flags, 0, nullptr, nullptr, &answer, shared_.get(),                                         //
      MHD_OPTION_LISTEN_SOCKET, socket.fd(),                                                       //
      MHD_OPTION_CONNECTION_LIMIT, static_cast<unsigned>(limits.max_clients),                       //
      MHD_OPTION_CONNECTION_TIMEOUT, static_cast<unsigned>(limits.idle_timeout_s),                  //
      MHD_OPTION_CONNECTION_MEMORY_LIMIT, limits.header_bytes,                                     //
      MHD_OPTION_EXTERNAL_LOGGER, &log_from_library, nullptr,                                      //
      MHD_OPTION_END);
  if (!daemon_) throw std::runtime_error(fmt::format("HTTP server on {}: libmicrohttpd did not start", socket.bound()));
}

HttpServer::~HttpServer() {
  // The listening socket stays the ListenSocket's to close; libmicrohttpd hands it back.
  MHD_quiesce_daemon(daemon_);
  MHD_stop_daemon(daemon_);
}

uint64_t HttpServer::requests() const { return shared_->requests; }

}  // namespace arpipe
