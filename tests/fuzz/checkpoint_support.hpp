#pragma once
// Shared by the checkpoint harnesses and the seed writer: what a loaded checkpoint promises,
// and the zip around a fuzzed pickle (checkpoint_pickle_fuzz.cpp), whose storages the seed
// pickles refer to.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "neuflow/model/checkpoint.hpp"

namespace neuflow::fuzz {

// The storages beside a fuzzed pickle: <folder>/data/0 .. data/<kPickleStorages - 1>, each
// kPickleStorageBytes bytes (a float32 ramp), so a pickle's persistent ids can name them.
inline constexpr const char* kPickleFolder = "archive";
inline constexpr int kPickleStorages = 4;
inline constexpr std::size_t kPickleStorageBytes = 256;
std::string pickle_storage_bytes(int index);

// A zip archive of stored (uncompressed) entries, written directly: libzip checks the CRCs
// when it reads, so a checkpoint whose data.pkl is the fuzz input needs them right.
std::string stored_zip(const std::vector<std::pair<std::string, std::string>>& entries);

// The whole checkpoint file around `pickle`: data.pkl, the storages above and version.
std::string checkpoint_around_pickle(std::string pickle);

// Aborts (invariant_failed) when a successfully loaded checkpoint breaks checkpoint.hpp's
// promises: keys and tensors agree, every tensor holds numel() values of an allowed dtype.
void check_checkpoint(const char* harness, const model::Checkpoint& checkpoint);

}  // namespace neuflow::fuzz
