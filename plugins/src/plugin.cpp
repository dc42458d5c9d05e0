// Registers the plugin's elements; each element lives in its own gst<name>.cpp.
#include <gst/gst.h>

#include "elements.hpp"

static gboolean plugin_init(GstPlugin *plugin) {
  gboolean ok = TRUE;
  ok &= gst_element_register(plugin, "neuflow", GST_RANK_NONE, gst_neuflow_get_type());
  ok &= gst_element_register(plugin, "neuflowviz", GST_RANK_NONE, gst_neuflow_viz_get_type());
  ok &= gst_element_register(plugin, "neuflowsink", GST_RANK_NONE, gst_neuflow_sink_get_type());
  ok &= gst_element_register(plugin, "neuflowshmsink", GST_RANK_NONE, gst_neuflow_shm_sink_get_type());
  return ok;
}

#define PACKAGE "neuflow"
GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, neuflow,
                  "NeuFlow-V2 optical flow: inference, visualization, flow file and shared-memory output", plugin_init,
                  NEUFLOW_VERSION, "Proprietary", "neuflow", "neuflow")
