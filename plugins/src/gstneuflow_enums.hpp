#pragma once
// The `neuflow` element's enum property types (gst-inspect shows their values): each value is the
// model's enumerator of the same name (session_settings.hpp), so a property value casts to it.
#include <glib-object.h>

GType gst_neuflow_channel_order_get_type();
GType gst_neuflow_backend_get_type();
GType gst_neuflow_precision_get_type();
GType gst_neuflow_behaviour_get_type();
