#include "skelgraph/playback/csv.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace skelgraph::playback {

namespace {
std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}
}  // namespace

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c != 0x7f) {
      out += ch;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

CsvReader::CsvReader(std::string path, char separator) : path_(std::move(path)), in_(path_), separator_(separator) {
  if (!in_) throw DataError(path_, 0, "cannot open file");
}

bool CsvReader::next(std::vector<std::string>& fields) {
  std::string text;
  while (std::getline(in_, text)) {
    ++line_;
    if (line_ == 1 && text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);  // UTF-8 BOM
    if (trim(text).empty()) continue;
    fields.clear();
    if (separator_ == ' ') {
      const std::string t = trim(text);
      std::size_t at = 0;
      while (at < t.size()) {
        const auto end = t.find_first_of(" \t", at);
        fields.push_back(t.substr(at, end == std::string::npos ? std::string::npos : end - at));
        if (end == std::string::npos) break;
        at = t.find_first_not_of(" \t", end);
      }
      return true;
    }
    std::size_t start = 0;
    while (true) {
      const auto comma = text.find(separator_, start);
      fields.push_back(trim(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (fields.size() > 1 && fields.back().empty()) fields.pop_back();
    return true;
  }
  return false;
}

double CsvReader::number(const std::vector<std::string>& fields, std::size_t i, const std::string& column) const {
  if (i >= fields.size()) fail("column '" + column + "' missing (the line has " + std::to_string(fields.size()) + " fields)");
  const auto& f = fields[i];
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(f.c_str(), &end);
  if (f.empty() || end != f.c_str() + f.size() || errno == ERANGE) {
    fail("column '" + column + "' expects a number, got '" + f + "'");
  }
  if (!std::isfinite(v)) fail("column '" + column + "' expects a finite number, got '" + f + "'");
  return v;
}

long long CsvReader::integer(const std::vector<std::string>& fields, std::size_t i, const std::string& column) const {
  if (i >= fields.size()) fail("column '" + column + "' missing (the line has " + std::to_string(fields.size()) + " fields)");
  const auto& f = fields[i];
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(f.c_str(), &end, 10);
  if (f.empty() || end != f.c_str() + f.size() || errno == ERANGE) {
    fail("column '" + column + "' expects an integer, got '" + f + "'");
  }
  return v;
}

}  // namespace skelgraph::playback
