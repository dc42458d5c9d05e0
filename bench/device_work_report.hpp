#pragma once
// What a GPU pass was asked to do (FlowSession::device_work()) as a benchmark's counters and,
// with --work, as a table of every command: the counts a GPU run would confirm, printed
// without one (they come from the commands' shapes, the same on every device).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "neuflow/model/device_work.hpp"

namespace neuflow::bench {

// dispatches, barriers, copies, submissions, host waits, GMAC, MB read and written.
void add_work_counters(benchmark::State& state, const model::DeviceWork& work);

// One row per command (kernel, stage, workgroups, bytes read and written, multiply-adds), then
// one per stage and the totals.
void print_work_table(std::FILE* out, const std::string& title, const model::DeviceWork& work);

}  // namespace neuflow::bench
