#include "gstneuflow_enums.hpp"

#include <string_view>

#include "neuflow/model/session_settings.hpp"

namespace {

using neuflow::model::Backend;
using neuflow::model::Behaviour;
using neuflow::model::ChannelOrder;
using neuflow::model::Precision;

// Each value's nick is the model's own name for it (session_settings.hpp), so a launch line,
// the command and neuflowd's config spell the values alike.
template <typename E>
constexpr GEnumValue value(E e, const char *description, std::string_view nick) {
  return {static_cast<gint>(e), description, nick.data()};  // the names are string literals
}
constexpr GEnumValue kEnd{0, nullptr, nullptr};

const GEnumValue kChannelOrders[] = {
    value(ChannelOrder::rgb, "RGB, the order the published weights were trained with",
          channel_order_name(ChannelOrder::rgb)),
    value(ChannelOrder::bgr, "BGR, as the reference demo scripts feed it", channel_order_name(ChannelOrder::bgr)),
    kEnd};
const GEnumValue kBackends[] = {
    value(Backend::automatic, "the first discrete or integrated GPU (Vulkan), else the CPU",
          backend_name(Backend::automatic)),
    value(Backend::cpu, "the CPU (oneDNN)", backend_name(Backend::cpu)),
    value(Backend::vulkan, "a Vulkan device (see 'device'), software ones included", backend_name(Backend::vulkan)),
    kEnd};
const GEnumValue kPrecisions[] = {
    value(Precision::fp32, "32-bit floats: exact to the reference", precision_name(Precision::fp32)),
    value(Precision::fp16, "16-bit storage on devices with shaderFloat16 (else fp32, with a warning)",
          precision_name(Precision::fp16)),
    kEnd};
const GEnumValue kBehaviours[] = {
    value(Behaviour::automatic, "live for live sources, every-pair otherwise", behaviour_name(Behaviour::automatic)),
    value(Behaviour::live, "hold real-time: newest frame wins, late frames dropped", behaviour_name(Behaviour::live)),
    value(Behaviour::every_pair, "every consecutive pair, upstream waits, nothing dropped",
          behaviour_name(Behaviour::every_pair)),
    kEnd};

// One GType per values table, registered on first use.
template <const GEnumValue *Values>
GType enum_type(const char *name) {
  static GType type = 0;
  if (g_once_init_enter(&type)) g_once_init_leave(&type, g_enum_register_static(name, Values));
  return type;
}

}  // namespace

GType gst_neuflow_channel_order_get_type() { return enum_type<kChannelOrders>("GstNeuflowChannelOrder"); }
GType gst_neuflow_backend_get_type() { return enum_type<kBackends>("GstNeuflowBackend"); }
GType gst_neuflow_precision_get_type() { return enum_type<kPrecisions>("GstNeuflowPrecision"); }
GType gst_neuflow_behaviour_get_type() { return enum_type<kBehaviours>("GstNeuflowBehaviour"); }
