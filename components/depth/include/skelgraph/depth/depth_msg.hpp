#pragma once
// Conversion between DepthImage and the wire type msg::DepthFrame (adapters only).

#include "skelgraph/depth/depth_image.hpp"
#include "skelgraph/msg/messages.hpp"

namespace skelgraph::depth {

msg::DepthFrame to_msg(const DepthImage& image);
msg::DepthFrame to_msg(DepthImage&& image);  // moves the pixels
// Throws std::invalid_argument when the frame's size and data disagree.
DepthImage from_msg(const msg::DepthFrame& m);

}  // namespace skelgraph::depth
