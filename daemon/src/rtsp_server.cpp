#include "rtsp_server.hpp"

#include <gst/rtsp-server/rtsp-server.h>

#include <stdexcept>

#include "log.hpp"
#include "neuflow/pipeline/graph_plan.hpp"
#include "rtsp_credentials.hpp"

namespace neuflow::daemon {

namespace {

// The role every user in the credentials file has; the mounts let it watch.
constexpr const char* kViewerRole = "viewer";

bool on_all_interfaces(const std::string& address) { return address == "0.0.0.0" || address == "::"; }

}  // namespace

GstRTSPAuth* RtspServer::make_auth() const {
  if (settings_.credentials.empty()) return nullptr;
  const std::vector<RtspUser> users = read_rtsp_credentials(settings_.credentials);
  if (readable_by_everyone(settings_.credentials)) {
    log_warning("rtsp: " + settings_.credentials.string() +
                " is readable by every user of this machine; chmod o-r it (it holds passwords)");
  }
  GstRTSPAuth* auth = gst_rtsp_auth_new();
  const bool digest = settings_.auth == "digest";
  gst_rtsp_auth_set_supported_methods(auth, digest ? GST_RTSP_AUTH_DIGEST : GST_RTSP_AUTH_BASIC);
  for (const RtspUser& user : users) {
    GstRTSPToken* token = gst_rtsp_token_new(GST_RTSP_TOKEN_MEDIA_FACTORY_ROLE, G_TYPE_STRING, kViewerRole, nullptr);
    if (digest) {
      gst_rtsp_auth_add_digest(auth, user.name.c_str(), user.password.c_str(), token);
    } else {
      gchar* basic = gst_rtsp_auth_make_basic(user.name.c_str(), user.password.c_str());
      gst_rtsp_auth_add_basic(auth, basic, token);
      g_free(basic);
    }
    gst_rtsp_token_unref(token);
  }
  log_info("rtsp: " + std::to_string(users.size()) + " user" + (users.size() == 1 ? "" : "s") + " from " +
           settings_.credentials.string() + " (" + settings_.auth + " authentication)");
  return auth;
}

RtspServer::RtspServer(const RtspSettings& settings) : settings_(settings) {
  GstRTSPAuth* auth = make_auth();  // first: nothing to undo when the credentials are unreadable
  server_ = gst_rtsp_server_new();
  if (auth) {
    gst_rtsp_server_set_auth(server_, auth);
    g_object_unref(auth);
  }
  gst_rtsp_server_set_address(server_, settings.address.c_str());
  gst_rtsp_server_set_service(server_, std::to_string(settings.port).c_str());
  GError* error = nullptr;
  GSource* source = gst_rtsp_server_create_source(server_, nullptr, &error);
  if (!source) {
    const std::string why = error ? error->message : "unknown error";
    g_clear_error(&error);
    g_object_unref(server_);
    throw std::runtime_error("rtsp: cannot listen on " + settings.address + ":" + std::to_string(settings.port) + ": " +
                             why);
  }
  source_id_ = g_source_attach(source, nullptr);
  g_source_unref(source);
  if (on_all_interfaces(settings.address)) {
    const std::string where = settings.address + ":" + std::to_string(settings.port);
    if (settings.credentials.empty()) {
      log_warning("rtsp: listening on every interface (" + where +
                  ") WITHOUT authentication: anyone who can reach this machine can watch the flow; set [rtsp] "
                  "credentials, or listen on 127.0.0.1");
    } else {
      log_notice("rtsp: listening on every interface (" + where + "); viewers log in with " + settings.auth +
                 " authentication");
    }
  }
}

void RtspServer::reload_credentials() {
  GstRTSPAuth* auth = make_auth();
  if (!auth) return;
  gst_rtsp_server_set_auth(server_, auth);
  g_object_unref(auth);
}

RtspServer::~RtspServer() {
  set_mounts({});
  if (source_id_) g_source_remove(source_id_);
  // Clients still connected are closed with the server.
  GstRTSPSessionPool* pool = gst_rtsp_server_get_session_pool(server_);
  gst_rtsp_session_pool_cleanup(pool);
  g_object_unref(pool);
  g_object_unref(server_);
}

int RtspServer::port() const { return gst_rtsp_server_get_bound_port(server_); }

void RtspServer::set_mounts(const std::map<std::string, RtspMount>& mounts) {
  GstRTSPMountPoints* points = gst_rtsp_server_get_mount_points(server_);
  for (const auto& [path, mount] : mounts_) {
    auto it = mounts.find(path);
    if (it == mounts.end() || !(it->second == mount)) gst_rtsp_mount_points_remove_factory(points, path.c_str());
  }
  for (const auto& [path, mount] : mounts) {
    auto it = mounts_.find(path);
    if (it != mounts_.end() && it->second == mount) continue;
    GstRTSPMediaFactory* factory = gst_rtsp_media_factory_new();
    gst_rtsp_media_factory_set_launch(factory, pipeline::rtsp_launch_line(mount.channel, mount.bitrate_kbps).c_str());
    gst_rtsp_media_factory_set_shared(factory, TRUE);
    if (!settings_.credentials.empty()) {
      // Without a permission for it, a role is refused: only the listed users may watch.
      GstRTSPPermissions* permissions = gst_rtsp_permissions_new();
      gst_rtsp_permissions_add_role(permissions, kViewerRole, GST_RTSP_PERM_MEDIA_FACTORY_ACCESS, G_TYPE_BOOLEAN, TRUE,
                                    GST_RTSP_PERM_MEDIA_FACTORY_CONSTRUCT, G_TYPE_BOOLEAN, TRUE, nullptr);
      gst_rtsp_media_factory_set_permissions(factory, permissions);
      gst_rtsp_permissions_unref(permissions);
    }
    gst_rtsp_mount_points_add_factory(points, path.c_str(), factory);  // takes the factory
    log_info("rtsp: serving rtsp://" + settings_.address + ":" + std::to_string(settings_.port) + path);
  }
  g_object_unref(points);
  mounts_ = mounts;
}

std::map<std::string, RtspMount> rtsp_mounts(const Config& config) {
  std::map<std::string, RtspMount> mounts;
  for (const StreamConfig& stream : config.streams) {
    for (const SinkConfig& sink : stream.sinks) {
      const auto* v = std::get_if<VideoSink>(&sink.settings);
      if (!v || v->target != VideoSink::Target::rtsp) continue;
      mounts[v->rtsp_mount] = RtspMount{pipeline::rtsp_channel_name(stream.name, v->rtsp_mount), v->bitrate_kbps};
    }
  }
  return mounts;
}

}  // namespace neuflow::daemon
