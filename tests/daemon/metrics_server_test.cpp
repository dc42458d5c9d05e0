// MetricsServer over real HTTP on the loopback interface. The test thread plays the daemon's
// main loop: it iterates the default GMainContext, where both the server and the libsoup
// client used here run, so nothing is served unless the loop turns.
#include <gio/gio.h>
#include <gtest/gtest.h>
#include <libsoup/soup.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "metrics_server.hpp"
#include "prometheus_text.hpp"

namespace neuflow::daemon {
namespace {

using namespace std::chrono_literals;

// Turns the loop until `done` or the deadline; returns `done()`.
bool iterate_until(const std::function<bool()>& done, std::chrono::milliseconds timeout = 5000ms) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    if (!g_main_context_iteration(nullptr, FALSE)) std::this_thread::sleep_for(1ms);
  }
  return true;
}

void iterate_for(std::chrono::milliseconds duration) {
  iterate_until([] { return false; }, duration);
}

struct Response {
  bool done = false;
  std::string error;  // transport error; empty when an HTTP answer came back
  guint status = 0;
  std::string content_type;
  std::string allow;
  std::string body;
};

// An asynchronous request on the test's loop, so that the server (same loop) can answer it.
class Request {
 public:
  Request(const char* method, const std::string& url) {
    // No proxy: an http_proxy in the environment must not take loopback requests elsewhere.
    session_ = soup_session_new_with_options("proxy-resolver", nullptr, "timeout", 10u, nullptr);
    message_ = soup_message_new(method, url.c_str());
    if (message_ == nullptr) throw std::invalid_argument("bad URL " + url);
    soup_session_send_and_read_async(session_, message_, G_PRIORITY_DEFAULT, nullptr, &Request::finished, this);
  }
  ~Request() {
    // The callback holds `this`: never leave with the request still running.
    if (!response_.done) {
      soup_session_abort(session_);
      iterate_until([this] { return response_.done; });
    }
    g_object_unref(message_);
    g_object_unref(session_);
  }
  Request(const Request&) = delete;
  Request& operator=(const Request&) = delete;

  const Response& wait() {
    if (!iterate_until([this] { return response_.done; })) response_.error = "no answer within 5 s";
    return response_;
  }
  bool done() const { return response_.done; }

 private:
  static void finished(GObject* source, GAsyncResult* result, gpointer data) {
    auto* self = static_cast<Request*>(data);
    Response& r = self->response_;
    GError* error = nullptr;
    GBytes* bytes = soup_session_send_and_read_finish(SOUP_SESSION(source), result, &error);
    if (bytes == nullptr) {
      r.error = error->message;
      g_error_free(error);
    } else {
      gsize size = 0;
      const auto* data_ptr = static_cast<const char*>(g_bytes_get_data(bytes, &size));
      r.body.assign(data_ptr == nullptr ? "" : data_ptr, size);
      g_bytes_unref(bytes);
      r.status = soup_message_get_status(self->message_);
      SoupMessageHeaders* headers = soup_message_get_response_headers(self->message_);
      const char* type = soup_message_headers_get_one(headers, "Content-Type");
      const char* allow = soup_message_headers_get_one(headers, "Allow");
      r.content_type = type ? type : "";
      r.allow = allow ? allow : "";
    }
    r.done = true;
  }

  SoupSession* session_ = nullptr;
  SoupMessage* message_ = nullptr;
  Response response_;
};

Response fetch(const char* method, const std::string& url) { return Request(method, url).wait(); }

std::string base_url(const MetricsServer& server) { return "http://127.0.0.1:" + std::to_string(server.port()); }

std::vector<StreamMetrics> one_stream() {
  StreamMetrics s;
  s.stream = "front";
  s.state = "playing";
  s.frames_in = 10;
  s.frames_processed = 9;
  s.flows = 8;
  s.inference.add(0.04);
  return {s};
}

// A raw TCP client, for what an HTTP library will not do: stall half-way through a request.
class RawClient {
 public:
  explicit RawClient(int port) {
    GSocketClient* client = g_socket_client_new();
    GError* error = nullptr;
    // The kernel completes the handshake from the listen backlog: no loop turn is needed.
    connection_ = g_socket_client_connect_to_host(client, "127.0.0.1", static_cast<guint16>(port), nullptr, &error);
    g_object_unref(client);
    if (connection_ == nullptr) {
      const std::string message = error->message;
      g_error_free(error);
      throw std::runtime_error("cannot connect: " + message);
    }
    g_socket_set_blocking(g_socket_connection_get_socket(connection_), FALSE);
  }
  ~RawClient() { g_object_unref(connection_); }
  RawClient(const RawClient&) = delete;
  RawClient& operator=(const RawClient&) = delete;

  void send(const std::string& bytes) {
    GError* error = nullptr;
    const gssize sent =
        g_socket_send(g_socket_connection_get_socket(connection_), bytes.data(), bytes.size(), nullptr, &error);
    if (error != nullptr) g_error_free(error);
    ASSERT_EQ(sent, static_cast<gssize>(bytes.size()));
  }

  // Turns the loop until the server closes the connection; false if it stays open.
  bool wait_closed(std::string& received, std::chrono::milliseconds timeout = 5000ms) {
    bool closed = false;
    iterate_until(
        [&] {
          char buffer[4096];
          GError* error = nullptr;
          const gssize n =
              g_socket_receive(g_socket_connection_get_socket(connection_), buffer, sizeof buffer, nullptr, &error);
          if (n > 0) {
            received.append(buffer, static_cast<size_t>(n));
            return false;
          }
          if (n == 0) return closed = true;
          const bool would_block = g_error_matches(error, G_IO_ERROR, G_IO_ERROR_WOULD_BLOCK);
          g_error_free(error);
          return closed = !would_block;  // reset by the peer counts as closed
        },
        timeout);
    return closed;
  }

 private:
  GSocketConnection* connection_ = nullptr;
};

TEST(MetricsServer, ServesTheRenderedTextAtMetrics) {
  const auto loop_thread = std::this_thread::get_id();
  std::atomic<int> calls{0};
  bool on_loop_thread = true;
  MetricsServer server("127.0.0.1", 0, [&] {
    ++calls;
    on_loop_thread = on_loop_thread && std::this_thread::get_id() == loop_thread;
    return render_prometheus(one_stream(), 12.0, "1.0");
  });
  ASSERT_GT(server.port(), 0);
  EXPECT_EQ(server.url(), base_url(server) + "/metrics");
  EXPECT_EQ(calls, 0);  // nothing is rendered before someone asks

  const Response r = fetch("GET", server.url());
  ASSERT_EQ(r.error, "");
  EXPECT_EQ(r.status, 200u);
  EXPECT_EQ(r.content_type, "text/plain; version=0.0.4; charset=utf-8");
  EXPECT_EQ(r.body, render_prometheus(one_stream(), 12.0, "1.0"));
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(on_loop_thread);

  // Each scrape renders afresh; a query string does not change the path.
  const Response again = fetch("GET", server.url() + "?name[]=neuflow_flows_total");
  EXPECT_EQ(again.status, 200u);
  EXPECT_EQ(calls, 2);
}

// A client that shares nothing with the server: the curl command line, run as a child while
// the loop turns.
TEST(MetricsServer, AnswersCurl) {
  gchar* curl = g_find_program_in_path("curl");
  if (curl == nullptr) GTEST_SKIP() << "curl is not installed";
  MetricsServer server("127.0.0.1", 0, [] { return render_prometheus(one_stream(), 1.0, "1.0"); });
  GError* error = nullptr;
  GSubprocess* child =
      g_subprocess_new(G_SUBPROCESS_FLAGS_STDOUT_PIPE, &error, curl, "--silent", "--show-error", "--noproxy", "*",
                       "--include", "--max-time", "5", server.url().c_str(), nullptr);
  g_free(curl);
  ASSERT_NE(child, nullptr) << error->message;
  struct Result {
    bool done = false;
    gchar* out = nullptr;
  } result;
  g_subprocess_communicate_utf8_async(
      child, nullptr, nullptr,
      [](GObject* source, GAsyncResult* res, gpointer data) {
        auto* r = static_cast<Result*>(data);
        g_subprocess_communicate_utf8_finish(G_SUBPROCESS(source), res, &r->out, nullptr, nullptr);
        r->done = true;
      },
      &result);
  ASSERT_TRUE(iterate_until([&] { return result.done; }, 10000ms));
  g_subprocess_wait(child, nullptr, nullptr);
  EXPECT_TRUE(g_subprocess_get_successful(child));
  g_object_unref(child);
  const std::string out = result.out ? result.out : "";
  g_free(result.out);
  EXPECT_EQ(out.rfind("HTTP/1.1 200 OK\r\n", 0), 0u) << out;
  EXPECT_NE(out.find("\r\nContent-Type: text/plain; version=0.0.4; charset=utf-8\r\n"), std::string::npos) << out;
  // Each connection serves one request (see metrics_server.cpp), and says so.
  EXPECT_NE(out.find("\r\nConnection: close\r\n"), std::string::npos) << out;
  const auto body = out.find("\r\n\r\n");
  ASSERT_NE(body, std::string::npos);
  EXPECT_EQ(out.substr(body + 4), render_prometheus(one_stream(), 1.0, "1.0"));
}

TEST(MetricsServer, AnswersHeadWithHeadersOnly) {
  MetricsServer server("127.0.0.1", 0, [] { return std::string("neuflow_daemon_uptime_seconds 1\n"); });
  const Response r = fetch("HEAD", server.url());
  ASSERT_EQ(r.error, "");
  EXPECT_EQ(r.status, 200u);
  EXPECT_EQ(r.content_type, kPrometheusContentType);
  EXPECT_EQ(r.body, "");
}

TEST(MetricsServer, OtherPathsAreNotFound) {
  int calls = 0;
  MetricsServer server("127.0.0.1", 0, [&] {
    ++calls;
    return std::string();
  });
  for (const char* path : {"/", "/metric", "/metrics/", "/metrics/x", "/metricsx", "/favicon.ico"}) {
    const Response r = fetch("GET", base_url(server) + path);
    ASSERT_EQ(r.error, "") << path;
    EXPECT_EQ(r.status, 404u) << path;
    EXPECT_NE(r.body.find("/metrics"), std::string::npos) << "a 404 should say where the metrics are";
  }
  EXPECT_EQ(calls, 0);
}

TEST(MetricsServer, OtherMethodsAreNotAllowed) {
  int calls = 0;
  MetricsServer server("127.0.0.1", 0, [&] {
    ++calls;
    return std::string();
  });
  for (const char* method : {"POST", "PUT", "DELETE", "PATCH"}) {
    const Response r = fetch(method, server.url());
    ASSERT_EQ(r.error, "") << method;
    EXPECT_EQ(r.status, 405u) << method;
    EXPECT_EQ(r.allow, "GET, HEAD") << method;
  }
  EXPECT_EQ(calls, 0);
}

TEST(MetricsServer, RenderFailureIsAServerErrorAndTheNextScrapeWorks) {
  bool fail = true;
  MetricsServer server("127.0.0.1", 0, [&] {
    if (fail) throw std::runtime_error("stream table is being rebuilt");
    return std::string("ok 1\n");
  });
  const Response failed = fetch("GET", server.url());
  EXPECT_EQ(failed.status, 500u);
  EXPECT_NE(failed.body.find("stream table is being rebuilt"), std::string::npos) << failed.body;
  fail = false;
  const Response ok = fetch("GET", server.url());
  EXPECT_EQ(ok.status, 200u);
  EXPECT_EQ(ok.body, "ok 1\n");
}

TEST(MetricsServer, SecondServerOnTheSamePortFailsWithTheAddress) {
  MetricsServer first("127.0.0.1", 0, [] { return std::string(); });
  const int port = first.port();
  try {
    MetricsServer second("127.0.0.1", port, [] { return std::string(); });
    FAIL() << "a second server listened on the same port";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "metrics: cannot listen on 127.0.0.1:" + std::to_string(port) + ": Address already in use");
  }
  // The first one is unharmed.
  EXPECT_EQ(fetch("GET", first.url()).status, 200u);
}

TEST(MetricsServer, RejectsWhatCannotBeListenedOn) {
  const auto message = [](const std::string& address, int port) {
    try {
      MetricsServer server(address, port, [] { return std::string(); });
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(no exception)");
  };
  EXPECT_EQ(message("metrics.example", 9464),
            "metrics: cannot listen on metrics.example:9464: not an IP address (write e.g. 127.0.0.1, ::1 or 0.0.0.0)");
  EXPECT_EQ(message("127.0.0.1", 70000),
            "metrics: cannot listen on 127.0.0.1:70000: the port must be between 0 and 65535");
  EXPECT_EQ(message("127.0.0.1", -1), "metrics: cannot listen on 127.0.0.1:-1: the port must be between 0 and 65535");
  // 192.0.2.1 (TEST-NET-1) is not an address of this machine.
  EXPECT_EQ(message("192.0.2.1", 0).rfind("metrics: cannot listen on 192.0.2.1:0: ", 0), 0u);
  EXPECT_THROW(MetricsServer("127.0.0.1", 0, nullptr), std::invalid_argument);
}

TEST(MetricsServer, LocalhostMeansTheIpv4Loopback) {
  MetricsServer server("localhost", 0, [] { return std::string("x 1\n"); });
  EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/metrics");
  EXPECT_EQ(fetch("GET", server.url()).body, "x 1\n");
}

TEST(MetricsServer, ListensOnIpv6Loopback) {
  std::unique_ptr<MetricsServer> server;
  try {
    server = std::make_unique<MetricsServer>("::1", 0, [] { return std::string("x 1\n"); });
  } catch (const std::runtime_error& e) {
    GTEST_SKIP() << "no IPv6 loopback here: " << e.what();
  }
  EXPECT_EQ(server->url(), "http://[::1]:" + std::to_string(server->port()) + "/metrics");
  EXPECT_EQ(fetch("GET", server->url()).body, "x 1\n");
}

size_t open_descriptors() {
  size_t n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) ++n;
  return n;
}

// A daemon is scraped for months: every connection must be closed and freed after its answer.
TEST(MetricsServer, ScrapesLeaveNoConnectionsBehind) {
  MetricsServer server("127.0.0.1", 0, [] { return std::string("x 1\n"); });
  ASSERT_EQ(fetch("GET", server.url()).status, 200u);  // first-use allocations out of the way
  iterate_for(20ms);
  const size_t before = open_descriptors();
  for (int i = 0; i < 40; ++i) {
    const Response r = fetch(i % 2 ? "GET" : "HEAD", server.url());
    ASSERT_EQ(r.status, 200u) << "scrape " << i << ": " << r.error;
  }
  EXPECT_TRUE(iterate_until([&] { return open_descriptors() <= before; }, 2000ms))
      << open_descriptors() - before << " descriptors more than before 40 scrapes";
}

TEST(MetricsServer, AStalledClientDoesNotHoldUpOthers) {
  MetricsServer server("127.0.0.1", 0, [] { return std::string("x 1\n"); });
  RawClient stalled(server.port());
  stalled.send("GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\n");  // headers never finished
  iterate_for(50ms);
  const Response r = fetch("GET", server.url());
  EXPECT_EQ(r.status, 200u);
  EXPECT_EQ(r.body, "x 1\n");
}

TEST(MetricsServer, DestroyingItClosesConnectedClients) {
  int calls = 0;
  auto server = std::make_unique<MetricsServer>("127.0.0.1", 0, [&] {
    ++calls;
    return std::string("x 1\n");
  });
  const int port = server->port();
  RawClient idle(port);
  RawClient halfway(port);
  halfway.send("GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\n");
  iterate_for(100ms);  // the server accepts both and starts reading

  server.reset();
  std::string received;
  EXPECT_TRUE(idle.wait_closed(received)) << "an idle client stays connected to a destroyed server";
  EXPECT_TRUE(halfway.wait_closed(received)) << "a client mid-request stays connected to a destroyed server";
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(received, "");

  // The port is free again: a restarted daemon can listen there at once.
  MetricsServer again("127.0.0.1", port, [] { return std::string("y 1\n"); });
  EXPECT_EQ(fetch("GET", again.url()).body, "y 1\n");
}

// A flood of idle connections (1,027 of them once used up the daemon's descriptors, and its
// file sinks failed): the server keeps at most max_connections, closing the oldest, and a
// scrape that comes after the flood is still answered.
TEST(MetricsServer, ConnectionsBeyondTheCapCloseTheOldestAndScrapesStillAnswer) {
  MetricsServer::Limits limits;
  limits.max_connections = 4;
  MetricsServer server(
      "127.0.0.1", 0, [] { return std::string("x 1\n"); }, limits);
  const size_t before = open_descriptors();
  std::vector<std::unique_ptr<RawClient>> flood;
  for (int i = 0; i < 40; ++i) {
    flood.push_back(std::make_unique<RawClient>(server.port()));
    iterate_for(2ms);
  }
  EXPECT_TRUE(iterate_until([&] { return server.open_connections() <= 4; }, 2000ms)) << server.open_connections();
  // Each client end is one descriptor of this process; the server's ends stay within its cap.
  EXPECT_LE(open_descriptors(), before + 40 + 4 + 2);
  std::string received;
  EXPECT_TRUE(flood.front()->wait_closed(received)) << "the oldest idle connection was kept open";
  const Response r = fetch("GET", server.url());
  EXPECT_EQ(r.status, 200u) << r.error;
  EXPECT_EQ(r.body, "x 1\n");
  EXPECT_LE(server.open_connections(), 4u);
}

TEST(MetricsServer, AConnectionThatSaysNothingIsClosedAfterTheIdleTimeout) {
  MetricsServer::Limits limits;
  limits.idle_timeout = 1000ms;
  MetricsServer server(
      "127.0.0.1", 0, [] { return std::string("x 1\n"); }, limits);
  RawClient silent(server.port());
  RawClient halfway(server.port());
  halfway.send("GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\n");  // and never the blank line
  std::string received;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(silent.wait_closed(received, 4000ms)) << "an idle connection stayed open";
  EXPECT_TRUE(halfway.wait_closed(received, 4000ms)) << "a stalled request stayed open";
  EXPECT_GE(std::chrono::steady_clock::now() - start, 900ms) << "closed before its timeout";
  EXPECT_TRUE(iterate_until([&] { return server.open_connections() == 0; }, 2000ms));
  EXPECT_EQ(fetch("GET", server.url()).status, 200u);
}

}  // namespace
}  // namespace neuflow::daemon
