#pragma once
// Who is in the cell against who the graph shows, over a long run: the
// measure of a cell that runs all day. DDS-free: the `presence` component
// feeds it what arrives (ground truth, raw and fused skeletons, sensor poses,
// the components' status, and which instances their writers disposed), with
// the time it arrived; `skelgraph eval presence` and bench/soak.sh report it.
//
// - Completeness, per true person: of the time at least one sensor's tracker
//   reports them (a raw skeleton whose torso is within match_m of theirs),
//   the share in which a fused skeleton shows them too (its torso that close).
//   A person no tracker sees yet (walking in from outside the views) cannot
//   be fused; that time is counted apart.
// - Departures: when a person has left (their truth instance disposed), how
//   long after the last raw instance that showed them was disposed readers
//   saw the fused instance that showed them disposed (the graph's part), and
//   after the truth itself (the trackers' part included: a tracker keeps
//   reporting a person it lost for a while).
// - Writers: what each component's status says of its outputs: writes DDS
//   refused, and live instances against the people there (present, or left
//   within `linger_ns`: a tracker's ghost), per sensor for raw skeletons.

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::eval {

struct PresenceOptions {
  double match_m = 0.5;                          // torsos this close (horizontally): the same person
  std::int64_t fresh_ns = 300'000'000;           // a sample is current this long after it arrived
  std::int64_t departure_limit_ns = 1'000'000'000;  // a fused departure seen later than this after its inputs' is late
  std::int64_t linger_ns = 3'000'000'000;        // people who left this recently still count for instance bounds
};

class Presence {
 public:
  explicit Presence(PresenceOptions options = {});

  void pose(const std::string& sensor, const Eigen::Isometry3d& world_from_sensor);
  void truth(const skeleton::Skeleton& world, std::int64_t t_ns);
  void truth_gone(std::uint32_t person, std::int64_t t_ns);
  void raw(const skeleton::Skeleton& in_sensor_frame, std::int64_t t_ns);  // dropped until its sensor has a pose
  void raw_gone(const std::string& sensor, std::uint32_t person, std::int64_t t_ns);
  void fused(const skeleton::Skeleton& world, std::int64_t t_ns);  // sensor_id names the fused stream
  void fused_gone(const std::string& stream, std::uint32_t person, std::int64_t t_ns);
  // One output of a component, from its status report.
  void output(const std::string& component, const std::string& topic, std::uint64_t failed_writes,
              std::uint32_t instances, std::int64_t t_ns);
  // Advances the time-weighted measures to t_ns (call often, e.g. every 100 ms).
  void sample(std::int64_t t_ns);

  // The figures (see the header comment); `people` lists every person when true.
  nlohmann::json report(bool people = false) const;

  // For tests and the soak check.
  std::size_t people_seen() const { return people_.size(); }
  std::size_t people_left() const;
  std::uint64_t failed_writes() const;

 private:
  struct Person {
    std::int64_t first_ns = 0, last_ns = 0;  // truth received
    Eigen::Vector3d torso = Eigen::Vector3d::Zero();
    std::optional<std::int64_t> left_ns;     // truth disposed
    std::int64_t tracked_until_ns = 0;       // a raw skeleton showed them until then (+ fresh_ns)
    std::int64_t shown_until_ns = 0;         // a fused skeleton showed them until then (+ fresh_ns)
    double present_s = 0, tracked_s = 0, shown_s = 0;
    std::optional<std::int64_t> inputs_gone_ns;  // the last raw instance that showed them was disposed
    std::set<std::pair<std::string, std::uint32_t>> fused_ids;  // fused instances that showed them
    std::optional<std::int64_t> fused_gone_ns;   // the last of those disposed
  };
  struct Stream {  // a raw or fused instance
    std::optional<std::uint32_t> person;  // the true person it showed last
    std::int64_t last_ns = 0;
  };
  struct Output {
    std::uint64_t failed = 0;
    std::uint32_t instances = 0, max_instances = 0;
    long long max_excess = 0;  // instances beyond the bound (people there, per sensor for raw)
    bool bounded = false;      // a topic whose instances are people
  };

  std::optional<std::uint32_t> nearest(const Eigen::Vector3d& torso) const;
  std::size_t people_there(std::int64_t t_ns) const;  // present, or left within linger_ns

  PresenceOptions o_;
  std::map<std::string, Eigen::Isometry3d> poses_;
  std::map<std::uint32_t, Person> people_;
  std::map<std::pair<std::string, std::uint32_t>, Stream> raw_, fused_;
  std::map<std::pair<std::string, std::uint32_t>, std::int64_t> fused_gone_;  // every fused instance seen disposed
  std::map<std::pair<std::string, std::string>, Output> outputs_;
  std::int64_t last_sample_ns_ = 0;
  std::uint64_t raw_without_pose_ = 0;
};

}  // namespace skelgraph::eval
