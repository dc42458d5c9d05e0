#pragma once
// GStreamer elements as values: a factory, a name and properties in their string form, linked
// in a chain. A graph plan is written once as chains; from them come the elements themselves,
// the list of factories a machine must have, and gst-launch text (the RTSP server's media).
#include <gst/gst.h>

#include <string>
#include <utility>
#include <vector>

namespace neuflow::pipeline {

struct ChildElement;

struct ElementSpec {
  std::string factory;
  std::string name;  // empty: GStreamer chooses
  // Set in order from their string form, so GStreamer converts each to the property's own
  // type (integers, enums by nick, caps, booleans).
  std::vector<std::pair<std::string, std::string>> properties;
  // Properties whose value is an element of its own (splitmuxsink's muxer and sink).
  std::vector<ChildElement> children;

  ElementSpec& set(std::string property, std::string value) {
    properties.emplace_back(std::move(property), std::move(value));
    return *this;
  }
};

struct ChildElement {
  std::string property;
  ElementSpec element;
};

using ElementChain = std::vector<ElementSpec>;

ElementSpec element(std::string factory, std::string name = {});
// A capsfilter holding these caps ("video/x-raw,width=320").
ElementSpec caps_filter(std::string caps, std::string name = {});

// Every factory the chain uses, children included, each once, in order of appearance.
std::vector<std::string> factories_of(const ElementChain& chain);

// gst-launch-1.0 syntax: "a p=v ! b ! video/x-raw,format=I420 ! c name=n". Throws
// std::logic_error for a chain with element-valued properties (launch syntax has none).
std::string launch_text(const ElementChain& chain);

// The element with its properties set (floating reference). Throws std::runtime_error naming
// the factory when it is not installed, or the property when the element has none by that name.
GstElement* make_element(const ElementSpec& spec);

}  // namespace neuflow::pipeline
