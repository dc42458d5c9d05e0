// neuflowsink's max-files / max-bytes: the newest files stay, the oldest this run wrote go,
// the index keeps listing what is on disk and stays bounded on a long run, and failures
// (unwritable directory, an old file that cannot be deleted) are reported.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "earlier_files.hpp"
#include "flow_index_compaction.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "sink_test_util.hpp"
#include "written_files.hpp"

namespace neuflow::gst_test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> read_lines(const fs::path &path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string flow_name(int index) {
  char name[32];
  std::snprintf(name, sizeof name, "flow_%03d.flo", index);
  return name;
}

// The index row neuflowsink writes for nth_flow(n) as file `index` beside the index.
std::string index_row(int index, int n) {
  const FlowSpec f = nth_flow(n);
  return std::to_string(index) + "," + std::to_string(f.from_frame) + "," + std::to_string(f.to_frame) + "," +
         std::to_string(f.from_pts) + "," + std::to_string(f.to_pts) + "," + flow_name(index) + ",,";
}

const std::string kHeader = "index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source";

RunningSink start_file_sink(const TempDir &dir, Properties properties) {
  properties.insert(properties.begin(), {"location", (dir / "flow_%03d.flo").string()});
  return start_sink("neuflowsink", properties);
}

TEST(NeuflowSinkRetention, LimitsAreOffByDefault) {
  ElementPtr sink = make_element("neuflowsink", {});
  ASSERT_TRUE(sink);
  EXPECT_EQ(uint64_property(sink.get(), "max-files"), 0u);
  EXPECT_EQ(uint64_property(sink.get(), "max-bytes"), 0u);
}

TEST(NeuflowSinkRetention, MaxFilesKeepsTheNewestFilesAndTheIndexListsExactlyThem) {
  TempDir dir;
  auto s = start_file_sink(dir, {{"max-files", "5"}});
  ASSERT_TRUE(s.harness);
  for (int n = 0; n < 20; ++n) {
    ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n))), GST_FLOW_OK);
    EXPECT_LE(dir.entries().size(), 5u + 1u) << "after flow " << n;
  }
  const std::vector<std::string> newest = {flow_name(15), flow_name(16), flow_name(17),
                                           flow_name(18), flow_name(19), "index.csv"};
  EXPECT_EQ(dir.entries(), newest);
  // While running the index may still hold rows of deleted files (at most twice the live
  // ones, at least 32), but always every file on disk.
  const auto running = read_lines(dir.path() / "index.csv");
  for (int i = 15; i < 20; ++i) EXPECT_NE(std::find(running.begin(), running.end(), index_row(i, i)), running.end());
  EXPECT_EQ(uint64_property(s.element.get(), "flows-written"), 20u);

  s.stop();
  EXPECT_EQ(read_lines(dir.path() / "index.csv"),
            (std::vector<std::string>{kHeader, index_row(15, 15), index_row(16, 16), index_row(17, 17),
                                      index_row(18, 18), index_row(19, 19)}));
  for (int i = 15; i < 20; ++i) {
    const flow::FlowField field = flow::read_flow(dir.path() / flow_name(i));
    EXPECT_EQ(field.uv, vectors_of(nth_flow(i))) << flow_name(i);
  }
}

TEST(NeuflowSinkRetention, MaxBytesKeepsTheNewestFilesThatFitAndCanBeSetWhilePlaying) {
  TempDir dir;
  auto s = start_file_sink(dir, {});
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(s.push(buffer_with_flow(nth_flow(0))), GST_FLOW_OK);
  const auto file_size = fs::file_size(dir.path() / flow_name(0));  // all flows here are as large
  g_object_set(s.element.get(), "max-bytes", static_cast<guint64>(3 * file_size + file_size / 2), nullptr);
  for (int n = 1; n < 12; ++n) ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n))), GST_FLOW_OK);

  // flow 0 was written before the limit: not this element's to delete.
  EXPECT_EQ(dir.entries(),
            (std::vector<std::string>{flow_name(0), flow_name(9), flow_name(10), flow_name(11), "index.csv"}));
  s.stop();
  EXPECT_EQ(read_lines(dir.path() / "index.csv"), (std::vector<std::string>{kHeader, index_row(0, 0), index_row(9, 9),
                                                                            index_row(10, 10), index_row(11, 11)}));
}

TEST(NeuflowSinkRetention, NewestFileIsKeptEvenWhenLargerThanMaxBytes) {
  TempDir dir;
  auto s = start_file_sink(dir, {{"max-bytes", "1"}});
  ASSERT_TRUE(s.harness);
  for (int n = 0; n < 3; ++n) ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n))), GST_FLOW_OK);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{flow_name(2), "index.csv"}));
}

TEST(NeuflowSinkRetention, IndexStaysBoundedOnALongRun) {
  TempDir dir;
  auto s = start_file_sink(dir, {{"max-files", "3"}});
  ASSERT_TRUE(s.harness);
  std::size_t most_rows = 0;
  for (int n = 0; n < 300; ++n) {
    ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n))), GST_FLOW_OK);
    const auto lines = read_lines(dir.path() / "index.csv");
    most_rows = std::max(most_rows, lines.size() - 1);
    ASSERT_EQ(lines.front(), kHeader);
    for (int i = std::max(0, n - 2); i <= n; ++i) {
      ASSERT_NE(std::find(lines.begin(), lines.end(), index_row(i, i)), lines.end()) << "flow " << i << " at " << n;
    }
  }
  EXPECT_LE(most_rows, 33u) << "more than twice the live rows (16 at least) plus the one just appended";
  EXPECT_GT(most_rows, 3u) << "compacting at every flow would cost a rewrite per flow";
  s.stop();
  EXPECT_EQ(read_lines(dir.path() / "index.csv"),
            (std::vector<std::string>{kHeader, index_row(297, 297), index_row(298, 298), index_row(299, 299)}));
}

TEST(NeuflowSinkRetention, EarlierRunsFilesCountAsOlderAndTheIndexKeepsTheLastRowPerFile) {
  TempDir dir;
  {
    auto s = start_file_sink(dir, {});  // no limit: files 0..4
    ASSERT_TRUE(s.harness);
    for (int n = 0; n < 5; ++n) ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n))), GST_FLOW_OK);
  }
  {
    // Restarted at index 0 with max-files = 2: the earlier files count (the two of highest
    // index stay at start), then what this run writes is newer than all of them.
    auto s = start_file_sink(dir, {{"max-files", "2"}});
    ASSERT_TRUE(s.harness);
    EXPECT_EQ(dir.entries(), (std::vector<std::string>{flow_name(3), flow_name(4), "index.csv"}));
    for (int n = 10; n < 14; ++n) ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n))), GST_FLOW_OK);
  }
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{flow_name(2), flow_name(3), "index.csv"}));
  EXPECT_EQ(read_lines(dir.path() / "index.csv"),
            (std::vector<std::string>{kHeader, index_row(2, 12), index_row(3, 13)}));
}

TEST(NeuflowSinkRetention, OldFileThatCannotBeDeletedIsAWarningAndWritingGoesOn) {
  TempDir dir;
  auto s = start_file_sink(dir, {{"max-files", "1"}});
  ASSERT_TRUE(s.harness);
  ASSERT_EQ(s.push(buffer_with_flow(nth_flow(0))), GST_FLOW_OK);
  // Replaced by a non-empty directory: remove() fails on it, even for root.
  const fs::path first = dir.path() / flow_name(0);
  fs::remove(first);
  fs::create_directory(first);
  std::ofstream(first / "keep") << "x";

  EXPECT_EQ(s.push(buffer_with_flow(nth_flow(1))), GST_FLOW_OK);
  // Popping one type discards the others: look for the warning first.
  MessagePtr warning(gst_bus_pop_filtered(s.bus.get(), GST_MESSAGE_WARNING));
  EXPECT_FALSE(pop_error(s.bus.get()).found);
  ASSERT_TRUE(warning);
  GError *error = nullptr;
  gst_message_parse_warning(warning.get(), &error, nullptr);
  ASSERT_TRUE(error);
  const std::string message = error->message;
  g_error_free(error);
  EXPECT_NE(message.find("\"" + first.string() + "\""), std::string::npos) << message;
  EXPECT_NE(message.find("max-files=1"), std::string::npos) << message;
  EXPECT_TRUE(fs::exists(dir.path() / flow_name(1)));
}

// A directory the sink cannot create files in: made read-only, or /sys when running as root
// (permissions do not stop root, sysfs does).
std::string unwritable_directory(const TempDir &dir) {
  const fs::path ro = dir.path() / "read-only";
  fs::create_directory(ro);
  ::chmod(ro.c_str(), 0555);
  if (::access(ro.c_str(), W_OK) != 0) return ro.string();
  return "/sys";
}

TEST(NeuflowSinkRetention, UnwritableDirectoryPostsTheErrorBeforeReturningTheFlowError) {
  TempDir dir;
  const std::string target = unwritable_directory(dir);
  auto s = start_sink(
      "neuflowsink",
      {{"location", target + "/flow_%03d.flo"}, {"index-location", (dir / "index.csv").string()}, {"max-files", "2"}});
  ASSERT_TRUE(s.harness);
  EXPECT_EQ(s.push(buffer_with_flow(nth_flow(0))), GST_FLOW_ERROR);
  // Synchronously on the bus by the time the flow error comes back: an application (the
  // daemon) learns which sink failed before it handles the failed flow.
  const ErrorMessage error = pop_error(s.bus.get());
  ASSERT_TRUE(error.found);
  const std::string file = target + "/flow_000.flo";
  EXPECT_NE(error.message.find("\"" + file + "\""), std::string::npos) << error.message;
  EXPECT_EQ(uint64_property(s.element.get(), "flows-written"), 0u);
  ::chmod((dir.path() / "read-only").c_str(), 0755);
}

// After a restart or a reload (the daemon starts each run at the next free index), the
// files of earlier runs count: max-files = 20 then 10 once left 30 files behind.
TEST(NeuflowSinkRetention, FilesOfEarlierRunsCountTowardsTheLimitsAtStart) {
  TempDir dir;
  for (int i = 0; i < 30; ++i) std::ofstream(dir / flow_name(i)) << "earlier run " << i;
  std::ofstream(dir / "notes.txt") << "not ours";
  std::ofstream(dir / "flow_abc.flo") << "not a name the pattern makes";
  auto s = start_file_sink(dir, {{"max-files", "10"}, {"index", "30"}});
  ASSERT_TRUE(s.harness);
  std::vector<std::string> expected;
  for (int i = 20; i < 30; ++i) expected.push_back(flow_name(i));
  expected.push_back("flow_abc.flo");
  expected.push_back("notes.txt");
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(dir.entries(), expected) << "the limit was not applied to earlier files at start";

  ASSERT_EQ(s.push(buffer_with_flow(nth_flow(0))), GST_FLOW_OK);
  ASSERT_EQ(s.push(buffer_with_flow(nth_flow(1))), GST_FLOW_OK);
  expected.erase(std::find(expected.begin(), expected.end(), flow_name(20)));
  expected.erase(std::find(expected.begin(), expected.end(), flow_name(21)));
  expected.insert(expected.end(), {flow_name(30), flow_name(31), "index.csv"});
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(dir.entries(), expected);
}

TEST(NeuflowSinkRetention, MaxBytesCountsEarlierFilesToo) {
  TempDir dir;
  for (int i = 0; i < 10; ++i) std::ofstream(dir / flow_name(i)) << std::string(100, 'x');
  auto s = start_file_sink(dir, {{"max-bytes", "450"}, {"index", "10"}});
  ASSERT_TRUE(s.harness);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{flow_name(6), flow_name(7), flow_name(8), flow_name(9)}));
}

// kill -9 during a write leaves ".NAME.tmp-XXXXXXXX" beside NAME; a fault test found 2.4 MB of
// them surviving restarts. They go when the sink starts again, with or without limits.
TEST(NeuflowSinkRetention, TemporariesOfInterruptedWritesAreRemovedAtStart) {
  TempDir dir;
  std::ofstream(dir / ".flow_003.flo.tmp-0123abcd") << "half a flow";
  std::ofstream(dir / ".index.csv.tmp-deadbeef") << "half an index";
  std::ofstream(dir / ".other.txt.tmp-01234567") << "someone else's";
  std::ofstream(dir / ".flow_004.flo.tmp-notahex!") << "not a temporary name";
  auto s = start_file_sink(dir, {});
  ASSERT_TRUE(s.harness);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{".flow_004.flo.tmp-notahex!", ".other.txt.tmp-01234567"}));
}

TEST(EarlierFiles, TheNamesAPatternMakesAreFoundInIndexOrder) {
  TempDir dir;
  for (const char *name :
       {"f_10.flo", "f_9.flo", "f_0100.flo", "f_x.flo", "g_1.flo", "f_2.npy", "f_-3.flo", "f_ff.flo"}) {
    std::ofstream(dir / name) << name;
  }
  std::filesystem::create_directory(dir / "f_5.flo");
  const auto found = gst::files_matching((dir / "f_%d.flo").string());
  std::vector<std::int64_t> indices(found.size());
  std::transform(found.begin(), found.end(), indices.begin(), [](const auto &f) { return f.index; });
  // Not f_0100 (%d writes 100 as "100"), not f_-3 (indices start at 0).
  EXPECT_EQ(indices, (std::vector<std::int64_t>{9, 10}));
  EXPECT_EQ(found[0].bytes, 7u);
  const auto hex = gst::files_matching((dir / "f_%x.flo").string());
  ASSERT_EQ(hex.size(), 3u);  // 9, 0x10, 0xff
  EXPECT_EQ(hex.back().index, 0xff);
  std::ofstream(dir / "50%_1.flo") << "x";
  EXPECT_EQ(gst::files_matching((dir / "50%%_%d.flo").string()).size(), 1u);
}

// Only what the pattern writes counts: the same width and zero padding, digits only, no sign.
TEST(EarlierFiles, OtherToolsFilesBesideThePatternAreNotTheSinks) {
  TempDir dir;
  for (const char *name : {"flow_7.flo", "flow_-5.flo", "flow_123456789012345.flo", "flow_0000007.flo",
                           "flow_+0000007.flo", "flow_ 0000007.flo", "flow_00000007.flo"}) {
    std::ofstream(dir / name) << name;
  }
  const auto found = gst::files_matching((dir / "flow_%08d.flo").string());
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(std::filesystem::path(found[0].path).filename(), "flow_00000007.flo");
  EXPECT_EQ(found[0].index, 7);
}

// The audit's case: a 12-flow run with max-files = 3 in a folder holding other files whose names
// look numbered keeps them all.
TEST(NeuflowSinkRetention, RetentionLeavesFilesThePatternDoesNotProduce) {
  TempDir dir;
  const std::vector<std::string> others = {"flow_-5.flo", "flow_123456789012345.flo", "flow_7.flo"};
  for (const auto &name : others) std::ofstream(dir / name) << name;
  auto s = start_sink("neuflowsink", {{"location", (dir / "flow_%08d.flo").string()}, {"max-files", "3"}});
  ASSERT_TRUE(s.harness);
  for (int n = 0; n < 12; ++n) ASSERT_EQ(s.push(buffer_with_flow(nth_flow(n))), GST_FLOW_OK);
  s.stop();
  const std::vector<std::string> entries = dir.entries();
  for (const auto &name : others) {
    EXPECT_NE(std::find(entries.begin(), entries.end(), name), entries.end()) << name << " was removed";
  }
  EXPECT_NE(std::find(entries.begin(), entries.end(), "flow_00000011.flo"), entries.end());
  EXPECT_EQ(std::find(entries.begin(), entries.end(), "flow_00000008.flo"), entries.end());
}

TEST(WrittenFiles, OldestGoFirstAndARewrittenPathCountsOnceAtItsNewestPosition) {
  gst::WrittenFiles files;
  files.add("a", 10);
  files.add("b", 20);
  files.add("c", 30);
  EXPECT_TRUE(files.take_excess(3, 60).empty());
  files.add("a", 5);  // written again: now the newest
  EXPECT_EQ(files.count(), 3u);
  EXPECT_EQ(files.bytes(), 55u);
  EXPECT_EQ(files.take_excess(2, 0), (std::vector<std::string>{"b"}));
  EXPECT_EQ(files.take_excess(0, 6), (std::vector<std::string>{"c"}));
  EXPECT_EQ(files.take_excess(0, 1), std::vector<std::string>{}) << "the newest file stays";
  EXPECT_EQ(files.count(), 1u);
  EXPECT_EQ(files.bytes(), 5u);
}

TEST(FlowIndexCompaction, CsvRecordsAndFieldsFollowRfc4180) {
  const std::string text = "h1,h2\r\n1,\"a,b\"\n2,\"line\nbreak\"\n3,\"say \"\"hi\"\"\"\n4,last";
  const auto records = gst::csv_records(text);
  ASSERT_EQ(records.size(), 5u);
  EXPECT_EQ(records[0], "h1,h2");
  EXPECT_EQ(gst::csv_fields(records[1]), (std::vector<std::string>{"1", "a,b"}));
  EXPECT_EQ(gst::csv_fields(records[2]), (std::vector<std::string>{"2", "line\nbreak"}));
  EXPECT_EQ(gst::csv_fields(records[3]), (std::vector<std::string>{"3", "say \"hi\""}));
  EXPECT_EQ(gst::csv_fields(records[4]), (std::vector<std::string>{"4", "last"}));
}

TEST(FlowIndexCompaction, KeepsRowsOfExistingFilesQuotedNamesAndRowsItCannotParse) {
  TempDir dir;
  std::ofstream(dir / "a,1.flo") << "x";
  std::ofstream(dir / "kept.flo") << "x";
  const std::string elsewhere = (dir / "sub").string();
  fs::create_directory(elsewhere);
  std::ofstream(elsewhere + "/far.flo") << "x";
  {
    std::ofstream index(dir / "index.csv");
    index << kHeader << "\n"
          << "0,0,1,0,10,gone.flo\n"
          << "1,1,2,10,20,\"a,1.flo\"\n"
          << "2,2,3,20,30,kept.flo\n"
          << "garbage row\n"
          << "3,3,4,30,40," << elsewhere << "/far.flo\n"
          << "4,4,5,40,50," << elsewhere << "/gone.flo\n";
  }
  const auto result = gst::compact_flow_index((dir / "index.csv").string(), dir.path().string());
  EXPECT_EQ(result.rows_kept, 4u);
  EXPECT_EQ(result.rows_dropped, 2u);
  EXPECT_EQ(read_lines(dir.path() / "index.csv"),
            (std::vector<std::string>{kHeader, "1,1,2,10,20,\"a,1.flo\"", "2,2,3,20,30,kept.flo", "garbage row",
                                      "3,3,4,30,40," + elsewhere + "/far.flo"}));
  EXPECT_EQ(gst::count_index_rows((dir / "index.csv").string()), 4u);
  EXPECT_EQ(gst::count_index_rows((dir / "missing.csv").string()), 0u);
}

}  // namespace
}  // namespace neuflow::gst_test
