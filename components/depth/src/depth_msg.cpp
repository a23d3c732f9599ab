#include "skelgraph/depth/depth_msg.hpp"

namespace skelgraph::depth {

namespace {
msg::DepthFrame header(const DepthImage& d) {
  msg::DepthFrame m;
  m.sensor_id(d.sensor_id.substr(0, 64));
  m.stamp_ns(d.stamp_ns);
  m.frame_number(d.frame_number);
  m.width(static_cast<std::uint32_t>(d.width()));
  m.height(static_cast<std::uint32_t>(d.height()));
  m.intrinsics().fx(d.intrinsics.fx);
  m.intrinsics().fy(d.intrinsics.fy);
  m.intrinsics().cx(d.intrinsics.cx);
  m.intrinsics().cy(d.intrinsics.cy);
  return m;
}
}  // namespace

msg::DepthFrame to_msg(const DepthImage& image) {
  auto m = header(image);
  m.depth_mm(image.mm);
  return m;
}

msg::DepthFrame to_msg(DepthImage&& image) {
  auto m = header(image);
  m.depth_mm(std::move(image.mm));
  return m;
}

DepthImage from_msg(const msg::DepthFrame& m) {
  DepthImage d;
  d.sensor_id = m.sensor_id();
  d.stamp_ns = m.stamp_ns();
  d.frame_number = m.frame_number();
  d.intrinsics.width = static_cast<int>(m.width());
  d.intrinsics.height = static_cast<int>(m.height());
  d.intrinsics.fx = m.intrinsics().fx();
  d.intrinsics.fy = m.intrinsics().fy();
  d.intrinsics.cx = m.intrinsics().cx();
  d.intrinsics.cy = m.intrinsics().cy();
  d.mm = m.depth_mm();
  check(d);
  return d;
}

}  // namespace skelgraph::depth
