#include "neuflow/pipeline/element_chain.hpp"

#include <algorithm>
#include <stdexcept>

namespace neuflow::pipeline {

namespace {

void collect_factories(const ElementSpec& spec, std::vector<std::string>& out) {
  if (std::find(out.begin(), out.end(), spec.factory) == out.end()) out.push_back(spec.factory);
  for (const auto& child : spec.children) collect_factories(child.element, out);
}

// A value as gst-launch reads it: quoted when it holds anything but a plain word.
std::string launch_value(const std::string& value) {
  const bool plain = !value.empty() && std::all_of(value.begin(), value.end(), [](char c) {
    return g_ascii_isalnum(c) || c == '-' || c == '_' || c == '.';
  });
  if (plain) return value;
  std::string quoted = "\"";
  for (const char c : value) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

ElementSpec element(std::string factory, std::string name) {
  ElementSpec spec;
  spec.factory = std::move(factory);
  spec.name = std::move(name);
  return spec;
}

ElementSpec caps_filter(std::string caps, std::string name) {
  return element("capsfilter", std::move(name)).set("caps", std::move(caps));
}

std::vector<std::string> factories_of(const ElementChain& chain) {
  std::vector<std::string> out;
  for (const auto& spec : chain) collect_factories(spec, out);
  return out;
}

std::string launch_text(const ElementChain& chain) {
  std::string text;
  for (const auto& spec : chain) {
    if (!spec.children.empty())
      throw std::logic_error(spec.factory + ": element-valued properties have no launch syntax");
    if (!text.empty()) text += " ! ";
    // A bare capsfilter reads best (and is written most often) as its caps.
    if (spec.factory == "capsfilter" && spec.name.empty() && spec.properties.size() == 1 &&
        spec.properties[0].first == "caps") {
      text += spec.properties[0].second;
      continue;
    }
    text += spec.factory;
    if (!spec.name.empty()) text += " name=" + launch_value(spec.name);
    for (const auto& [property, value] : spec.properties) text += " " + property + "=" + launch_value(value);
  }
  return text;
}

GstElement* make_element(const ElementSpec& spec) {
  GstElement* e = gst_element_factory_make(spec.factory.c_str(), spec.name.empty() ? nullptr : spec.name.c_str());
  if (!e) {
    throw std::runtime_error("the GStreamer element '" + spec.factory +
                             "' is not installed (or the neuflow plugin is not on GST_PLUGIN_PATH)");
  }
  try {
    for (const auto& [property, value] : spec.properties) {
      if (!g_object_class_find_property(G_OBJECT_GET_CLASS(e), property.c_str())) {
        throw std::runtime_error("element " + std::string(GST_ELEMENT_NAME(e)) + " has no property '" + property +
                                 "' (is the installed plugin older than this program?)");
      }
      gst_util_set_object_arg(G_OBJECT(e), property.c_str(), value.c_str());
    }
    for (const auto& child : spec.children) {
      GstElement* c = make_element(child.element);
      g_object_set(e, child.property.c_str(), c, nullptr);  // takes the floating reference
    }
  } catch (...) {
    gst_object_unref(gst_object_ref_sink(e));  // still floating: nobody else holds it
    throw;
  }
  return e;
}

}  // namespace neuflow::pipeline
