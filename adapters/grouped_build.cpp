#include "grouped_build.h"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <thread>

#include "cuda/core/parallel_errors.h"
#include "cuda/core/threads.h"
#include "cuda/metrics/sah.h"
#include "cuda/sweep_sah/sweep_sah.h"

namespace kmbvh {

namespace {

// The top tree over the groups' boxes: sweep SAH (docs/design.md §5) with every group a
// leaf of its own, so that a group's root can take its leaf's place.
Bvh top_tree(const GroupedBvh& grouped) {
  PrimitiveSet set;
  for (uint32_t g = 0; g < grouped.groups(); ++g) set.push_back(grouped.trees[g].root().box, PrimitiveId{0, g});
  SweepSahParams params;
  params.max_leaf_size = 1;
  return build_sweep_sah(set, params);
}

void add_counters(BuildInfo* info, const BuildInfo& group) {
  if (!info) return;
  for (const auto& [name, ms] : group.phase_ms) info->add_phase(name, ms);
  info->levels = std::max(info->levels, group.levels);
  info->level_host_syncs += group.level_host_syncs;
  info->forced_splits += group.forced_splits;
  info->excluded_ms += group.excluded_ms;
  info->backend += group.backend;
}

}  // namespace

std::vector<uint32_t> groups_by_geometry(const std::vector<PrimitiveId>& ids) {
  std::vector<uint32_t> first;
  for (uint32_t t = 0; t < ids.size(); ++t)
    if (t == 0 || ids[t].geom != ids[t - 1].geom) first.push_back(t);
  return first;
}

PrimitiveSet group_primitives(const PrimitiveSet& prims, const std::vector<uint32_t>& first, size_t g) {
  const uint32_t begin = first[g], end = group_end(first, g, prims.size());
  PrimitiveSet group;
  group.boxes.assign(prims.boxes.begin() + begin, prims.boxes.begin() + end);
  group.ids.assign(prims.ids.begin() + begin, prims.ids.begin() + end);
  return group;
}

GroupedBvh build_grouped(const BuilderConfig& config, const PrimitiveSet& prims, const std::vector<uint32_t>& first,
                         BuildInfo* info, BuildContext* context) {
  if (first.empty() || first[0] != 0)
    throw std::invalid_argument("build_grouped: the first group must start at primitive 0");
  for (size_t g = 0; g < first.size(); ++g)
    if (first[g] >= group_end(first, g, prims.size()))
      throw std::invalid_argument(fmt::format("build_grouped: group {} of {} is empty or out of order", g, first.size()));
  GroupedBvh grouped;
  grouped.first = first;
  grouped.trees.resize(first.size());
  grouped.built_sah.resize(first.size());
  std::vector<size_t> all(first.size());
  for (size_t g = 0; g < all.size(); ++g) all[g] = g;
  rebuild_groups(grouped, all, config, prims, info, context);
  return grouped;
}

namespace {

void build_group(GroupedBvh& grouped, size_t g, const BuilderConfig& config, const PrimitiveSet& prims,
                 BuildInfo* info, BuildContext* context) {
  BuildInfo group_info;
  BuildInfo* counted = info ? &group_info : nullptr;
  if (context) context->lend_tree(std::move(grouped.trees[g]));  // the new tree takes its memory
  grouped.trees[g] = grouped.groups() == 1 ? run_builder(config, prims, counted, context)  // no copy of the set
                                           : run_builder(config, group_primitives(prims, grouped.first, g), counted, context);
  grouped.built_sah[g] = sah_cost(grouped.trees[g]);
  add_counters(info, group_info);
}

}  // namespace

void rebuild_groups(GroupedBvh& grouped, const std::vector<size_t>& which, const BuilderConfig& config,
                    const PrimitiveSet& prims, BuildInfo* info, BuildContext* context) {
  const auto threads = size_t(std::max(1, thread_count()));
  size_t total = 0;
  for (const size_t g : which) total += grouped.group_size(g, prims.size());
  std::vector<size_t> small;
  for (const size_t g : which) {
    if (threads == 1 || grouped.group_size(g, prims.size()) * threads > total)
      build_group(grouped, g, config, prims, info, context);  // every thread on it
    else
      small.push_back(g);
  }
  if (small.empty()) return;
  // The largest first, so that the last builds to start are short.
  std::sort(small.begin(), small.end(), [&](size_t a, size_t b) {
    return grouped.group_size(a, prims.size()) > grouped.group_size(b, prims.size());
  });
  const size_t workers = std::min(threads, small.size());
  if (grouped.thread_contexts.size() < workers) grouped.thread_contexts.resize(workers);
  std::vector<BuildInfo> infos(workers);
  std::atomic<size_t> next{0};
  ParallelErrors errors;
  // std::threads, not an OpenMP region: each sets its own OpenMP thread count to one, so
  // the builder's parallel regions, and whatever sizes its work by omp_get_max_threads, run
  // as they would in a one-thread process. Nested OpenMP regions would get one thread while
  // omp_get_max_threads still said two (the radix sort split its work so until 2026-12-07).
  const auto work = [&](size_t w) {
    omp_set_num_threads(1);
    for (size_t i; (i = next.fetch_add(1)) < small.size();)
      errors.capture([&] {
        build_group(grouped, small[i], config, prims, info ? &infos[w] : nullptr, &grouped.thread_contexts[w]);
      });
  };
  std::vector<std::thread> pool;
  try {
    for (size_t w = 0; w < workers; ++w) pool.emplace_back(work, w);
  } catch (...) {
    // A thread that cannot start leaves the groups to those that did.
  }
  for (std::thread& t : pool) t.join();
  if (pool.empty()) {  // none could: this thread builds every group, its thread count kept
    const int before = omp_get_max_threads();
    work(0);
    omp_set_num_threads(before);
  }
  errors.rethrow();
  for (const BuildInfo& i : infos) add_counters(info, i);
}

void join_groups(const GroupedBvh& grouped, Bvh& out) {
  if (grouped.groups() == 1) {
    out.nodes.assign(grouped.trees[0].nodes.begin(), grouped.trees[0].nodes.end());
    out.prim_indices.assign(grouped.trees[0].prim_indices.begin(), grouped.trees[0].prim_indices.end());
    return;
  }
  const Bvh top = top_tree(grouped);
  size_t nodes = top.nodes.size(), indices = 0;
  for (const Bvh& t : grouped.trees) nodes += t.nodes.size() - 1, indices += t.prim_indices.size();
  out.nodes.resize(nodes);
  out.prim_indices.resize(indices);
  // Group g's node i > 0 goes to `next` + i - 1, its leaves' ranges after the groups
  // before it, its primitives to their place in the whole set.
  auto next = uint32_t(top.nodes.size()), next_index = uint32_t(0);
  for (size_t i = 0; i < top.nodes.size(); ++i) {
    if (!top.nodes[i].is_leaf()) {
      out.nodes[i] = top.nodes[i];
      continue;
    }
    if (top.nodes[i].count != 1) throw std::logic_error("join_groups: a top leaf of several groups");
    const uint32_t g = top.prim_indices[top.nodes[i].first];
    const Bvh& tree = grouped.trees[g];
    const uint32_t offset = next, index_offset = next_index, primitive_offset = grouped.first[g];
    const auto joined = [&](BvhNode n) {
      n.first = n.is_leaf() ? n.first + index_offset : offset + n.first - 1;
      return n;
    };
    out.nodes[i] = joined(tree.nodes[0]);
    for (size_t j = 1; j < tree.nodes.size(); ++j) out.nodes[next++] = joined(tree.nodes[j]);
    for (const uint32_t p : tree.prim_indices) out.prim_indices[next_index++] = p + primitive_offset;
  }
}

}  // namespace kmbvh
