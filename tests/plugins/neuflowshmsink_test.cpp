// neuflowshmsink and the flow ring: flows from synthetic NeuflowFlowMeta read back through the
// header-only reader (exact values and metadata), slot reuse, generation changes, name and
// ownership errors, a writer racing a separate reader process (neuflow-shm-reader --check),
// and the Python reader.
#include <fcntl.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "flow_ring_writer.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow_ring.hpp"
#include "sink_test_util.hpp"

namespace neuflow::gst_test {
namespace {

namespace fs = std::filesystem;
using ring::FlowInfo;
using ring::FlowRingReader;
using ring::ReadStatus;
using ring::RingError;

// A name no other test (or test process running beside this one) uses.
std::string unique_name(const char *what) {
  static std::atomic<int> counter{0};
  return "/neuflow-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" + what;
}

// Unlinks the name at the end of a test that may leave it behind.
struct NameGuard {
  std::string name;
  ~NameGuard() { ::shm_unlink(name.c_str()); }
};

RunningSink start_shm_sink(const std::string &name, unsigned slots = 4) {
  return start_sink("neuflowshmsink", {{"shm-name", name}, {"slots", std::to_string(slots)}});
}

void expect_info(const FlowInfo &info, const FlowSpec &f, std::uint64_t sequence) {
  EXPECT_EQ(info.sequence, sequence);
  EXPECT_EQ(info.from_frame, f.from_frame);
  EXPECT_EQ(info.to_frame, f.to_frame);
  EXPECT_EQ(info.from_pts_ns, f.from_pts);
  EXPECT_EQ(info.to_pts_ns, f.to_pts);
  EXPECT_EQ(info.inference_ns, f.inference_time);
  EXPECT_EQ(info.grid_width, static_cast<std::uint32_t>(f.width));
  EXPECT_EQ(info.grid_height, static_cast<std::uint32_t>(f.height));
  EXPECT_EQ(info.frame_width, static_cast<std::uint32_t>(f.frame_width));
  EXPECT_EQ(info.frame_height, static_cast<std::uint32_t>(f.frame_height));
  EXPECT_EQ(info.model_width, f.model_width);
  EXPECT_EQ(info.model_height, f.model_height);
  EXPECT_EQ(info.iters_s16, f.iters_s16);
  EXPECT_EQ(info.iters_s8, f.iters_s8);
  EXPECT_EQ(info.data_bytes, static_cast<std::uint64_t>(f.width) * static_cast<std::uint64_t>(f.height) * 8u);
}

// Reads flow `sequence` and checks it is exactly `f`.
void expect_flow(const FlowRingReader &reader, std::uint64_t sequence, const FlowSpec &f) {
  std::vector<float> uv(reader.values_per_flow());
  FlowInfo info;
  ASSERT_EQ(reader.read(sequence, uv, info), ReadStatus::ok) << "sequence " << sequence;
  expect_info(info, f, sequence);
  EXPECT_EQ(uv, vectors_of(f)) << "sequence " << sequence;
  EXPECT_TRUE(ring::verify(uv, info));
  // The writer's checksum is zlib's: what Python's zlib.crc32 computes too.
  EXPECT_EQ(info.crc32, ::crc32(0, reinterpret_cast<const Bytef *>(uv.data()), static_cast<uInt>(info.data_bytes)));
}

RingError::Kind open_error_kind(const std::string &name, std::string *message = nullptr) {
  try {
    FlowRingReader reader(name);
  } catch (const RingError &e) {
    if (message) *message = e.what();
    return e.kind();
  }
  ADD_FAILURE() << "opening " << name << " succeeded";
  return RingError::Kind::system;
}

TEST(NeuflowShmSink, PropertiesHaveTheirDocumentedDefaults) {
  ElementPtr sink = make_element("neuflowshmsink", {});
  ASSERT_TRUE(sink) << "neuflowshmsink not found: is GST_PLUGIN_PATH the build directory?";
  gchar *name = nullptr;
  guint slots = 0;
  gboolean sync = TRUE;
  g_object_get(sink.get(), "shm-name", &name, "slots", &slots, "sync", &sync, nullptr);
  EXPECT_EQ(name, nullptr);
  EXPECT_EQ(slots, 4u);
  EXPECT_FALSE(sync);
  EXPECT_EQ(uint64_property(sink.get(), "flows-written"), 0u);
  EXPECT_EQ(uint64_property(sink.get(), "buffers-skipped"), 0u);
  g_free(name);
}

TEST(NeuflowShmSink, ReaderReadsEveryFlowWithExactValuesAndMetadata) {
  const std::string name = unique_name("exact");
  auto s = start_shm_sink(name);
  ASSERT_TRUE(s.harness);

  // Started, no flow yet: the name exists, readers are told to wait.
  std::string message;
  EXPECT_EQ(open_error_kind(name, &message), RingError::Kind::not_ready);
  EXPECT_NE(message.find(name), std::string::npos) << message;

  FlowSpec flows[3] = {nth_flow(0), nth_flow(1), nth_flow(3)};
  flows[2].from_pts = GST_CLOCK_TIME_NONE;  // unknown start: the ring's "no timestamp"
  for (const FlowSpec &f : flows) ASSERT_EQ(s.push(buffer_with_flow(f)), GST_FLOW_OK);

  FlowRingReader reader(name);
  EXPECT_EQ(reader.width(), 8u);
  EXPECT_EQ(reader.height(), 6u);
  EXPECT_EQ(reader.slot_count(), 4u);
  EXPECT_EQ(reader.values_per_flow(), 8u * 6u * 2u);
  EXPECT_EQ(reader.writer_pid(), static_cast<std::uint32_t>(::getpid()));
  EXPECT_EQ(reader.published(), 3u);
  EXPECT_FALSE(reader.replaced());

  std::vector<float> uv(reader.values_per_flow());
  FlowInfo info;
  ASSERT_EQ(reader.latest(uv, info), ReadStatus::ok);
  expect_info(info, flows[2], 3);
  EXPECT_EQ(info.from_pts_ns, ring::kNoTimestamp);
  EXPECT_EQ(uv, vectors_of(flows[2]));
  for (std::uint64_t seq = 1; seq <= 3; ++seq) expect_flow(reader, seq, flows[seq - 1]);
  EXPECT_EQ(reader.read(4, uv, info), ReadStatus::not_published);
  EXPECT_EQ(reader.read(0, uv, info), ReadStatus::not_published);

  std::vector<float> small(10);
  EXPECT_THROW(reader.read(1, small, info), std::invalid_argument);
  EXPECT_EQ(uint64_property(s.element.get(), "flows-written"), 3u);
  EXPECT_EQ(uint64_property(s.element.get(), "bytes-written"), 3u * 8u * 6u * 2u * sizeof(float));
  EXPECT_FALSE(pop_error(s.bus.get()).found);
}

TEST(NeuflowShmSink, MoreFlowsThanSlotsLeaveOnlyTheNewestReadable) {
  const std::string name = unique_name("reuse");
  auto s = start_shm_sink(name, 3);
  ASSERT_TRUE(s.harness);
  for (int n = 0; n < 10; ++n) ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n))), GST_FLOW_OK);

  FlowRingReader reader(name);
  EXPECT_EQ(reader.published(), 10u);
  for (std::uint64_t seq = 8; seq <= 10; ++seq) expect_flow(reader, seq, nth_flow(static_cast<int>(seq) - 1));
  std::vector<float> uv(reader.values_per_flow());
  FlowInfo info;
  for (std::uint64_t seq = 1; seq <= 7; ++seq) EXPECT_EQ(reader.read(seq, uv, info), ReadStatus::overwritten) << seq;
  EXPECT_EQ(reader.read(11, uv, info), ReadStatus::not_published);
}

TEST(NeuflowShmSink, BuffersWithoutFlowAreSkippedAndCounted) {
  const std::string name = unique_name("skip");
  auto s = start_shm_sink(name);
  ASSERT_TRUE(s.harness);
  EXPECT_EQ(s.push(gst_buffer_new()), GST_FLOW_OK);
  EXPECT_EQ(s.push(buffer_with_flow(nth_flow(0))), GST_FLOW_OK);
  EXPECT_EQ(s.push(gst_buffer_new()), GST_FLOW_OK);
  EXPECT_EQ(uint64_property(s.element.get(), "buffers-skipped"), 2u);
  EXPECT_EQ(uint64_property(s.element.get(), "flows-written"), 1u);
  FlowRingReader reader(name);
  EXPECT_EQ(reader.published(), 1u);
}

TEST(NeuflowShmSink, GridSizeChangeReplacesTheSegmentAndTheReaderNotices) {
  const std::string name = unique_name("resize");
  auto s = start_shm_sink(name);
  ASSERT_TRUE(s.harness);
  const FlowSpec big = nth_flow(0, 8, 6), small = nth_flow(1, 4, 3);
  ASSERT_EQ(s.push(buffer_with_flow(big)), GST_FLOW_OK);
  FlowRingReader reader(name);
  const std::uint64_t generation = reader.generation();
  EXPECT_FALSE(reader.replaced());

  ASSERT_EQ(s.push(buffer_with_flow(small)), GST_FLOW_OK);
  EXPECT_TRUE(reader.replaced());
  expect_flow(reader, 1, big);  // the old mapping still holds its flows

  reader.reopen();
  EXPECT_FALSE(reader.replaced());
  EXPECT_EQ(reader.generation(), generation + 1);
  EXPECT_EQ(reader.width(), 4u);
  EXPECT_EQ(reader.height(), 3u);
  EXPECT_EQ(reader.published(), 1u);  // sequences start again in each segment
  expect_flow(reader, 1, small);
  EXPECT_EQ(uint64_property(s.element.get(), "flows-written"), 2u);
}

TEST(NeuflowShmSink, StopUnlinksTheNameButMappedReadersKeepTheLastFlows) {
  const std::string name = unique_name("stop");
  NameGuard guard{name};
  auto s = start_shm_sink(name);
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(s.push(buffer_with_flow(nth_flow(0))), GST_FLOW_OK);
  ASSERT_EQ(s.push(buffer_with_flow(nth_flow(1))), GST_FLOW_OK);
  FlowRingReader reader(name);
  s.stop();

  EXPECT_TRUE(reader.replaced());
  expect_flow(reader, 2, nth_flow(1));
  std::string message;
  EXPECT_EQ(open_error_kind(name, &message), RingError::Kind::no_such_segment);
  EXPECT_NE(message.find("\"" + name + "\""), std::string::npos) << message;
}

TEST(NeuflowShmSink, RestartContinuesTheGeneration) {
  const std::string name = unique_name("restart");
  ElementPtr sink = make_element("neuflowshmsink", {{"shm-name", name}});
  ASSERT_TRUE(sink);
  std::uint64_t first = 0;
  for (int run = 0; run < 2; ++run) {
    HarnessPtr h(gst_harness_new_with_element(sink.get(), "sink", nullptr));
    gst_harness_set_src_caps_str(h.get(), caps_string(GST_VIDEO_FORMAT_RGBA, 32, 24).c_str());
    ASSERT_EQ(gst_harness_push(h.get(), buffer_with_flow(nth_flow(run))), GST_FLOW_OK);
    FlowRingReader reader(name);
    if (run == 0) {
      first = reader.generation();
    } else {
      EXPECT_GT(reader.generation(), first) << "a reader must be able to tell the runs' segments apart";
    }
  }
}

class NeuflowShmSinkBadNames : public ::testing::TestWithParam<std::string> {};

TEST_P(NeuflowShmSinkBadNames, FailAtStartNamingTheNameAndWhatIsExpected) {
  const std::string name = GetParam();
  const ErrorMessage error = start_error("neuflowshmsink", {{"shm-name", name}});
  ASSERT_TRUE(error.found) << "no error for \"" << name << "\"";
  EXPECT_NE(error.message.find("\"" + name + "\""), std::string::npos) << error.message;
  EXPECT_NE(error.message.find("shm-name"), std::string::npos) << error.message;
}

INSTANTIATE_TEST_SUITE_P(Names, NeuflowShmSinkBadNames,
                         ::testing::Values("neuflow-front", "/", "/a/b", "/neuflow/", "/..",
                                           std::string("/") + std::string(300, 'x')));

TEST(NeuflowShmSink, MissingNameFailsAtStartSayingWhatToSet) {
  const ErrorMessage error = start_error("neuflowshmsink", {});
  ASSERT_TRUE(error.found);
  EXPECT_NE(error.message.find("shared-memory name"), std::string::npos) << error.message;
  EXPECT_NE(error.debug.find("shm-name"), std::string::npos) << error.debug;
}

TEST(NeuflowShmSink, SecondWriterOnTheSameNameFailsAtStartAndTheFirstCarriesOn) {
  const std::string name = unique_name("twice");
  auto first = start_shm_sink(name);
  ASSERT_TRUE(first.harness);
  const ErrorMessage error = start_error("neuflowshmsink", {{"shm-name", name}});
  ASSERT_TRUE(error.found);
  EXPECT_NE(error.message.find("\"" + name + "\""), std::string::npos) << error.message;
  EXPECT_NE(error.message.find("in use"), std::string::npos) << error.message;

  ASSERT_EQ(first.push(buffer_with_flow(nth_flow(0))), GST_FLOW_OK);
  FlowRingReader reader(name);
  expect_flow(reader, 1, nth_flow(0));
}

// Creates a segment by hand: `bytes` at its start, padded with zeros to `size`.
void create_segment(const std::string &name, const std::vector<std::byte> &bytes, std::size_t size) {
  const int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0600);
  ASSERT_GE(fd, 0) << std::strerror(errno);
  ASSERT_EQ(::ftruncate(fd, static_cast<off_t>(size)), 0);
  if (!bytes.empty()) {
    ASSERT_EQ(::pwrite(fd, bytes.data(), bytes.size(), 0), static_cast<ssize_t>(bytes.size()));
  }
  ::close(fd);
}

std::vector<std::byte> header_bytes(const ring::RingHeader &h) {
  std::vector<std::byte> out(sizeof h);
  std::memcpy(out.data(), &h, sizeof h);
  return out;
}

ring::RingHeader live_header(std::uint64_t generation) {
  ring::RingHeader h{};
  std::memcpy(h.magic, ring::kMagic.data(), 8);
  h.version = ring::kLayoutVersion;
  h.header_size = 128;
  h.slot_count = 1;
  h.slot_header_size = 128;
  h.grid_width = 2;
  h.grid_height = 2;
  h.data_bytes = 32;
  h.slot_stride = 192;
  h.value_layout = ring::kValueLayoutF32UV;
  h.state = static_cast<std::uint32_t>(ring::SegmentState::live);
  h.generation = generation;
  h.segment_size = 128 + 192;
  return h;
}

TEST(NeuflowShmSink, SegmentLeftByADeadWriterIsTakenOverWithALaterGeneration) {
  const std::string name = unique_name("stale");
  NameGuard guard{name};
  create_segment(name, header_bytes(live_header(41)), 128 + 192);  // nobody holds its lock
  {
    FlowRingReader stale(name);  // a reader of the dead writer's segment
    auto s = start_shm_sink(name);
    ASSERT_TRUE(s.harness);
    EXPECT_FALSE(pop_error(s.bus.get()).found);
    EXPECT_TRUE(stale.replaced()) << "readers of the stale segment must be told to re-open";
    ASSERT_EQ(s.push(buffer_with_flow(nth_flow(0))), GST_FLOW_OK);
    FlowRingReader reader(name);
    EXPECT_GT(reader.generation(), 41u);
    expect_flow(reader, 1, nth_flow(0));
  }
}

TEST(FlowRingReader, RejectsWhatIsNotAFlowRingWithClearErrors) {
  const std::string name = unique_name("foreign");
  NameGuard guard{name};
  std::string message;

  EXPECT_EQ(open_error_kind(name, &message), RingError::Kind::no_such_segment);
  EXPECT_NE(message.find("\"" + name + "\""), std::string::npos) << message;
  EXPECT_NE(message.find("no such"), std::string::npos) << message;

  create_segment(name, {}, 0);  // created, not yet sized
  EXPECT_EQ(open_error_kind(name), RingError::Kind::not_ready);

  std::vector<std::byte> garbage(256, std::byte{0x5a});
  create_segment(name, garbage, 4096);
  EXPECT_EQ(open_error_kind(name, &message), RingError::Kind::bad_magic);
  EXPECT_NE(message.find("magic"), std::string::npos) << message;

  ring::RingHeader h = live_header(1);
  h.version = 99;
  create_segment(name, header_bytes(h), 128 + 192);
  EXPECT_EQ(open_error_kind(name, &message), RingError::Kind::unsupported_version);
  EXPECT_NE(message.find("version 99"), std::string::npos) << message;

  h = live_header(1);
  h.slot_count = 5;  // does not fit the segment
  create_segment(name, header_bytes(h), 128 + 192);
  EXPECT_EQ(open_error_kind(name, &message), RingError::Kind::bad_layout);
  EXPECT_NE(message.find("5 slots"), std::string::npos) << message;

  EXPECT_EQ(open_error_kind("no-slash"), RingError::Kind::no_such_segment);
}

TEST(FlowRingReader, Crc32IsZlibs) {
  std::mt19937 rng(7);
  std::vector<unsigned char> data(100000);
  for (auto &b : data) b = static_cast<unsigned char>(rng());
  for (std::size_t size : {0u, 1u, 7u, 8u, 9u, 63u, 1000u, 100000u}) {
    EXPECT_EQ(ring::crc32(data.data(), size), ::crc32(0, data.data(), static_cast<uInt>(size))) << size;
  }
  // Continuing over pieces gives the checksum of the whole.
  EXPECT_EQ(ring::crc32(data.data() + 333, 1000, ring::crc32(data.data(), 333)), ring::crc32(data.data(), 1333));
  EXPECT_EQ(ring::crc32("123456789", 9), 0xCBF43926u);  // the CRC-32 check value
}

TEST(NeuflowShmSink, MetaWithTooFewVectorsStopsWithAnErrorSayingWhatWasExpected) {
  const std::string name = unique_name("short");
  auto s = start_shm_sink(name);
  ASSERT_TRUE(s.harness);
  GstBuffer *buffer = buffer_with_flow(nth_flow(0));
  // neuflow_buffer_add_flow_meta checks the size, but the fields are public: a buggy
  // producer can still swap the data for less than the grid needs.
  NeuflowFlowMeta *meta = neuflow_buffer_get_flow_meta(buffer);
  std::vector<float> uv(10);
  g_bytes_unref(meta->data);
  meta->data = g_bytes_new(uv.data(), uv.size() * sizeof(float));
  EXPECT_EQ(s.push(buffer), GST_FLOW_ERROR);
  const ErrorMessage error = pop_error(s.bus.get());
  ASSERT_TRUE(error.found);
  EXPECT_NE(error.message.find("8x6"), std::string::npos) << error.message;
  EXPECT_NE(error.message.find("expected 384"), std::string::npos) << error.message;
}

// Runs a program to completion; its exit status and standard output.
struct ProgramResult {
  bool ran = false;
  int exit_status = -1;
  std::string out, err;
};

ProgramResult run_program(const std::vector<std::string> &args) {
  std::vector<gchar *> argv;
  for (const auto &a : args) argv.push_back(const_cast<gchar *>(a.c_str()));
  argv.push_back(nullptr);
  gchar *out = nullptr, *err = nullptr;
  gint status = 0;
  GError *error = nullptr;
  ProgramResult r;
  r.ran = g_spawn_sync(nullptr, argv.data(), nullptr, G_SPAWN_DEFAULT, nullptr, nullptr, &out, &err, &status, &error);
  if (!r.ran) {
    r.err = error->message;
    g_error_free(error);
    return r;
  }
  r.out = out ? out : "";
  r.err = err ? err : "";
  g_free(out);
  g_free(err);
  r.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

std::map<std::string, std::uint64_t> summary_of(const std::string &out) {
  std::map<std::string, std::uint64_t> values;
  const auto at = out.rfind("summary ");
  if (at == std::string::npos) return values;
  const std::regex pair("(\\w+)=(\\d+)");
  const std::string line = out.substr(at);
  for (auto it = std::sregex_iterator(line.begin(), line.end(), pair); it != std::sregex_iterator(); ++it) {
    values[(*it)[1]] = std::stoull((*it)[2]);
  }
  return values;
}

TEST(NeuflowShmSinkReaderProcess, SeesOnlyWholeFlowsWhileTheWriterPublishesAsFastAsItCan) {
  const std::string name = unique_name("stress");
  // Two slots and a grid of 24 KiB: the writer laps the reader and rewrites the slot being
  // read all the time, the case the seqlock exists for.
  auto s = start_shm_sink(name, 2);
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(s.push(buffer_with_flow(nth_flow(0, 64, 48))), GST_FLOW_OK);

  std::atomic<bool> stop{false};
  std::atomic<int> published{1};
  std::atomic<bool> failed{false};
  std::thread writer([&] {
    // Vectors that differ in every value from one flow to the next: a mix of two flows
    // cannot pass the checksum.
    for (int n = 1; !stop.load(); ++n) {
      if (s.push(buffer_with_flow(nth_flow(n, 64, 48))) != GST_FLOW_OK) {
        failed = true;
        return;
      }
      published = n + 1;
    }
  });
  const ProgramResult r = run_program({NEUFLOW_SHM_READER, name, "--check", "--quiet", "--timeout", "1"});
  stop = true;
  writer.join();

  ASSERT_TRUE(r.ran) << r.err;
  EXPECT_FALSE(failed.load());
  EXPECT_EQ(r.exit_status, 0) << r.out << r.err;
  const auto summary = summary_of(r.out);
  ASSERT_TRUE(summary.count("read")) << r.out << r.err;
  EXPECT_GT(summary.at("read"), 0u) << r.out;
  EXPECT_EQ(summary.at("bad_checksum"), 0u) << r.out;
  EXPECT_EQ(summary.at("torn"), 0u) << r.out;
  RecordProperty("flows_published", published.load());
  RecordProperty("flows_read", static_cast<int>(summary.at("read")));
  RecordProperty("flows_missed", static_cast<int>(summary.at("missed")));
}

TEST(NeuflowShmSinkReaderProcess, PrintsOneLinePerFlowAndStopsAfterCount) {
  const std::string name = unique_name("lines");
  auto s = start_shm_sink(name);
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(s.push(buffer_with_flow(nth_flow(6))), GST_FLOW_OK);
  const ProgramResult r = run_program({NEUFLOW_SHM_READER, name, "--count", "1", "--timeout", "5"});
  ASSERT_TRUE(r.ran) << r.err;
  EXPECT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("seq=1 frames=6->7 pts=0.200000->0.233333 grid=8x6 frame=32x24"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("crc=ok"), std::string::npos) << r.out;
  EXPECT_EQ(summary_of(r.out)["read"], 1u) << r.out;
}

TEST(NeuflowShmSinkReaderProcess, MissingRingTimesOutWithStatus3) {
  const ProgramResult r = run_program({NEUFLOW_SHM_READER, unique_name("absent"), "--count", "1", "--timeout", "0.2"});
  ASSERT_TRUE(r.ran) << r.err;
  EXPECT_EQ(r.exit_status, 3) << r.out << r.err;
  EXPECT_NE(r.err.find("no such shared-memory segment"), std::string::npos) << r.err;
}

TEST(NeuflowShmSinkPythonReader, ReadsTheNewestFlowExactly) {
  const char *python = "/usr/bin/python3";
  if (!g_file_test(python, G_FILE_TEST_IS_EXECUTABLE)) GTEST_SKIP() << python << " not found";
  const std::string name = unique_name("python");
  auto s = start_shm_sink(name, 2);
  ASSERT_TRUE(s.harness);
  for (int n = 0; n < 3; ++n) ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n, 10, 7))), GST_FLOW_OK);

  TempDir dir;
  const std::string saved = (dir / "newest.npy").string();
  const ProgramResult r = run_program({python, NEUFLOW_SHM_PY_READER, name, "--save", saved, "--wait", "5"});
  ASSERT_TRUE(r.ran) << r.err;
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("seq=3 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frames=2->3 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("grid=10x7 frame=32x24"), std::string::npos) << r.out;
  const flow::FlowField field = flow::read_flow(saved);
  ASSERT_EQ(field.width, 10);
  ASSERT_EQ(field.height, 7);
  EXPECT_EQ(field.uv, vectors_of(nth_flow(2, 10, 7)));
}

// What a reader running as another user gets, checked as two users: the test (root) creates
// the ring, then a child process drops to an unprivileged uid, in the segment's group or not,
// and tries to open it the way neuflow::ring::FlowRingReader does. Under systemd the daemon's
// units give the segment the fixed group `neuflow` (Group=neuflow), which readers join.
class FlowRingAsAnotherUser : public ::testing::Test {
 protected:
  static constexpr uid_t kReaderUid = 65534;  // nobody
  static constexpr gid_t kRingGroup = 64000;  // stands for the `neuflow` group
  static constexpr gid_t kOtherGroup = 64001;

  void SetUp() override {
    if (::geteuid() != 0) GTEST_SKIP() << "needs root to act as a second user (CI runs as root)";
  }

  // 0: opened and mapped the header; otherwise the errno of shm_open.
  static int open_as(uid_t uid, gid_t gid, const std::string &name) {
    const pid_t child = ::fork();
    if (child == 0) {
      const gid_t groups[] = {gid};
      if (::setgroups(1, groups) != 0 || ::setgid(gid) != 0 || ::setuid(uid) != 0) ::_exit(200);
      const int fd = ::shm_open(name.c_str(), O_RDONLY, 0);
      if (fd < 0) ::_exit(errno);
      // What FlowRingReader does next: map it for reading.
      void *header = ::mmap(nullptr, sizeof(neuflow::ring::RingHeader), PROT_READ, MAP_SHARED, fd, 0);
      ::_exit(header == MAP_FAILED ? 201 : 0);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 202;
  }

  static void give_group(const std::string &name, gid_t gid) {
    ASSERT_EQ(::chown(("/dev/shm" + name).c_str(), static_cast<uid_t>(-1), gid), 0) << std::strerror(errno);
  }
};

TEST_F(FlowRingAsAnotherUser, TheDefaultModeLetsTheGroupReadAndNobodyElse) {
  const std::string name = unique_name("mode-default");
  const mode_t old_umask = ::umask(077);  // the mode is set exactly, whatever the umask
  gst::FlowRingWriter writer(name, 2, 0);
  ::umask(old_umask);
  struct stat st {};
  ASSERT_EQ(::stat(("/dev/shm" + name).c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u);
  give_group(name, kRingGroup);
  EXPECT_EQ(open_as(kReaderUid, kRingGroup, name), 0) << "a reader in the ring's group cannot read it";
  EXPECT_EQ(open_as(kReaderUid, kOtherGroup, name), EACCES) << "a reader outside the group can read it";
}

TEST_F(FlowRingAsAnotherUser, Mode0644LetsEveryoneRead) {
  const std::string name = unique_name("mode-0644");
  gst::FlowRingWriter writer(name, 2, 0, 0644);
  give_group(name, kRingGroup);
  EXPECT_EQ(open_as(kReaderUid, kOtherGroup, name), 0);
}

TEST(FlowRingMode, OnlyReadAndWriteBitsWithTheOwnersAreAccepted) {
  EXPECT_FALSE(gst::check_flow_ring_mode(0640));
  EXPECT_FALSE(gst::check_flow_ring_mode(0600));
  EXPECT_FALSE(gst::check_flow_ring_mode(0666));
  for (const mode_t bad : {0400, 0200, 0644 | 0100, 0610, 04640, 01640, 0777}) {
    EXPECT_TRUE(gst::check_flow_ring_mode(static_cast<mode_t>(bad))) << std::oct << bad;
  }
  EXPECT_THROW(gst::FlowRingWriter(unique_name("mode-bad"), 2, 0, 0700), gst::FlowRingError);
}

TEST(NeuflowShmSink, ShmModeIsAppliedAndAnInvalidOneFailsAtStart) {
  const std::string name = unique_name("mode-prop");
  {
    auto s = start_sink("neuflowshmsink", {{"shm-name", name}, {"shm-mode", "0644"}});
    ASSERT_TRUE(s.harness);
    struct stat st {};
    ASSERT_EQ(::stat(("/dev/shm" + name).c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 07777, 0644u);
  }
  const ErrorMessage error = start_error("neuflowshmsink", {{"shm-name", name}, {"shm-mode", "0610"}});
  ASSERT_TRUE(error.found);
  EXPECT_NE(error.message.find("Invalid shm-mode 0610"), std::string::npos) << error.message;
}

}  // namespace
}  // namespace neuflow::gst_test
