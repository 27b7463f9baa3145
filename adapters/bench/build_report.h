// A builder's measurements as a person reads them (the build command's report, the bench's
// table per scene) and as programs read them (JSON, CSV).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "measure.h"
#include "paper_table.h"
#include "table.h"

namespace kmbvh {

// The paper's Table 1 column this configuration reproduces, if any.
std::optional<PaperFigures> paper_figures_for(const Measurement& m);

nlohmann::json to_json(const Measurement& m);
// What the build asked of its backend (BuildInfo::backend), with host syncs per level.
nlohmann::json backend_steps_json(const BuildInfo& info);

// `kmbvh build`'s report: one "name   value" line per figure.
std::string measurement_text(const Measurement& m);

// Sets every row's sah_over_sweep from the scene's sweep-sah row, if there is one.
void normalise_to_sweep(std::vector<Measurement>& rows);

// One scene's rows as `kmbvh bench` prints them: a title line, the table, and a legend;
// build-time ratios are to the row labelled `reference` (when present).
std::string scene_report(const std::vector<Measurement>& rows, const std::string& reference);

// Every row of every scene, as `kmbvh bench --csv` writes them; ratios as in scene_report.
Table bench_csv_table(const std::vector<std::vector<Measurement>>& scenes, const std::string& reference);

}  // namespace kmbvh
