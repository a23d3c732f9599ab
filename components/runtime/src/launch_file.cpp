#include "skelgraph/runtime/launch_file.hpp"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

namespace skelgraph::runtime {

namespace {

std::string where(const std::string& source, const YAML::Mark& m) {
  if (m.is_null()) return source;
  return source + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

std::string node_kind(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Map: return "a mapping";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Scalar: return "'" + n.Scalar() + "'";
    case YAML::NodeType::Null: return "nothing";
    default: return "an undefined value";
  }
}

class Parser {
 public:
  explicit Parser(std::string source) : source_(std::move(source)) {}

  LaunchSpec parse(const YAML::Node& root) {
    LaunchSpec spec;
    spec.source = source_;
    if (!root.IsMap()) fail(root, "expected a mapping with 'components:' at the top, got " + node_kind(root));
    for (const auto& kv : root) {
      const auto key = kv.first.Scalar();
      if (key == "profile") {
        spec.profile = scalar(kv.second, "profile", "a profile name");
      } else if (key == "domain") {
        const auto text = scalar(kv.second, "domain", "a domain id 0..232");
        int d = -1;
        std::istringstream is(text);
        if (!(is >> d) || !is.eof() || d < 0 || d > 232) {
          fail(kv.second, "'domain' expects a domain id 0..232, got '" + text + "'");
        }
        spec.domain = d;
      } else if (key == "components") {
        if (!kv.second.IsSequence()) fail(kv.second, "'components' expects a list, got " + node_kind(kv.second));
        for (const auto& c : kv.second) spec.components.push_back(component(c));
      } else {
        fail(kv.first, "unknown key '" + key + "' (expected: profile, domain, components)");
      }
    }
    if (spec.components.empty()) fail(root, "no components listed");
    std::set<std::string> names;
    for (const auto& c : spec.components) {
      if (!names.insert(c.name).second) throw LaunchError(c.origin + ": component name '" + c.name + "' used twice");
    }
    return spec;
  }

 private:
  [[noreturn]] void fail(const YAML::Node& n, const std::string& what) const {
    throw LaunchError(where(source_, n.Mark()) + ": " + what);
  }

  std::string scalar(const YAML::Node& n, const std::string& key, const std::string& expected) const {
    if (!n.IsScalar()) fail(n, "'" + key + "' expects " + expected + ", got " + node_kind(n));
    return n.Scalar();
  }

  ComponentSpec component(const YAML::Node& n) {
    if (!n.IsMap()) fail(n, "a component entry expects a mapping with name and type, got " + node_kind(n));
    ComponentSpec c;
    c.origin = where(source_, n.Mark());
    for (const auto& kv : n) {
      const auto key = kv.first.Scalar();
      if (key == "name") {
        c.name = scalar(kv.second, "name", "a name");
      } else if (key == "type") {
        c.kind = scalar(kv.second, "type", "a component type");
      } else if (key == "host") {
        if (kv.second.IsScalar()) {
          c.hosts.push_back(kv.second.Scalar());
        } else if (kv.second.IsSequence()) {
          for (const auto& h : kv.second) c.hosts.push_back(scalar(h, "host", "a host name"));
        } else {
          fail(kv.second, "'host' expects a host name or a list of them, got " + node_kind(kv.second));
        }
      } else if (key == "params") {
        if (kv.second.IsNull()) continue;
        if (!kv.second.IsMap()) fail(kv.second, "'params' expects a mapping, got " + node_kind(kv.second));
        for (const auto& p : kv.second) {
          RawParam raw;
          raw.key = p.first.Scalar();
          raw.origin = where(source_, p.first.Mark());
          if (p.second.IsScalar()) {
            raw.value = p.second.Scalar();
          } else if (p.second.IsSequence()) {
            std::vector<std::string> items;
            for (const auto& item : p.second) items.push_back(scalar(item, raw.key, "a list of scalars"));
            raw.value = items;
          } else {
            fail(p.second, "parameter '" + raw.key + "' expects a value or a list, got " + node_kind(p.second));
          }
          c.params.push_back(std::move(raw));
        }
      } else {
        fail(kv.first, "unknown key '" + key + "' in a component (expected: name, type, host, params)");
      }
    }
    if (c.name.empty()) fail(n, "component without a 'name'");
    if (c.kind.empty()) fail(n, "component '" + c.name + "' has no 'type'");
    return c;
  }

  std::string source_;
};

}  // namespace

LaunchSpec parse_launch_text(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw LaunchError(where(source, e.mark) + ": not valid YAML: " + e.msg);
  }
  return Parser(source).parse(root);
}

LaunchSpec parse_launch_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw LaunchError(path + ": cannot open launch file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_launch_text(ss.str(), path);
}

void set_launch_params(LaunchSpec& spec, const std::vector<std::string>& assignments) {
  for (const auto& a : assignments) {
    const auto origin = "--set " + a;
    const auto dot = a.find('.');
    const auto eq = a.find('=');
    if (dot == std::string::npos || dot == 0 || eq == std::string::npos || eq < dot + 2) {
      throw LaunchError(origin + ": expected COMPONENT.KEY=VALUE");
    }
    const auto name = a.substr(0, dot);
    auto it = std::find_if(spec.components.begin(), spec.components.end(),
                           [&](const ComponentSpec& c) { return c.name == name; });
    if (it == spec.components.end()) {
      std::string known;
      for (const auto& c : spec.components) known += (known.empty() ? "" : ", ") + c.name;
      throw LaunchError(origin + ": " + spec.source + " has no component '" + name + "' (it has: " + known + ")");
    }
    RawParam p;
    try {
      p = parse_param_assignment(a.substr(dot + 1), origin);
    } catch (const ParamError& e) {
      throw LaunchError(e.what());
    }
    auto& params = it->params;
    const auto same = std::find_if(params.begin(), params.end(), [&](const RawParam& q) { return q.key == p.key; });
    if (same != params.end()) *same = std::move(p);
    else params.push_back(std::move(p));
  }
}

std::vector<ResolvedComponent> resolve_launch(const LaunchSpec& spec, const ComponentRegistry& registry,
                                              const std::string& host) {
  std::vector<ResolvedComponent> out;
  std::vector<std::string> errors;
  std::set<std::string> hosts_named;
  for (const auto& c : spec.components) {
    hosts_named.insert(c.hosts.begin(), c.hosts.end());
    if (!host.empty() && std::find(c.hosts.begin(), c.hosts.end(), host) == c.hosts.end()) continue;
    const auto* entry = registry.find(c.kind);
    if (entry == nullptr) {
      errors.push_back(c.origin + ": component '" + c.name + "' has unknown type '" + c.kind +
                       "' (known: " + registry.kinds_text() + ")");
      continue;
    }
    try {
      out.push_back({c.name, c.kind, entry->info.params.resolve(c.params, "component '" + c.name + "' (" + c.kind + ")")});
    } catch (const ParamError& e) {
      errors.push_back(e.what());
    }
  }
  if (!errors.empty()) {
    std::string msg;
    for (const auto& e : errors) msg += (msg.empty() ? "" : "\n") + e;
    throw LaunchError(msg);
  }
  if (out.empty()) {
    std::string names;
    for (const auto& h : hosts_named) names += (names.empty() ? "" : ", ") + h;
    throw LaunchError(spec.source + ": no components for host '" + host + "' (hosts named there: " +
                      (names.empty() ? "none" : names) + ")");
  }
  return out;
}

}  // namespace skelgraph::runtime
