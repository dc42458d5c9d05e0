#pragma once
// The plugin's elements, each registered by the file that defines it
// (GST_ELEMENT_REGISTER_DEFINE), for plugin.cpp.
#include <gst/gst.h>

G_BEGIN_DECLS
GST_ELEMENT_REGISTER_DECLARE(neuflow);
GST_ELEMENT_REGISTER_DECLARE(neuflowviz);
GST_ELEMENT_REGISTER_DECLARE(neuflowsink);
GST_ELEMENT_REGISTER_DECLARE(neuflowshmsink);
G_END_DECLS
