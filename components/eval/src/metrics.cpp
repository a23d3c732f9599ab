#include "skelgraph/eval/metrics.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <limits>

namespace skelgraph::eval {

using skeleton::JointId;

const std::array<const char*, kGroupCount>& group_names() {
  static const std::array<const char*, kGroupCount> n{"Head", "Neck", "Torso", "Shoulders", "Elbows", "Hands"};
  return n;
}

int group_of(JointId j) {
  switch (j) {
    case JointId::Head: return 0;
    case JointId::Neck: return 1;
    case JointId::Torso: return 2;
    case JointId::LeftShoulder:
    case JointId::RightShoulder: return 3;
    case JointId::LeftElbow:
    case JointId::RightElbow: return 4;
    case JointId::LeftHand:
    case JointId::RightHand: return 5;
    default: return -1;
  }
}

void Accumulator::add(const skeleton::Skeleton& estimate, const skeleton::Skeleton& truth) {
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    const int g = group_of(skeleton::joint_at(j));
    if (g < 0) continue;
    joint_frames_[g] += 1;
    if (estimate.joints[j].confidence < skeleton::kTracked) continue;
    tracked_[g] += 1;
    error_sum_[g] += (estimate.joints[j].position - truth.joints[j].position).norm();
  }
}

void Accumulator::add_missed(std::uint64_t frames) {
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    const int g = group_of(skeleton::joint_at(j));
    if (g >= 0) joint_frames_[g] += static_cast<double>(frames);
  }
}

Figures Accumulator::figures() const {
  Figures f;
  for (std::size_t g = 0; g < kGroupCount; ++g) {
    f[g].joint_frames = static_cast<std::uint64_t>(joint_frames_[g]);
    f[g].tracked = static_cast<std::uint64_t>(tracked_[g]);
    f[g].detection_pct = joint_frames_[g] > 0 ? 100.0 * tracked_[g] / joint_frames_[g] : 0.0;
    f[g].error_cm = tracked_[g] > 0 ? 100.0 * error_sum_[g] / tracked_[g] : std::nan("");
  }
  return f;
}

double Accumulator::mean_error_cm() const {
  double n = 0, sum = 0;
  for (std::size_t g = 0; g < kGroupCount; ++g) {
    n += tracked_[g];
    sum += error_sum_[g];
  }
  return n > 0 ? 100.0 * sum / n : std::nan("");
}

double Accumulator::mean_group_error_cm() const {
  double sum = 0;
  int groups = 0;
  for (const auto& g : figures()) {
    if (std::isnan(g.error_cm)) continue;
    sum += g.error_cm;
    ++groups;
  }
  return groups > 0 ? sum / groups : std::nan("");
}

void TruthTimeline::add(const skeleton::Skeleton& truth, std::int64_t t_ns) {
  auto& v = by_person_[truth.person_id];
  if (!v.empty() && t_ns < v.back().first) {
    const auto it = std::upper_bound(v.begin(), v.end(), t_ns, [](std::int64_t t, const auto& p) { return t < p.first; });
    v.insert(it, {t_ns, truth});
  } else {
    v.emplace_back(t_ns, truth);
  }
}

namespace {
// Truth of one person at t, interpolated; empty if no sample is close enough.
std::optional<skeleton::Skeleton> interpolate(const std::vector<std::pair<std::int64_t, skeleton::Skeleton>>& v,
                                              std::int64_t t, std::int64_t max_gap) {
  if (v.empty()) return std::nullopt;
  const auto after = std::lower_bound(v.begin(), v.end(), t, [](const auto& p, std::int64_t x) { return p.first < x; });
  if (after != v.end() && after->first == t) return after->second;
  if (after == v.begin()) return after->first - t <= max_gap ? std::optional(after->second) : std::nullopt;
  const auto before = std::prev(after);
  if (after == v.end()) return t - before->first <= max_gap ? std::optional(before->second) : std::nullopt;
  if (after->first - before->first > 2 * max_gap) return std::nullopt;
  const double a = static_cast<double>(t - before->first) / static_cast<double>(after->first - before->first);
  skeleton::Skeleton s = before->second;
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    s.joints[j].position = (1 - a) * before->second.joints[j].position + a * after->second.joints[j].position;
  }
  s.stamp_ns = t;
  return s;
}
}  // namespace

std::optional<skeleton::Skeleton> TruthTimeline::at(std::int64_t t_ns, const Eigen::Vector3d& near,
                                                    std::int64_t max_gap_ns) const {
  std::optional<skeleton::Skeleton> best;
  double best_d = std::numeric_limits<double>::infinity();
  for (const auto& [id, v] : by_person_) {
    auto s = interpolate(v, t_ns, max_gap_ns);
    if (!s) continue;
    const double d = ((*s)[JointId::Torso].position - near).norm();
    if (d < best_d) {
      best_d = d;
      best = std::move(s);
    }
  }
  return best;
}

std::vector<skeleton::Skeleton> TruthTimeline::all_at(std::int64_t t_ns, std::int64_t max_gap_ns) const {
  std::vector<skeleton::Skeleton> out;
  for (const auto& [id, v] : by_person_) {
    if (auto s = interpolate(v, t_ns, max_gap_ns)) out.push_back(std::move(*s));
  }
  return out;
}

void TruthTimeline::forget_before(std::int64_t t_ns) {
  for (auto& [id, v] : by_person_) {
    const auto first_kept = std::lower_bound(v.begin(), v.end(), t_ns, [](const auto& p, std::int64_t x) { return p.first < x; });
    if (first_kept - v.begin() > 1) v.erase(v.begin(), first_kept - 1);
  }
}

bool TruthTimeline::covers(std::int64_t t_ns, std::int64_t max_gap_ns) const {
  return std::any_of(by_person_.begin(), by_person_.end(),
                     [&](const auto& p) { return interpolate(p.second, t_ns, max_gap_ns).has_value(); });
}

namespace {
struct Bone {
  const char* name;
  JointId a, b;
};
constexpr Bone kBones[] = {{"neck-head", JointId::Neck, JointId::Head},
                           {"torso-neck", JointId::Torso, JointId::Neck},
                           {"left upper arm", JointId::LeftShoulder, JointId::LeftElbow},
                           {"left forearm", JointId::LeftElbow, JointId::LeftHand},
                           {"right upper arm", JointId::RightShoulder, JointId::RightElbow},
                           {"right forearm", JointId::RightElbow, JointId::RightHand},
                           {"shoulders", JointId::LeftShoulder, JointId::RightShoulder}};
}  // namespace

bool upper_body_complete(const skeleton::Skeleton& s) {
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    if (group_of(skeleton::joint_at(j)) >= 0 && s.joints[j].confidence < skeleton::kTracked) return false;
  }
  return true;
}

void Steadiness::add(const skeleton::Skeleton& s) {
  ++frames_;
  if (upper_body_complete(s)) ++complete_;
  for (const auto& b : kBones) {
    if (s[b.a].confidence < skeleton::kTracked || s[b.b].confidence < skeleton::kTracked) continue;
    const double len = (s[b.a].position - s[b.b].position).norm();
    auto& m = bones_[{b.name, s.person_id}];
    m.n += 1;
    m.sum += len;
    m.sum2 += len * len;
  }
}

double Steadiness::upper_body_complete_pct() const {
  return frames_ > 0 ? 100.0 * static_cast<double>(complete_) / static_cast<double>(frames_) : 0.0;
}

std::map<std::string, double> Steadiness::bone_sd_cm() const {
  // Per bone: the within-person variances, pooled by frame count.
  std::map<std::string, std::pair<double, double>> pooled;  // bone -> (sum of n * var, sum of n)
  for (const auto& [key, m] : bones_) {
    if (m.n < 2) continue;
    const double mean = m.sum / m.n;
    auto& p = pooled[key.first];
    p.first += m.n * std::max(0.0, m.sum2 / m.n - mean * mean);
    p.second += m.n;
  }
  std::map<std::string, double> out;
  for (const auto& [name, p] : pooled) out[name] = 100.0 * std::sqrt(p.first / p.second);
  return out;
}

double Steadiness::mean_bone_sd_cm() const {
  const auto sd = bone_sd_cm();
  if (sd.empty()) return std::nan("");
  double sum = 0;
  for (const auto& [n, v] : sd) sum += v;
  return sum / static_cast<double>(sd.size());
}

namespace {
constexpr std::size_t kKeptForSpearman = 200000;
constexpr double kChi2Of3At95 = 7.8147;
// Nominal levels (%) and their chi-square(3) quantiles.
constexpr std::pair<double, double> kReliabilityLevels[] = {{10, 0.5844}, {20, 1.0052}, {30, 1.4237}, {40, 1.8692},
                                                            {50, 2.3660}, {60, 2.9462}, {70, 3.6649}, {80, 4.6416},
                                                            {90, 6.2514}, {95, 7.8147}, {99, 11.3449}};

std::vector<double> ranks(std::vector<double> v) {
  std::vector<std::size_t> order(v.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  std::vector<double> r(v.size());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t k = i;
    while (k + 1 < order.size() && v[order[k + 1]] == v[order[i]]) ++k;
    const double mean_rank = 0.5 * static_cast<double>(i + k);
    for (std::size_t q = i; q <= k; ++q) r[order[q]] = mean_rank;
    i = k + 1;
  }
  return r;
}
}  // namespace

double spearman(const std::vector<std::pair<double, double>>& xy) {
  if (xy.size() < 3) return std::nan("");
  std::vector<double> x, y;
  for (const auto& [a, b] : xy) x.push_back(a), y.push_back(b);
  const auto rx = ranks(x), ry = ranks(y);
  const double n = static_cast<double>(xy.size()), mean = (n - 1) / 2;
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < xy.size(); ++i) {
    sxy += (rx[i] - mean) * (ry[i] - mean);
    sxx += (rx[i] - mean) * (rx[i] - mean);
    syy += (ry[i] - mean) * (ry[i] - mean);
  }
  return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : std::nan("");
}

void UncertaintyCheck::add(const skeleton::Skeleton& estimate, const skeleton::Skeleton& truth) {
  for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
    const auto& e = estimate.joints[j];
    if (group_of(skeleton::joint_at(j)) < 0 || e.confidence < skeleton::kTracked || !skeleton::has_covariance(e)) continue;
    const Eigen::Matrix3d c = skeleton::covariance_of(e);
    const Eigen::LLT<Eigen::Matrix3d> llt(c);
    if (llt.info() != Eigen::Success) continue;  // not a covariance
    const Eigen::Vector3d d = e.position - truth.joints[j].position;
    ++n_;
    const double m2 = d.dot(llt.solve(d));
    if (m2 <= kChi2Of3At95) ++inside_;
    for (std::size_t k = 0; k < kLevels; ++k) {
      if (m2 <= kReliabilityLevels[k].second) ++inside_level_[k];
    }
    const std::pair<double, double> sample{std::sqrt(c.trace() / 3.0), d.norm()};
    if (kept_.size() < kKeptForSpearman) {
      kept_.push_back(sample);
    } else {
      rng_ = rng_ * 6364136223846793005ULL + 1442695040888963407ULL;  // reservoir sampling, fixed seed
      const std::uint64_t slot = (rng_ >> 11) % n_;
      if (slot < kKeptForSpearman) kept_[slot] = sample;
    }
  }
}

double UncertaintyCheck::inside_95_pct() const {
  return n_ > 0 ? 100.0 * static_cast<double>(inside_) / static_cast<double>(n_) : std::nan("");
}

std::vector<std::pair<double, double>> UncertaintyCheck::reliability() const {
  static_assert(std::size(kReliabilityLevels) == kLevels);
  std::vector<std::pair<double, double>> out;
  if (n_ == 0) return out;
  for (std::size_t k = 0; k < kLevels; ++k) {
    out.emplace_back(kReliabilityLevels[k].first, 100.0 * static_cast<double>(inside_level_[k]) / static_cast<double>(n_));
  }
  return out;
}

double UncertaintyCheck::sigma_error_spearman() const { return spearman(kept_); }

double UncertaintyCheck::median_sigma_cm() const {
  if (kept_.empty()) return std::nan("");
  std::vector<double> s;
  for (const auto& [sigma, err] : kept_) s.push_back(sigma);
  std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(s.size() / 2), s.end());
  return 100.0 * s[s.size() / 2];
}

}  // namespace skelgraph::eval
