// The paper's Table 1 (Meister and Bittner 2016; docs/design.md §4) for the scenes kmbvh has:
// SAH cost, Mrays/s and build time (GPU) per builder, to print beside kmbvh's figures.
#pragma once

#include <optional>
#include <string>

namespace kmbvh {

struct PaperFigures {
  double sah_cost = 0;
  double mrays_per_s = 0;
  double build_ms = 0;  // 0 where the paper gives none
};

// scene: a file name such as "conference.glb"; column: "sweep-sah", "lbvh", "hlbvh",
// "atrbvh" or "Q1".."Q5".
std::optional<PaperFigures> paper_figures(const std::string& scene, const std::string& column);

}  // namespace kmbvh
