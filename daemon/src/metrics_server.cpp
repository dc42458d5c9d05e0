#include "metrics_server.hpp"

#include <libsoup/soup.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <exception>
#include <list>
#include <memory>
#include <stdexcept>
#include <utility>

#include "log.hpp"

namespace neuflow::daemon {

namespace {

// Lives as long as libsoup keeps the handler registered (freed by its destroy notify), so a
// request can never reach a callback whose data is gone.
struct Handler {
  MetricsServer::Render render;
};

void respond(SoupServerMessage* msg, guint status, const char* content_type, const std::string& body) {
  // A server fed with accepted streams (see on_incoming) closes each connection after its
  // response; saying so lets clients open a new one instead of finding this one gone.
  soup_message_headers_replace(soup_server_message_get_response_headers(msg), "Connection", "close");
  soup_server_message_set_status(msg, status, nullptr);
  soup_server_message_set_response(msg, content_type, SOUP_MEMORY_COPY, body.data(), body.size());
}

void handle_request(SoupServer*, SoupServerMessage* msg, const char* path, GHashTable*, gpointer data) {
  const auto& handler = *static_cast<Handler*>(data);
  constexpr const char* kPlain = "text/plain; charset=utf-8";
  if (std::strcmp(path, "/metrics") != 0) {
    respond(msg, SOUP_STATUS_NOT_FOUND, kPlain, "neuflowd serves its metrics at /metrics\n");
    return;
  }
  const char* method = soup_server_message_get_method(msg);
  if (std::strcmp(method, "GET") != 0 && std::strcmp(method, "HEAD") != 0) {
    soup_message_headers_replace(soup_server_message_get_response_headers(msg), "Allow", "GET, HEAD");
    respond(msg, SOUP_STATUS_METHOD_NOT_ALLOWED, kPlain, std::string(method) + " is not allowed: use GET\n");
    return;
  }
  try {
    respond(msg, SOUP_STATUS_OK, kPrometheusContentType, handler.render());
  } catch (const std::exception& e) {
    // The scraper records the failure; the daemon keeps serving the next scrape.
    respond(msg, SOUP_STATUS_INTERNAL_SERVER_ERROR, kPlain,
            std::string("neuflowd could not collect its metrics: ") + e.what() + "\n");
  }
}

// "127.0.0.1:9464", "[::1]:9464": how the address is written in the config and in messages.
std::string host_port(const std::string& host, int port) {
  const bool ipv6 = host.find(':') != std::string::npos;
  return (ipv6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

// GLib words bind errors as "Error binding to address 127.0.0.1:9464: Address already in use";
// the address is already in our message, so only the reason after the last ": " is kept.
std::string bind_reason(const GError* error) {
  std::string message = error->message;
  const auto colon = message.rfind(": ");
  if (message.rfind("Error binding to address", 0) == 0 && colon != std::string::npos) return message.substr(colon + 2);
  return message;
}

}  // namespace

// Connections are accepted here and handed to the SoupServer, rather than by
// soup_server_listen(): libsoup 3.2's own listener leaks the GSocket of every connection it
// accepts (fixed upstream in later releases), which a daemon scraped for months cannot afford.
// Our own accept loop also bounds what clients can take: at most `max_connections` open at
// once (the oldest is closed to admit a new one, so a flood of idle connections can neither
// exhaust the daemon's file descriptors nor lock a scraper out), a connection silent for
// `idle_timeout` is closed by its socket's timeout, and a failing accept (EMFILE when the
// process is out of descriptors for other reasons) is retried after a pause and logged at most
// once per interval instead of in a tight loop.
struct MetricsServer::Impl {
  SoupServer* server = nullptr;
  GSocketListener* listener = nullptr;
  GCancellable* cancellable = nullptr;
  guint retry_source = 0;
  std::string host;
  int port = 0;
  Limits limits;
  std::list<GSocketConnection*> connections;  // oldest first; weak references
  std::chrono::steady_clock::time_point last_accept_log{};
  unsigned accept_failures_unlogged = 0;

  ~Impl() {
    for (GSocketConnection* c : connections) g_object_weak_unref(G_OBJECT(c), &Impl::on_connection_gone, this);
  }

  static void on_connection_gone(gpointer data, GObject* gone) {
    static_cast<Impl*>(data)->connections.remove(reinterpret_cast<GSocketConnection*>(gone));
  }

  void admit(GSocketConnection* connection) {
    while (!connections.empty() && connections.size() >= static_cast<std::size_t>(limits.max_connections)) {
      GSocketConnection* oldest = connections.front();
      connections.pop_front();
      g_object_weak_unref(G_OBJECT(oldest), &Impl::on_connection_gone, this);
      // libsoup reads end of stream and closes it the usual way.
      g_socket_shutdown(g_socket_connection_get_socket(oldest), TRUE, TRUE, nullptr);
    }
    const auto idle_s = std::chrono::ceil<std::chrono::seconds>(limits.idle_timeout).count();
    g_socket_set_timeout(g_socket_connection_get_socket(connection), static_cast<guint>(std::max<long>(1, idle_s)));
    connections.push_back(connection);
    g_object_weak_ref(G_OBJECT(connection), &Impl::on_connection_gone, this);
    GSocketAddress* local = g_socket_connection_get_local_address(connection, nullptr);
    GSocketAddress* remote = g_socket_connection_get_remote_address(connection, nullptr);
    soup_server_accept_iostream(server, G_IO_STREAM(connection), local, remote, nullptr);
    if (local != nullptr) g_object_unref(local);
    if (remote != nullptr) g_object_unref(remote);
  }

  void report_accept_failure(const GError* error) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_accept_log < std::chrono::seconds(10)) {
      ++accept_failures_unlogged;
      return;
    }
    std::string text = "metrics: cannot accept a connection: " + std::string(error->message);
    if (accept_failures_unlogged > 0) {
      text += " (" + std::to_string(accept_failures_unlogged) + " more failures since the last report)";
    }
    log_warning(text + "; retrying in 1 s");
    last_accept_log = now;
    accept_failures_unlogged = 0;
  }
};

namespace {

// The pending accept's hold on the server: the server may be destroyed while it is pending.
struct PendingAccept {
  std::weak_ptr<MetricsServer::Impl> impl;
};

void accept_next(const std::shared_ptr<MetricsServer::Impl>& impl);

void on_accepted(GObject* source, GAsyncResult* result, gpointer data) {
  std::unique_ptr<PendingAccept> pending(static_cast<PendingAccept*>(data));
  GError* error = nullptr;
  GSocketConnection* connection = g_socket_listener_accept_finish(G_SOCKET_LISTENER(source), result, nullptr, &error);
  const auto impl = pending->impl.lock();
  if (!impl || g_error_matches(error, G_IO_ERROR, G_IO_ERROR_CANCELLED)) {
    if (connection != nullptr) g_object_unref(connection);
    if (error != nullptr) g_error_free(error);
    return;
  }
  if (connection == nullptr) {
    impl->report_accept_failure(error);
    g_error_free(error);
    impl->retry_source = g_timeout_add_full(
        G_PRIORITY_DEFAULT, 1000,
        [](gpointer p) -> gboolean {
          if (const auto again = static_cast<PendingAccept*>(p)->impl.lock()) {
            again->retry_source = 0;
            accept_next(again);
          }
          return G_SOURCE_REMOVE;
        },
        new PendingAccept{impl}, [](gpointer p) { delete static_cast<PendingAccept*>(p); });
    return;
  }
  impl->admit(connection);
  g_object_unref(connection);
  accept_next(impl);
}

void accept_next(const std::shared_ptr<MetricsServer::Impl>& impl) {
  g_socket_listener_accept_async(impl->listener, impl->cancellable, on_accepted, new PendingAccept{impl});
}

}  // namespace

MetricsServer::MetricsServer(std::string address, int port, Render render, Limits limits)
    : impl_(std::make_shared<Impl>()) {
  if (!render) throw std::invalid_argument("metrics: no render function given");
  if (limits.max_connections < 1) throw std::invalid_argument("metrics: max_connections must be at least 1");
  impl_->limits = limits;
  impl_->host = address == "localhost" ? "127.0.0.1" : std::move(address);
  const std::string where = host_port(impl_->host, port);
  if (port < 0 || port > 65535)
    throw std::runtime_error("metrics: cannot listen on " + where + ": the port must be between 0 and 65535");

  GInetAddress* inet = g_inet_address_new_from_string(impl_->host.c_str());
  if (inet == nullptr)
    throw std::runtime_error("metrics: cannot listen on " + where +
                             ": not an IP address (write e.g. 127.0.0.1, ::1 or 0.0.0.0)");
  GSocketAddress* socket_address = g_inet_socket_address_new(inet, static_cast<guint16>(port));
  g_object_unref(inet);

  // Bound before anything else exists, so a failure has nothing to undo but the listener.
  impl_->listener = g_socket_listener_new();
  // Room for a burst of connections between two turns of the main loop (GLib's default is 10).
  g_socket_listener_set_backlog(impl_->listener, 128);
  GSocketAddress* bound = nullptr;
  GError* error = nullptr;
  const gboolean listening = g_socket_listener_add_address(impl_->listener, socket_address, G_SOCKET_TYPE_STREAM,
                                                           G_SOCKET_PROTOCOL_TCP, nullptr, &bound, &error);
  g_object_unref(socket_address);
  if (!listening) {
    const std::string reason = bind_reason(error);
    g_error_free(error);
    g_object_unref(impl_->listener);
    throw std::runtime_error("metrics: cannot listen on " + where + ": " + reason);
  }
  impl_->port = g_inet_socket_address_get_port(G_INET_SOCKET_ADDRESS(bound));
  g_object_unref(bound);

  impl_->server = soup_server_new("server-header", "neuflowd", nullptr);
  soup_server_add_handler(impl_->server, nullptr, handle_request, new Handler{std::move(render)},
                          [](gpointer data) { delete static_cast<Handler*>(data); });
  impl_->cancellable = g_cancellable_new();
  // Accepts once this thread's (thread-default) main context iterates.
  accept_next(impl_);
}

MetricsServer::~MetricsServer() {
  // Stop accepting first, then close every client connection now, so no later iteration of
  // the loop can run a request; the server's last reference then frees the handler. A pending
  // accept completes later as cancelled and finds the server gone.
  g_cancellable_cancel(impl_->cancellable);
  if (impl_->retry_source != 0) g_source_remove(impl_->retry_source);
  g_socket_listener_close(impl_->listener);
  g_object_unref(impl_->listener);
  g_object_unref(impl_->cancellable);
  soup_server_disconnect(impl_->server);
  g_object_unref(impl_->server);
}

std::size_t MetricsServer::open_connections() const { return impl_->connections.size(); }

int MetricsServer::port() const { return impl_->port; }

std::string MetricsServer::url() const { return "http://" + host_port(impl_->host, impl_->port) + "/metrics"; }

}  // namespace neuflow::daemon
