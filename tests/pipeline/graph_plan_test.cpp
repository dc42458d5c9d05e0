// The graph plan: one description gives the elements to check for, the chains to build, the
// RTSP server's media and the sinks' kinds.
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>

#include "neuflow/pipeline/element_chain.hpp"
#include "neuflow/pipeline/graph_plan.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::pipeline {
namespace {

bool contains(const std::vector<std::string>& list, const std::string& item) {
  return std::find(list.begin(), list.end(), item) != list.end();
}

VideoSink video_to(VideoSink::Target target) {
  VideoSink v;
  v.target = target;
  v.file = "/tmp/out/viz.mkv";
  v.rtsp_mount = "/front";
  v.udp_host = "127.0.0.1";
  v.udp_port = 5000;
  v.bitrate_kbps = 1500;
  return v;
}

TEST(GraphPlan, RequiredElementsFollowWhatIsBuilt) {
  EXPECT_EQ(required_elements(SourceDescription{V4l2Source{}}), (std::vector<std::string>{"v4l2src", "capsfilter"}));
  V4l2Source mjpeg;
  mjpeg.mjpeg = true;
  EXPECT_TRUE(contains(required_elements(SourceDescription{mjpeg}), "jpegdec"));
  EXPECT_EQ(required_elements(SourceDescription{UriSource{"file:///a.mp4"}}),
            (std::vector<std::string>{"uridecodebin"}));
  EXPECT_TRUE(contains(required_elements(SourceDescription{LibcameraSource{}}), "libcamerasrc"));
  EXPECT_EQ(required_elements(FlowStage{}), (std::vector<std::string>{"videoconvert", "neuflow"}));

  EXPECT_TRUE(contains(required_elements(SinkDescription{FilesSink{}}), "neuflowsink"));
  EXPECT_TRUE(contains(required_elements(SinkDescription{ShmSink{}}), "neuflowshmsink"));
  const auto file = required_elements(SinkDescription{video_to(VideoSink::Target::file)});
  for (const char* e : {"neuflowviz", "x264enc", "h264parse", "splitmuxsink", "matroskamux", "filesink"}) {
    EXPECT_TRUE(contains(file, e)) << e;
  }
  // An RTSP sink needs the server's side too: it encodes and packetizes what the channel carries.
  const auto rtsp = required_elements(SinkDescription{video_to(VideoSink::Target::rtsp)});
  for (const char* e : {"intervideosink", "intervideosrc", "x264enc", "rtph264pay"})
    EXPECT_TRUE(contains(rtsp, e)) << e;
  const auto udp = required_elements(SinkDescription{video_to(VideoSink::Target::udp)});
  for (const char* e : {"x264enc", "rtph264pay", "udpsink"}) EXPECT_TRUE(contains(udp, e)) << e;
}

// The window sink follows the environment, never a probe (autovideosink's in-process probing
// crashed the daemon without a display); without a display the sink cannot be built, and says why.
TEST(GraphPlan, ADisplaySinkTakesTheWindowSinkOfTheSessionItRunsIn) {
  const NamedSink display{"screen", DisplaySink{}};
  const auto plan_with = [&](DisplayServer server) {
    PlanContext context;
    context.display_server = [server] { return server; };
    return plan_sink("g", display, context);
  };
  EXPECT_EQ(plan_with(DisplayServer::wayland).chain.back().factory, "waylandsink");
  EXPECT_EQ(plan_with(DisplayServer::x11).chain.back().factory, "ximagesink");
  EXPECT_EQ(plan_with(DisplayServer::x11).chain.back().name, "screen-display");
  try {
    plan_with(DisplayServer::none);
    FAIL() << "a display sink without a display was planned";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("neither WAYLAND_DISPLAY nor DISPLAY is set"), std::string::npos) << e.what();
  }
  for (const auto& element : plan_with(DisplayServer::x11).chain) EXPECT_NE(element.factory, "autovideosink");
}

// A live branch's sink never waits for the clock: flows leave the network later than their
// frames' times, and a synchronised sink drops the late ones with a warning ("A lot of buffers
// are being dropped", seven times in 15 s with an RTSP client).
TEST(GraphPlan, LiveVideoSinksDoNotSynchroniseToTheClock) {
  PlanContext context;
  context.display_server = [] { return DisplayServer::x11; };
  const auto last_sync = [&](const SinkDescription& sink) {
    const SinkPlan plan = plan_sink("g", {"out", sink}, context);
    for (const auto& [property, value] : plan.chain.back().properties) {
      if (property == "sync") return value;
    }
    return std::string("(unset: true)");
  };
  EXPECT_EQ(last_sync(video_to(VideoSink::Target::rtsp)), "false");
  EXPECT_EQ(last_sync(video_to(VideoSink::Target::udp)), "false");
  EXPECT_EQ(last_sync(DisplaySink{}), "false");
}

TEST(GraphPlan, TheDisplayServerComesFromTheEnvironment) {
  const auto saved = [](const char* name) {
    const char* v = std::getenv(name);
    return v ? std::optional<std::string>(v) : std::nullopt;
  };
  const auto wayland = saved("WAYLAND_DISPLAY"), x11 = saved("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  unsetenv("DISPLAY");
  EXPECT_EQ(display_server_from_environment(), DisplayServer::none);
  EXPECT_TRUE(required_elements(SinkDescription{DisplaySink{}}).empty()) << "cut off at start: needs nothing";
  setenv("DISPLAY", ":0", 1);
  EXPECT_EQ(display_server_from_environment(), DisplayServer::x11);
  EXPECT_TRUE(contains(required_elements(SinkDescription{DisplaySink{}}), "ximagesink"));
  setenv("WAYLAND_DISPLAY", "wayland-0", 1);
  EXPECT_EQ(display_server_from_environment(), DisplayServer::wayland);
  unsetenv("WAYLAND_DISPLAY");
  unsetenv("DISPLAY");
  if (wayland) setenv("WAYLAND_DISPLAY", wayland->c_str(), 1);
  if (x11) setenv("DISPLAY", x11->c_str(), 1);
}

TEST(GraphPlan, SinkKindsNameEachOutput) {
  EXPECT_EQ(sink_kind(FilesSink{}), "files");
  EXPECT_EQ(sink_kind(ShmSink{}), "shm");
  EXPECT_EQ(sink_kind(DisplaySink{}), "display");
  EXPECT_EQ(sink_kind(video_to(VideoSink::Target::file)), "video-file");
  EXPECT_EQ(sink_kind(video_to(VideoSink::Target::rtsp)), "rtsp");
  EXPECT_EQ(sink_kind(video_to(VideoSink::Target::udp)), "udp");
}

TEST(GraphPlan, SinkElementsAreNamedAfterTheSinkAndFilesContinueEarlierRuns) {
  PlanContext context;
  context.first_free_index = [](const std::string& pattern) { return pattern.ends_with(".flo") ? 42 : 0; };
  FilesSink files;
  files.directory = "/var/lib/neuflow/front";
  files.max_files = 100;
  const SinkPlan plan = plan_sink("front", {"archive", files}, context);
  EXPECT_EQ(plan.kind, "files");
  ASSERT_EQ(plan.chain.size(), 2u);
  EXPECT_EQ(plan.chain[0].name, "archive-queue");
  const ElementSpec& out = plan.chain[1];
  EXPECT_EQ(out.name, "archive-files");
  const auto value = [&](const std::string& property) {
    for (const auto& [p, v] : out.properties) {
      if (p == property) return v;
    }
    return std::string("(unset)");
  };
  EXPECT_EQ(value("location"), "/var/lib/neuflow/front/flow_%08d.flo");
  EXPECT_EQ(value("index"), "42");
  EXPECT_EQ(value("max-files"), "100");
  EXPECT_EQ(value("max-bytes"), "(unset)");
  EXPECT_EQ(value("async"), "false");
  EXPECT_EQ(plan.folders, (std::vector<std::filesystem::path>{"/var/lib/neuflow/front"}));
}

TEST(GraphPlan, FlowStageCarriesTheSessionSettings) {
  FlowStage flow;
  flow.model = "/m.pth";
  flow.session = {.iterations = {2, 6},
                  .model_width = 640,
                  .model_height = 352,
                  .threads = 3,
                  .network_order = model::ChannelOrder::bgr,
                  .backend = model::Backend::vulkan,
                  .device = 1};
  flow.behaviour = model::Behaviour::live;
  const ElementChain chain = plan_flow(flow);
  ASSERT_EQ(chain.size(), 2u);
  EXPECT_EQ(launch_text({chain[1]}),
            "neuflow name=flow model=\"/m.pth\" iters-s16=2 iters-s8=6 model-width=640 model-height=352 threads=3 "
            "behaviour=live channel-order=bgr backend=vulkan device=1 precision=fp32 max-memory=0 stats-interval=0");
}

TEST(GraphPlan, RtspMediaIsTheChannelEncodedAndPacketized) {
  const std::string channel = rtsp_channel_name("front", "/live");
  EXPECT_EQ(channel, "neuflowd/front/live");
  const std::string line = rtsp_launch_line(channel, 1500);
  EXPECT_EQ(line,
            "( intervideosrc channel=\"neuflowd/front/live\" ! videoconvert ! video/x-raw,format=I420 ! x264enc "
            "tune=zerolatency speed-preset=ultrafast key-int-max=30 option-string=\"scenecut=0\" bitrate=1500 ! "
            "rtph264pay name=pay0 pt=96 config-interval=1 )");
  // GStreamer reads it back as the server will (when the elements are installed here).
  gst_init(nullptr, nullptr);
  for (const char* factory : {"intervideosrc", "x264enc", "rtph264pay"}) {
    GstElementFactory* f = gst_element_factory_find(factory);
    if (!f) GTEST_SKIP() << factory << " is not installed";
    gst_object_unref(f);
  }
  GError* error = nullptr;
  GstElement* parsed = gst_parse_launch(line.substr(2, line.size() - 4).c_str(), &error);
  ASSERT_NE(parsed, nullptr) << (error ? error->message : "");
  EXPECT_EQ(error, nullptr) << error->message;
  GstElement* pay = gst_bin_get_by_name(GST_BIN(parsed), "pay0");
  EXPECT_NE(pay, nullptr);
  if (pay) gst_object_unref(pay);
  gst_object_unref(parsed);
  g_clear_error(&error);
}

TEST(ElementChain, LaunchTextQuotesWhatIsNotAPlainWord) {
  EXPECT_EQ(launch_text({element("filesink").set("location", "/tmp/a b.mp4")}), "filesink location=\"/tmp/a b.mp4\"");
  EXPECT_EQ(launch_text({element("identity").set("silent", "true"), caps_filter("video/x-raw,width=320")}),
            "identity silent=true ! video/x-raw,width=320");
  ElementSpec mux = element("splitmuxsink");
  mux.children = {{"muxer", element("mp4mux")}};
  EXPECT_THROW(launch_text({mux}), std::logic_error);
  EXPECT_EQ(factories_of({element("queue"), mux, element("queue")}),
            (std::vector<std::string>{"queue", "splitmuxsink", "mp4mux"}));
}

TEST(ElementChain, MakeElementNamesWhatIsMissing) {
  gst_init(nullptr, nullptr);
  try {
    make_element(element("no-such-element-factory"));
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'no-such-element-factory' is not installed"), std::string::npos);
  }
  try {
    make_element(element("identity").set("no-such-property", "1"));
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no property 'no-such-property'"), std::string::npos);
  }
  GstElement* queue = make_element(element("queue", "q").set("max-size-buffers", "7"));
  guint buffers = 0;
  g_object_get(queue, "max-size-buffers", &buffers, nullptr);
  EXPECT_EQ(buffers, 7u);
  gst_object_unref(gst_object_ref_sink(queue));
}

TEST(GraphPlan, NextFreeIndexFollowsTheFilesAlreadyThere) {
  test::TempDir dir;
  const std::string pattern = (dir.path() / "flow_%08d.flo").string();
  EXPECT_EQ(next_free_index(pattern), 0);
  for (const char* name : {"flow_00000003.flo", "flow_00000011.flo", "flow_x.flo", "other_00000099.flo"}) {
    std::ofstream(dir.path() / name) << "x";
  }
  EXPECT_EQ(next_free_index(pattern), 12);
}

}  // namespace
}  // namespace neuflow::pipeline
