#include "skelgraph/runtime/registry.hpp"

#include <algorithm>
#include <stdexcept>

namespace skelgraph::runtime {

void ComponentRegistry::add(ComponentInfo info, ComponentFactory factory) {
  if (info.kind.empty()) throw std::logic_error("component kind must not be empty");
  if (find(info.kind) != nullptr) throw std::logic_error("component kind '" + info.kind + "' registered twice");
  entries_.push_back(Entry{std::move(info), std::move(factory)});
}

const ComponentRegistry::Entry* ComponentRegistry::find(const std::string& kind) const {
  for (const auto& e : entries_) {
    if (e.info.kind == kind) return &e;
  }
  return nullptr;
}

std::vector<std::string> ComponentRegistry::kinds() const {
  std::vector<std::string> out;
  for (const auto& e : entries_) out.push_back(e.info.kind);
  std::sort(out.begin(), out.end());
  return out;
}

std::string ComponentRegistry::kinds_text() const {
  std::string out;
  for (const auto& k : kinds()) out += (out.empty() ? "" : ", ") + k;
  return out;
}

}  // namespace skelgraph::runtime
