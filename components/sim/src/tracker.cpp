#include "skelgraph/sim/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace skelgraph::sim {

using Eigen::Vector3d;
using skeleton::JointId;
using skeleton::kJointCount;

namespace {

constexpr std::size_t idx(JointId j) { return static_cast<std::size_t>(j); }

// -1 left side, +1 right side, 0 on the midline.
int side_of(JointId j) {
  switch (j) {
    case JointId::LeftShoulder: case JointId::LeftElbow: case JointId::LeftHand:
    case JointId::LeftHip: case JointId::LeftKnee: case JointId::LeftFoot:
      return -1;
    case JointId::RightShoulder: case JointId::RightElbow: case JointId::RightHand:
    case JointId::RightHip: case JointId::RightKnee: case JointId::RightFoot:
      return 1;
    default:
      return 0;
  }
}

bool is_arm(JointId j) {
  return j == JointId::LeftShoulder || j == JointId::LeftElbow || j == JointId::LeftHand ||
         j == JointId::RightShoulder || j == JointId::RightElbow || j == JointId::RightHand;
}
bool is_hand(JointId j) { return j == JointId::LeftHand || j == JointId::RightHand; }

// Distance between segments p1-q1 and p2-q2 (Ericson, Real-Time Collision
// Detection, 5.1.9); `along`: where on p1-q1 the closest point is (0..1).
double segment_distance(const Vector3d& p1, const Vector3d& q1, const Vector3d& p2, const Vector3d& q2,
                        double* along = nullptr) {
  const Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (along) *along = 0;
  if (a <= 1e-12 && e <= 1e-12) return r.norm();
  if (a <= 1e-12) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 1e-12) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 1e-12 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  if (along) *along = s;
  return ((p1 + d1 * s) - (p2 + d2 * t)).norm();
}

struct BodyCapsule {
  Vector3d a, b;
  double r;
  JointId ja, jb;  // the joints it joins (the trunk: hips' midpoint counts as Torso)
};

// The body as capsules: trunk and head first (what can hide the person's own limbs), then the limbs.
std::vector<BodyCapsule> capsules(const skeleton::Skeleton& s, double scale) {
  auto P = [&s](JointId j) { return s[j].position; };
  const Vector3d pelvis = 0.5 * (P(JointId::LeftHip) + P(JointId::RightHip));
  std::vector<BodyCapsule> c{{pelvis, P(JointId::Neck), 0.13 * scale, JointId::Torso, JointId::Neck},
                         {P(JointId::Head), P(JointId::Head), 0.10 * scale, JointId::Head, JointId::Head}};
  for (auto [a, b, r] : {std::tuple{JointId::LeftShoulder, JointId::LeftElbow, 0.05},
                         {JointId::LeftElbow, JointId::LeftHand, 0.045},
                         {JointId::RightShoulder, JointId::RightElbow, 0.05},
                         {JointId::RightElbow, JointId::RightHand, 0.045},
                         {JointId::LeftHip, JointId::LeftKnee, 0.07},
                         {JointId::LeftKnee, JointId::LeftFoot, 0.05},
                         {JointId::RightHip, JointId::RightKnee, 0.07},
                         {JointId::RightKnee, JointId::RightFoot, 0.05}}) {
    c.push_back({P(a), P(b), r * scale, a, b});
  }
  return c;
}

TrackerProfile make_mssdk() {
  TrackerProfile p;
  p.name = "mssdk";
  p.acquire_s = 0.2;
  p.reacquire_s = 1.0;
  p.ghost_s = 0.15;
  p.out_of_view_lost = true;
  p.ghost_on_prop_s = 0.15;
  p.settle_sd = 0.15;
  p.settle_s = 0.7;
  p.self_hidden_tracked = 0.1;
  p.object_hidden_tracked = 0.05;
  p.near_object_inferred = 0.6;
  p.back_limbs_inferred = 0.6;
  p.head_doubt = 0.0;
  p.head_doubt_unusual = 0.0;
  p.elbow_doubt_bent = 0.0;
  p.elbow_doubt_sitting = 0.4;
  p.flip_delay_s = 0.5;
  p.unflip_delay_s = 0.8;
  auto& o = p.offset;
  o[idx(JointId::Head)] = {0.0, 0.09, 0.11};
  o[idx(JointId::Neck)] = {0.0, -0.08, 0.06};
  o[idx(JointId::Torso)] = {0.0, 0.03, 0.01};
  for (auto j : {JointId::LeftShoulder, JointId::RightShoulder}) o[idx(j)] = {0.03, -0.03, 0.02};
  for (auto j : {JointId::LeftElbow, JointId::RightElbow}) o[idx(j)] = {0.02, 0.0, 0.04};
  for (auto j : {JointId::LeftHand, JointId::RightHand}) o[idx(j)] = {0.0, 0.05, 0.06};
  for (auto j : {JointId::LeftHip, JointId::RightHip}) o[idx(j)] = {0.02, 0.04, 0.0};
  p.bias_sd = 0.018;
  p.hand_bias_sd = 0.03;
  p.noise_sd = 0.006;
  p.lag_s = 0.03;
  p.hidden_sd = 0.10;
  p.contamination = 0.4;
  return p;
}

TrackerProfile make_nite() {
  TrackerProfile p;
  p.name = "nite";
  p.acquire_s = 0.6;
  p.reacquire_s = 0.4;
  p.ghost_s = 2.5;
  p.ghost_on_prop_s = 3.5;
  p.settle_sd = 0.25;
  p.settle_s = 1.0;
  p.self_hidden_tracked = 0.95;
  p.object_hidden_tracked = 0.6;
  p.near_object_inferred = 0.25;
  p.back_limbs_inferred = 0.2;
  p.back_shoulders_factor = 0.0;
  p.head_doubt = 0.07;
  p.head_doubt_unusual = 0.35;
  p.elbow_doubt_bent = 0.7;
  p.elbow_doubt_sitting = 0.05;
  p.flip_delay_s = 0.3;
  p.unflip_delay_s = 0.3;
  auto& o = p.offset;
  o[idx(JointId::Head)] = {0.0, 0.06, 0.07};
  o[idx(JointId::Neck)] = {0.0, 0.02, 0.02};
  o[idx(JointId::Torso)] = {0.0, 0.05, 0.03};
  for (auto j : {JointId::LeftShoulder, JointId::RightShoulder}) o[idx(j)] = {0.02, 0.03, 0.02};
  for (auto j : {JointId::LeftElbow, JointId::RightElbow}) o[idx(j)] = {0.02, 0.0, 0.05};
  for (auto j : {JointId::LeftHand, JointId::RightHand}) o[idx(j)] = {0.0, 0.06, 0.07};
  for (auto j : {JointId::LeftHip, JointId::RightHip}) o[idx(j)] = {0.03, 0.05, 0.0};
  p.bias_sd = 0.02;
  p.hand_bias_sd = 0.035;
  p.noise_sd = 0.006;
  p.lag_s = 0.05;
  p.hidden_sd = 0.08;
  p.contamination = 1.0;
  return p;
}

}  // namespace

const std::vector<std::string>& TrackerProfile::names() {
  static const std::vector<std::string> n{"mssdk", "nite"};
  return n;
}

const TrackerProfile& TrackerProfile::by_name(const std::string& name) {
  static const TrackerProfile mssdk = make_mssdk(), nite = make_nite();
  if (name == "mssdk") return mssdk;
  if (name == "nite") return nite;
  throw std::invalid_argument("unknown tracker profile '" + name + "' (expected mssdk or nite)");
}

Visibility visibility(const SensorView& view, const Scene& scene, std::size_t actor,
                      const std::vector<skeleton::Skeleton>& truths, double body_scale) {
  Visibility v;
  const Vector3d origin = view.config().position;
  std::vector<std::vector<BodyCapsule>> bodies;
  for (const auto& s : truths) bodies.push_back(capsules(s, body_scale));
  int sighted = 0, hidden = 0, by_props = 0;
  for (std::size_t j = 0; j < kJointCount; ++j) {
    const Vector3d p = truths[actor].joints[j].position;
    v.in_view[j] = view.in_view(p);
    double depth = 0.0;
    bool blocked = view.blocked(p, scene.obstacles, &depth);
    if (blocked && j <= idx(JointId::RightHand)) ++by_props;
    v.hit_depth[j] = blocked ? depth : (p - origin).norm();
    // The line of sight, stopped a little short of the joint itself.
    const Vector3d dir = (p - origin).normalized();
    const Vector3d end = p - 0.04 * dir;
    for (std::size_t k = 0; k < bodies.size() && !blocked; ++k) {
      if (k == actor) continue;
      for (const auto& c : bodies[k]) {
        double s = 0;
        if (segment_distance(origin, end, c.a, c.b, &s) < c.r) {
          blocked = true;
          // Where the line of sight passes the other body's limb, on its near surface.
          v.hit_depth[j] = std::min(v.hit_depth[j], std::max(0.1, s * (end - origin).norm() - c.r));
          break;
        }
      }
    }
    // Behind something that is no person (a robot's link): hidden like behind a prop.
    for (std::size_t k = 0; k < scene.occluders.size() && !blocked; ++k) {
      const auto& c = scene.occluders[k];
      double s = 0;
      if (segment_distance(origin, end, c.a, c.b, &s) < c.radius) {
        blocked = true;
        if (j <= idx(JointId::RightHand)) ++by_props;
        v.hit_depth[j] = std::min(v.hit_depth[j], std::max(0.1, s * (end - origin).norm() - c.radius));
      }
    }
    v.object_hidden[j] = blocked;
    const auto jid = skeleton::joint_at(j);
    if (jid != JointId::Head && jid != JointId::Neck && jid != JointId::Torso) {
      for (std::size_t c = 0; c < 2; ++c) {
        const auto& cap = bodies[actor][c];
        if (segment_distance(origin, end, cap.a, cap.b) < cap.r) v.self_hidden[j] = true;
      }
    }
    for (const auto& o : scene.obstacles) {
      if (o.box.exteriorDistance(p) < 0.06) v.near_object[j] = true;
    }
    // A hand or elbow touching the person's own trunk or legs cannot be told
    // apart from them in the depth image either.
    if (jid == JointId::LeftHand || jid == JointId::RightHand || jid == JointId::LeftElbow ||
        jid == JointId::RightElbow) {
      for (std::size_t c = 0; c < bodies[actor].size(); ++c) {
        const auto& cap = bodies[actor][c];
        if (c >= 2 && c < 6) continue;  // the arms themselves
        if (segment_distance(p, p, cap.a, cap.b) < cap.r + 0.05) v.near_object[j] = true;
      }
    }
    if (v.in_view[j] && !blocked) ++sighted;
    if (blocked && j <= idx(JointId::RightHand)) ++hidden;
  }
  v.sighted_fraction = sighted / static_cast<double>(kJointCount);
  v.object_fraction = hidden / static_cast<double>(idx(JointId::RightHand) + 1);
  v.prop_fraction = by_props / static_cast<double>(idx(JointId::RightHand) + 1);
  return v;
}

void TrackerModel::Flicker::step(double p, double dwell, double dt, Rng& rng) {
  p = std::clamp(p, 0.0, 0.98);
  if (on) {
    if (rng.chance(1.0 - std::exp(-dt / dwell))) on = false;
  } else if (p > 0.0) {
    const double rate = p / ((1.0 - p) * dwell);
    if (rng.chance(1.0 - std::exp(-rate * dt))) on = true;
  }
}

TrackerModel::TrackerModel(const TrackerProfile& profile, const SensorConfig& sensor, Rng rng, double noise_scale,
                           double body_scale, std::uint32_t* next_user_id)
    : p_(profile),
      view_(sensor),
      rng_(rng),
      noise_scale_(noise_scale),
      body_scale_(body_scale),
      next_user_id_(next_user_id) {
  for (auto& b : bias_) b.setZero();
  for (auto& b : hidden_bias_) b.setZero();
}

// The correlated errors evolve whether or not anything is reported.
void TrackerModel::evolve_errors(double dt, double back) {
  const double decay = dt / p_.bias_tau_s;
  for (std::size_t j = 0; j < kJointCount; ++j) {
    const double sd = (is_hand(skeleton::joint_at(j)) ? p_.hand_bias_sd : p_.bias_sd) * (1.0 + p_.back_bias_gain * back) *
                      noise_scale_;
    const double kick = std::sqrt(2.0 * decay);
    bias_[j] += -bias_[j] * decay + sd * kick * Vector3d(rng_.normal(), rng_.normal(), rng_.normal());
    hidden_bias_[j] += -hidden_bias_[j] * decay +
                       p_.hidden_sd * noise_scale_ * kick * Vector3d(rng_.normal(), rng_.normal(), rng_.normal());
  }
}

std::optional<skeleton::Skeleton> TrackerModel::ghost(double dt, const Scene& scene) {
  if (!last_report_) return std::nullopt;
  // The last skeleton, where the person was, sliding onto the nearest prop.
  Vector3d c = report_world_[idx(JointId::Torso)];
  double best = 1.5;
  Vector3d slide = Vector3d::Zero();
  for (const auto& o : scene.obstacles) {
    const Vector3d centre = o.box.center();
    if ((centre - c).norm() < best) {
      best = (centre - c).norm();
      slide = centre - c;
    }
  }
  ghost_on_prop_ = best < 1.5;
  const double k = p_.contamination * (1.0 - std::exp(-dt / 0.7));
  for (std::size_t j = 0; j < kJointCount; ++j) {
    report_world_[j] += k * slide;
    auto& joint = last_report_->joints[j];
    joint.position = view_.to_sensor(report_world_[j]);
    // A wall-shaped blob has a trunk but no arms to speak of.
    const auto jid = skeleton::joint_at(j);
    if (ghost_on_prop_ && is_arm(jid) && jid != JointId::LeftShoulder && jid != JointId::RightShoulder) {
      joint.confidence = std::min(joint.confidence, skeleton::kInferred);
    }
  }
  return last_report_;
}

// The person is not in the scene (gone from the cell): nothing in sight.
std::optional<skeleton::Skeleton> TrackerModel::observe_nobody(double t, double dt, const Scene& scene) {
  evolve_errors(dt, 0.0);
  if (state_ == State::Tracking) {
    state_ = State::Ghost;
    lost_at_ = t;
  }
  if (state_ == State::Ghost && t - lost_at_ > (ghost_on_prop_ ? p_.ghost_on_prop_s : p_.ghost_s)) {
    state_ = State::Searching;
    sighted_since_ = -1.0;
    last_report_.reset();
  }
  if (state_ == State::Searching) {
    sighted_since_ = -1.0;
    return std::nullopt;
  }
  return ghost(dt, scene);
}

std::optional<skeleton::Skeleton> TrackerModel::observe(double t, const Scene& scene, std::size_t actor,
                                                        const std::vector<skeleton::Skeleton>& truths) {
  const double dt = last_t_ < 0.0 ? 1.0 / view_.config().rate_hz : std::max(1e-4, t - last_t_);
  const bool first_frame = last_t_ < 0.0;
  last_t_ = t;
  if (actor >= scene.actors.size()) return observe_nobody(t, dt, scene);
  const auto& truth = truths[actor];
  const BodyPose& pose = scene.actors[actor].pose;
  const Visibility vis = visibility(view_, scene, actor, truths, body_scale_);
  const double theta = view_.view_angle(pose);
  const double back = std::clamp((theta - M_PI / 2) / (M_PI / 2), 0.0, 1.0);

  evolve_errors(dt, back);

  // Finding and losing the person.
  const bool in_sight = vis.sighted_fraction >= p_.lose_fraction;
  switch (state_) {
    case State::Searching:
      if (vis.sighted_fraction >= 0.5) {
        if (sighted_since_ < 0.0) sighted_since_ = t;
        if (t - sighted_since_ >= (acquired_once_ ? p_.reacquire_s : p_.acquire_s)) {
          state_ = State::Tracking;
          user_id_ = (*next_user_id_)++;
          acquired_once_ = true;
          flipped_ = theta > M_PI / 2;  // a new user is assumed to face the sensor
          acquired_at_ = t;
          for (auto& e : settle_) e = p_.settle_sd * noise_scale_ * Vector3d(rng_.normal(), rng_.normal(), rng_.normal());
        }
      } else {
        sighted_since_ = -1.0;
      }
      break;
    case State::Tracking:
      if (!in_sight) {
        state_ = State::Ghost;
        lost_at_ = t;
      }
      break;
    case State::Ghost:
      if (in_sight) {
        // The person is back: the skeleton slides back from where the ghost was.
        state_ = State::Tracking;
        acquired_at_ = t;
        for (std::size_t j = 0; j < kJointCount; ++j) settle_[j] = report_world_[j] - truth.joints[j].position;
      } else if (t - lost_at_ > (ghost_on_prop_ ? p_.ghost_on_prop_s : p_.ghost_s)) {
        state_ = State::Searching;
        sighted_since_ = -1.0;
        last_report_.reset();
      }
      break;
  }
  auto remember_truth = [&] {
    for (std::size_t j = 0; j < kJointCount; ++j) last_truth_[j] = truth.joints[j].position;
  };
  if (state_ == State::Searching) {
    remember_truth();
    return std::nullopt;
  }
  if (state_ == State::Ghost) {
    remember_truth();
    return ghost(dt, scene);
  }

  // Left/right flips with the back to the sensor.
  if (!flipped_ && theta > p_.flip_on_deg * M_PI / 180 && rng_.chance(1.0 - std::exp(-dt / p_.flip_delay_s))) {
    flipped_ = true;
  } else if (flipped_ && theta < p_.flip_off_deg * M_PI / 180 &&
             rng_.chance(1.0 - std::exp(-dt / p_.unflip_delay_s))) {
    flipped_ = false;
  }

  // The body frame the tracker believes in: a flipped tracker thinks the person faces it.
  const double believed_heading = pose.heading + (flipped_ ? M_PI : 0.0);
  const Vector3d fwd(std::sin(believed_heading), 0.0, std::cos(believed_heading));
  const Vector3d up = Vector3d::UnitY();
  const Vector3d left = up.cross(fwd);
  const double bent = std::clamp(pose.trunk_pitch / 0.8, 0.0, 1.0);
  const double sitting = std::clamp(pose.pelvis_drop / 0.3, 0.0, 1.0) * (1.0 - bent);  // hips down, trunk up
  const double unusual = std::min(1.0, bent + sitting);

  // A prop hiding part of the body merges with it in the depth image and
  // drags the fitted skeleton towards itself.
  Vector3d drag = Vector3d::Zero();
  if (vis.prop_fraction > 0.0 && !scene.obstacles.empty()) {
    const Vector3d c = truth[JointId::Torso].position;
    double best = 1e9;
    Vector3d nearest = c;
    for (const auto& o : scene.obstacles) {
      const Vector3d q = c.cwiseMax(o.box.min()).cwiseMin(o.box.max());
      if ((q - c).norm() < best) {
        best = (q - c).norm();
        nearest = q;
      }
    }
    if (best < 1.5) drag = p_.contamination * vis.prop_fraction * (nearest - c);
  }

  skeleton::Skeleton out;
  out.sensor_id = view_.config().id;
  out.frame_id = view_.config().id;
  out.person_id = user_id_;
  const Eigen::Quaterniond sensor_q(view_.sensor_from_world().rotation());
  const Vector3d origin = view_.config().position;
  for (std::size_t j = 0; j < kJointCount; ++j) {
    const JointId jid = skeleton::joint_at(j);
    const std::size_t src = idx(flipped_ ? skeleton::mirror(jid) : jid);  // where the reported joint really is
    const Vector3d truth_pos = truth.joints[src].position;
    const Vector3d velocity = first_frame ? Vector3d::Zero() : Vector3d((truth_pos - last_truth_[src]) / dt);
    Vector3d pos = truth_pos - p_.lag_s * velocity;
    const Eigen::Vector3d& off = p_.offset[j];
    const int side = side_of(jid);
    const Vector3d outward = side < 0 ? left : side > 0 ? Vector3d(-left) : Vector3d::Zero();
    pos += off.x() * outward + off.y() * up + off.z() * fwd;
    pos += bias_[j] + drag + std::exp(-(t - acquired_at_) / p_.settle_s) * settle_[j];
    const double depth = std::max(0.5, view_.to_sensor(pos).z());
    const double noise = p_.noise_sd * noise_scale_ * (depth / 2.0) * (depth / 2.0);
    pos += noise * Vector3d(rng_.normal(), rng_.normal(), rng_.normal());

    float conf = skeleton::kTracked;
    if (!vis.in_view[src]) {
      // Outside the image: guessed from the rest of the body, or given up on.
      conf = p_.out_of_view_lost ? skeleton::kLost : skeleton::kInferred;
      pos += hidden_bias_[j];
    } else if (vis.object_hidden[src] && side_of(jid) == 0) {
      // Head, neck and torso follow from the rest of the body: still claimed, inferred with an error.
      pos += hidden_bias_[j];
    } else if (vis.object_hidden[src]) {
      // The depth image shows the prop: the joint lands on its surface.
      hidden_claim_[j].step(p_.object_hidden_tracked, p_.doubt_dwell_s, dt, rng_);
      conf = hidden_claim_[j].on ? skeleton::kTracked : skeleton::kInferred;
      const Vector3d dir = (truth_pos - origin).normalized();
      pos = origin + dir * vis.hit_depth[src] + hidden_bias_[j] + bias_[j];
    } else if (vis.self_hidden[src]) {
      hidden_claim_[j].step(p_.self_hidden_tracked, p_.doubt_dwell_s, dt, rng_);
      conf = hidden_claim_[j].on ? skeleton::kTracked : skeleton::kInferred;
      pos += hidden_bias_[j];
    } else {
      hidden_claim_[j].on = true;  // claims tracking again as soon as it sees the joint
      near_drop_[j].step(vis.near_object[src] ? p_.near_object_inferred : 0.0, p_.doubt_dwell_s, dt, rng_);
      if (near_drop_[j].on) conf = skeleton::kInferred;
    }
    double doubt = 0.0;
    if (is_arm(jid)) {
      const bool shoulder = jid == JointId::LeftShoulder || jid == JointId::RightShoulder;
      doubt = p_.back_limbs_inferred * back * (shoulder ? p_.back_shoulders_factor : 1.0);
    }
    if (jid == JointId::Head) doubt = p_.head_doubt + p_.head_doubt_unusual * unusual;
    if (jid == JointId::LeftElbow || jid == JointId::RightElbow) {
      doubt += p_.elbow_doubt_bent * bent + p_.elbow_doubt_sitting * sitting;
    }
    doubt_[j].step(doubt, p_.doubt_dwell_s, dt, rng_);
    if (doubt_[j].on) conf = std::min(conf, skeleton::kInferred);

    auto& joint = out.joints[j];
    report_world_[j] = pos;
    joint.position = view_.to_sensor(pos);
    joint.orientation = (sensor_q * truth.joints[src].orientation).normalized();
    joint.confidence = conf;
  }
  remember_truth();
  last_report_ = out;
  return out;
}

}  // namespace skelgraph::sim
