#include "gstneuflow_enums.hpp"

#include "neuflow/model/session_settings.hpp"

using neuflow::model::Backend;
using neuflow::model::Behaviour;
using neuflow::model::ChannelOrder;
using neuflow::model::Precision;

// An enum GType from its values' (value, description, nick) triples.
static GType gst_neuflow_register_enum(GType &type, const char *name, const GEnumValue *values) {
  if (g_once_init_enter(&type)) g_once_init_leave(&type, g_enum_register_static(name, values));
  return type;
}

GType gst_neuflow_channel_order_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(ChannelOrder::rgb), "RGB, the order the published weights were trained with", "rgb"},
      {static_cast<gint>(ChannelOrder::bgr), "BGR, as the reference demo scripts feed it", "bgr"},
      {0, nullptr, nullptr}};
  return gst_neuflow_register_enum(type, "GstNeuflowChannelOrder", values);
}

GType gst_neuflow_backend_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(Backend::automatic), "the first discrete or integrated GPU (Vulkan), else the CPU", "auto"},
      {static_cast<gint>(Backend::cpu), "the CPU (oneDNN)", "cpu"},
      {static_cast<gint>(Backend::vulkan), "a Vulkan device (see 'device'), software ones included", "vulkan"},
      {0, nullptr, nullptr}};
  return gst_neuflow_register_enum(type, "GstNeuflowBackend", values);
}

GType gst_neuflow_precision_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(Precision::fp32), "32-bit floats: exact to the reference", "fp32"},
      {static_cast<gint>(Precision::fp16), "16-bit storage on devices with shaderFloat16 (else fp32, with a warning)",
       "fp16"},
      {0, nullptr, nullptr}};
  return gst_neuflow_register_enum(type, "GstNeuflowPrecision", values);
}

GType gst_neuflow_behaviour_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(Behaviour::automatic), "live for live sources, every-pair otherwise", "auto"},
      {static_cast<gint>(Behaviour::live), "hold real-time: newest frame wins, late frames dropped", "live"},
      {static_cast<gint>(Behaviour::every_pair), "every consecutive pair, upstream waits, nothing dropped",
       "every-pair"},
      {0, nullptr, nullptr}};
  return gst_neuflow_register_enum(type, "GstNeuflowBehaviour", values);
}
