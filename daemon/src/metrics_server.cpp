#include "metrics_server.hpp"

#include <libsoup/soup.h>

#include <cstring>
#include <exception>
#include <stdexcept>
#include <utility>

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

// Connections are accepted here and handed to the SoupServer, rather than by
// soup_server_listen(): libsoup 3.2's own listener leaks the GSocket of every connection it
// accepts (fixed upstream in later releases), which a daemon scraped for months cannot afford.
gboolean on_incoming(GSocketService*, GSocketConnection* connection, GObject*, gpointer data) {
  auto* server = static_cast<SoupServer*>(data);
  GSocketAddress* local = g_socket_connection_get_local_address(connection, nullptr);
  GSocketAddress* remote = g_socket_connection_get_remote_address(connection, nullptr);
  soup_server_accept_iostream(server, G_IO_STREAM(connection), local, remote, nullptr);
  if (local != nullptr) g_object_unref(local);
  if (remote != nullptr) g_object_unref(remote);
  return TRUE;
}

// "127.0.0.1:9464", "[::1]:9464": how the address is written in the config and in messages.
std::string host_port(const std::string& host, int port) {
  const bool ipv6 = host.find(':') != std::string::npos;
  return (ipv6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

// GLib words bind errors as "Error binding to address 127.0.0.1:9464: Address already in use";
// the address is already in our message, so only the reason after the last ": " is kept.
std::string bind_reason(const GError* error) {
  const std::string message = error->message;
  const auto colon = message.rfind(": ");
  if (message.rfind("Error binding to address", 0) == 0 && colon != std::string::npos)
    return message.substr(colon + 2);
  return message;
}

}  // namespace

struct MetricsServer::Impl {
  SoupServer* server = nullptr;
  GSocketService* service = nullptr;
  std::string host;
  int port = 0;
};

MetricsServer::MetricsServer(std::string address, int port, Render render) : impl_(std::make_unique<Impl>()) {
  if (!render) throw std::invalid_argument("metrics: no render function given");
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

  // Bound before anything else exists, so a failure has nothing to undo but the service.
  impl_->service = g_socket_service_new();
  GSocketAddress* bound = nullptr;
  GError* error = nullptr;
  const gboolean listening =
      g_socket_listener_add_address(G_SOCKET_LISTENER(impl_->service), socket_address, G_SOCKET_TYPE_STREAM,
                                    G_SOCKET_PROTOCOL_TCP, nullptr, &bound, &error);
  g_object_unref(socket_address);
  if (!listening) {
    const std::string reason = bind_reason(error);
    g_error_free(error);
    g_object_unref(impl_->service);
    throw std::runtime_error("metrics: cannot listen on " + where + ": " + reason);
  }
  impl_->port = g_inet_socket_address_get_port(G_INET_SOCKET_ADDRESS(bound));
  g_object_unref(bound);

  impl_->server = soup_server_new("server-header", "neuflowd", nullptr);
  soup_server_add_handler(impl_->server, nullptr, handle_request, new Handler{std::move(render)},
                          [](gpointer data) { delete static_cast<Handler*>(data); });
  // The service is active from its creation: it accepts once this thread's (thread-default)
  // main context iterates, which cannot happen before this handler is connected.
  g_signal_connect(impl_->service, "incoming", G_CALLBACK(on_incoming), impl_->server);
}

MetricsServer::~MetricsServer() {
  // Stop accepting first, then close every client connection now, so no later iteration of
  // the loop can run a request; the server's last reference then frees the handler.
  g_socket_service_stop(impl_->service);
  g_socket_listener_close(G_SOCKET_LISTENER(impl_->service));
  g_signal_handlers_disconnect_by_data(impl_->service, impl_->server);
  g_object_unref(impl_->service);
  soup_server_disconnect(impl_->server);
  g_object_unref(impl_->server);
}

int MetricsServer::port() const { return impl_->port; }

std::string MetricsServer::url() const { return "http://" + host_port(impl_->host, impl_->port) + "/metrics"; }

}  // namespace neuflow::daemon
