#pragma once
// A video frame rate as GStreamer states it: a fraction of frames per second.
namespace neuflow::pipeline {

struct FrameRate {
  int numerator = 0;  // 0: unknown or variable
  int denominator = 1;

  bool known() const { return numerator > 0 && denominator > 0; }
  double fps() const { return known() ? static_cast<double>(numerator) / denominator : 0.0; }
};

}  // namespace neuflow::pipeline
