#include "neuflow/eval/pair_figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "neuflow/flow/figures.hpp"
#include "neuflow/flow/metrics.hpp"

namespace neuflow::eval {

namespace {

constexpr int kGap = 4;
constexpr std::uint8_t kGapGrey = 128;

void paste(flow::RgbImage& canvas, const flow::RgbImage& panel, int left) {
  for (int y = 0; y < panel.height; ++y) {
    std::copy_n(panel.rgb.begin() + static_cast<std::ptrdiff_t>(3) * y * panel.width, 3 * panel.width,
                canvas.rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * canvas.width + left));
  }
}

std::string xml_text(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// A value with `decimals` digits after the point.
std::string number(double v, int decimals = 3) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

flow::RgbImage pair_figure(const flow::FlowField& predicted, const flow::FlowField& ground_truth) {
  if (predicted.width != ground_truth.width || predicted.height != ground_truth.height) {
    throw std::invalid_argument("the prediction and the ground truth differ in size");
  }
  flow::VisualizeOptions options;
  options.max_flow = std::max(flow::max_flow_magnitude(ground_truth), 1e-6);  // one scale for both flows
  flow::FlowField masked = predicted;
  masked.valid = ground_truth.valid;  // the prediction is shown where the ground truth is known
  flow::RgbImage left = flow::visualize_flow(masked, options).image;
  flow::RgbImage middle = flow::visualize_flow(ground_truth, options).image;
  flow::RgbImage right = flow::error_map(predicted, ground_truth);
  flow::draw_label(left, "prediction");
  flow::draw_label(middle, "ground truth");
  const double epe = flow::compute_metrics(predicted, ground_truth).epe;
  flow::draw_label(right, std::isfinite(epe) ? "error, EPE " + number(epe, 2) + " px" : std::string("error"));
  flow::draw_key(middle, *options.max_flow);  // the scale of both flow panels

  const int w = ground_truth.width, h = ground_truth.height;
  flow::RgbImage canvas{3 * w + 2 * kGap, h, {}};
  canvas.rgb.assign(3 * static_cast<std::size_t>(canvas.width) * h, kGapGrey);
  paste(canvas, left, 0);
  paste(canvas, middle, w + kGap);
  paste(canvas, right, 2 * (w + kGap));
  return canvas;
}

void write_pair_figure(const flow::FlowField& predicted, const flow::FlowField& ground_truth,
                       const std::filesystem::path& path) {
  flow::write_rgb_png(pair_figure(predicted, ground_truth), path);
}

void write_epe_plot(const std::vector<SetResult>& results, const std::filesystem::path& path) {
  constexpr int kBar = 18, kLabel = 220, kWidth = 760, kTitle = 28, kMargin = 10;
  double largest = 0;
  std::size_t bars = 0;
  for (const auto& set : results) {
    for (const auto& seq : set.sequences) {
      if (std::isfinite(seq.summary.epe)) largest = std::max(largest, seq.summary.epe);
      ++bars;
    }
  }
  const int height = kMargin * 2 + static_cast<int>(results.size()) * kTitle + static_cast<int>(bars) * kBar;
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(kWidth) + "\" height=\"" +
                    std::to_string(height) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  svg += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  int y = kMargin;
  const double scale = largest > 0 ? (kWidth - kLabel - 80) / largest : 0;
  for (const auto& set : results) {
    svg += "<text x=\"" + std::to_string(kMargin) + "\" y=\"" + std::to_string(y + 18) + "\" font-weight=\"bold\">" +
           xml_text(set.name) + ": EPE " + number(set.summary.epe) + " px</text>\n";
    y += kTitle;
    for (const auto& seq : set.sequences) {
      const double epe = seq.summary.epe;
      const double length = std::isfinite(epe) ? epe * scale : kWidth - kLabel - 80;
      svg += "<text x=\"" + std::to_string(kLabel - 6) + "\" y=\"" + std::to_string(y + 13) +
             "\" text-anchor=\"end\">" + xml_text(seq.name) + "</text>\n";
      svg += "<rect x=\"" + std::to_string(kLabel) + "\" y=\"" + std::to_string(y + 2) + "\" width=\"" +
             number(length, 1) + "\" height=\"" + std::to_string(kBar - 4) + "\" fill=\"" +
             (std::isfinite(epe) ? "#4c72b0" : "#c44e52") + "\"/>\n";
      svg += "<text x=\"" + number(kLabel + length + 4, 1) + "\" y=\"" + std::to_string(y + 13) + "\">" +
             (std::isfinite(epe) ? number(epe) : std::string(std::isnan(epe) ? "no pixels" : "inf")) + "</text>\n";
      y += kBar;
    }
  }
  svg += "</svg>\n";
  const std::filesystem::path temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << svg;
    if (!out.flush()) {
      std::error_code ec;
      std::filesystem::remove(temporary, ec);
      throw std::runtime_error(path.string() + ": cannot write the plot");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw std::runtime_error(path.string() + ": cannot write the plot (" + ec.message() + ")");
  }
}

}  // namespace neuflow::eval
