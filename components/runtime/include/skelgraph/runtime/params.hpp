#pragma once
// Typed component parameters: each component declares a schema (names, types,
// defaults, limits); launch files and command lines give raw text that is
// checked against it. Unknown keys, wrong types and out-of-range values are
// errors that name where the value came from (file:line:column).

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace skelgraph::runtime {

enum class ParamType { Bool, Int, Double, String, StringList };
const char* to_string(ParamType t);

using ParamValue = std::variant<bool, std::int64_t, double, std::string, std::vector<std::string>>;
std::string format_value(const ParamValue& v);

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::String;
  std::optional<ParamValue> default_value;  // nullopt: the parameter is required
  std::string description;
  std::optional<double> min;                // Int and Double only, inclusive
  std::optional<double> max;
  std::vector<std::string> choices;         // String only; empty: any string
};

// A value as written by a user, before it is checked.
struct RawParam {
  std::string key;
  std::variant<std::string, std::vector<std::string>> value;  // scalar text, or a list of them
  std::string origin;  // where it was written, e.g. "bringup/sync.yaml:9:21"
};

class ParamError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Params {
 public:
  template <class T>
  const T& get(const std::string& name) const {
    const auto it = values_.find(name);
    if (it == values_.end()) throw std::logic_error("parameter '" + name + "' was not declared");
    const T* v = std::get_if<T>(&it->second);
    if (v == nullptr) throw std::logic_error("parameter '" + name + "' read with the wrong type");
    return *v;
  }
  bool has(const std::string& name) const { return values_.count(name) != 0; }
  void set(const std::string& name, ParamValue v) { values_[name] = std::move(v); }
  const std::map<std::string, ParamValue>& values() const { return values_; }

 private:
  std::map<std::string, ParamValue> values_;
};

class ParamSchema {
 public:
  ParamSchema& add(ParamSpec spec);  // throws std::logic_error on a duplicate or bad default
  ParamSchema& add_bool(const std::string& name, bool def, const std::string& description);
  ParamSchema& add_int(const std::string& name, std::int64_t def, const std::string& description,
                       std::optional<double> min = {}, std::optional<double> max = {});
  ParamSchema& add_double(const std::string& name, double def, const std::string& description,
                          std::optional<double> min = {}, std::optional<double> max = {});
  ParamSchema& add_string(const std::string& name, const std::string& def, const std::string& description,
                          std::vector<std::string> choices = {});
  ParamSchema& add_string_list(const std::string& name, std::vector<std::string> def,
                               const std::string& description);

  const std::vector<ParamSpec>& specs() const { return specs_; }
  const ParamSpec* find(const std::string& name) const;

  // Checks raw values against the schema and fills in defaults. `who` names the
  // owner in messages, e.g. "component 'sync' (sync_master)". Throws ParamError
  // listing every problem found, one per line.
  Params resolve(const std::vector<RawParam>& raw, const std::string& who) const;

 private:
  std::vector<ParamSpec> specs_;
};

// Parses "key=value" (value "a,b" for lists stays text; the schema splits it).
RawParam parse_param_assignment(const std::string& text, const std::string& origin);

// A list of "name:a,b,c" items given on a command line comes split at every
// comma: a piece without a ':' continues the item before it.
std::vector<std::string> rejoin_named_items(const std::vector<std::string>& pieces);

}  // namespace skelgraph::runtime
