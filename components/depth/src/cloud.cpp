#include "skelgraph/depth/cloud.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace skelgraph::depth {

Points to_points(const DepthImage& image, int stride, double max_depth_m) {
  check(image);
  stride = std::max(stride, 1);
  const auto& k = image.intrinsics;
  const auto max_mm = static_cast<std::uint32_t>(std::lround(max_depth_m * 1000.0));
  Points out;
  out.reserve(image.mm.size() / static_cast<std::size_t>(stride * stride) / 2);
  for (int v = 0; v < k.height; v += stride) {
    for (int u = 0; u < k.width; u += stride) {
      const std::uint16_t z = image.at(u, v);
      if (z == 0 || z > max_mm) continue;
      out.push_back(unproject(k, u, v, z * 1e-3).cast<float>());
    }
  }
  return out;
}

Points to_points(const DepthImage& image, const std::vector<std::uint8_t>& mask, int stride) {
  check(image);
  if (mask.size() != image.mm.size()) throw std::invalid_argument("to_points: mask size differs from the image");
  stride = std::max(stride, 1);
  const auto& k = image.intrinsics;
  Points out;
  for (int v = 0; v < k.height; v += stride) {
    for (int u = 0; u < k.width; u += stride) {
      const auto i = static_cast<std::size_t>(v) * k.width + u;
      if (mask[i] == 0 || image.mm[i] == 0) continue;
      out.push_back(unproject(k, u, v, image.mm[i] * 1e-3).cast<float>());
    }
  }
  return out;
}

namespace {
struct VoxelKeyHash {
  std::size_t operator()(const Eigen::Vector3i& k) const {
    return (static_cast<std::size_t>(k.x()) * 73856093u) ^ (static_cast<std::size_t>(k.y()) * 19349663u) ^
           (static_cast<std::size_t>(k.z()) * 83492791u);
  }
};
struct VoxelKeyEq {
  bool operator()(const Eigen::Vector3i& a, const Eigen::Vector3i& b) const { return a == b; }
};
}  // namespace

Points voxel_downsample(const Points& points, double voxel_m) {
  if (!(voxel_m > 0)) throw std::invalid_argument("voxel_downsample: voxel size must be positive");
  std::unordered_map<Eigen::Vector3i, std::size_t, VoxelKeyHash, VoxelKeyEq> index;
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  const double inv = 1.0 / voxel_m;
  for (const auto& p : points) {
    const Eigen::Vector3i key((p.cast<double>() * inv).array().floor().cast<int>());
    auto [it, fresh] = index.try_emplace(key, sums.size());
    if (fresh) {
      sums.emplace_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    sums[it->second] += p.cast<double>();
    ++counts[it->second];
  }
  Points out;
  out.reserve(sums.size());
  for (std::size_t i = 0; i < sums.size(); ++i) out.push_back((sums[i] / counts[i]).cast<float>());
  return out;
}

Points transformed(const Points& points, const Eigen::Isometry3d& pose) {
  const Eigen::Isometry3f f = pose.cast<float>();
  Points out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(f * p);
  return out;
}

Points merge_clouds(const std::vector<SensorCloud>& clouds, double voxel_m) {
  Points all;
  for (const auto& c : clouds) {
    const auto moved = transformed(c.points, c.pose);
    all.insert(all.end(), moved.begin(), moved.end());
  }
  return voxel_downsample(all, voxel_m);
}

// --- background ---

BackgroundModel::BackgroundModel(Options options) : opt_(options) {
  if (!(opt_.margin_m >= 0) || !(opt_.margin_per_m2 >= 0) || opt_.frames_to_learn < 1) {
    throw std::invalid_argument("background model: margins must be >= 0 and frames_to_learn >= 1");
  }
}

namespace {
double margin_mm(const BackgroundModel::Options& o, double z_mm) {
  const double z = z_mm * 1e-3;
  return (o.margin_m + o.margin_per_m2 * z * z) * 1000.0;
}
}  // namespace

void BackgroundModel::learn(const DepthImage& image) {
  check(image);
  if (frames_ == 0) {
    width_ = image.width();
    height_ = image.height();
    background_.assign(image.mm.size(), 0);
    candidate_.assign(image.mm.size(), 0);
    seen_.assign(image.mm.size(), 0);
  } else if (image.width() != width_ || image.height() != height_) {
    throw std::invalid_argument("background model: image is " + std::to_string(image.width()) + "x" +
                                std::to_string(image.height()) + ", the model was learnt at " +
                                std::to_string(width_) + "x" + std::to_string(height_));
  }
  constexpr int kConfirm = 3;  // frames a farther reading must persist to become the background
  for (std::size_t i = 0; i < image.mm.size(); ++i) {
    const double z = image.mm[i];
    if (z == 0) continue;
    auto& bg = background_[i];
    if (bg == 0) {
      bg = image.mm[i];
      continue;
    }
    const double m = margin_mm(opt_, z);
    if (z > bg + m) {
      if (candidate_[i] != 0 && std::abs(z - candidate_[i]) <= m) {
        if (++seen_[i] >= kConfirm) {
          bg = candidate_[i];
          candidate_[i] = 0;
          seen_[i] = 0;
        }
      } else {
        candidate_[i] = image.mm[i];
        seen_[i] = 1;
      }
    } else if (z >= bg - m) {
      bg = static_cast<std::uint16_t>(std::lround((7.0 * bg + z) / 8.0));  // follow slow drift, average the noise
    }
  }
  ++frames_;
}

std::vector<std::uint8_t> BackgroundModel::foreground(const DepthImage& image) const {
  check(image);
  std::vector<std::uint8_t> mask(image.mm.size(), 0);
  const bool sized = image.width() == width_ && image.height() == height_;
  for (std::size_t i = 0; i < image.mm.size(); ++i) {
    const double z = image.mm[i];
    if (z == 0) continue;
    const double bg = sized ? background_[i] : 0.0;
    mask[i] = (bg == 0 || z < bg - margin_mm(opt_, z)) ? 1 : 0;
  }
  return mask;
}

// --- segmentation ---

Segmentation segment(const DepthImage& image, const std::vector<std::uint8_t>& mask, double max_step_m,
                     std::size_t min_pixels) {
  check(image);
  if (mask.size() != image.mm.size()) throw std::invalid_argument("segment: mask size differs from the image");
  const int w = image.width(), h = image.height();
  const double step_mm = max_step_m * 1000.0;
  Segmentation seg;
  seg.labels.assign(mask.size(), 0);
  std::vector<std::size_t> stack;
  std::vector<std::size_t> members;
  std::uint32_t next = 1;
  constexpr std::uint32_t kDropped = 0xffffffffu;
  for (std::size_t start = 0; start < mask.size(); ++start) {
    if (mask[start] == 0 || image.mm[start] == 0 || seg.labels[start] != 0) continue;
    const std::uint32_t label = next++;
    members.clear();
    stack.assign(1, start);
    seg.labels[start] = label;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      members.push_back(i);
      const int u = static_cast<int>(i % w), v = static_cast<int>(i / w);
      const double z = image.mm[i];
      const auto visit = [&](int uu, int vv) {
        if (uu < 0 || vv < 0 || uu >= w || vv >= h) return;
        const auto j = static_cast<std::size_t>(vv) * w + uu;
        if (seg.labels[j] != 0 || mask[j] == 0 || image.mm[j] == 0) return;
        if (std::abs(image.mm[j] - z) > step_mm) return;
        seg.labels[j] = label;
        stack.push_back(j);
      };
      visit(u - 1, v);
      visit(u + 1, v);
      visit(u, v - 1);
      visit(u, v + 1);
    }
    if (members.size() < min_pixels) {
      for (auto i : members) seg.labels[i] = kDropped;  // visited; cleared at the end
      continue;
    }
    Region r;
    r.label = label;
    r.pixels = members.size();
    for (auto i : members) {
      const Eigen::Vector3d p =
          unproject(image.intrinsics, static_cast<double>(i % w), static_cast<double>(i / w), image.mm[i] * 1e-3);
      r.centroid += p;
      r.bounds.extend(p);
    }
    r.centroid /= static_cast<double>(members.size());
    seg.regions.push_back(r);
  }
  for (auto& l : seg.labels) {
    if (l == kDropped) l = 0;
  }
  std::sort(seg.regions.begin(), seg.regions.end(), [](const Region& a, const Region& b) { return a.pixels > b.pixels; });
  return seg;
}

}  // namespace skelgraph::depth
