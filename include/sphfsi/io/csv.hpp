// sphfsi: comma-separated files: a time-series writer for probes and a small reader for validation data.
//
//   sphfsi::io::CsvWriter probe("out/gate_tip.csv", {"t", "dx", "dy"});
//   probe.write_row({t, dx, dy});                     // one line, flushed at once
//
//   const auto exp = sphfsi::io::read_csv(data_dir / "antoci2007_gate_tip_experiment.csv");
//   std::vector<double> t = exp.column("t");
//
// Format read and written: lines starting with '#' (after optional blanks) are comments, blank lines are skipped,
// the first other line is the header of column names, every further line is one row with one field per column.
// Fields are separated by ',' and trimmed of blanks; quoting is not supported (no field may contain a comma).
// An empty numeric field reads as NaN (the data files leave missing samples empty).
#pragma once

#include <sphfsi/core/error.hpp>

#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace sphfsi::io {

/// Writes a CSV time series: an optional block of '#' comment lines, a header, then one row per write_row() call,
/// each flushed to the operating system at once so an interrupted run keeps every row written so far. Numbers are
/// written with `{:.9g}` (round-trips float exactly, double to 9 significant digits).
class CsvWriter {
 public:
  /// Opens (truncates) `path`, creating its parent folders. `comment` may hold several lines; each is written
  /// prefixed with "# ". Throws InputError for an empty column list, an empty, duplicate or comma-containing column
  /// name, or a file that cannot be opened.
  CsvWriter(std::filesystem::path path, std::vector<std::string> columns, std::string_view comment = {})
      : path_(std::move(path)), columns_(std::move(columns)) {
    if (columns_.empty()) throw InputError(fmt::format("CsvWriter '{}': no columns given", path_.string()));
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      const auto& name = columns_[c];
      if (name.empty() || name.find_first_of(",\n\r") != std::string::npos)
        throw InputError(fmt::format("CsvWriter '{}': column #{} name '{}' is empty or contains ',' or a line break",
                                     path_.string(), c, name));
      for (std::size_t d = 0; d < c; ++d)
        if (columns_[d] == name)
          throw InputError(fmt::format("CsvWriter '{}': column name '{}' is given twice", path_.string(), name));
    }
    if (path_.has_parent_path()) {
      std::error_code ec;
      std::filesystem::create_directories(path_.parent_path(), ec);  // failure is reported by the open below
    }
    out_.open(path_, std::ios::binary | std::ios::trunc);
    if (!out_)
      throw InputError(
          fmt::format("CsvWriter: cannot open '{}' for writing: {}", path_.string(), std::strerror(errno)));

    std::string text;
    std::string_view rest = comment;
    while (!rest.empty()) {
      const auto eol = rest.find('\n');
      text += "# ";
      text += rest.substr(0, eol);
      text += '\n';
      rest = eol == std::string_view::npos ? std::string_view{} : rest.substr(eol + 1);
    }
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      if (c) text += ',';
      text += columns_[c];
    }
    text += '\n';
    put(text);
  }

  CsvWriter(CsvWriter&&) noexcept = default;
  CsvWriter& operator=(CsvWriter&&) noexcept = default;

  /// Appends one row; `values.size()` must equal the number of columns.
  void write_row(std::span<const double> values) {
    if (values.size() != columns_.size())
      throw InputError(fmt::format("CsvWriter '{}': row has {} values but the header has {} columns", path_.string(),
                                   values.size(), columns_.size()));
    line_.clear();
    for (std::size_t c = 0; c < values.size(); ++c) {
      if (c) line_ += ',';
      fmt::format_to(std::back_inserter(line_), "{:.9g}", values[c]);
    }
    line_ += '\n';
    put(line_);
    ++rows_;
  }
  void write_row(std::initializer_list<double> values) {
    write_row(std::span<const double>(values.begin(), values.size()));
  }

  const std::filesystem::path& path() const noexcept { return path_; }
  const std::vector<std::string>& columns() const noexcept { return columns_; }
  /// Rows written so far (header and comments not counted).
  std::size_t row_count() const noexcept { return rows_; }

 private:
  void put(const std::string& text) {
    out_.write(text.data(), static_cast<std::streamsize>(text.size()));
    out_.flush();
    if (!out_)
      throw std::runtime_error(
          fmt::format("CsvWriter: error while writing '{}': {}", path_.string(), std::strerror(errno)));
  }

  std::filesystem::path path_;
  std::vector<std::string> columns_;
  std::ofstream out_;
  std::string line_;  // reused row buffer
  std::size_t rows_ = 0;
};

/// A CSV file read into memory: column names and the text of every field, converted to numbers on request.
class CsvTable {
 public:
  CsvTable(std::filesystem::path source, std::vector<std::string> names, std::vector<std::vector<std::string>> cells,
           std::vector<std::size_t> line_numbers)
      : source_(std::move(source)),
        names_(std::move(names)),
        cells_(std::move(cells)),
        lines_(std::move(line_numbers)) {}

  const std::filesystem::path& source() const noexcept { return source_; }
  const std::vector<std::string>& column_names() const noexcept { return names_; }
  std::size_t row_count() const noexcept { return lines_.size(); }
  bool has_column(std::string_view name) const noexcept { return find(name) != names_.size(); }

  /// Values of a numeric column, one per row. Empty fields give NaN. Throws InputError naming the file and the
  /// available columns if there is no such column, or the file, line and text of a field that is not a number.
  std::vector<double> column(std::string_view name) const {
    const std::size_t c = index_of(name);
    std::vector<double> v;
    v.reserve(cells_[c].size());
    for (std::size_t r = 0; r < cells_[c].size(); ++r) {
      const std::string& s = cells_[c][r];
      if (s.empty()) {
        v.push_back(std::numeric_limits<double>::quiet_NaN());
        continue;
      }
      const char* first = s.data();
      const char* last = s.data() + s.size();
      if (*first == '+' && last - first > 1 && first[1] != '-') ++first;  // from_chars rejects a leading '+'
      double x = 0;
      const auto [end, ec] = std::from_chars(first, last, x);
      if (ec == std::errc::result_out_of_range) {
        x = std::strtod(s.c_str(), nullptr);  // overflow or underflow: keep the +-inf or denormal strtod gives
      } else if (ec != std::errc{} || end != last) {
        throw InputError(
            fmt::format("{}:{}: column '{}': field '{}' is not a number", source_.string(), lines_[r], name, s));
      }
      v.push_back(x);
    }
    return v;
  }

  /// Raw text of a column (for label columns such as "method"). Throws InputError like column().
  const std::vector<std::string>& text_column(std::string_view name) const { return cells_[index_of(name)]; }

 private:
  std::size_t find(std::string_view name) const noexcept {
    for (std::size_t c = 0; c < names_.size(); ++c)
      if (names_[c] == name) return c;
    return names_.size();
  }
  std::size_t index_of(std::string_view name) const {
    const std::size_t c = find(name);
    if (c == names_.size()) {
      std::string available;
      for (const auto& n : names_) available += (available.empty() ? "" : ", ") + n;
      throw InputError(fmt::format("column '{}' not found in CSV file '{}'; available columns: {}", name,
                                   source_.string(), available));
    }
    return c;
  }

  std::filesystem::path source_;
  std::vector<std::string> names_;
  std::vector<std::vector<std::string>> cells_;  // [column][row]
  std::vector<std::size_t> lines_;               // 1-based file line of each row, for messages
};

namespace detail {
inline std::string_view trim(std::string_view s) {
  const auto blank = " \t\r\n";
  const auto b = s.find_first_not_of(blank);
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(blank) - b + 1);
}
inline std::vector<std::string> split_fields(std::string_view line) {
  std::vector<std::string> f;
  for (;;) {
    const auto comma = line.find(',');
    f.emplace_back(trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return f;
    line.remove_prefix(comma + 1);
  }
}
}  // namespace detail

/// Reads a CSV file (format in the header comment of this file). Throws InputError if the file cannot be opened,
/// has no header line, repeats a column name, or has a row with the wrong number of fields (naming the line).
inline CsvTable read_csv(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(fmt::format("cannot open CSV file '{}': {}", path.string(),
                                 std::filesystem::exists(path) ? std::strerror(errno) : "no such file"));
  std::vector<std::string> names;
  std::vector<std::vector<std::string>> cells;
  std::vector<std::size_t> lines;
  std::string raw;
  std::size_t line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    std::string_view line = raw;
    if (line_no == 1 && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);  // UTF-8 byte order mark
    line = detail::trim(line);
    if (line.empty() || line.front() == '#') continue;
    auto fields = detail::split_fields(line);
    if (names.empty()) {
      for (std::size_t c = 0; c < fields.size(); ++c) {
        if (fields[c].empty())
          throw InputError(fmt::format("{}:{}: header column #{} has an empty name", path.string(), line_no, c));
        for (std::size_t d = 0; d < c; ++d)
          if (fields[d] == fields[c])
            throw InputError(fmt::format("{}:{}: header names column '{}' twice", path.string(), line_no, fields[c]));
      }
      names = std::move(fields);
      cells.resize(names.size());
      continue;
    }
    if (fields.size() != names.size())
      throw InputError(fmt::format("{}:{}: row has {} fields but the header has {} columns", path.string(), line_no,
                                   fields.size(), names.size()));
    for (std::size_t c = 0; c < fields.size(); ++c) cells[c].push_back(std::move(fields[c]));
    lines.push_back(line_no);
  }
  if (in.bad()) throw InputError(fmt::format("error while reading CSV file '{}'", path.string()));
  if (names.empty()) throw InputError(fmt::format("CSV file '{}' has no header line", path.string()));
  return CsvTable(path, std::move(names), std::move(cells), std::move(lines));
}

}  // namespace sphfsi::io
