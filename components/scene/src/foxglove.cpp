#include "skelgraph/scene/foxglove.hpp"

#include <cstring>

namespace skelgraph::scene {

namespace {

// Plain CDR (XCDR1), little endian, after the 4-byte encapsulation header
// (CDR_LE): every value aligned to its size from the end of the header,
// padding zeroed (so a decoder that encodes again gets the same bytes).
class Cdr {
 public:
  Cdr() : b_{0x00, 0x01, 0x00, 0x00} {}
  Cdr& operator<<(std::uint32_t v) { return raw(&v, sizeof v); }
  Cdr& operator<<(std::int32_t v) { return raw(&v, sizeof v); }
  Cdr& operator<<(double v) { return raw(&v, sizeof v); }
  Cdr& operator<<(bool v) {
    b_.push_back(v ? 1 : 0);
    return *this;
  }
  Cdr& operator<<(const std::string& s) {  // length with the terminating NUL, the bytes, the NUL
    *this << static_cast<std::uint32_t>(s.size() + 1);
    b_.insert(b_.end(), s.begin(), s.end());
    b_.push_back(0);
    return *this;
  }
  std::vector<std::uint8_t> take() { return std::move(b_); }

 private:
  Cdr& raw(const void* v, std::size_t n) {  // x86 and ARM are little endian, as the header says
    while ((b_.size() - 4) % n != 0) b_.push_back(0);
    const auto at = b_.size();
    b_.resize(at + n);
    std::memcpy(b_.data() + at, v, n);
    return *this;
  }
  std::vector<std::uint8_t> b_;
};
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the CDR writer assumes a little-endian machine");

void put(Cdr& c, const Eigen::Vector3d& v) { c << v.x() << v.y() << v.z(); }
void put(Cdr& c, const Eigen::Quaterniond& q) { c << q.x() << q.y() << q.z() << q.w(); }
void put(Cdr& c, const Color& k) { c << k.r << k.g << k.b << k.a; }
void put(Cdr& c, const Pose& p) {
  put(c, p.position);
  put(c, p.orientation);
}
void put_time(Cdr& c, std::int64_t ns) {  // foxglove::Time: unsigned seconds
  c << static_cast<std::uint32_t>(ns / 1'000'000'000) << static_cast<std::uint32_t>(ns % 1'000'000'000);
}
void put_duration(Cdr& c, std::int64_t ns) {  // foxglove::Duration: seconds signed, nanoseconds not
  auto sec = ns / 1'000'000'000, nsec = ns % 1'000'000'000;
  if (nsec < 0) {
    --sec;
    nsec += 1'000'000'000;
  }
  c << static_cast<std::int32_t>(sec) << static_cast<std::uint32_t>(nsec);
}
template <class T, class F>
void put_seq(Cdr& c, const std::vector<T>& v, F each) {
  c << static_cast<std::uint32_t>(v.size());
  for (const auto& x : v) each(x);
}
void put(Cdr& c, const Entity& e) {
  put_time(c, e.stamp_ns);
  c << e.frame_id << e.id;
  put_duration(c, e.lifetime_ns);
  c << e.frame_locked;
  put_seq(c, e.metadata, [&](const auto& kv) { c << kv.first << kv.second; });
  put_seq(c, e.arrows, [&](const Arrow& a) {
    put(c, a.pose);
    c << a.shaft_length << a.shaft_diameter << a.head_length << a.head_diameter;
    put(c, a.color);
  });
  c << std::uint32_t{0};  // cubes
  put_seq(c, e.spheres, [&](const Sphere& s) {
    put(c, s.pose);
    put(c, s.size);
    put(c, s.color);
  });
  put_seq(c, e.cylinders, [&](const Cylinder& y) {
    put(c, y.pose);
    put(c, y.size);
    c << y.bottom_scale << y.top_scale;
    put(c, y.color);
  });
  put_seq(c, e.lines, [&](const Line& l) {
    c << static_cast<std::uint32_t>(l.type);
    put(c, l.pose);
    c << l.thickness << l.scale_invariant;
    put_seq(c, l.points, [&](const Eigen::Vector3d& p) { put(c, p); });
    put(c, l.color);
    put_seq(c, l.colors, [&](const Color& k) { put(c, k); });
    put_seq(c, l.indices, [&](std::uint32_t i) { c << i; });
  });
  c << std::uint32_t{0};  // triangles
  put_seq(c, e.texts, [&](const Text& t) {
    put(c, t.pose);
    c << t.billboard << t.font_size << t.scale_invariant;
    put(c, t.color);
    c << t.text;
  });
  c << std::uint32_t{0};  // models
}

template <class F>
std::vector<std::uint8_t> encode(F body) {
  Cdr c;
  body(c);
  return c.take();
}

}  // namespace

std::vector<std::uint8_t> to_cdr(const SceneUpdate& u) {
  return encode([&](Cdr& c) {
    c << std::uint32_t{0};  // deletions
    put_seq(c, u.entities, [&](const Entity& e) { put(c, e); });
  });
}

std::vector<std::uint8_t> to_cdr(const FrameTransform& t) {
  return encode([&](Cdr& c) {
    put_time(c, t.stamp_ns);
    c << t.parent << t.child;
    put(c, t.translation);
    put(c, t.rotation);
  });
}

}  // namespace skelgraph::scene
