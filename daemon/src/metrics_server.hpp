#pragma once
// neuflowd's metrics endpoint: an HTTP server (libsoup's SoupServer) that answers
// GET /metrics with whatever `render` returns, as Prometheus text.
//
// It runs on the GMainContext that is thread-default where it is constructed (the daemon's
// main loop) and never blocks it: connections are handled asynchronously by libsoup, and
// `render` is called on that loop's thread, between the daemon's other events, so it can read
// the daemon's state without locks. It must be quick; it is called once per request.
//
// libsoup's server is meant for trusted clients: keep it on the loopback interface (the
// default) or a trusted network.
#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

namespace neuflow::daemon {

// What clients may hold: a scrape takes one short connection, so these only bite a client that
// opens many, or opens one and says nothing.
struct MetricsConnectionLimits {
  int max_connections = 16;                      // the oldest is closed to admit one more
  std::chrono::milliseconds idle_timeout{5000};  // a connection silent this long is closed (whole seconds)
};

class MetricsServer {
 public:
  using Render = std::function<std::string()>;

  using Limits = MetricsConnectionLimits;

  // Listens at once on `address` (an IPv4 or IPv6 literal, or "localhost" for 127.0.0.1) and
  // `port` (0: any free port, see port()). Throws std::runtime_error naming the address when
  // it cannot, e.g. "metrics: cannot listen on 127.0.0.1:9464: Address already in use".
  // If `render` throws, the request gets a 500 with the exception's message.
  MetricsServer(std::string address, int port, Render render, Limits limits = {});
  // Stops listening and closes every client connection; `render` is not called afterwards.
  ~MetricsServer();

  MetricsServer(const MetricsServer&) = delete;
  MetricsServer& operator=(const MetricsServer&) = delete;

  int port() const;                      // the port actually bound
  std::string url() const;               // "http://127.0.0.1:9464/metrics", for the log
  std::size_t open_connections() const;  // client connections libsoup still holds

  struct Impl;  // public so that the accept loop's callbacks can name it

 private:
  std::shared_ptr<Impl> impl_;
};

// The text format's media type, as Prometheus expects it from an exporter.
inline constexpr const char* kPrometheusContentType = "text/plain; version=0.0.4; charset=utf-8";

}  // namespace neuflow::daemon
