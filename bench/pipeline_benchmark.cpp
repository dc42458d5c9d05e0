// End-to-end throughput of `videotestsrc ! neuflow behaviour=every-pair ! fakesink` against
// the core's streaming time per frame at the same size, both measured in this process; the
// ratio is the element's overhead (conversion, queueing, metadata, thread hand-over).
//
//   GST_PLUGIN_PATH=build/release/plugins neuflow-bench-pipeline [--model CKPT] [--threads N]
//       [--size WxH] [--frames N]
#include <gst/gst.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"

namespace {

double core_seconds_per_frame(const std::string& model, int w, int h, int threads, int frames) {
  neuflow::model::FlowSession session(neuflow::model::FlowModel::load(model), {.threads = threads});
  std::vector<std::vector<std::uint8_t>> images(2, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3));
  for (std::size_t i = 0; i < images[0].size(); ++i) {
    images[0][i] = static_cast<std::uint8_t>(i * 7);
    images[1][i] = static_cast<std::uint8_t>(i * 7 + 3);
  }
  const auto view = [&](int i) { return neuflow::model::ImageView{images[i % 2].data(), w, h, w * 3}; };
  session.push(view(0));
  session.push(view(1));  // warm-up: primitives and buffers
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < frames - 1; ++i) session.push(view(i));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / (frames - 1);
}

// Seconds per frame between the first and the last frame leaving the element.
double pipeline_seconds_per_frame(const std::string& model, int w, int h, int threads, int frames) {
  const std::string description = "videotestsrc num-buffers=" + std::to_string(frames + 1) +
                                  " pattern=ball ! video/x-raw,format=RGB,width=" + std::to_string(w) +
                                  ",height=" + std::to_string(h) +
                                  " ! neuflow name=nf behaviour=every-pair threads=" + std::to_string(threads) +
                                  " model=" + model + " ! fakesink name=sink sync=false";
  GError* err = nullptr;
  GstElement* pipeline = gst_parse_launch(description.c_str(), &err);
  if (!pipeline || err) {
    std::fprintf(stderr, "neuflow-bench-pipeline: %s\n", err ? err->message : "cannot build the pipeline");
    std::exit(1);
  }
  struct Times {
    std::vector<std::chrono::steady_clock::time_point> out;
  } times;
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  GstPad* pad = gst_element_get_static_pad(sink, "sink");
  gst_pad_add_probe(
      pad, GST_PAD_PROBE_TYPE_BUFFER,
      [](GstPad*, GstPadProbeInfo*, gpointer data) {
        static_cast<Times*>(data)->out.push_back(std::chrono::steady_clock::now());
        return GST_PAD_PROBE_OK;
      },
      &times, nullptr);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(pipeline);
  GstMessage* msg = gst_bus_timed_pop_filtered(bus, GST_CLOCK_TIME_NONE,
                                               static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  if (GST_MESSAGE_TYPE(msg) == GST_MESSAGE_ERROR) {
    GError* e = nullptr;
    gst_message_parse_error(msg, &e, nullptr);
    std::fprintf(stderr, "neuflow-bench-pipeline: %s\n", e->message);
    std::exit(1);
  }
  gst_message_unref(msg);
  gst_object_unref(bus);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pad);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  // The first frame out carries no flow and the second pays for primitive creation: skip both.
  const std::size_t n = times.out.size();
  return std::chrono::duration<double>(times.out[n - 1] - times.out[2]).count() / static_cast<double>(n - 3);
}

}  // namespace

int main(int argc, char** argv) {
  gst_init(&argc, &argv);
  const char* shared = std::getenv("NEUFLOW_SHARED_DIR");
  std::string model = std::string(shared && *shared ? shared : NEUFLOW_DEFAULT_SHARED_DIR) +
                      "/fixtures/neuflow-v2-seed0/checkpoint.pth";
  int threads = 2, w = 768, h = 432, frames = 8;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--model"))
      model = argv[i + 1];
    else if (!std::strcmp(argv[i], "--threads"))
      threads = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--frames"))
      frames = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--size"))
      std::sscanf(argv[i + 1], "%dx%d", &w, &h);
    else {
      std::fprintf(stderr, "usage: neuflow-bench-pipeline [--model CKPT] [--threads N] [--size WxH] [--frames N]\n");
      return 64;
    }
  }
  if (frames < 4) frames = 4;
  // The pipeline first, then the core: neither runs while the other's threads wind down.
  const double pipe = pipeline_seconds_per_frame(model, w, h, threads, frames);
  const double core = core_seconds_per_frame(model, w, h, threads, frames);
  std::printf("size %dx%d, %d threads, %d frames\n", w, h, threads, frames);
  std::printf("core stream:          %8.1f ms/frame\n", core * 1e3);
  std::printf("pipeline (every-pair): %7.1f ms/frame\n", pipe * 1e3);
  std::printf("pipeline / core:      %8.3f\n", pipe / core);
  return 0;
}
