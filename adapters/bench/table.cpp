#include "table.h"

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace kmbvh {
namespace {

std::string markdown_cell(const std::string& cell) {
  std::string out;
  for (const char c : cell) {
    if (c == '|') out += '\\';
    out += c == '\n' ? ' ' : c;
  }
  return out;
}

std::string csv_cell(const std::string& cell) {
  if (cell.find_first_of(",\"\r\n") == std::string::npos) return cell;
  std::string out = "\"";
  for (const char c : cell) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + '"';
}

}  // namespace

Table::Table(std::vector<Column> columns) : columns_(std::move(columns)) {
  if (columns_.empty()) throw std::invalid_argument("a table needs at least one column");
}

void Table::add_row(std::vector<std::string> cells) {
  if (cells.size() != columns_.size())
    throw std::invalid_argument("a row of " + std::to_string(cells.size()) + " cells in a table of " +
                                std::to_string(columns_.size()) + " columns");
  rows_.push_back(std::move(cells));
}

std::string Table::text() const {
  std::vector<size_t> width(columns_.size());
  for (size_t c = 0; c < columns_.size(); ++c) {
    width[c] = columns_[c].header.size();
    for (const auto& row : rows_) width[c] = std::max(width[c], row[c].size());
  }
  const auto line = [&](auto cell_of) {
    std::string out;
    for (size_t c = 0; c < columns_.size(); ++c) {
      const std::string& cell = cell_of(c);
      const std::string pad(width[c] - cell.size(), ' ');
      const bool last = c + 1 == columns_.size();
      if (c) out += "  ";
      out += columns_[c].align == Align::Left ? cell + (last ? "" : pad) : pad + cell;
    }
    return out + '\n';
  };
  std::string out = line([&](size_t c) -> const std::string& { return columns_[c].header; });
  for (const auto& row : rows_) out += line([&](size_t c) -> const std::string& { return row[c]; });
  return out;
}

std::string Table::markdown() const {
  std::string header = "|", rule = "|";
  for (const Column& column : columns_) {
    header += ' ' + markdown_cell(column.header) + " |";
    rule += column.align == Align::Left ? "---|" : "---:|";
  }
  std::string out = header + '\n' + rule + '\n';
  for (const auto& row : rows_) {
    out += '|';
    for (const std::string& cell : row) out += ' ' + markdown_cell(cell) + " |";
    out += '\n';
  }
  return out;
}

std::string Table::csv() const {
  const auto line = [](auto begin, auto end, auto text_of) {
    std::string out;
    for (auto it = begin; it != end; ++it) out += (it == begin ? "" : ",") + csv_cell(text_of(*it));
    return out + '\n';
  };
  std::string out = line(columns_.begin(), columns_.end(), [](const Column& c) { return c.header; });
  for (const auto& row : rows_) out += line(row.begin(), row.end(), [](const std::string& s) { return s; });
  return out;
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!(out << text) || !out.flush()) throw std::invalid_argument(path + ": cannot be written");
}

}  // namespace kmbvh
