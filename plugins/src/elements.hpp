#pragma once
// The GTypes of the plugin's elements, for plugin.cpp.
#include <glib-object.h>

G_BEGIN_DECLS
GType gst_neuflow_get_type(void);
GType gst_neuflow_viz_get_type(void);
GType gst_neuflow_sink_get_type(void);
GType gst_neuflow_shm_sink_get_type(void);
G_END_DECLS
