#pragma once
// Arrows over a flow field, as the `neuflowviz` element and the `neuflow` command draw them: one
// anti-aliased arrow from the centre of each spacing × spacing cell of the picture, showing the
// vector of the field under it (nearest; the field is stretched over the picture).
#include <cstdint>
#include <vector>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::flow {

// Pixels between arrows by default: the element's arrow-spacing and `neuflow viz`'s.
inline constexpr int kArrowSpacing = 24;

// The arrows' coverage, 0 (none) to 255, over a width × height picture, row-major: each
// vector times `scale`, at most `max_length` pixels long (longer ones are shortened), clipped
// to the picture; a vector under a pixel long, or not finite, marks just its anchor.
// `coverage` is resized and overwritten (callers that draw every frame keep it).
// Throws std::invalid_argument for a spacing under 1, an empty field or picture.
void arrow_coverage(const FlowField& field, int width, int height, int spacing, double scale, double max_length,
                    std::vector<std::uint8_t>& coverage);

// The usual scale: a vector of `max_flow` pixels is drawn one spacing long, longer ones no
// longer, so arrows stay within their cell.
struct ArrowScale {
  double scale = 1;
  double max_length = 0;
};
ArrowScale automatic_arrow_scale(int spacing, double max_flow);

}  // namespace neuflow::flow
