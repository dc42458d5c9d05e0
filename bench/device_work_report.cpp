#include "device_work_report.hpp"

#include <map>
#include <vector>

namespace neuflow::bench {

namespace {

constexpr double kMB = 1e6;

struct Totals {
  int commands = 0, barriers = 0;
  std::uint64_t workgroups = 0, read = 0, written = 0, multiply_adds = 0;
  void add(const model::DeviceCommand& c) {
    ++commands;
    barriers += c.after_barrier ? 1 : 0;
    workgroups += c.workgroups;
    read += c.bytes_read;
    written += c.bytes_written;
    multiply_adds += c.multiply_adds;
  }
};

void print_row(std::FILE* out, const std::string& kernel, const std::string& stage, const Totals& t) {
  std::fprintf(out, "  %-26s %-22s %5d %5d %10llu %11.3f %11.3f %12.3f\n", kernel.c_str(), stage.c_str(), t.commands,
               t.barriers, static_cast<unsigned long long>(t.workgroups), static_cast<double>(t.read) / kMB,
               static_cast<double>(t.written) / kMB, static_cast<double>(t.multiply_adds) / 1e6);
}

}  // namespace

void add_work_counters(benchmark::State& state, const model::DeviceWork& work) {
  state.counters["dispatches"] = work.dispatches;
  state.counters["barriers"] = work.barriers;
  state.counters["copies"] = work.copies;
  state.counters["submits"] = work.submissions;
  state.counters["host_waits"] = work.host_waits;
  state.counters["GMAC"] = static_cast<double>(work.multiply_adds()) / 1e9;
  state.counters["read_MB"] = static_cast<double>(work.bytes_read()) / kMB;
  state.counters["written_MB"] = static_cast<double>(work.bytes_written()) / kMB;
}

void print_work_table(std::FILE* out, const std::string& title, const model::DeviceWork& work) {
  std::fprintf(out, "\n%s: %d dispatches, %d copies, %d barriers, %d timestamps, %d submissions, %d host waits\n",
               title.c_str(), work.dispatches, work.copies, work.barriers, work.timestamps, work.submissions,
               work.host_waits);
  // waits: commands with a pipeline barrier before them.
  std::fprintf(out, "  %-26s %-22s %5s %5s %10s %11s %11s %12s\n", "kernel", "stage", "cmds", "waits", "workgroups",
               "read MB", "written MB", "M mult-adds");
  std::vector<std::string> stages;  // in the order they ran
  std::map<std::string, Totals> by_stage;
  Totals all;
  for (const auto& c : work.commands) {
    Totals one;
    one.add(c);
    print_row(out, c.kernel, c.stage, one);
    if (!by_stage.contains(c.stage)) stages.push_back(c.stage);
    by_stage[c.stage].add(c);
    all.add(c);
  }
  std::fprintf(out, "  by stage:\n");
  for (const auto& s : stages) print_row(out, "", s.empty() ? "(after the last)" : s, by_stage[s]);
  print_row(out, "total", "", all);
}

}  // namespace neuflow::bench
