// What a builder may report besides its tree: where its time went, for the phase charts
// and for finding what limits it.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "backend_counters.h"

namespace kmbvh {

struct BuildInfo {
  std::vector<std::pair<std::string, double>> phase_ms;  // in the order the phases first ran
  uint32_t levels = 0;          // top-down levels (k-means)
  uint64_t level_host_syncs = 0;  // backend.host_syncs made inside those levels (the rest: once a build)
  // Steps taken by position because clustering made no progress: k-means nodes split by
  // index, PLOC iterations that paired Morton neighbours.
  uint32_t forced_splits = 0;
  // Time inside the builder call spent only to hand its result to kmbvh's measuring (for
  // Embree: refilling its input array and converting its nodes into a Bvh). Reported build
  // times leave it out, so each builder is charged what an application using it pays.
  double excluded_ms = 0;
  // What the build asked of its backend: parallel steps, host waits, allocations (the
  // portable builders; zero for the others).
  BackendCounters backend;

  void add_phase(const std::string& name, double ms) {
    for (auto& [n, t] : phase_ms)
      if (n == name) {
        t += ms;
        return;
      }
    phase_ms.emplace_back(name, ms);
  }
};

}  // namespace kmbvh
