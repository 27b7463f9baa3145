// A hand-written CPU path for the bottom of the tree (docs/design.md §3: where a CPU path is
// measurably faster than the generic one, keep both). Once a node holds at most one piece
// of primitives, the level loop would still stream the whole level's arrays through every
// pass for it; here one work item splits the node's entire subtree depth-first instead,
// while its primitives stay in cache, with a dynamic schedule across nodes.
//
// It runs the same steps as the level loop (initialise.h, assign.h, update_means.h,
// update_medians.h, partition's stable counting sort and guaranteed split, emit.h's
// lay_out_children), on the same random streams (keyed by primitive range, not by node
// number), and a node of one piece has exactly one fixed-point sum per cluster either way.
// The finished tree, reordered breadth-first, is therefore the same bit for bit; the tests
// build every preset both ways and compare.
#pragma once

#include <cstdint>
#include <vector>

#include "../core/bvh.h"
#include "assign.h"
#include "emit.h"
#include "initialise.h"
#include "level.h"
#include "params.h"
#include "seed_cells.h"
#include "update_means.h"
#include "update_medians.h"

namespace kmbvh {

// Where a split subtree's nodes are: `count` of them from `first` on in the build's array of
// subtree nodes, numbered locally: node 0 stands for the subtree's root (its segment's node
// in the level loop's array), the others are new.
struct SubtreeNodes {
  uint32_t root = 0;  // the segment's node in the level loop's array
  size_t first = 0;
  uint32_t count = 0;
};

template <uint32_t KMax, ClusterMetric M>
class SubtreeSplitter {
 public:
  explicit SubtreeSplitter(const KMeansParams& params) : params_(params) {}

  // Splits everything under `root`, reordering its range of boxes and ids in place and
  // writing the output order of its primitives into final_ids. Returns the subtree's nodes,
  // numbered locally (SubtreeNodes), in the splitter's own array: reused by the next split,
  // so a work item allocates nothing once it has split its largest subtree. A subtree of c
  // primitives has at most 2c - 1 nodes (every interior node has two children or more).
  const std::vector<BvhNode>& split(const Segment& root, Aabb* boxes, uint32_t* ids, uint32_t* final_ids,
                                    uint32_t& forced_splits) {
    nodes_.clear();
    nodes_.push_back(BvhNode::make_interior(root.box, 0, 0));
    scratch_boxes_.resize(root.count);
    scratch_ids_.resize(root.count);
    cluster_of_.resize(root.count);
    pending_.clear();
    pending_.push_back({root.begin, root.count, 0, root.k, root.box});
    while (!pending_.empty()) {
      const Pending p = pending_.back();
      pending_.pop_back();
      forced_splits += split_node(p, boxes + p.begin, ids + p.begin, final_ids + p.begin, nodes_);
    }
    return nodes_;
  }

 private:
  struct Pending {
    uint32_t begin, count, node, k;
    Aabb box;
  };

  // Returns 1 when the node had to be split by position (the guaranteed split).
  uint32_t split_node(const Pending& p, Aabb* boxes, uint32_t* ids, uint32_t* final_ids, std::vector<BvhNode>& nodes) {
    const uint32_t k = p.k;
    const NodeRules rules = node_rules(params_);
    Aabb reps[KMax];
    const auto draw = [&](uint32_t representatives) {
      initialise_representatives<M>(boxes, p.count, representatives, rules.candidates(k), params_.seed,
                                    node_stream(p.begin, p.count), reps);
    };
    if (params_.seeding == Seeding::Cells)
      seed_from_cells(p, boxes, reps, draw);
    else
      draw(k);
    // The first iteration compares with leftovers of another node, as the level loop's does.
    for (uint32_t iteration = 0; iteration < rules.iterations(k); ++iteration)
      if (rules.settled(update(p, boxes, reps), p.count) && iteration > 0 && rules.until_stable) break;

    // The final assignment, with the guaranteed split when it leaves one cluster.
    uint32_t count[KMax];
    Aabb bounds[KMax];
    assign_final(boxes, p.count, k, reps, count, bounds);
    uint32_t non_empty = 0;
    for (uint32_t c = 0; c < k; ++c) non_empty += count[c] != 0;
    const bool forced = non_empty < 2;
    if (forced) {
      for (uint32_t c = 0; c < k; ++c) {
        count[c] = 0;
        bounds[c] = Aabb::empty();
      }
      for (uint32_t x = 0; x < p.count; ++x) {
        const uint32_t c = static_cast<uint32_t>((uint64_t(x) * k) / p.count);
        cluster_of_[x] = static_cast<uint8_t>(c);
        ++count[c];
        bounds[c].grow(boxes[x]);
      }
    }

    uint32_t begin[KMax];
    partition(boxes, ids, p.count, k, count, begin, /*gather_only=*/false);
    for (uint32_t x = 0; x < p.count; ++x) final_ids[x] = ids[x];

    // Children: the same layout as the level loop's EmitChildren.
    uint32_t weight[KMax], first[KMax];
    Aabb box[KMax];
    uint32_t j = 0;
    for (uint32_t c = 0; c < k; ++c) {
      if (count[c] == 0) continue;
      weight[j] = count[c];
      first[j] = p.begin + begin[c];
      box[j] = bounds[c];
      ++j;
    }
    const auto first_node = static_cast<uint32_t>(nodes.size());
    nodes.resize(nodes.size() + (rules.wide ? j : 2 * j - 2));
    lay_out_children<KMax>(nodes.data(), p.node, first_node, box, weight, j, rules.wide, [&](uint32_t t, uint32_t node) {
      if (write_cluster_node(nodes[node], box[t], first[t], weight[t], rules.max_leaf_size))
        pending_.push_back({first[t], weight[t], node, rules.child_k(weight[t]), box[t]});
    });
    return forced ? 1u : 0u;
  }

  // Cell seeding (seed_cells.h): what the level loop's paper draws, CellSums pass and mean
  // update do to a segment of one piece. Only the representatives of empty cells keep their
  // draws, and the draw of representative r depends on those before it alone, so the draws
  // stop at the last empty cell (none where every cell has members): the same
  // representatives for less work. draw(r): the paper's draws of representatives 0..r-1.
  template <typename Draw>
  void seed_from_cells(const Pending& p, const Aabb* boxes, Aabb* reps, const Draw& draw) const {
    const CellGrid grid = CellGrid::of(p.box, p.k);
    SumAccumulator<KMax> acc;
    acc.clear(p.k);
    uint32_t count[KMax];
    for (uint32_t c = 0; c < p.k; ++c) count[c] = 0;
    for (uint32_t x = 0; x < p.count; ++x) {
      const uint32_t c = grid.cell(boxes[x]);
      ++count[c];
      acc.add(c, boxes[x]);
    }
    uint32_t draws = 0;
    for (uint32_t c = 0; c < p.k; ++c)
      if (count[c] == 0) draws = c + 1;
    if (draws > 0) draw(draws);
    decode_means(p, acc, count, reps);
  }

  // Representatives of the clusters with members become their fixed-point means, as one
  // piece of the level loop publishes them and UpdateMeans decodes them.
  void decode_means(const Pending& p, const SumAccumulator<KMax>& acc, const uint32_t* count, Aabb* reps) const {
    const FixedPointFrame frame = FixedPointFrame::of(p.box);
    for (uint32_t c = 0; c < p.k; ++c) {
      if (count[c] == 0) continue;
      ClusterSums sums;
      acc.publish(c, count[c], frame, /*sole=*/true, sums);
      for (int d = 0; d < 3; ++d) {
        reps[c].lo[d] = frame.decode_mean(sums.s[d], count[c], d);
        reps[c].hi[d] = frame.decode_mean(sums.s[3 + d], count[c], d);
      }
    }
  }

  // One Lloyd iteration after an assignment: the mean (fixed point, as one piece of the
  // level loop publishes it) or the component-wise median. Returns how many assignments
  // changed since the last iteration.
  uint32_t update(const Pending& p, Aabb* boxes, Aabb* reps) {
    RepresentativeTable<KMax, M> table;
    table.load(reps, p.k);
    uint32_t count[KMax];
    for (uint32_t c = 0; c < p.k; ++c) count[c] = 0;
    uint32_t changed = 0;
    if constexpr (M == ClusterMetric::Means) {
      SumAccumulator<KMax> acc;
      acc.clear(p.k);
      for (uint32_t x = 0; x < p.count; ++x) {
        const uint32_t c = table.nearest(boxes[x]);
        changed += cluster_of_[x] != c;
        cluster_of_[x] = static_cast<uint8_t>(c);
        ++count[c];
        acc.add(c, boxes[x]);
      }
      decode_means(p, acc, count, reps);
    } else {
      for (uint32_t x = 0; x < p.count; ++x) {
        const uint32_t c = table.nearest(boxes[x]);
        changed += cluster_of_[x] != c;
        cluster_of_[x] = static_cast<uint8_t>(c);
        ++count[c];
      }
      uint32_t begin[KMax];
      partition(boxes, nullptr, p.count, p.k, count, begin, /*gather_only=*/true);
      for (uint32_t c = 0; c < p.k; ++c) {
        if (count[c] == 0) continue;
        Aabb* members = scratch_boxes_.data() + begin[c];
        const uint32_t rank = (count[c] - 1) / 2;
        for (int d = 0; d < 3; ++d) {
          reps[c].lo[d] = select_component(members, count[c], d, rank);
          reps[c].hi[d] = select_component(members, count[c], 3 + d, rank);
        }
      }
    }
    return changed;
  }

  void assign_final(const Aabb* boxes, uint32_t n, uint32_t k, const Aabb* reps, uint32_t* count, Aabb* bounds) {
    RepresentativeTable<KMax, M> table;
    table.load(reps, k);
    BoundsAccumulator<KMax> acc;
    acc.clear(k);
    for (uint32_t c = 0; c < k; ++c) count[c] = 0;
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t c = table.nearest(boxes[x]);
      cluster_of_[x] = static_cast<uint8_t>(c);
      ++count[c];
      acc.add(c, boxes[x]);
    }
    for (uint32_t c = 0; c < k; ++c) bounds[c] = acc.box(c);
  }

  // Stable counting sort by cluster. gather_only: the boxes go to the scratch buffer and
  // stay there (the median update selects on them); otherwise boxes and ids are reordered
  // in place. begin[c]: where cluster c starts, relative to the node.
  void partition(Aabb* boxes, uint32_t* ids, uint32_t n, uint32_t k, const uint32_t* count, uint32_t* begin,
                 bool gather_only) {
    uint32_t cursor[KMax];
    uint32_t at = 0;
    for (uint32_t c = 0; c < k; ++c) {
      begin[c] = cursor[c] = at;
      at += count[c];
    }
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t to = cursor[cluster_of_[x]]++;
      scratch_boxes_[to] = boxes[x];
      if (!gather_only) scratch_ids_[to] = ids[x];
    }
    if (gather_only) return;
    std::copy(scratch_boxes_.begin(), scratch_boxes_.begin() + n, boxes);
    std::copy(scratch_ids_.begin(), scratch_ids_.begin() + n, ids);
  }

  const KMeansParams& params_;
  std::vector<Aabb> scratch_boxes_;
  std::vector<uint32_t> scratch_ids_;
  std::vector<uint8_t> cluster_of_;
  std::vector<Pending> pending_;
  std::vector<BvhNode> nodes_;
};

}  // namespace kmbvh
