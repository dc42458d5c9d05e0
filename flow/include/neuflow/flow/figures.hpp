#pragma once
// Pictures of flow fields for people to look at, beyond the colour rendering itself
// (visualize.hpp): the colour key, arrows, the rendering over the video frame, the end-point
// error as a colour map with its scale, and panel labels. `neuflow viz`, `compare --error-map`,
// `convert --viz-mode` and `eval --save-viz` draw with these.
#include <cstdint>
#include <string>

#include "neuflow/flow/colorwheel.hpp"
#include "neuflow/flow/flow_field.hpp"
#include "neuflow/flow/visualize.hpp"

namespace neuflow::flow {

// The colour wheel as a disc in the bottom-right corner, its rim at `max_flow` pixels (the
// rendering's saturation), labelled with that value, so a reader can tell direction and speed.
// Sized to the picture (a sixth of its shorter side, 12 to 64 px of radius).
void draw_key(RgbImage& image, double max_flow);

// Arrows (arrows.hpp) over the picture, the field stretched over it, in `colour`.
void draw_arrows(RgbImage& image, const FlowField& field, int spacing, double scale, double max_length,
                 Rgb8 colour = {0, 0, 0});

// The opacity of the colours over a video frame wherever a default is needed: the neuflowviz
// element's alpha, `neuflow viz --overlay`'s and `convert --viz-mode overlay`'s.
inline constexpr double kOverlayAlpha = 0.6;

// `over` blended onto `under` with opacity `alpha` (0: under only, 1: over only). Throws
// std::invalid_argument when the sizes differ or alpha is outside [0, 1].
RgbImage blend(const RgbImage& under, const RgbImage& over, double alpha);

// The end-point error |predicted - ground truth| of every pixel the ground truth marks valid,
// through a perceptual colour map (dark: small, bright yellow: `max_error` and above; a
// non-finite prediction is the largest error), grey where nothing is scored, with a colour bar
// labelled 0 and max_error at the right edge. max_error <= 0: the largest finite error (at
// least 1 px). Throws std::invalid_argument when the fields differ in size.
RgbImage error_map(const FlowField& predicted, const FlowField& ground_truth, double max_error = 0);

// `text` in the top-left corner, white on a dark box, sized to the picture.
void draw_label(RgbImage& image, const std::string& text);

}  // namespace neuflow::flow
