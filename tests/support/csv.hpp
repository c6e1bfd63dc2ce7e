// Reading the CSV files and CSV output of the project's programs in tests: a header line, then
// rows of numbers; lines starting with '#' are comments.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace gfins::test {

/// The lines of a text, without their '\n'.
inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// The comma-separated cells of one line, as written.
inline std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) out.push_back(cell);
  return out;
}

/// The cells of one line as numbers (strtod: a cell that is no number reads 0).
inline std::vector<double> numbers_of(const std::string& line) {
  std::vector<double> out;
  for (const auto& cell : cells_of(line)) out.push_back(std::strtod(cell.c_str(), nullptr));
  return out;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;

  /// Index of a column; a test failure (and 0) when there is none.
  std::size_t index(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return i;
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
  /// A whole column; a test failure (and nothing) when there is none.
  std::vector<double> column(const std::string& name) const {
    std::vector<double> out;
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] != name) continue;
      for (const auto& r : rows) out.push_back(r.at(i));
      return out;
    }
    ADD_FAILURE() << "no column " << name;
    return out;
  }
};

/// A CSV text: the first line that is neither empty nor a '#' comment is the header.
inline Csv parse_csv(const std::string& text) {
  Csv c;
  for (const auto& line : lines_of(text)) {
    if (line.empty() || line[0] == '#') continue;
    if (c.header.empty()) {
      c.header = cells_of(line);
    } else {
      c.rows.push_back(numbers_of(line));
    }
  }
  return c;
}

/// `gfins-can decode --view csv` output: the header's names without their units ("Roll" of
/// "Roll[rad]") and every row's cells as text, an empty cell being a value not available (or a
/// message not in that epoch). Trailing empty cells are kept, so each row has the header's width.
struct DecodedTable {
  std::vector<std::string> names;
  std::vector<std::vector<std::string>> rows;
  /// Index of a column, -1 when there is none.
  int col(const std::string& n) const {
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == n) return static_cast<int>(i);
    }
    return -1;
  }
};

/// The cells of a line of the decoder's CSV, empty ones (and a trailing one) included.
inline std::vector<std::string> decoded_cells(const std::string& line) {
  std::vector<std::string> out = cells_of(line);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

/// The header of the decoder's CSV: its names without units.
inline std::vector<std::string> decoded_names(const std::string& header) {
  std::vector<std::string> out;
  for (const std::string& h : decoded_cells(header)) out.push_back(h.substr(0, h.find('[')));
  return out;
}

inline DecodedTable read_decoded_csv(const std::string& text) {
  DecodedTable t;
  std::istringstream in(text);
  std::string line;
  if (std::getline(in, line)) t.names = decoded_names(line);
  while (std::getline(in, line)) t.rows.push_back(decoded_cells(line));
  return t;
}

}  // namespace gfins::test
