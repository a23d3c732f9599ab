#pragma once
// Line-oriented CSV reading for recorded data sets: BOM, CRLF, ", " separators
// and trailing commas handled once here; every problem names file:line.

#include <cstddef>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace skelgraph::playback {

// `text` safe to print on a terminal: control bytes (and DEL) as \n, \r, \t
// or \xNN; everything else, UTF-8 included, as it is.
std::string printable(std::string_view text);

// A problem in an input file, with where and what was expected. The message
// is printable(): input quoted in it cannot send control bytes to a terminal.
class DataError : public std::runtime_error {
 public:
  DataError(const std::string& file, std::size_t line, const std::string& what)
      : std::runtime_error(printable(file + ":" + std::to_string(line) + ": " + what)), file_(file), line_(line) {}
  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }

 private:
  std::string file_;
  std::size_t line_;
};

class CsvReader {
 public:
  // Throws DataError (line 0) if the file cannot be opened. `separator`
  // ' ': fields are separated by runs of spaces or tabs (MSRC-12).
  explicit CsvReader(std::string path, char separator = ',');
  // The next non-empty line split into trimmed fields; false at the end.
  // A trailing empty field (a line ending with a comma) is dropped.
  bool next(std::vector<std::string>& fields);
  std::size_t line() const { return line_; }  // 1-based number of the line last read
  const std::string& path() const { return path_; }

  [[noreturn]] void fail(const std::string& what) const { throw DataError(path_, line_, what); }
  // Converts fields[i]; NaN, Inf, empty or trailing junk is an error naming `column`.
  double number(const std::vector<std::string>& fields, std::size_t i, const std::string& column) const;
  long long integer(const std::vector<std::string>& fields, std::size_t i, const std::string& column) const;

 private:
  std::string path_;
  std::ifstream in_;
  char separator_ = ',';
  std::size_t line_ = 0;
};

}  // namespace skelgraph::playback
