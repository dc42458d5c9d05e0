// neuflowsink with synthetic NeuflowFlowMeta: numbered files readable by read_flow with the
// same vectors, the CSV index, skipped buffers, and errors that name the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "gst_test_util.hpp"
#include "neuflow/flow/flow_io.hpp"

namespace neuflow::gst_test {
namespace {

namespace fs = std::filesystem;

constexpr int kFrameWidth = 32, kFrameHeight = 24;

using Properties = std::vector<std::pair<const char *, std::string>>;

ElementPtr make_sink(const Properties &properties) {
  ElementPtr sink = owned(gst_element_factory_make("neuflowsink", nullptr));
  if (!sink) return sink;
  for (const auto &[name, value] : properties) gst_util_set_object_arg(G_OBJECT(sink.get()), name, value.c_str());
  return sink;
}

// A started sink (the harness sets it to PLAYING) with an error bus attached.
struct RunningSink {
  ElementPtr element;
  BusPtr bus;
  HarnessPtr harness;
};

RunningSink start_sink(const Properties &properties) {
  RunningSink s;
  s.element = make_sink(properties);
  if (!s.element) return s;
  s.bus.reset(gst_bus_new());
  gst_element_set_bus(s.element.get(), s.bus.get());
  s.harness.reset(gst_harness_new_with_element(s.element.get(), "sink", nullptr));
  gst_harness_set_src_caps_str(s.harness.get(), caps_string(GST_VIDEO_FORMAT_RGBA, kFrameWidth, kFrameHeight).c_str());
  return s;
}

struct FlowSpec {
  int width, height;
  guint64 from_frame, to_frame;
  GstClockTime from_pts, to_pts;
  float offset;  // makes each flow's vectors distinct
};

std::vector<float> vectors_of(const FlowSpec &f) {
  return make_vectors(f.width, f.height, [&](int x, int y) {
    // Multiples of 1/64, so the KITTI PNG quantization keeps them exact.
    return std::pair{f.offset + static_cast<float>(x) / 4.f, -static_cast<float>(y) / 8.f - f.offset};
  });
}

GstBuffer *buffer_with_flow(const FlowSpec &f) {
  GstBuffer *buffer = gst_buffer_new();
  GST_BUFFER_PTS(buffer) = f.to_pts;
  NeuflowFlowMeta *meta = add_flow(buffer, f.width, f.height, vectors_of(f), kFrameWidth, kFrameHeight);
  meta->from_frame = f.from_frame;
  meta->to_frame = f.to_frame;
  meta->from_pts = f.from_pts;
  meta->to_pts = f.to_pts;
  return buffer;
}

std::vector<std::string> read_lines(const fs::path &path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

void expect_flow_file(const fs::path &path, const FlowSpec &f) {
  ASSERT_TRUE(fs::exists(path)) << path;
  const flow::FlowField field = flow::read_flow(path);
  ASSERT_EQ(field.width, f.width);
  ASSERT_EQ(field.height, f.height);
  EXPECT_EQ(field.uv, vectors_of(f)) << path;
}

guint64 uint64_property(GstElement *element, const char *name) {
  guint64 value = 0;
  g_object_get(element, name, &value, nullptr);
  return value;
}

TEST(NeuflowSink, PropertiesHaveTheirDocumentedDefaults) {
  ElementPtr sink = make_sink({});
  ASSERT_TRUE(sink) << "neuflowsink not found: is GST_PLUGIN_PATH the build directory?";
  gchar *location = nullptr, *index_location = nullptr;
  gint index = -1;
  gboolean sync = TRUE;
  g_object_get(sink.get(), "location", &location, "index-location", &index_location, "index", &index, "sync", &sync,
               nullptr);
  EXPECT_STREQ(location, "flow_%05d.flo");
  EXPECT_EQ(index_location, nullptr);
  EXPECT_EQ(index, 0);
  EXPECT_FALSE(sync) << "a file writer should not wait for the clock";
  g_free(location);
  g_free(index_location);
}

// The warnings the sink posted on its bus, their texts.
std::vector<std::string> warnings(GstBus *bus) {
  std::vector<std::string> texts;
  while (GstMessage *m = gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING)) {
    GError *error = nullptr;
    gst_message_parse_warning(m, &error, nullptr);
    texts.emplace_back(error ? error->message : "");
    if (error) g_error_free(error);
    gst_message_unref(m);
  }
  return texts;
}

// A pipeline without a neuflow element upstream would otherwise write nothing and say nothing.
TEST(NeuflowSink, WarnsOnceWhenNoBufferCarriesFlow) {
  TempDir dir;
  auto s = start_sink({{"location", (dir / "flow_%03d.flo").string()}});
  ASSERT_TRUE(s.harness);
  for (int i = 0; i < 8; ++i) ASSERT_EQ(gst_harness_push(s.harness.get(), gst_buffer_new()), GST_FLOW_OK);
  const auto texts = warnings(s.bus.get());
  ASSERT_EQ(texts.size(), 1u);
  EXPECT_NE(texts[0].find("Is a neuflow element upstream?"), std::string::npos) << texts[0];
  EXPECT_NE(texts[0].find("! neuflowsink"), std::string::npos) << texts[0];
  EXPECT_EQ(uint64_property(s.element.get(), "buffers-skipped"), 8u);
}

// The first buffer of a stream (and of each flush) has no flow: no warning for that.
TEST(NeuflowSink, AStreamWhoseFirstFrameHasNoFlowIsNotWarnedAbout) {
  TempDir dir;
  auto s = start_sink({{"location", (dir / "flow_%03d.flo").string()}});
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(gst_harness_push(s.harness.get(), gst_buffer_new()), GST_FLOW_OK);
  for (int n = 0; n < 4; ++n)
    ASSERT_EQ(gst_harness_push(s.harness.get(),
                               buffer_with_flow(FlowSpec{8, 6, static_cast<guint64>(n), static_cast<guint64>(n) + 1, 0,
                                                         33333333, 0.5f * n})),
              GST_FLOW_OK);
  for (int i = 0; i < 4; ++i) ASSERT_EQ(gst_harness_push(s.harness.get(), gst_buffer_new()), GST_FLOW_OK);
  EXPECT_TRUE(warnings(s.bus.get()).empty());
}

TEST(NeuflowSink, WritesNumberedFilesWithTheSameVectorsAndAnIndexRowEach) {
  TempDir dir;
  auto s = start_sink({{"location", (dir / "flow_%03d.flo").string()}, {"index", "5"}});
  ASSERT_TRUE(s.harness);
  const FlowSpec first{8, 6, 0, 1, 0, 33333333, 0.5f};
  const FlowSpec second{8, 6, 1, 3, 33333333, 100000000, 1.25f};           // frame 2 was dropped upstream
  const FlowSpec third{4, 3, 3, 4, GST_CLOCK_TIME_NONE, 133333333, -2.f};  // unknown start time

  EXPECT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow(first)), GST_FLOW_OK);
  EXPECT_EQ(gst_harness_push(s.harness.get(), gst_buffer_new()), GST_FLOW_OK);  // no flow: skipped
  EXPECT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow(second)), GST_FLOW_OK);
  EXPECT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow(third)), GST_FLOW_OK);

  expect_flow_file(dir.path() / "flow_005.flo", first);
  expect_flow_file(dir.path() / "flow_006.flo", second);
  expect_flow_file(dir.path() / "flow_007.flo", third);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"flow_005.flo", "flow_006.flo", "flow_007.flo", "index.csv"}));

  EXPECT_EQ(read_lines(dir.path() / "index.csv"),
            (std::vector<std::string>{"index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source",
                                      "5,0,1,0,33333333,flow_005.flo,,", "6,1,3,33333333,100000000,flow_006.flo,,",
                                      "7,3,4,,133333333,flow_007.flo,,"}));

  EXPECT_EQ(uint64_property(s.element.get(), "flows-written"), 3u);
  EXPECT_EQ(uint64_property(s.element.get(), "bytes-written"), fs::file_size(dir.path() / "flow_005.flo") +
                                                                   fs::file_size(dir.path() / "flow_006.flo") +
                                                                   fs::file_size(dir.path() / "flow_007.flo"));
  EXPECT_EQ(uint64_property(s.element.get(), "buffers-skipped"), 1u);
  gint index = 0;
  g_object_get(s.element.get(), "index", &index, nullptr);
  EXPECT_EQ(index, 8);
  EXPECT_FALSE(pop_error(s.bus.get()).found);
}

class NeuflowSinkFormats : public ::testing::TestWithParam<const char *> {};

TEST_P(NeuflowSinkFormats, FormatFollowsTheExtension) {
  TempDir dir;
  const std::string pattern = std::string("f%d.") + GetParam();
  auto s = start_sink({{"location", (dir / pattern).string()}});
  ASSERT_TRUE(s.harness);
  const FlowSpec f{10, 7, 0, 1, 0, 40000000, 3.5f};
  ASSERT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow(f)), GST_FLOW_OK);
  const fs::path written = dir.path() / (std::string("f0.") + GetParam());
  expect_flow_file(written, f);
  const auto format = flow::flow_format_from_path(written);
  ASSERT_TRUE(format);
  // read_flow dispatches on the extension too: check the bytes are really that format.
  std::ifstream in(written, std::ios::binary);
  char magic[8] = {};
  in.read(magic, sizeof magic);
  switch (*format) {
    case flow::FlowFormat::flo: EXPECT_EQ(std::string(magic, 4), "PIEH"); break;
    case flow::FlowFormat::npy: EXPECT_EQ(std::string(magic + 1, 5), "NUMPY"); break;
    case flow::FlowFormat::kitti_png: EXPECT_EQ(std::string(magic + 1, 3), "PNG"); break;
  }
}

INSTANTIATE_TEST_SUITE_P(AllFormats, NeuflowSinkFormats, ::testing::Values("flo", "npy", "png"));

TEST(NeuflowSink, IndexIsAppendedAcrossRestartsWithOneHeader) {
  TempDir dir;
  {
    auto s = start_sink({{"location", (dir / "flow_%d.flo").string()}});
    ASSERT_TRUE(s.harness);
    ASSERT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 0, 1, 0, 10, 0.f})), GST_FLOW_OK);
    ASSERT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 1, 2, 10, 20, 0.f})), GST_FLOW_OK);
  }
  {
    auto s = start_sink({{"location", (dir / "flow_%d.flo").string()}, {"index", "2"}});
    ASSERT_TRUE(s.harness);
    ASSERT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 0, 1, 30, 40, 0.f})), GST_FLOW_OK);
  }
  EXPECT_EQ(
      read_lines(dir.path() / "index.csv"),
      (std::vector<std::string>{"index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source",
                                "0,0,1,0,10,flow_0.flo,,", "1,1,2,10,20,flow_1.flo,,", "2,0,1,30,40,flow_2.flo,,"}));
}

TEST(NeuflowSink, IndexElsewhereNamesTheFilesAsWritten) {
  TempDir flows, elsewhere;
  const std::string pattern = (flows / "x,y_%02d.npy").string();  // a comma: the CSV field gets quoted
  auto s = start_sink({{"location", pattern}, {"index-location", (elsewhere / "list.csv").string()}});
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 7, 8, 70, 80, 0.f})), GST_FLOW_OK);
  EXPECT_FALSE(fs::exists(flows.path() / "index.csv"));
  EXPECT_EQ(read_lines(elsewhere.path() / "list.csv"),
            (std::vector<std::string>{"index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source",
                                      "0,7,8,70,80,\"" + (flows / "x,y_00.npy").string() + "\",,"}));
}

TEST(NeuflowSink, EmptyIndexLocationWritesNoIndex) {
  TempDir dir;
  auto s = start_sink({{"location", (dir / "flow_%d.flo").string()}, {"index-location", ""}});
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 0, 1, 0, 10, 0.f})), GST_FLOW_OK);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"flow_0.flo"}));
}

// Starting (READY -> PAUSED) fails with one error message, which contains `expected`.
void expect_start_error(const Properties &properties, const std::string &expected) {
  ElementPtr sink = make_sink(properties);
  ASSERT_TRUE(sink);
  BusPtr bus(gst_bus_new());
  gst_element_set_bus(sink.get(), bus.get());
  EXPECT_EQ(gst_element_set_state(sink.get(), GST_STATE_PAUSED), GST_STATE_CHANGE_FAILURE);
  const ErrorMessage error = pop_error(bus.get());
  ASSERT_TRUE(error.found);
  EXPECT_NE(error.message.find(expected), std::string::npos) << "error: " << error.message;
  // Reported once: no generic "state change failed" error from GstBaseSink after ours.
  const ErrorMessage second = pop_error(bus.get());
  EXPECT_FALSE(second.found) << "a second error: " << second.message;
  gst_element_set_state(sink.get(), GST_STATE_NULL);
}

class NeuflowSinkBadPatterns : public ::testing::TestWithParam<const char *> {};

TEST_P(NeuflowSinkBadPatterns, AreRejectedAtStartNamingTheLocation) {
  TempDir dir;
  const std::string location = (dir / GetParam()).string();
  expect_start_error({{"location", location}}, "\"" + location + "\"");
}

INSTANTIATE_TEST_SUITE_P(Patterns, NeuflowSinkBadPatterns,
                         ::testing::Values("flow.flo", "flow_%d_%d.flo", "flow_%s.flo", "flow_%ld.flo", "flow_%n.flo",
                                           "flow_%*d.flo", "flow_%d.txt", "flow_%d", "flow_%"));

TEST(NeuflowSink, AcceptsLiteralPercentAndPrintfFlags) {
  TempDir dir;
  auto s = start_sink({{"location", (dir / "100%%_%04x.flo").string()}, {"index", "255"}});
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 0, 1, 0, 10, 0.f})), GST_FLOW_OK);
  EXPECT_TRUE(fs::exists(dir.path() / "100%_00ff.flo")) << ::testing::PrintToString(dir.entries());
}

TEST(NeuflowSink, MissingDirectoryFailsAtStartNamingTheLocation) {
  TempDir dir;
  const std::string location = (dir / "missing/flow_%05d.flo").string();
  expect_start_error({{"location", location}}, "\"" + location + "\"");
  expect_start_error({{"location", location}}, "does not exist");
  const std::string index = (dir / "missing/index.csv").string();
  expect_start_error({{"location", (dir / "flow_%05d.flo").string()}, {"index-location", index}}, "\"" + index + "\"");
}

TEST(NeuflowSink, WriteFailureStopsWithAnErrorNamingTheFileAndTheReason) {
  TempDir dir;
  const fs::path sub = dir.path() / "out";
  fs::create_directory(sub);
  auto s = start_sink({{"location", (sub / "flow_%05d.flo").string()}, {"index", "3"}});
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 0, 1, 0, 10, 0.f})), GST_FLOW_OK);
  fs::remove_all(sub);  // the directory disappears while running (unmounted disk, cleanup job)

  EXPECT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 1, 2, 10, 20, 0.f})), GST_FLOW_ERROR);
  const ErrorMessage error = pop_error(s.bus.get());
  ASSERT_TRUE(error.found);
  const std::string file = (sub / "flow_00004.flo").string();
  EXPECT_NE(error.message.find("\"" + file + "\""), std::string::npos) << error.message;
  EXPECT_NE(error.message.find("No such file or directory"), std::string::npos) << error.message;
  EXPECT_EQ(uint64_property(s.element.get(), "flows-written"), 1u);
}

// An index written in another format (an older neuflow's six columns) is not appended to:
// its rows would not line up with the header.
TEST(NeuflowSink, IndexWithOtherColumnsStopsWithAnErrorAndStaysAsItWas) {
  TempDir dir;
  const fs::path index = dir.path() / "index.csv";
  const std::string old = "index,from_frame,to_frame,from_pts_ns,to_pts_ns,file\n0,0,1,0,10,flow_0.flo\n";
  std::ofstream(index) << old;
  auto s = start_sink({{"location", (dir / "flow_%d.flo").string()}, {"index", "1"}});
  ASSERT_TRUE(s.harness);
  EXPECT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 1, 2, 10, 20, 0.f})), GST_FLOW_ERROR);
  const ErrorMessage error = pop_error(s.bus.get());
  ASSERT_TRUE(error.found);
  EXPECT_NE(error.message.find("\"" + index.string() + "\" has other columns"), std::string::npos) << error.message;
  std::ifstream in(index);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), old);
}

TEST(NeuflowSink, UnwritableIndexStopsWithAnErrorNamingIt) {
  TempDir dir;
  const fs::path index = dir.path() / "index.csv";
  fs::create_directory(index);  // a directory where the index file should be
  auto s = start_sink({{"location", (dir / "flow_%d.flo").string()}});
  ASSERT_TRUE(s.harness);
  EXPECT_EQ(gst_harness_push(s.harness.get(), buffer_with_flow({4, 4, 0, 1, 0, 10, 0.f})), GST_FLOW_ERROR);
  const ErrorMessage error = pop_error(s.bus.get());
  ASSERT_TRUE(error.found);
  EXPECT_NE(error.message.find("\"" + index.string() + "\""), std::string::npos) << error.message;
}

TEST(NeuflowSink, PipelineWithoutFlowReachesEosWritingNothing) {
  TempDir dir;
  const std::string launch =
      "videotestsrc num-buffers=7 ! video/x-raw,width=64,height=48 ! neuflowsink name=sink "
      "location=\"" +
      (dir / "flow_%05d.flo").string() + "\"";
  ElementPtr pipeline = owned(gst_parse_launch(launch.c_str(), nullptr));
  ASSERT_TRUE(pipeline);
  ASSERT_NE(gst_element_set_state(pipeline.get(), GST_STATE_PLAYING), GST_STATE_CHANGE_FAILURE);
  BusPtr bus(gst_element_get_bus(pipeline.get()));
  MessagePtr msg(gst_bus_timed_pop_filtered(bus.get(), 10 * GST_SECOND,
                                            static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR)));
  ASSERT_TRUE(msg);
  EXPECT_EQ(GST_MESSAGE_TYPE(msg.get()), GST_MESSAGE_EOS);
  ElementPtr sink(gst_bin_get_by_name(GST_BIN(pipeline.get()), "sink"));
  ASSERT_TRUE(sink);
  EXPECT_EQ(uint64_property(sink.get(), "buffers-skipped"), 7u);
  EXPECT_EQ(uint64_property(sink.get(), "flows-written"), 0u);
  gst_element_set_state(pipeline.get(), GST_STATE_NULL);
  EXPECT_TRUE(dir.entries().empty()) << ::testing::PrintToString(dir.entries());
}

}  // namespace
}  // namespace neuflow::gst_test
