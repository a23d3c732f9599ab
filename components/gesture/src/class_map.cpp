#include "skelgraph/gesture/class_map.hpp"
#include "skelgraph/gesture/hmm.hpp"

#include <algorithm>
#include <string>

#include <yaml-cpp/yaml.h>

namespace skelgraph::gesture {

const std::vector<std::string>& ClassMap::preset_names() {
  static const std::vector<std::string> names{"two-class", "five-class", "robot"};
  return names;
}

ClassMap ClassMap::preset(const std::string& name) {
  ClassMap m;
  if (name == "two-class") {
    m.classes = {"point", "other"};
    m.action_class = {{"Point-at-the-camera", "point"}};
    m.garbage = "other";
  } else if (name == "five-class") {
    m.classes = {"point", "reach", "walk", "overhead", "wave"};
    m.action_class = {{"Point-at-the-camera", "point"},
                      {"Push-an-imaginary-button-in-front-of-you", "reach"},
                      {"Walk-in-place", "walk"},
                      {"Raise-your-hand", "overhead"},
                      {"Wave-your-hand", "wave"}};
  } else if (name == "robot") {
    // A robot cell's commands: point (fetch), stop (a raised palm), come here, wave; the rest rejected.
    m.classes = {"point", "stop", "come_here", "wave", "other"};
    m.action_class = {{"Point-at-the-camera", "point"},
                      {"Signal-someone-to-stop", "stop"},
                      {"Signal-someone-to-come-here", "come_here"},
                      {"Wave-your-hand", "wave"},
                      {"Wave-your-other-hand", "wave"}};
    m.garbage = "other";
  } else {
    throw ModelError("unknown class preset '" + name + "' (expected two-class, five-class, robot or a YAML file)");
  }
  return m;
}

ClassMap ClassMap::load(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ModelError(path + ": " + e.what());
  }
  const auto where = [&](const YAML::Node& n) { return path + ":" + std::to_string(n.Mark().line + 1); };
  if (!root.IsMap() || !root["classes"] || !root["classes"].IsMap() || root["classes"].size() == 0)
    throw ModelError(path + ": expected a map with 'classes: {name: [action, ...], ...}'");
  ClassMap m;
  for (const auto& kv : root["classes"]) {
    const auto name = kv.first.as<std::string>();
    if (!kv.second.IsSequence() || kv.second.size() == 0)
      throw ModelError(where(kv.second) + ": class '" + name + "' needs a non-empty list of actions");
    m.classes.push_back(name);
    for (const auto& a : kv.second) {
      const auto action = a.as<std::string>();
      if (!m.action_class.emplace(action, name).second)
        throw ModelError(where(a) + ": action '" + action + "' is in two classes");
    }
  }
  for (const auto& kv : root) {
    const auto key = kv.first.as<std::string>();
    if (key != "classes" && key != "garbage") throw ModelError(where(kv.first) + ": unknown key '" + key + "' (expected classes, garbage)");
  }
  if (root["garbage"]) {
    m.garbage = root["garbage"].as<std::string>();
    if (std::find(m.classes.begin(), m.classes.end(), m.garbage) != m.classes.end())
      throw ModelError(where(root["garbage"]) + ": the garbage class '" + m.garbage + "' must not also list actions");
    m.classes.push_back(m.garbage);
  }
  return m;
}

std::optional<int> ClassMap::label_of(const std::string& action) const {
  const auto it = action_class.find(action);
  const std::string& c = it != action_class.end() ? it->second : garbage;
  if (c.empty()) return std::nullopt;
  return static_cast<int>(std::find(classes.begin(), classes.end(), c) - classes.begin());
}

int ClassMap::garbage_index() const { return garbage.empty() ? -1 : static_cast<int>(classes.size()) - 1; }

nlohmann::json ClassMap::to_json() const {
  nlohmann::json c = nlohmann::json::object();
  for (const auto& name : classes) {
    if (name == garbage) continue;
    auto& list = c[name] = nlohmann::json::array();
    for (const auto& [a, k] : action_class)
      if (k == name) list.push_back(a);
  }
  nlohmann::json j{{"classes", c}};
  if (!garbage.empty()) j["garbage"] = garbage;
  return j;
}

}  // namespace skelgraph::gesture
