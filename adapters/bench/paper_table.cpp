#include "paper_table.h"

#include <map>

namespace kmbvh {
namespace {

using Row = std::map<std::string, PaperFigures>;

const std::map<std::string, Row>& table() {
  static const std::map<std::string, Row> t{
      {"sponza_dabrovic",
       {{"sweep-sah", {216, 211, 0}}, {"lbvh", {264, 189, 1.8}}, {"hlbvh", {219, 206, 11.7}},
        {"atrbvh", {180, 223, 5.4}}, {"Q1", {229, 200, 2.7}}, {"Q2", {211, 212, 4.2}},
        {"Q3", {203, 212, 9.0}}, {"Q4", {198, 224, 30.1}}, {"Q5", {195, 216, 111}}}},
      {"sibenik",
       {{"sweep-sah", {147, 199, 0}}, {"lbvh", {192, 175, 2.1}}, {"hlbvh", {156, 192, 12.3}},
        {"atrbvh", {138, 209, 6.0}}, {"Q1", {177, 184, 3.0}}, {"Q2", {165, 190, 4.5}},
        {"Q3", {158, 190, 9.3}}, {"Q4", {150, 201, 33.7}}, {"Q5", {147, 199, 117}}}},
      {"conference",
       {{"sweep-sah", {120, 223, 0}}, {"lbvh", {159, 192, 5.8}}, {"hlbvh", {135, 212, 13.5}},
        {"atrbvh", {93, 239, 20.4}}, {"Q1", {131, 220, 6.8}}, {"Q2", {115, 231, 12.3}},
        {"Q3", {102, 240, 22.4}}, {"Q4", {101, 240, 75.0}}, {"Q5", {96, 240, 282}}}},
  };
  return t;
}

}  // namespace

std::optional<PaperFigures> paper_figures(const std::string& scene, const std::string& column) {
  if (scene.find('@') != std::string::npos) return std::nullopt;  // copies (instanced_scene.h): not the paper's scene
  const std::string stem = scene.substr(0, scene.find('.'));
  const auto row = table().find(stem);
  if (row == table().end()) return std::nullopt;
  const auto cell = row->second.find(column);
  if (cell == row->second.end()) return std::nullopt;
  return cell->second;
}

}  // namespace kmbvh
