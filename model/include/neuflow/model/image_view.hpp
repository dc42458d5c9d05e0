#pragma once
// A frame as the core takes it from a caller: the session, the backends' frame conversion and
// the plugin's frame converter all read this, so it lives apart from the session's header.
#include <cstddef>
#include <cstdint>

#include "neuflow/model/session_settings.hpp"

namespace neuflow::model {

// An 8-bit, 3-channel interleaved image; `stride` is the number of bytes between rows and
// `order` the order its pixels hold (the session feeds the network SessionOptions::network_order).
struct ImageView {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;
  ChannelOrder order = ChannelOrder::rgb;
};

}  // namespace neuflow::model
