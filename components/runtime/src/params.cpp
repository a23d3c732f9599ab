#include "skelgraph/runtime/params.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace skelgraph::runtime {

const char* to_string(ParamType t) {
  switch (t) {
    case ParamType::Bool: return "bool";
    case ParamType::Int: return "integer";
    case ParamType::Double: return "number";
    case ParamType::String: return "string";
    case ParamType::StringList: return "list of strings";
  }
  return "?";
}

std::string format_value(const ParamValue& v) {
  struct Visitor {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(std::int64_t i) const { return std::to_string(i); }
    std::string operator()(double d) const {
      std::ostringstream os;
      os << d;
      return os.str();
    }
    std::string operator()(const std::string& s) const { return "\"" + s + "\""; }
    std::string operator()(const std::vector<std::string>& l) const {
      std::string out = "[";
      for (std::size_t i = 0; i < l.size(); ++i) out += (i ? ", " : "") + l[i];
      return out + "]";
    }
  };
  return std::visit(Visitor{}, v);
}

namespace {

bool matches_type(const ParamValue& v, ParamType t) {
  switch (t) {
    case ParamType::Bool: return std::holds_alternative<bool>(v);
    case ParamType::Int: return std::holds_alternative<std::int64_t>(v);
    case ParamType::Double: return std::holds_alternative<double>(v);
    case ParamType::String: return std::holds_alternative<std::string>(v);
    case ParamType::StringList: return std::holds_alternative<std::vector<std::string>>(v);
  }
  return false;
}

std::optional<bool> parse_bool(const std::string& s) {
  std::string l = s;
  std::transform(l.begin(), l.end(), l.begin(), [](unsigned char c) { return std::tolower(c); });
  if (l == "true" || l == "yes" || l == "on" || l == "1") return true;
  if (l == "false" || l == "no" || l == "off" || l == "0") return false;
  return std::nullopt;
}

std::optional<std::int64_t> parse_int(const std::string& s) {
  if (s.empty()) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (errno != 0 || end != s.c_str() + s.size()) return std::nullopt;
  return static_cast<std::int64_t>(v);
}

std::optional<double> parse_double(const std::string& s) {
  if (s.empty()) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (errno != 0 || end != s.c_str() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string range_text(const ParamSpec& spec) {
  std::ostringstream os;
  if (spec.min && spec.max) {
    os << " in [" << *spec.min << ", " << *spec.max << "]";
  } else if (spec.min) {
    os << " >= " << *spec.min;
  } else if (spec.max) {
    os << " <= " << *spec.max;
  }
  return os.str();
}

// Converts one raw value; returns an error text or the value.
std::variant<ParamValue, std::string> convert(const ParamSpec& spec, const RawParam& raw) {
  const auto* scalar = std::get_if<std::string>(&raw.value);
  const auto expected = std::string("expects ") + to_string(spec.type);
  if (spec.type == ParamType::StringList) {
    if (scalar != nullptr) {
      // "a,b,c" on a command line; a YAML list arrives as a list already.
      std::vector<std::string> out;
      std::stringstream ss(*scalar);
      std::string item;
      while (std::getline(ss, item, ',')) {
        if (!item.empty()) out.push_back(item);
      }
      return ParamValue{out};
    }
    return ParamValue{std::get<std::vector<std::string>>(raw.value)};
  }
  if (scalar == nullptr) return expected + ", got a list";
  switch (spec.type) {
    case ParamType::Bool: {
      auto b = parse_bool(*scalar);
      if (!b) return expected + " (true/false), got '" + *scalar + "'";
      return ParamValue{*b};
    }
    case ParamType::Int: {
      auto i = parse_int(*scalar);
      if (!i) return expected + range_text(spec) + ", got '" + *scalar + "'";
      if ((spec.min && *i < *spec.min) || (spec.max && *i > *spec.max)) {
        return expected + range_text(spec) + ", got " + *scalar;
      }
      return ParamValue{*i};
    }
    case ParamType::Double: {
      auto d = parse_double(*scalar);
      if (!d) return expected + range_text(spec) + ", got '" + *scalar + "'";
      if ((spec.min && *d < *spec.min) || (spec.max && *d > *spec.max)) {
        return expected + range_text(spec) + ", got " + *scalar;
      }
      return ParamValue{*d};
    }
    case ParamType::String: {
      if (!spec.choices.empty() &&
          std::find(spec.choices.begin(), spec.choices.end(), *scalar) == spec.choices.end()) {
        std::string list;
        for (const auto& c : spec.choices) list += (list.empty() ? "" : ", ") + c;
        return "expects one of {" + list + "}, got '" + *scalar + "'";
      }
      return ParamValue{*scalar};
    }
    case ParamType::StringList: break;
  }
  return std::string("unsupported parameter type");
}

}  // namespace

ParamSchema& ParamSchema::add(ParamSpec spec) {
  if (find(spec.name) != nullptr) throw std::logic_error("parameter '" + spec.name + "' declared twice");
  if (spec.default_value && !matches_type(*spec.default_value, spec.type)) {
    throw std::logic_error("parameter '" + spec.name + "': default does not match its type");
  }
  specs_.push_back(std::move(spec));
  return *this;
}

ParamSchema& ParamSchema::add_bool(const std::string& name, bool def, const std::string& description) {
  return add({name, ParamType::Bool, ParamValue{def}, description, {}, {}, {}});
}
ParamSchema& ParamSchema::add_int(const std::string& name, std::int64_t def, const std::string& description,
                                  std::optional<double> min, std::optional<double> max) {
  return add({name, ParamType::Int, ParamValue{def}, description, min, max, {}});
}
ParamSchema& ParamSchema::add_double(const std::string& name, double def, const std::string& description,
                                     std::optional<double> min, std::optional<double> max) {
  return add({name, ParamType::Double, ParamValue{def}, description, min, max, {}});
}
ParamSchema& ParamSchema::add_string(const std::string& name, const std::string& def,
                                     const std::string& description, std::vector<std::string> choices) {
  return add({name, ParamType::String, ParamValue{def}, description, {}, {}, std::move(choices)});
}
ParamSchema& ParamSchema::add_string_list(const std::string& name, std::vector<std::string> def,
                                          const std::string& description) {
  return add({name, ParamType::StringList, ParamValue{std::move(def)}, description, {}, {}, {}});
}

const ParamSpec* ParamSchema::find(const std::string& name) const {
  for (const auto& s : specs_) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

Params ParamSchema::resolve(const std::vector<RawParam>& raw, const std::string& who) const {
  Params out;
  std::vector<std::string> errors;
  auto prefix = [&](const RawParam& r) { return (r.origin.empty() ? "" : r.origin + ": ") + who + ": "; };
  for (const auto& r : raw) {
    const ParamSpec* spec = find(r.key);
    if (spec == nullptr) {
      std::string known;
      for (const auto& s : specs_) known += (known.empty() ? "" : ", ") + s.name;
      errors.push_back(prefix(r) + "unknown parameter '" + r.key + "' (known: " +
                       (known.empty() ? "none" : known) + ")");
      continue;
    }
    if (out.has(r.key)) {
      errors.push_back(prefix(r) + "parameter '" + r.key + "' given twice");
      continue;
    }
    auto v = convert(*spec, r);
    if (auto* err = std::get_if<std::string>(&v)) {
      errors.push_back(prefix(r) + "parameter '" + r.key + "' " + *err);
    } else {
      out.set(r.key, std::get<ParamValue>(std::move(v)));
    }
  }
  for (const auto& s : specs_) {
    if (out.has(s.name)) continue;
    if (s.default_value) {
      out.set(s.name, *s.default_value);
    } else {
      errors.push_back(who + ": required parameter '" + s.name + "' (" + to_string(s.type) + ") is missing");
    }
  }
  if (!errors.empty()) {
    std::string msg;
    for (const auto& e : errors) msg += (msg.empty() ? "" : "\n") + e;
    throw ParamError(msg);
  }
  return out;
}

RawParam parse_param_assignment(const std::string& text, const std::string& origin) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw ParamError(origin + ": expected KEY=VALUE, got '" + text + "'");
  }
  return RawParam{text.substr(0, eq), text.substr(eq + 1), origin};
}

std::vector<std::string> rejoin_named_items(const std::vector<std::string>& pieces) {
  std::vector<std::string> items;
  for (const auto& piece : pieces) {
    if (piece.find(':') == std::string::npos && !items.empty()) items.back() += "," + piece;
    else items.push_back(piece);
  }
  return items;
}

}  // namespace skelgraph::runtime
