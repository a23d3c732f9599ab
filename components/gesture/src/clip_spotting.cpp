#include "skelgraph/gesture/clip_spotting.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

#include "skelgraph/gesture/dataset.hpp"

namespace skelgraph::gesture {

std::pair<skeleton::Skeleton, Wrists> arms_down(const skeleton::Skeleton& s, const Wrists& w) {
  using skeleton::JointId;
  auto r = s;
  Wrists rw = w;
  const Eigen::Vector3d down(0, -1, 0);
  const JointId arms[2][3] = {{JointId::LeftShoulder, JointId::LeftElbow, JointId::LeftHand},
                              {JointId::RightShoulder, JointId::RightElbow, JointId::RightHand}};
  for (int side = 0; side < 2; ++side) {
    const auto [sh, el, ha] = std::tuple{s[arms[side][0]].position, s[arms[side][1]].position, s[arms[side][2]].position};
    const Eigen::Vector3d elbow = sh + (el - sh).norm() * down;
    r[arms[side][1]].position = elbow;
    r[arms[side][2]].position = elbow + (ha - el).norm() * down;
    Eigen::Vector3d& wr = side == 0 ? rw.left : rw.right;
    if (wr.allFinite()) wr = elbow + (wr - el).norm() * down;
  }
  return {r, rw};
}

namespace {

constexpr std::int64_t kFrame = 33'333'333;
constexpr double kLower = 0.5;  // s to lower or raise the arms

// One subject's clips as a continuous 30 Hz stream, with the truth.
struct Stream {
  std::vector<skeleton::Skeleton> frames;
  std::vector<Wrists> wrists;  // per frame, for the hands features
  std::vector<TruthGesture> truth;
  struct ClipRange {
    std::int64_t start_ns, end_ns;
    std::string action;
  };
  std::vector<ClipRange> ranges;  // each clip's place in the stream, to say which clip an event came in

  // From (a, wa) to (b, wb) over `seconds`, 30 Hz, positions blended linearly.
  void move(const skeleton::Skeleton& a, const Wrists& wa, const skeleton::Skeleton& b, const Wrists& wb, double seconds,
            std::int64_t t0) {
    const auto n = static_cast<int>(std::lround(seconds * 30));
    for (int k = 1; k <= n; ++k) {
      const double u = static_cast<double>(k) / n;
      auto f = a;
      for (std::size_t j = 0; j < f.joints.size(); ++j) f.joints[j].position = (1 - u) * a.joints[j].position + u * b.joints[j].position;
      f.stamp_ns = frames.empty() ? t0 : frames.back().stamp_ns + kFrame;
      frames.push_back(f);
      wrists.push_back({(1 - u) * wa.left + u * wb.left, (1 - u) * wa.right + u * wb.right});
    }
  }
};

Stream make_stream(const std::vector<Clip>& clips, const std::vector<std::size_t>& idx, const ClassMap& map,
                   const ClassifierOptions& c, const ClipStreamOptions& o) {
  Stream st;
  std::int64_t t0 = 0;
  const auto gap = static_cast<std::int64_t>(o.gap_s * 1e9);
  for (std::size_t i : idx) {
    const auto rec = playback::read_recording(o.format, clips[i].source, o.read);
    const auto rec_wrists = wrists_of(rec);
    const auto wrist_at = [&](std::size_t k) { return rec_wrists.empty() ? Wrists{} : rec_wrists[k]; };
    if (o.rest_s > 0) {
      // Arms down from the last frame, rest, arms up into this clip's first frame.
      auto first = rec.frames.front();
      first.person_id = 1;
      const auto [rest_next, rest_next_w] = arms_down(first, wrist_at(0));
      if (st.frames.empty()) {
        st.frames.push_back(rest_next);
        st.frames.back().stamp_ns = t0;
        st.wrists.push_back(rest_next_w);
        st.move(rest_next, rest_next_w, rest_next, rest_next_w, o.rest_s, t0);
      } else {
        const auto [rest_prev, rest_prev_w] = arms_down(st.frames.back(), st.wrists.back());
        const auto last_frame = st.frames.back();
        const auto last_w = st.wrists.back();
        st.move(last_frame, last_w, rest_prev, rest_prev_w, kLower, t0);
        st.move(rest_prev, rest_prev_w, rest_next, rest_next_w, o.rest_s, t0);
      }
      st.move(rest_next, rest_next_w, first, wrist_at(0), kLower, t0);
      t0 = st.frames.back().stamp_ns + kFrame;
    }
    const std::int64_t shift = t0 - rec.frames.front().stamp_ns;
    std::int64_t last = t0;
    st.ranges.push_back({t0, rec.frames.back().stamp_ns + shift, clips[i].action});
    for (std::size_t k = 0; k < rec.frames.size(); ++k) {
      auto f = rec.frames[k];
      f.stamp_ns += shift;
      f.person_id = 1;
      if (!st.frames.empty() && f.stamp_ns <= st.frames.back().stamp_ns) continue;
      last = f.stamp_ns;
      st.frames.push_back(f);
      st.wrists.push_back(wrist_at(k));
    }
    const auto span = motion_span(recording_features(rec, c.features).x, c.features.set);
    TruthGesture g;
    g.label = clips[i].label >= 0 ? map.classes[static_cast<std::size_t>(clips[i].label)] : clips[i].action;
    g.start_ns = rec.frames[static_cast<std::size_t>(span.begin)].stamp_ns + shift;
    g.end_ns = rec.frames[static_cast<std::size_t>(std::max<Eigen::Index>(span.begin, span.end - 1))].stamp_ns + shift;
    st.truth.push_back(g);
    for (std::int64_t t = last + kFrame; t < last + gap; t += kFrame) {
      auto f = st.frames.back();
      f.stamp_ns = t;
      st.frames.push_back(f);
      st.wrists.push_back(st.wrists.back());
    }
    t0 = st.frames.back().stamp_ns + kFrame;  // the next clip one frame after the rest
  }
  if (o.rest_s > 0 && !st.frames.empty()) {  // the last clip ends in a rest too
    const auto [rest_last, rest_last_w] = arms_down(st.frames.back(), st.wrists.back());
    const auto last_frame = st.frames.back();
    const auto last_w = st.wrists.back();
    st.move(last_frame, last_w, rest_last, rest_last_w, kLower, t0);
    st.move(rest_last, rest_last_w, rest_last, rest_last_w, o.rest_s, t0);
  }
  return st;
}

}  // namespace

ClipSpotting spot_clips(const std::vector<Clip>& clips, const ClassMap& map, const ClassifierOptions& c,
                        const ClipStreamOptions& o, const std::function<void(int, int)>& progress) {
  std::map<std::string, std::vector<std::size_t>> by_subject;
  for (std::size_t i = 0; i < clips.size(); ++i) by_subject[clips[i].subject].push_back(i);
  if (by_subject.size() < 2) {
    throw std::invalid_argument(
        "spotting needs recordings of at least 2 subjects (each is spotted by a model trained on the others)");
  }
  ClipSpotting out;
  out.label = map.classes[0];
  std::vector<SpottingReport> reports;
  int done = 0;
  for (const auto& [subject, idx] : by_subject) {
    std::vector<Clip> train;
    for (std::size_t i = 0; i < clips.size(); ++i) {
      if (clips[i].subject != subject) train.push_back(clips[i]);
    }
    const auto model = Classifier::train(train, map, c);
    const auto st = make_stream(clips, idx, map, c, o);
    Spotter spotter(model, o.spot);
    std::vector<SpottedEvent> events;
    for (std::size_t k = 0; k < st.frames.size(); ++k) {
      for (const auto& e : spotter.step(st.frames[k], needs_wrists(c.features.set) ? &st.wrists[k] : nullptr)) events.push_back(e);
    }
    SubjectSpotting s;
    s.subject = subject;
    s.clips = idx.size();
    s.report = score_spotting(events, st.truth, out.label);
    if (!st.frames.empty()) {  // the stream outside the clips of the spotted class
      double inside = 0;
      for (std::size_t k = 0; k < st.ranges.size() && k < st.truth.size(); ++k) {
        if (st.truth[k].label == out.label) inside += 1e-9 * static_cast<double>(st.ranges[k].end_ns - st.ranges[k].start_ns);
      }
      s.report.non_gesture_s = 1e-9 * static_cast<double>(st.frames.back().stamp_ns - st.frames.front().stamp_ns) - inside;
      finish(s.report);
    }
    reports.push_back(s.report);
    s.spotted = nlohmann::json::array();
    const std::int64_t origin = st.frames.empty() ? 0 : st.frames.front().stamp_ns;
    const auto secs = [origin](std::int64_t t) { return 1e-9 * static_cast<double>(t - origin); };
    for (const auto& e : events) {
      std::string in = "rest";
      for (const auto& cr : st.ranges) {
        if (e.end_ns >= cr.start_ns && e.end_ns <= cr.end_ns) in = cr.action;
      }
      s.spotted.push_back({{"label", e.label}, {"clip", in}, {"start_s", secs(e.start_ns)}, {"end_s", secs(e.end_ns)},
                           {"confidence", e.confidence}});
    }
    s.clips_in_stream = nlohmann::json::array();
    for (std::size_t k = 0; k < st.truth.size(); ++k) {
      s.clips_in_stream.push_back({{"clip", st.ranges[k].action},
                                   {"label", st.truth[k].label},
                                   {"clip_start_s", secs(st.ranges[k].start_ns)},
                                   {"clip_end_s", secs(st.ranges[k].end_ns)},
                                   {"motion_start_s", secs(st.truth[k].start_ns)},
                                   {"motion_end_s", secs(st.truth[k].end_ns)}});
    }
    out.subjects.push_back(std::move(s));
    ++done;
    if (progress) progress(done, static_cast<int>(by_subject.size()));
  }
  out.combined = combine(reports);
  return out;
}

}  // namespace skelgraph::gesture
