#include "rtsp_server.hpp"

#include <gst/rtsp-server/rtsp-server.h>

#include <stdexcept>

#include "log.hpp"
#include "stream_graph.hpp"

namespace neuflow::daemon {

namespace {

std::string launch_line(const RtspMount& m) {
  return "( intervideosrc channel=\"" + m.channel + "\" ! videoconvert ! video/x-raw,format=I420 ! "
         "x264enc tune=zerolatency speed-preset=ultrafast key-int-max=30 bitrate=" + std::to_string(m.bitrate_kbps) +
         " ! rtph264pay name=pay0 pt=96 config-interval=1 )";
}

}  // namespace

RtspServer::RtspServer(const RtspSettings& settings) : settings_(settings) {
  server_ = gst_rtsp_server_new();
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
    gst_rtsp_media_factory_set_launch(factory, launch_line(mount).c_str());
    gst_rtsp_media_factory_set_shared(factory, TRUE);
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
      mounts[v->rtsp_mount] = RtspMount{rtsp_channel_name(stream.name, v->rtsp_mount), v->bitrate_kbps};
    }
  }
  return mounts;
}

}  // namespace neuflow::daemon
