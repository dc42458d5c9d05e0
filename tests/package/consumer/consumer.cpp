// Flow between two synthetic frames (the second is the first moved right by 2 pixels) with the
// installed core, written as a .flo file and read back: what a program built against the
// neuflow-dev package does. Usage: neuflow_consumer CHECKPOINT OUT.flo
#include <cmath>
#include <cstdint>
#include <exception>
#include <iostream>
#include <vector>

#include "neuflow/flow/flow_io.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"

namespace {

constexpr int kWidth = 96;
constexpr int kHeight = 64;

std::vector<std::uint8_t> pattern(int shift) {
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(kWidth) * kHeight * 3);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double u = x - shift;
      for (int c = 0; c < 3; ++c) {
        const double v = 127.5 + 100.0 * std::sin(0.21 * u + 0.9 * c) * std::cos(0.17 * y);
        rgb[(static_cast<std::size_t>(y) * kWidth + x) * 3 + c] = static_cast<std::uint8_t>(v);
      }
    }
  }
  return rgb;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: neuflow_consumer CHECKPOINT OUT.flo\n";
    return 64;
  }
  try {
    const auto model = neuflow::model::FlowModel::load(argv[1]);
    neuflow::model::SessionOptions options;
    options.backend = neuflow::model::Backend::cpu;
    neuflow::model::FlowSession session(model, options);
    const auto first = pattern(0);
    const auto second = pattern(2);
    const neuflow::model::ImageView a{first.data(), kWidth, kHeight, kWidth * 3};
    const neuflow::model::ImageView b{second.data(), kWidth, kHeight, kWidth * 3};
    const auto flow = session.compute(a, b);
    neuflow::flow::write_flow(flow, argv[2]);
    const auto back = neuflow::flow::read_flow(argv[2]);
    if (back.width != flow.width || back.height != flow.height || back.uv != flow.uv) {
      std::cerr << "neuflow_consumer: " << argv[2] << " does not read back as written\n";
      return 1;
    }
    double mean_u = 0;
    for (std::size_t i = 0; i < flow.pixel_count(); ++i) mean_u += flow.uv[2 * i];
    mean_u /= static_cast<double>(flow.pixel_count());
    std::cout << "neuflow_consumer: " << flow.width << "x" << flow.height << " flow on "
              << session.backend_description() << ", mean u " << mean_u << ", written to " << argv[2]
              << " and read back\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "neuflow_consumer: " << e.what() << "\n";
    return 1;
  }
}
