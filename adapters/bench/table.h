// One table, three renderings: aligned text for a terminal, Markdown for the results pages,
// CSV for spreadsheets and scripts. Every report the tools print (bench, stress, the paper
// suite) is built as a Table, so the three forms always carry the same rows.
#pragma once

#include <string>
#include <vector>

namespace kmbvh {

enum class Align { Left, Right };

struct Column {
  std::string header;
  Align align = Align::Right;
};

class Table {
 public:
  explicit Table(std::vector<Column> columns);

  // Throws std::invalid_argument unless there is one cell per column.
  void add_row(std::vector<std::string> cells);

  size_t rows() const { return rows_.size(); }
  const std::vector<Column>& columns() const { return columns_; }
  const std::vector<std::string>& row(size_t index) const { return rows_[index]; }

  // Columns padded to their widest cell and two spaces apart; one line each, header first.
  std::string text() const;
  // GitHub-flavoured: a header, a rule saying each column's alignment, '|' in cells escaped.
  std::string markdown() const;
  // RFC 4180: a header line, then one line per row; a cell holding a comma, a quote or a
  // line break is quoted, with its quotes doubled.
  std::string csv() const;

 private:
  std::vector<Column> columns_;
  std::vector<std::vector<std::string>> rows_;
};

// Writes a report to a file, replacing it; throws std::invalid_argument naming the file
// when it cannot be written (the tools' exit code for bad input).
void write_text_file(const std::string& path, const std::string& text);

}  // namespace kmbvh
