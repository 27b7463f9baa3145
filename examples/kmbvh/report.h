// Measurements as a person reads them (tables) and as programs read them (JSON, CSV).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "measure.h"
#include "paper_table.h"

namespace kmbvh {

// The paper's Table 1 column this configuration reproduces, if any.
std::optional<PaperFigures> paper_figures_for(const Measurement& m);

nlohmann::json to_json(const Measurement& m);

void print_measurement(const Measurement& m);

// Sets every row's sah_over_sweep from the scene's sweep-sah row, if there is one.
void normalise_to_sweep(std::vector<Measurement>& rows);

// One table for one scene; build-time ratios are to the row labelled `reference` (when present).
void print_scene_table(const std::vector<Measurement>& rows, const std::string& reference);

std::string csv_header();
std::string csv_row(const Measurement& m, const std::vector<Measurement>& same_scene, const std::string& reference);

}  // namespace kmbvh
