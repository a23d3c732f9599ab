#pragma once
// Every sensor of a cell from the skeletons they report, at once.
//
// 1. Each pair of sensors that saw the person at the same moments is
//    calibrated on its own (calibrate_from_skeletons: mirrored views of the
//    back included).
// 2. The sensors are placed from the reference outwards along the pairs that
//    share the most (a maximum spanning tree on the inlier counts): a sensor
//    that never shares a view with the reference is reached through others.
// 3. One joint solution: every pair that shares views contributes its joint
//    pairs (re-paired under the current poses), and all poses are refined
//    together (Gauss-Newton on the rigid poses, Cauchy weights on the
//    residuals), so a chain's errors do not add up along it.
//
// Clocks: the sensors' skeletons are taken to be on one clock (one
// recorder's log time, a data set's stamps).

#include <map>
#include <string>
#include <vector>

#include "skelgraph/calib/skeleton_calib.hpp"

namespace skelgraph::calib {

struct CellCalibOptions {
  SkeletonCalibOptions pair;           // for each pair (its clock offset search is not used)
  std::size_t min_link_pairs = 200;    // joint pairs two sensors must share to link them
  int rounds = 6;                      // re-pairing rounds of the joint solution
  // Poses roughly known (a previous calibration, a measured layout), any
  // common frame: they decide, pair by pair, between poses the skeletons
  // cannot tell apart (a person turning on the spot; SkeletonCalibOptions::prior).
  std::map<std::string, Eigen::Isometry3d> prior;
};

struct CellLink {
  std::string a, b;                    // b against a
  bool solved = false;                 // the pair on its own gave a pose
  std::string error;                   // why not
  SkeletonCalibResult fit;             // a_from_b, on its own
  bool in_tree = false;                // used to place b or a (step 2)
  std::size_t pairs = 0;               // joint pairs it gave the joint solution (0: not used)
  std::size_t mirrored = 0;            // frames matched with the sides swapped, in the joint solution
  double median_m = 0;                 // median distance of its joint pairs under the final poses (NaN: none)
};

struct CellSensor {
  std::string id;
  bool placed = false;                 // reached from the reference
  Eigen::Isometry3d reference_from_sensor = Eigen::Isometry3d::Identity();
  std::vector<std::string> path;       // reference ... this sensor, along the tree
  bool ambiguous = false;              // a pair on the path could not tell the sensors' sides apart (and no prior did)
  std::size_t pairs = 0;               // joint pairs of its links in the joint solution
  double median_m = 0;                 // their median distance under the final poses (NaN: none)
  double rms_m = 0, max_m = 0;         // ... RMS and largest
};

struct CellCalibResult {
  std::string reference;
  std::vector<CellSensor> sensors;     // the reference first, then by id
  std::vector<CellLink> links;         // every pair of sensors
  int rounds = 0;                      // joint solution rounds run
  const CellSensor* sensor(const std::string& id) const;
};

// Throws CalibError when the reference has no skeletons or nothing links to it.
CellCalibResult calibrate_cell(const std::map<std::string, std::vector<TimedSkeleton>>& by_sensor,
                               const std::string& reference, const CellCalibOptions& options = {});

}  // namespace skelgraph::calib
