// [stream.source]: a V4L2 camera, a libcamera camera, a URI (files, RTSP, HTTP) or a test pattern.
#include <glib.h>

#include <array>
#include <climits>

#include "config_read.hpp"
#include "config_values.hpp"
#include "neuflow/pipeline/graph_plan.hpp"

namespace neuflow::daemon {
namespace {

using Need = TableReader::Need;

// width, height, framerate: optional caps the source is asked for.
VideoMode read_video_mode(const TableReader& t) {
  VideoMode mode;
  if (auto v = t.integer("width", 1, 16384)) mode.width = static_cast<int>(*v);
  if (auto v = t.integer("height", 1, 16384)) mode.height = static_cast<int>(*v);
  const auto* rate = t.get("framerate");
  if (!rate) return mode;
  const std::string expected = "frames per second: an integer 1..1000 or a fraction like \"30000/1001\"";
  if (const auto* i = rate->as_integer(); i && i->get() >= 1 && i->get() <= 1000) {
    mode.framerate_num = static_cast<int>(i->get());
    mode.framerate_den = 1;
    return mode;
  }
  int num = 0;
  int den = 0;
  if (const auto* s = rate->as_string(); s && parse_fraction(s->get(), num, den) && num <= 1000LL * den) {
    mode.framerate_num = num;
    mode.framerate_den = den;
    return mode;
  }
  t.report("framerate", "expected " + expected + ", got " + describe_value(*rate));
  return mode;
}

V4l2Source read_v4l2(const TableReader& t, ReadContext& context) {
  static constexpr std::array<std::string_view, 6> keys = {"type", "device", "width", "height", "framerate", "format"};
  static constexpr std::array<std::string_view, 2> formats = {"raw", "mjpeg"};
  t.allow_only(keys);
  V4l2Source v;
  const auto device = t.string("device");
  if (device && device->empty()) {
    t.report("device", "expected a V4L2 device node like \"/dev/video0\", got an empty string");
  } else if (!t.has("device") || device) {
    v.device =
        context.need_path(PathNeed::Kind::video_device, device.value_or(v.device), "device", t.position("device"))
            .string();
  }
  v.mode = read_video_mode(t);
  if (auto format = t.choice("format", formats)) v.mjpeg = *format == "mjpeg";
  return v;
}

LibcameraSource read_libcamera(const TableReader& t) {
  static constexpr std::array<std::string_view, 5> keys = {"type", "camera", "width", "height", "framerate"};
  t.allow_only(keys);
  LibcameraSource l;
  if (auto camera = t.string("camera")) l.camera = *camera;
  l.mode = read_video_mode(t);
  return l;
}

// `uri = "scheme://..."`, or `path = "file"` made a file:// URI.
UriSource read_uri(const TableReader& t, const std::string& user, ReadContext& context) {
  static constexpr std::array<std::string_view, 3> keys = {"type", "uri", "path"};
  t.allow_only(keys);
  UriSource u;
  if (t.has("uri") && t.has("path")) {
    t.report("path", "give either uri or path, not both");
    return u;
  }
  if (!t.has("uri") && !t.has("path")) {
    t.report_here(
        "missing 'uri' or 'path' in [stream.source] of type \"uri\": expected uri = \"rtsp://...\" "
        "(or file://, http://) or path = \"video.mp4\"");
    return u;
  }
  if (auto path = t.string("path")) {
    if (path->empty()) {
      t.report("path", "expected a video file, got an empty string");
      return u;
    }
    const auto file = context.need_path(PathNeed::Kind::readable_file, *path, "path", t.position("path"));
    gchar* uri = g_filename_to_uri(file.c_str(), nullptr, nullptr);
    if (uri) u.uri = uri;
    g_free(uri);
    return u;
  }
  const auto uri = t.string("uri");
  if (!uri) return u;
  GError* error = nullptr;
  if (!g_uri_is_valid(uri->c_str(), G_URI_FLAGS_NONE, &error)) {
    t.report("uri",
             "expected an absolute URI like \"rtsp://camera/stream\" or \"file:///videos/in.mp4\" "
             "(or path = \"...\" for a file), got \"" +
                 *uri + "\": " + error->message);
    g_error_free(error);
    return u;
  }
  u.uri = *uri;
  // Lower-cased by GLib, as GStreamer's URI handlers register them.
  const char* scheme = g_uri_peek_scheme(uri->c_str());
  const std::string scheme_text = scheme ? scheme : "";
  if (scheme_text != "file") {
    context.needs.uri_schemes.push_back({scheme_text, user, t.position("uri")});
    return u;
  }
  gchar* filename = g_filename_from_uri(uri->c_str(), nullptr, &error);
  if (!filename) {
    t.report("uri", std::string("expected a file URI with an absolute path like \"file:///videos/in.mp4\" (or "
                                "path = \"...\" for a relative one): ") +
                        error->message);
    g_error_free(error);
    return u;
  }
  context.needs.paths.push_back({PathNeed::Kind::readable_file, filename, *uri, "uri", t.position("uri")});
  g_free(filename);
  return u;
}

TestSource read_test(const TableReader& t) {
  static constexpr std::array<std::string_view, 7> keys = {"type",      "pattern", "width", "height",
                                                           "framerate", "frames",  "live"};
  t.allow_only(keys);
  TestSource s;
  if (auto pattern = t.choice("pattern", test_patterns())) s.pattern = *pattern;
  s.mode = read_video_mode(t);
  if (auto frames = t.integer("frames", 1, INT_MAX)) s.frames = static_cast<int>(*frames);
  if (auto live = t.boolean("live")) s.live = *live;
  return s;
}

}  // namespace

SourceConfig read_source(const TableReader& t, const std::string& stream, ReadContext& context) {
  static constexpr std::array<std::string_view, 4> types = {"v4l2", "libcamera", "uri", "test"};
  SourceConfig source;
  source.where = t.where();
  const auto type = t.choice("type", types, Need::required);
  // Without a known type the valid keys are unknown too: only the type is reported.
  if (!type) return source;
  const std::string user = "the " + *type + " source of stream '" + stream + "'";
  if (*type == "v4l2") source.settings = read_v4l2(t, context);
  if (*type == "libcamera") source.settings = read_libcamera(t);
  if (*type == "uri") source.settings = read_uri(t, user, context);
  if (*type == "test") source.settings = read_test(t);
  context.need_elements(pipeline::required_elements(source.settings), user, source.where);
  return source;
}

}  // namespace neuflow::daemon
