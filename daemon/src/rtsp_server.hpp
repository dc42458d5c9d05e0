#pragma once
// The RTSP server behind `video` sinks with `rtsp = "/mount"`: one server per daemon on the
// [rtsp] address, one shared mount per sink. A stream's pipeline hands its visualization to
// the mount through an intervideo channel, so clients coming and going never touch the
// stream's pipeline, and encoding only runs while someone watches.
#include <map>
#include <string>

#include "config.hpp"

typedef struct _GstRTSPServer GstRTSPServer;
typedef struct _GstRTSPAuth GstRTSPAuth;

namespace neuflow::daemon {

struct RtspMount {
  std::string channel;  // the intervideo channel the stream writes to
  int bitrate_kbps = 2000;
  bool operator==(const RtspMount&) const = default;
};

class RtspServer {
 public:
  // Listens at once on the default main context; throws std::runtime_error when it cannot,
  // RtspCredentialsError when settings.credentials is set and cannot be read (a server that
  // was asked for authentication never serves without it).
  explicit RtspServer(const RtspSettings& settings);
  ~RtspServer();
  RtspServer(const RtspServer&) = delete;
  RtspServer& operator=(const RtspServer&) = delete;

  // Makes the served mounts exactly these (path → mount).
  void set_mounts(const std::map<std::string, RtspMount>& mounts);
  // Reads the credentials file again (at a reload); on failure the users stay as they were
  // and RtspCredentialsError says why.
  void reload_credentials();
  int port() const;
  const RtspSettings& settings() const { return settings_; }

 private:
  GstRTSPAuth* make_auth() const;  // nullptr without credentials

  RtspSettings settings_;
  GstRTSPServer* server_ = nullptr;
  unsigned source_id_ = 0;
  std::map<std::string, RtspMount> mounts_;
};

// Every rtsp mount the config asks for, by path.
std::map<std::string, RtspMount> rtsp_mounts(const Config& config);

}  // namespace neuflow::daemon
