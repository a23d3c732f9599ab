#pragma once
// Which recorded actions make which gesture class: the presets and YAML class
// files the classifier and cross-validation take. No DDS.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skelgraph::gesture {

// Which recorded actions make which class. File (YAML):
//   classes:            # in this order; each class lists the actions it takes
//     point: [Point-at-the-camera]
//   garbage: other      # optional: every unlisted action becomes this class
// Without `garbage`, unlisted actions take part in no training; cross-validation
// scores them as inputs that should be rejected.
struct ClassMap {
  std::vector<std::string> classes;                  // model order; the garbage class (if any) is last
  std::map<std::string, std::string> action_class;   // action -> class
  std::string garbage;                               // "" if none

  static ClassMap preset(const std::string& name);   // "two-class", "five-class"; throws ModelError
  static ClassMap load(const std::string& path);     // throws ModelError naming the file and field
  static const std::vector<std::string>& preset_names();
  // The class index of an action, or nullopt when it is not used.
  std::optional<int> label_of(const std::string& action) const;
  int garbage_index() const;  // -1 without a garbage class
  nlohmann::json to_json() const;
};

}  // namespace skelgraph::gesture
