// Registers the plugin's elements; each element lives in its own gst<name>.cpp.
#include <gst/gst.h>

#include "elements.hpp"

static gboolean plugin_init(GstPlugin *plugin) {
  gboolean ok = TRUE;
  ok &= GST_ELEMENT_REGISTER(neuflow, plugin);
  ok &= GST_ELEMENT_REGISTER(neuflowviz, plugin);
  ok &= GST_ELEMENT_REGISTER(neuflowsink, plugin);
  ok &= GST_ELEMENT_REGISTER(neuflowshmsink, plugin);
  return ok;
}

#define PACKAGE "neuflow"
GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, neuflow,
                  "NeuFlow-V2 optical flow: inference, visualization, flow file and shared-memory output", plugin_init,
                  NEUFLOW_VERSION, "MIT/X11", "neuflow", NEUFLOW_ORIGIN_URL)
