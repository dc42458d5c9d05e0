// neuflowd's config file on its own (ConfigChecks::file_only): what a valid file becomes, and
// every kind of mistake reported where it is, with what was expected. The checks against the
// machine are in config_environment_test.cpp.
#include "config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "config_test_util.hpp"
#include "config_values.hpp"
#include "neuflow/flow_ring.hpp"

namespace neuflow::daemon {
namespace {

using test::has_issue;
using test::issues_of;
using test::kConfigFile;
namespace fs = std::filesystem;

// A [stream.flow] table as read: the given keys, every other one at its default.
FlowConfig flow_config(const fs::path& model, model::Iterations iterations = {}, int model_width = 0,
                       int model_height = 0, int threads = 0, model::Behaviour behaviour = model::Behaviour::automatic,
                       model::ChannelOrder order = model::ChannelOrder::rgb,
                       model::Backend backend = model::Backend::automatic, int device = -1) {
  FlowConfig f;
  f.stage.model = model;
  f.stage.behaviour = behaviour;
  model::SessionOptions& s = f.stage.session;
  s.iterations = iterations;
  s.model_width = model_width;
  s.model_height = model_height;
  s.threads = threads;
  s.network_order = order;
  s.backend = backend;
  s.device = device;
  return f;
}

Config parse(const std::string& text, const fs::path& file = kConfigFile) {
  return parse_config(text, file, ConfigChecks::file_only);
}

// A minimal valid stream, for tests about one other part.
const std::string kMinimalStream = R"([[stream]]
name = "s"
source = { type = "test" }
flow = { model = "/m.pth" }
sink = [ { type = "display" } ]
)";

// ---- what a valid file becomes -------------------------------------------------------------

TEST(Config, FullFileBecomesTheExpectedStructs) {
  const Config c = parse(R"(# every table and key
[daemon]
log-level = "debug"
threads = 6
restart-delay-min = 0.5
restart-delay-max = 30
stop-timeout = 5.0
stall-timeout = 12.5

[metrics]
listen = "0.0.0.0:9100"

[rtsp]
listen = "[::]:8555"

[[stream]]
name = "front"
  [stream.source]
  type = "v4l2"
  device = "/dev/video2"
  width = 1280
  height = 720
  framerate = "30000/1001"
  format = "mjpeg"
  [stream.flow]
  model = "/var/lib/neuflow/neuflow_mixed.pth"
  iters-s16 = 2
  iters-s8 = 6
  model-width = 640
  model-height = 352
  threads = 3
  behaviour = "live"
  channel-order = "bgr"
  backend = "cpu"
  device = 0
  [[stream.sink]]
  type = "shm"
  name = "front-ring"
  shm-name = "/neuflow-front"
  slots = 8
  [[stream.sink]]
  type = "video"
  rtsp = "/front"
  bitrate = 3000
  max-flow = 25
  [[stream.sink]]
  type = "files"
  directory = "/var/lib/neuflow/front"
  format = "npy"
  max-files = 1000
  max-bytes = 5_000_000
  [[stream.sink]]
  type = "display"
  max-flow = 0.0

[[stream]]
name = "cam_2"
source = { type = "libcamera", camera = "/base/imx219@10", width = 640, height = 480, framerate = 15 }
flow = { model = "/models/m.pth" }
  [[stream.sink]]
  type = "video"
  name = "rec"
  file = "/rec/viz-%05d.mkv"
  segment-seconds = 600
  [[stream.sink]]
  type = "video"
  udp = "192.168.1.10:5000"

[[stream]]
name = "clip"
source = { type = "uri", uri = "rtsp://camera.local:554/stream1" }
flow = { model = "/models/m.pth", behaviour = "every-pair" }
sink = [ { type = "files", directory = "/out/clip" } ]

[[stream]]
name = "trial"
source = { type = "test", pattern = "pinwheel", frames = 100, live = false, framerate = 60 }
flow = { model = "/models/m.pth" }
sink = [ { type = "display" } ]
)");

  EXPECT_EQ(c.file, kConfigFile);
  EXPECT_EQ(c.daemon, (DaemonSettings{"debug", 6, 0.5, 30.0, 5.0, 12.5}));
  ASSERT_TRUE(c.metrics);
  EXPECT_EQ(*c.metrics, (MetricsSettings{"0.0.0.0", 9100}));
  ASSERT_TRUE(c.rtsp);
  EXPECT_EQ(*c.rtsp, (RtspSettings{"::", 8555}));
  ASSERT_EQ(c.streams.size(), 4u);

  const StreamConfig& front = c.streams[0];
  EXPECT_EQ(front.name, "front");
  EXPECT_EQ(front.where.line, 16);
  EXPECT_EQ(std::get<V4l2Source>(front.source.settings),
            (V4l2Source{"/dev/video2", VideoMode{1280, 720, 30000, 1001}, true}));
  EXPECT_EQ(front.source.where.line, 18);
  EXPECT_EQ(front.flow, flow_config("/var/lib/neuflow/neuflow_mixed.pth", {2, 6}, 640, 352, 3, model::Behaviour::live,
                                    model::ChannelOrder::bgr, model::Backend::cpu, 0));
  EXPECT_EQ(front.flow.where.line, 25);
  ASSERT_EQ(front.sinks.size(), 4u);
  EXPECT_EQ(front.sinks[0].name, "front-ring");
  EXPECT_EQ(front.sinks[0].where.line, 36);
  EXPECT_EQ(std::get<ShmSink>(front.sinks[0].settings), (ShmSink{"/neuflow-front", 8}));
  EXPECT_EQ(front.sinks[1].name, "video-1");
  VideoSink rtsp;
  rtsp.target = VideoSink::Target::rtsp;
  rtsp.rtsp_mount = "/front";
  rtsp.bitrate_kbps = 3000;
  rtsp.max_flow = 25.0;
  EXPECT_EQ(std::get<VideoSink>(front.sinks[1].settings), rtsp);
  EXPECT_EQ(front.sinks[2].name, "files-2");
  EXPECT_EQ(std::get<FilesSink>(front.sinks[2].settings), (FilesSink{"/var/lib/neuflow/front", "npy", 1000, 5000000}));
  EXPECT_EQ(front.sinks[3].name, "display-3");
  EXPECT_EQ(std::get<DisplaySink>(front.sinks[3].settings), DisplaySink{0.0});

  const StreamConfig& cam = c.streams[1];
  EXPECT_EQ(std::get<LibcameraSource>(cam.source.settings),
            (LibcameraSource{"/base/imx219@10", VideoMode{640, 480, 15, 1}}));
  EXPECT_EQ(cam.flow, flow_config("/models/m.pth"));
  ASSERT_EQ(cam.sinks.size(), 2u);
  EXPECT_EQ(cam.sinks[0].name, "rec");
  VideoSink file;
  file.file = "/rec/viz-%05d.mkv";
  file.segment_seconds = 600;
  EXPECT_EQ(std::get<VideoSink>(cam.sinks[0].settings), file);
  VideoSink udp;
  udp.target = VideoSink::Target::udp;
  udp.udp_host = "192.168.1.10";
  udp.udp_port = 5000;
  EXPECT_EQ(std::get<VideoSink>(cam.sinks[1].settings), udp);

  EXPECT_EQ(std::get<UriSource>(c.streams[2].source.settings).uri, "rtsp://camera.local:554/stream1");
  EXPECT_EQ(c.streams[2].flow.stage.behaviour, model::Behaviour::every_pair);
  EXPECT_EQ(std::get<FilesSink>(c.streams[2].sinks[0].settings), (FilesSink{"/out/clip", "flo", 0, 0}));

  EXPECT_EQ(std::get<TestSource>(c.streams[3].source.settings),
            (TestSource{"pinwheel", VideoMode{0, 0, 60, 1}, 100, false}));
}

TEST(Config, OmittedKeysTakeTheirDefaults) {
  const Config c = parse(kMinimalStream);
  EXPECT_EQ(c.daemon, DaemonSettings{});
  EXPECT_FALSE(c.metrics);
  EXPECT_FALSE(c.rtsp);
  ASSERT_EQ(c.streams.size(), 1u);
  EXPECT_EQ(std::get<TestSource>(c.streams[0].source.settings), TestSource{});
  EXPECT_EQ(c.streams[0].flow, flow_config("/m.pth"));
  EXPECT_EQ(c.streams[0].sinks[0].name, "display-0");
  EXPECT_EQ(std::get<DisplaySink>(c.streams[0].sinks[0].settings), DisplaySink{});

  // Empty [metrics] and [rtsp] tables turn them on at their default addresses.
  const Config on = parse("[metrics]\n[rtsp]\n" + kMinimalStream);
  EXPECT_EQ(on.metrics, MetricsSettings{});
  EXPECT_EQ(on.rtsp, RtspSettings{});

  const Config v4l2 = parse(R"([[stream]]
name = "s"
source = { type = "v4l2" }
flow = { model = "/m.pth" }
sink = [ { type = "shm", shm-name = "/x" }, { type = "video", file = "/v/out.mp4" } ]
)");
  EXPECT_EQ(std::get<V4l2Source>(v4l2.streams[0].source.settings), V4l2Source{});
  EXPECT_EQ(std::get<ShmSink>(v4l2.streams[0].sinks[0].settings), (ShmSink{"/x", 4}));
  VideoSink video;
  video.file = "/v/out.mp4";
  EXPECT_EQ(std::get<VideoSink>(v4l2.streams[0].sinks[1].settings), video);
}

TEST(Config, RelativePathsAreTakenFromTheConfigFilesFolder) {
  const Config c = parse(R"([[stream]]
name = "s"
source = { type = "uri", path = "videos/in put.mp4" }
flow = { model = "../models/neuflow_mixed.pth" }
  [[stream.sink]]
  type = "files"
  directory = "out/./flow"
  [[stream.sink]]
  type = "video"
  file = "viz.mp4"
  [[stream.sink]]
  type = "files"
  directory = "/abs/../flow"
)",
                         "/srv/neuflow/conf/main.toml");
  const StreamConfig& s = c.streams[0];
  EXPECT_EQ(s.flow.stage.model, fs::path("/srv/neuflow/models/neuflow_mixed.pth"));
  // A path becomes a file:// URI, escaped as URIs must be.
  EXPECT_EQ(std::get<UriSource>(s.source.settings).uri, "file:///srv/neuflow/conf/videos/in%20put.mp4");
  EXPECT_EQ(std::get<FilesSink>(s.sinks[0].settings).directory, fs::path("/srv/neuflow/conf/out/flow"));
  EXPECT_EQ(std::get<VideoSink>(s.sinks[1].settings).file, fs::path("/srv/neuflow/conf/viz.mp4"));
  EXPECT_EQ(std::get<FilesSink>(s.sinks[2].settings).directory, fs::path("/flow"));

  // A config named by a relative path: its folder is taken from the working directory.
  const Config relative = parse(kMinimalStream, "conf/x.toml");
  EXPECT_EQ(relative.file, fs::current_path() / "conf/x.toml");
  const Config model = parse(R"([[stream]]
name = "s"
source = { type = "test" }
flow = { model = "m.pth" }
sink = [ { type = "display" } ]
)",
                             "conf/x.toml");
  EXPECT_EQ(model.streams[0].flow.stage.model, fs::current_path() / "conf/m.pth");
}

TEST(Config, FramerateIsAnIntegerOrAFraction) {
  const auto rate = [](const std::string& value) {
    const Config c = parse("[[stream]]\nname = \"s\"\nsource = { type = \"test\", framerate = " + value +
                           " }\nflow = { model = \"/m\" }\nsink = [ { type = \"display\" } ]\n");
    const VideoMode& m = std::get<TestSource>(c.streams[0].source.settings).mode;
    return std::pair(m.framerate_num, m.framerate_den);
  };
  EXPECT_EQ(rate("25"), std::pair(25, 1));
  EXPECT_EQ(rate("\"30000/1001\""), std::pair(30000, 1001));
  for (const std::string bad : {"0", "29.97", "\"30\"", "\"30/0\"", "\"-30/1\"", "\"2000/1\"", "1001"}) {
    const auto issues = issues_of("[[stream]]\nname = \"s\"\nsource = { type = \"test\", framerate = " + bad +
                                  " }\nflow = { model = \"/m\" }\nsink = [ { type = \"display\" } ]\n");
    EXPECT_TRUE(has_issue(issues, 3, 0, "framerate: expected frames per second: an integer 1..1000 or a fraction"))
        << bad;
  }
}

TEST(Config, ConfigIssueAndConfigErrorText) {
  EXPECT_EQ((ConfigIssue{"a.toml", 3, 7, "bad"}).to_string(), "a.toml:3:7: bad");
  EXPECT_EQ((ConfigIssue{"a.toml", 3, 0, "bad"}).to_string(), "a.toml:3: bad");
  EXPECT_EQ((ConfigIssue{"a.toml", 0, 0, "bad"}).to_string(), "a.toml: bad");
  const ConfigError error({ConfigIssue{"a.toml", 1, 2, "one"}, ConfigIssue{"a.toml", 5, 6, "two"}});
  EXPECT_STREQ(error.what(), "a.toml:1:2: one\na.toml:5:6: two");
  EXPECT_EQ(error.issues().size(), 2u);
}

// ---- mistakes ------------------------------------------------------------------------------

TEST(ConfigValues, ShmModeIsOctalAsAStringOrATomlOctalInteger) {
  const auto mode_of = [](const std::string& value) {
    const Config c = parse(
        "[[stream]]\nname = \"s\"\nsource = { type = \"test\" }\nflow = { model = \"/m.pth\" }\n"
        "sink = [ { type = \"shm\", shm-name = \"/x\", shm-mode = " +
        value + " } ]\n");
    return std::get<ShmSink>(c.streams[0].sinks[0].settings).mode;
  };
  EXPECT_EQ(mode_of("\"0644\""), 0644u);
  EXPECT_EQ(mode_of("\"660\""), 0660u);
  EXPECT_EQ(mode_of("0o600"), 0600u);
  for (const std::string bad : {"\"0700\"", "\"0400\"", "\"rw-r-----\"", "644", "\"04640\""}) {
    const auto issues = issues_of(
        "[[stream]]\nname = \"s\"\nsource = { type = \"test\" }\nflow = { model = \"/m.pth\" }\n"
        "sink = [ { type = \"shm\", shm-name = \"/x\", shm-mode = " +
        bad + " } ]\n");
    EXPECT_TRUE(has_issue(issues, 5, 0, "shm-mode: expected an octal mode like \"0640\"")) << bad;
  }
}

TEST(ConfigErrors, TomlSyntaxErrorGivesItsPosition) {
  const auto issues = issues_of("[daemon]\nthreads = 4\nlog-level = \"info\n");
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].file, kConfigFile);
  EXPECT_EQ(issues[0].line, 3);
  EXPECT_GT(issues[0].column, 1);
  EXPECT_NE(issues[0].message.find("invalid TOML"), std::string::npos) << issues[0].message;

  const auto redefined = issues_of("[daemon]\nthreads = 1\nthreads = 2\n");
  EXPECT_TRUE(has_issue(redefined, 3, 0, "invalid TOML"));
}

TEST(ConfigErrors, UnknownKeysNameTheTableTheValidKeysAndTheClosestOne) {
  const auto issues = issues_of(R"([daemon]
log_level = "info"
[[stream]]
name = "s"
source = { type = "v4l2", pattern = "ball" }
  [stream.flow]
  model = "/m.pth"
  iter-s8 = 4
  [[stream.sink]]
  type = "files"
  directory = "/out"
  max-size = 100
[extra]
)");
  EXPECT_TRUE(has_issue(issues, 2, 1, "unknown key 'log_level' in [daemon] (did you mean 'log-level'?)"));
  EXPECT_TRUE(has_issue(issues, 5, 27,
                        "unknown key 'pattern' in [stream.source]; valid keys: type, device, width, "
                        "height, framerate, format"));
  EXPECT_TRUE(has_issue(issues, 8, 3,
                        "unknown key 'iter-s8' in [stream.flow] (did you mean 'iters-s8'?); valid "
                        "keys: model, iters-s16, iters-s8, model-width, model-height, threads, "
                        "behaviour, channel-order"));
  EXPECT_TRUE(has_issue(issues, 12, 3, "unknown key 'max-size' in [[stream.sink]]"));
  EXPECT_TRUE(has_issue(issues, 13, 2,
                        "unknown key 'extra' in the file's top level; valid keys: daemon, metrics, rtsp, "
                        "stream"));
  EXPECT_EQ(issues.size(), 5u) << test::listed(issues);
}

// max-memory: MiB, 0 (automatic) by default; a negative one is an error naming the key.
TEST(Config, MaxMemoryIsReadInMebibytesAndChecked) {
  const auto with = [](const std::string& value) {
    return R"([[stream]]
name = "s"
source = { type = "test" }
flow = { model = "/m.pth", max-memory = )" +
           value + R"( }
sink = [ { type = "display" } ]
)";
  };
  EXPECT_EQ(parse(with("512")).streams.at(0).flow.stage.session.max_memory_mb, 512);
  EXPECT_EQ(parse(kMinimalStream).streams.at(0).flow.stage.session.max_memory_mb, 0);
  const auto issues = issues_of(with("-3"));
  EXPECT_TRUE(has_issue(issues, 4, 0, "max-memory")) << test::listed(issues);
}

TEST(ConfigErrors, WrongTypesSayWhatWasExpectedAndWhatWasFound) {
  const auto issues = issues_of(R"([daemon]
threads = "4"
stop-timeout = true
[metrics]
listen = 9464
[[stream]]
name = 7
source = { type = "test", live = "yes", width = 1.5 }
  [stream.flow]
  model = "/m.pth"
  iters-s8 = "8"
  [[stream.sink]]
  type = "display"
  max-flow = "20"
)");
  EXPECT_TRUE(has_issue(issues, 2, 11, "threads: expected an integer 0..1024, got a string (\"4\")"));
  EXPECT_TRUE(has_issue(issues, 3, 16, "stop-timeout: expected a number > 0 and <= 86400, got true"));
  EXPECT_TRUE(has_issue(issues, 5, 10, "listen: expected a string, got 9464"));
  EXPECT_TRUE(has_issue(issues, 7, 8, "name: expected a string, got 7"));
  EXPECT_TRUE(has_issue(issues, 8, 34, "live: expected true or false, got a string (\"yes\")"));
  EXPECT_TRUE(has_issue(issues, 8, 49, "width: expected an integer 1..16384, got 1.5"));
  EXPECT_TRUE(has_issue(issues, 11, 14, "iters-s8: expected an integer 0..64, got a string (\"8\")"));
  EXPECT_TRUE(has_issue(issues, 14, 14, "max-flow: expected a number 0..1000000, got a string (\"20\")"));
  EXPECT_EQ(issues.size(), 8u) << test::listed(issues);
}

TEST(ConfigErrors, TablesWrittenAsTheWrongKind) {
  const auto issues = issues_of(R"([stream]
name = "s"
)");
  EXPECT_TRUE(has_issue(issues, 1, 1, "stream: expected an array of tables (each one written [[...]]"));

  const auto inner = issues_of(R"([[stream]]
name = "s"
source = "test"
flow = { model = "/m" }
  [stream.sink]
  type = "display"
)");
  EXPECT_TRUE(has_issue(inner, 3, 10, "source: expected a table, got a string (\"test\")"));
  EXPECT_TRUE(has_issue(inner, 5, 3, "sink: expected an array of tables"));
}

TEST(ConfigErrors, ValuesOutOfRange) {
  const auto issues = issues_of(R"([daemon]
restart-delay-min = 10
restart-delay-max = 5
stall-timeout = 0
[metrics]
listen = "127.0.0.1:70000"
[[stream]]
name = "s"
source = { type = "test", width = 0, frames = 0 }
  [stream.flow]
  model = "/m.pth"
  iters-s16 = 33
  iters-s8 = -1
  model-width = 100
  model-height = 352
  threads = 5000
  [[stream.sink]]
  type = "shm"
  shm-name = "/a"
  slots = 0
  [[stream.sink]]
  type = "video"
  udp = "10.0.0.1:0"
  bitrate = 0
  max-flow = -1
  [[stream.sink]]
  type = "files"
  directory = "/out"
  max-files = -3
)");
  EXPECT_TRUE(has_issue(issues, 3, 21, "expected restart-delay-min (10 s) <= restart-delay-max (5 s)"));
  EXPECT_TRUE(has_issue(issues, 4, 17, "stall-timeout: expected a number > 0 and <= 86400, got 0"));
  EXPECT_TRUE(has_issue(issues, 6, 10, "listen: expected \"host:port\""));
  EXPECT_TRUE(has_issue(issues, 6, 10, "with a port 1..65535, got \"127.0.0.1:70000\""));
  EXPECT_TRUE(has_issue(issues, 9, 35, "width: expected an integer 1..16384, got 0"));
  EXPECT_TRUE(has_issue(issues, 9, 47, "frames: expected an integer 1..2147483647, got 0"));
  EXPECT_TRUE(has_issue(issues, 12, 15, "iters-s16: expected an integer 0..32, got 33"));
  EXPECT_TRUE(has_issue(issues, 13, 14, "iters-s8: expected an integer 0..64, got -1"));
  EXPECT_TRUE(has_issue(issues, 14, 17,
                        "model-width: expected a multiple of 16, at least 32 (or 0 for the "
                        "frames' own size), got 100"));
  EXPECT_TRUE(has_issue(issues, 16, 13, "threads: expected an integer 0..1024, got 5000"));
  EXPECT_TRUE(has_issue(issues, 20, 11, "slots: expected an integer 1..64, got 0"));
  EXPECT_TRUE(has_issue(issues, 23, 9, "udp: expected \"host:port\""));
  EXPECT_TRUE(has_issue(issues, 24, 13, "bitrate: expected an integer 1..2048000, got 0"));
  EXPECT_TRUE(has_issue(issues, 25, 14, "max-flow: expected a number 0..1000000, got -1"));
  EXPECT_TRUE(has_issue(issues, 29, 15, "max-files: expected an integer >= 0, got -3"));
  EXPECT_EQ(issues.size(), 14u) << test::listed(issues);
}

TEST(ConfigErrors, ModelSizeNeedsBothSidesOrNeither) {
  const auto one = issues_of(R"([[stream]]
name = "s"
source = { type = "test" }
sink = [ { type = "display" } ]
  [stream.flow]
  model = "/m.pth"
  model-width = 320
)");
  EXPECT_TRUE(has_issue(one, 7, 17, "model-width and model-height go together: add model-height"));
  const auto zero = issues_of(R"([[stream]]
name = "s"
source = { type = "test" }
sink = [ { type = "display" } ]
  [stream.flow]
  model = "/m.pth"
  model-width = 320
  model-height = 0
)");
  EXPECT_TRUE(has_issue(zero, 8, 18, "both 0 (the frames' own size) or both set"));
  EXPECT_TRUE(has_issue(issues_of(R"([[stream]]
name = "s"
source = { type = "test" }
sink = [ { type = "display" } ]
flow = { model = "/m.pth", model-width = 320, model-height = 24 }
)"),
                        5, 62, "model-height: expected a multiple of 16, at least 32"));
}

TEST(ConfigErrors, MissingRequiredKeysPointAtTheTableThatLacksThem) {
  const auto issues = issues_of(R"([[stream]]
  [stream.source]
  device = "/dev/video0"
  [stream.flow]
  iters-s8 = 4
  [[stream.sink]]
  type = "shm"
  [[stream.sink]]
  type = "files"
  [[stream.sink]]
  name = "x"
  [[stream.sink]]
  type = "video"
[[stream]]
name = "b"
)");
  EXPECT_TRUE(has_issue(issues, 1, 1, "missing 'name' in [[stream]]: expected a string"));
  EXPECT_TRUE(has_issue(issues, 2, 3,
                        "missing 'type' in [stream.source]: expected one of \"v4l2\", \"libcamera\", "
                        "\"uri\" or \"test\""));
  EXPECT_TRUE(has_issue(issues, 4, 3, "missing 'model' in [stream.flow]: expected a string"));
  EXPECT_TRUE(has_issue(issues, 6, 3, "missing 'shm-name' in [[stream.sink]]"));
  EXPECT_TRUE(has_issue(issues, 8, 3, "missing 'directory' in [[stream.sink]]"));
  EXPECT_TRUE(has_issue(issues, 10, 3,
                        "missing 'type' in [[stream.sink]]: expected one of \"files\", \"shm\", "
                        "\"video\" or \"display\""));
  EXPECT_TRUE(has_issue(issues, 12, 3,
                        "missing the video sink's target in [[stream.sink]]: expected exactly one "
                        "of file"));
  EXPECT_TRUE(has_issue(issues, 14, 1, "missing 'source' in [[stream]]: expected a [stream.source] table"));
  EXPECT_TRUE(has_issue(issues, 14, 1, "missing 'flow' in [[stream]]: expected a [stream.flow] table"));
  EXPECT_TRUE(has_issue(issues, 14, 1, "missing 'sink' in [[stream]]: expected at least one [[stream.sink]] table"));
  EXPECT_EQ(issues.size(), 10u) << test::listed(issues);

  const auto no_stream = issues_of("[daemon]\nthreads = 2\n");
  ASSERT_EQ(no_stream.size(), 1u);
  EXPECT_NE(
      no_stream[0].message.find("missing 'stream' in the file's top level: expected at least one [[stream]] table"),
      std::string::npos)
      << no_stream[0].message;
  EXPECT_TRUE(has_issue(issues_of("stream = []\n"), 1, 10, "stream: expected at least one [[stream]] table"));
  EXPECT_TRUE(has_issue(issues_of(R"([[stream]]
name = "s"
source = { type = "test" }
flow = { model = "/m" }
sink = []
)"),
                        5, 8, "sink: expected at least one [[stream.sink]] table of type \"files\""));
  EXPECT_TRUE(has_issue(issues_of(R"([[stream]]
name = "s"
flow = { model = "/m" }
sink = [ { type = "display" } ]
source = { type = "uri" }
)"),
                        5, 10, "missing 'uri' or 'path' in [stream.source] of type \"uri\""));
}

TEST(ConfigErrors, ValuesOutsideTheirChoices) {
  const auto issues = issues_of(R"([daemon]
log-level = "verbose"
[[stream]]
name = "s"
  [stream.source]
  type = "v4l2"
  format = "yuyv"
  [stream.flow]
  model = "/m.pth"
  behaviour = "fast"
  channel-order = "RGB"
  [[stream.sink]]
  type = "files"
  directory = "/o"
  format = "tiff"
  [[stream.sink]]
  type = "window"
[[stream]]
name = "t"
source = { type = "camera" }
flow = { model = "/m.pth" }
sink = [ { type = "display" } ]
[[stream]]
name = "u"
source = { type = "test", pattern = "bouncing-ball" }
flow = { model = "/m.pth" }
sink = [ { type = "display" } ]
)");
  EXPECT_TRUE(has_issue(issues, 2, 13,
                        "log-level: expected one of \"error\", \"warning\", \"notice\", \"info\" or "
                        "\"debug\", got a string (\"verbose\")"));
  EXPECT_TRUE(has_issue(issues, 7, 12, "format: expected one of \"raw\" or \"mjpeg\", got a string (\"yuyv\")"));
  EXPECT_TRUE(has_issue(issues, 10, 15, "behaviour: expected one of \"auto\", \"live\" or \"every-pair\""));
  EXPECT_TRUE(has_issue(issues, 11, 19, "channel-order: expected one of \"rgb\" or \"bgr\", got a string (\"RGB\")"));
  EXPECT_TRUE(has_issue(issues, 15, 12, "format: expected one of \"flo\", \"npy\" or \"png\""));
  EXPECT_TRUE(has_issue(issues, 17, 10,
                        "type: expected one of \"files\", \"shm\", \"video\" or \"display\", got a "
                        "string (\"window\")"));
  EXPECT_TRUE(has_issue(issues, 20, 19, "type: expected one of \"v4l2\", \"libcamera\", \"uri\" or \"test\""));
  EXPECT_TRUE(has_issue(issues, 25, 37, "pattern: expected one of \"smpte\""));
  EXPECT_TRUE(has_issue(issues, 25, 37, "\"ball\""));
  EXPECT_EQ(issues.size(), 8u) << test::listed(issues);
}

TEST(ConfigErrors, StreamNamesAreUniqueAndPlain) {
  const std::string body =
      "source = { type = \"test\" }\nflow = { model = \"/m\" }\nsink = [ { type = \"display\" } ]\n";
  const auto issues = issues_of("[[stream]]\nname = \"front\"\n" + body + "[[stream]]\nname = \"front\"\n" + body +
                                "[[stream]]\nname = \"front door\"\n" + body + "[[stream]]\nname = \"\"\n" + body);
  EXPECT_TRUE(has_issue(issues, 7, 8, "stream \"front\" is already defined at line 2; stream names must be unique"));
  EXPECT_TRUE(has_issue(issues, 12, 8,
                        "name: expected only the characters A-Z a-z 0-9 _ - (at most 64), got "
                        "\"front door\""));
  EXPECT_TRUE(has_issue(issues, 17, 8, "name: expected 1 to 64 characters from A-Z a-z 0-9 _ -, got \"\""));
  EXPECT_EQ(issues.size(), 3u) << test::listed(issues);
}

TEST(ConfigErrors, SinkNamesAreUniqueInAStream) {
  const auto issues = issues_of(R"([[stream]]
name = "s"
source = { type = "test" }
flow = { model = "/m" }
  [[stream.sink]]
  type = "display"
  name = "view"
  [[stream.sink]]
  type = "display"
  name = "view"
  [[stream.sink]]
  type = "display"
  name = "bad name"
)");
  EXPECT_TRUE(has_issue(issues, 10, 10, "sink \"view\" is already defined in this stream at line 5"));
  EXPECT_TRUE(has_issue(issues, 13, 10, "name: expected only the characters A-Z a-z 0-9 _ -"));
  EXPECT_EQ(issues.size(), 2u) << test::listed(issues);
}

TEST(ConfigErrors, SharedMemoryNamesMountsAndOutputsAreUniqueAcrossStreams) {
  const auto issues = issues_of(R"([rtsp]
[[stream]]
name = "a"
source = { type = "test" }
flow = { model = "/m" }
  [[stream.sink]]
  type = "shm"
  shm-name = "/ring"
  [[stream.sink]]
  type = "video"
  rtsp = "/live"
  [[stream.sink]]
  type = "files"
  directory = "/out/flow"
[[stream]]
name = "b"
source = { type = "test" }
flow = { model = "/m" }
  [[stream.sink]]
  type = "shm"
  shm-name = "/ring"
  [[stream.sink]]
  type = "video"
  rtsp = "/live"
  [[stream.sink]]
  type = "files"
  directory = "/out/x/../flow"
  [[stream.sink]]
  type = "video"
  file = "/v/a.mp4"
  [[stream.sink]]
  type = "video"
  file = "/v/./a.mp4"
)");
  EXPECT_TRUE(has_issue(issues, 21, 14,
                        "shared-memory name \"/ring\" is already used by the shm sink 'shm-0' of "
                        "stream 'a' (line 8)"));
  EXPECT_TRUE(has_issue(issues, 24, 10,
                        "RTSP mount \"/live\" is already used by the video sink 'video-1' of stream "
                        "'a' (line 11)"));
  EXPECT_TRUE(has_issue(issues, 27, 15, "output directory \"/out/flow\" is already used by the files sink"));
  EXPECT_TRUE(has_issue(issues, 33, 10,
                        "video file \"/v/a.mp4\" is already used by the video sink 'video-3' of "
                        "stream 'b' (line 30)"));
  EXPECT_EQ(issues.size(), 4u) << test::listed(issues);
}

TEST(ConfigErrors, NamesAndAddressesInTheirFormats) {
  const auto issues = issues_of(R"([rtsp]
listen = "8554"
[[stream]]
name = "s"
source = { type = "uri", uri = "not a uri" }
flow = { model = "" }
  [[stream.sink]]
  type = "shm"
  shm-name = "neuflow"
  [[stream.sink]]
  type = "video"
  rtsp = "live"
  [[stream.sink]]
  type = "video"
  udp = "::1:5000"
)");
  EXPECT_TRUE(has_issue(issues, 2, 10,
                        "listen: expected \"host:port\" (e.g. \"127.0.0.1:9464\", \"[::1]:9464\"); "
                        "the port is missing, got \"8554\""));
  EXPECT_TRUE(has_issue(issues, 5, 32, "uri: expected an absolute URI like \"rtsp://camera/stream\""));
  EXPECT_TRUE(has_issue(issues, 6, 18,
                        "model: expected the path of a NeuFlow-V2 checkpoint (.pth), got an empty "
                        "string"));
  EXPECT_TRUE(has_issue(issues, 9, 14, "shm-name: expected a name like \"/neuflow-front\""));
  EXPECT_TRUE(has_issue(issues, 12, 10, "rtsp: expected a mount point like \"/front\""));
  EXPECT_TRUE(has_issue(issues, 15, 9, "write IPv6 addresses in brackets"));
  EXPECT_EQ(issues.size(), 6u) << test::listed(issues);
}

TEST(ConfigErrors, RtspSinkNeedsTheRtspTable) {
  const auto issues = issues_of(R"([[stream]]
name = "s"
source = { type = "test" }
flow = { model = "/m" }
sink = [ { type = "video", rtsp = "/s" } ]
)");
  ASSERT_EQ(issues.size(), 1u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 5, 35, "rtsp: a video sink on an RTSP mount needs the server: add an [rtsp] table"));
  EXPECT_TRUE(issues_of("[rtsp]\n" + std::string(R"([[stream]]
name = "s"
source = { type = "test" }
flow = { model = "/m" }
sink = [ { type = "video", rtsp = "/s" } ]
)"))
                  .empty());
}

TEST(ConfigErrors, RtspServerAndMetricsCannotShareAPort) {
  const auto issues =
      issues_of("[metrics]\nlisten = \"127.0.0.1:8554\"\n[rtsp]\nlisten = \"0.0.0.0:8554\"\n" + kMinimalStream);
  EXPECT_TRUE(has_issue(issues, 4, 10, "cannot both listen on port 8554"));
  EXPECT_TRUE(
      issues_of("[metrics]\nlisten = \"127.0.0.1:8554\"\n[rtsp]\nlisten = \"127.0.0.2:8554\"\n" + kMinimalStream)
          .empty());
}

TEST(ConfigErrors, VideoSinkTargets) {
  const auto issues = issues_of(R"([rtsp]
[[stream]]
name = "s"
source = { type = "test" }
flow = { model = "/m" }
  [[stream.sink]]
  type = "video"
  file = "/v/out.avi"
  [[stream.sink]]
  type = "video"
  file = "/v/out-%s.mp4"
  [[stream.sink]]
  type = "video"
  file = "/v/%d-%05d.mkv"
  [[stream.sink]]
  type = "video"
  file = "/v/a.mp4"
  rtsp = "/a"
  [[stream.sink]]
  type = "video"
  udp = "127.0.0.1:5000"
  segment-seconds = 60
  [[stream.sink]]
  type = "video"
  file = "/v/100%%-%03d.mp4"
  segment-seconds = 60
  [[stream.sink]]
  type = "video"
  file = "/v/v-%99999d.mp4"
  [[stream.sink]]
  type = "video"
  file = "/v/w-%010d.mp4"
)");
  EXPECT_TRUE(has_issue(issues, 8, 10, "file: expected a file name ending in .mp4 or .mkv, got \"/v/out.avi\""));
  EXPECT_TRUE(has_issue(issues, 11, 10,
                        "file: expected at most one number conversion like %05d (write %% for a "
                        "literal %)"));
  EXPECT_TRUE(has_issue(issues, 14, 10, "found 2"));
  EXPECT_TRUE(has_issue(issues, 18, 10, "rtsp: give exactly one of file, rtsp, udp; file is already set"));
  EXPECT_TRUE(has_issue(issues, 22, 21, "segment-seconds: applies only to a video sink with file = \"...\""));
  // A width past an index's digits would make names no file system takes.
  EXPECT_TRUE(
      has_issue(issues, 29, 10, "file: expected a number conversion at most 10 digits wide like %05d, found %99999d"));
  EXPECT_EQ(issues.size(), 6u) << test::listed(issues);
}

TEST(ConfigErrors, UriSourceTakesUriOrPathNotBoth) {
  const auto issues = issues_of(R"([[stream]]
name = "s"
source = { type = "uri", uri = "file:///a.mp4", path = "a.mp4" }
flow = { model = "/m" }
sink = [ { type = "display" } ]
[[stream]]
name = "t"
source = { type = "uri", uri = "file:relative.mp4" }
flow = { model = "/m" }
sink = [ { type = "display" } ]
)");
  EXPECT_TRUE(has_issue(issues, 3, 56, "path: give either uri or path, not both"));
  EXPECT_TRUE(has_issue(issues, 8, 32, "uri: expected a file URI with an absolute path"));
  EXPECT_EQ(issues.size(), 2u) << test::listed(issues);
}

TEST(ConfigErrors, EveryProblemIsReportedInFileOrder) {
  const auto issues = issues_of(R"([daemon]
threads = -1
colour = "red"
[[stream]]
name = "a b"
source = { type = "test", pattern = "plaid" }
flow = { iters-s8 = 99 }
sink = [ { type = "shm", shm-name = "x", slots = 100 } ]
)");
  ASSERT_EQ(issues.size(), 8u) << test::listed(issues);
  for (std::size_t i = 1; i < issues.size(); ++i) {
    EXPECT_LE(std::pair(issues[i - 1].line, issues[i - 1].column), std::pair(issues[i].line, issues[i].column));
  }
  EXPECT_EQ(issues[0].line, 2);
  EXPECT_EQ(issues[1].line, 3);
  EXPECT_EQ(issues[2].line, 5);
  EXPECT_EQ(issues[3].line, 6);
  EXPECT_TRUE(has_issue(issues, 7, 8, "missing 'model' in [stream.flow]"));
  EXPECT_TRUE(has_issue(issues, 7, 21, "iters-s8: expected an integer 0..64, got 99"));
  EXPECT_TRUE(has_issue(issues, 8, 37, "shm-name"));
  EXPECT_TRUE(has_issue(issues, 8, 50, "slots"));

  // And the exception's text holds every one of them, one a line.
  try {
    parse_config("[daemon]\nthreads = -1\ncolour = 1\n" + kMinimalStream, "x.toml", ConfigChecks::file_only);
    FAIL() << "accepted";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()),
              "x.toml:2:11: threads: expected an integer 0..1024, got -1\n"
              "x.toml:3:1: unknown key 'colour' in [daemon]; valid keys: log-level, threads, restart-delay-min, "
              "restart-delay-max, stop-timeout, stall-timeout");
  }
}

TEST(ConfigFile, LoadConfigReadsTheFileAndNamesItInIssues) {
  test::TempFolder folder;
  const fs::path file = folder / "neuflowd.toml";
  std::ofstream(file) << "[daemon]\nthreads = \"x\"\n" << kMinimalStream;
  try {
    load_config(file, ConfigChecks::file_only);
    FAIL() << "accepted";
  } catch (const ConfigError& error) {
    ASSERT_EQ(error.issues().size(), 1u);
    EXPECT_EQ(error.issues()[0].file, file);
    EXPECT_EQ(error.issues()[0].line, 2);
  }
  std::ofstream(file) << kMinimalStream;
  EXPECT_EQ(load_config(file, ConfigChecks::file_only).file, file);

  for (const fs::path& bad : {folder / "missing.toml", folder.path()}) {
    try {
      load_config(bad, ConfigChecks::file_only);
      FAIL() << "accepted " << bad;
    } catch (const ConfigError& error) {
      ASSERT_EQ(error.issues().size(), 1u);
      EXPECT_EQ(error.issues()[0].line, 0);
      EXPECT_NE(error.issues()[0].to_string().find(bad.string() + ": "), std::string::npos) << error.what();
    }
  }
}

TEST(ConfigFile, MachineChecksNeedGstreamerInitialized) {
  // This test program never calls gst_init(): checking against the machine is refused, as the
  // element lookups would fail for every element.
  EXPECT_THROW(parse_config(kMinimalStream, kConfigFile, ConfigChecks::all), std::logic_error);
  EXPECT_NO_THROW(parse_config(kMinimalStream, kConfigFile, ConfigChecks::file_only));
}

// ---- the shipped examples ------------------------------------------------------------------

TEST(ConfigExamples, EveryShippedExampleIsValid) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(NEUFLOW_CONFIG_DIR)) {
    if (entry.path().extension() != ".toml") continue;
    ++count;
    try {
      const Config c = load_config(entry.path(), ConfigChecks::file_only);
      EXPECT_FALSE(c.streams.empty()) << entry.path();
    } catch (const ConfigError& error) {
      ADD_FAILURE() << error.what();
    }
  }
  EXPECT_EQ(count, 4);
}

TEST(ConfigExamples, QuickStartDemoWritesIntoTheRepository) {
  const fs::path dir = NEUFLOW_CONFIG_DIR;
  const Config c = load_config(dir / "test-pattern-to-mp4.toml", ConfigChecks::file_only);
  ASSERT_EQ(c.streams.size(), 1u);
  const StreamConfig& s = c.streams[0];
  const fs::path repository = fs::weakly_canonical(dir / "..");
  EXPECT_EQ(s.flow.stage.model, repository / "models/neuflow_mixed.pth");
  const auto& source = std::get<TestSource>(s.source.settings);
  EXPECT_GT(source.frames, 0);
  EXPECT_LE(source.mode.width * source.mode.height, 640 * 480);
  ASSERT_EQ(s.sinks.size(), 2u);
  EXPECT_EQ(std::get<VideoSink>(s.sinks[0].settings).file.parent_path(), repository / "out/demo");
  EXPECT_EQ(std::get<FilesSink>(s.sinks[1].settings).directory, repository / "out/demo/flow");
}

}  // namespace
}  // namespace neuflow::daemon

namespace neuflow::daemon {
namespace {

// The config accepts exactly the shared-memory names and modes neuflowshmsink accepts (one rule,
// in neuflow/flow_ring.hpp), so a config that passes never fails at the element's start.
TEST(ConfigValues, ShmNameAndModeFollowTheRingsOwnRules) {
  const auto shm_sink = [](const std::string& name) {
    return "[[stream]]\nname = \"s\"\nsource = { type = \"test\" }\nflow = { model = \"/m.pth\" }\n"
           "sink = [ { type = \"shm\", shm-name = \"" +
           name + "\" } ]\n";
  };
  for (const std::string& good : {"/" + std::string(ring::kMaxSegmentNameLength, 'a'), std::string("/cam@front+2")}) {
    EXPECT_TRUE(ring::segment_name_problem(good).empty()) << good;
    EXPECT_EQ(std::get<ShmSink>(parse(shm_sink(good)).streams[0].sinks[0].settings).name, good);
  }
  for (const std::string& bad : {"/" + std::string(ring::kMaxSegmentNameLength + 1, 'a'), std::string("/a/b"),
                                 std::string("/.."), std::string("noslash")}) {
    EXPECT_FALSE(ring::segment_name_problem(bad).empty()) << bad;
    EXPECT_TRUE(has_issue(issues_of(shm_sink(bad)), 5, 0, "shm-name: expected a name like \"/neuflow-front\" ("))
        << bad;
  }
  for (unsigned mode = 0; mode <= 07777; ++mode) {
    EXPECT_EQ(check_shm_mode(mode).empty(), ring::segment_mode_problem(mode).empty()) << mode;
  }
}

}  // namespace
}  // namespace neuflow::daemon
