#pragma once
// Media made at test time for the convert tests: videos from videotestsrc, small frames
// from the fixture camera sequence. (Temporary folders: support/temp_dir.hpp.)
#include <filesystem>
#include <string>

namespace neuflow::test {

// Runs a gst-launch-1.0 style pipeline description to its end; throws std::runtime_error
// with GStreamer's message if it fails.
void run_gst_pipeline(const std::string& description);

// An H.264 MP4 of `frames` frames at 10 fps showing a moving ball (so the flow is not zero).
std::filesystem::path make_test_video(const std::filesystem::path& path, int frames, int width, int height);

// A WAV file: a real media file without any video stream.
std::filesystem::path make_audio_only(const std::filesystem::path& path);

// Names of the files in `dir` whose name starts with '.' (temporary files left behind).
std::string hidden_files(const std::filesystem::path& dir);

}  // namespace neuflow::test
