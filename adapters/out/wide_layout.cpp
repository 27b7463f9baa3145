#include "wide_layout.h"

#include <immintrin.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <stdexcept>
#include <string>

#include "collapse_wide.h"
#include "cuda/core/parallel_errors.h"
#include "cuda/traversal/watertight.h"

namespace kmbvh {
namespace {

// A leaf of the source tree (its primitives: bvh.prim_indices[first, first + count)) and
// the first of the packs it fills.
struct LeafJob {
  uint32_t first, count, first_pack;
};

// The plan: every node written (boxes, counts and links: all but the packs), and each
// leaf's place among the packs, in the order make_wide_bvh packs them. The leaves are
// published as they are planned, so that the other threads fill their packs meanwhile:
// `leaves` never grows past the room it is given (its elements stay where the fillers
// read them), nor `packs` past `pack_room`.
template <int W>
struct Plan {
  WideBvh<W> out;
  LayoutArray<LeafJob> leaves;
  uint32_t packs = 0;
  uint32_t pack_room = 0;
  std::atomic<size_t> published{0};  // leaves[0, published) are planned
  std::atomic<bool> planned{false};  // and published is final
};

// Lane `lane` of `node` for source node `c`; a leaf's packs are reserved in order.
template <int W>
void plan_lane(Plan<W>& plan, WideNode<W>& node, int lane, const Bvh& bvh, uint32_t c) {
  const BvhNode& n = bvh.nodes[c];
  if (n.is_leaf() && n.count == 0) return;  // the empty set's leaf: an empty lane
  for (int d = 0; d < 3; ++d) {
    node.lo[d][lane] = n.box.lo[d];
    node.hi[d][lane] = n.box.hi[d];
  }
  node.count[lane] = n.is_leaf() ? n.count : 0;
  node.ref[lane] = 0;  // an interior child's index is set when it is written
  if (n.is_leaf()) {
    const uint32_t packs = (n.count + kPackWidth - 1) / kPackWidth;
    // Every leaf of a tree is reached once, and the room counts each once: more is a node
    // reached twice (not a tree), and growing the arrays would move what the fillers read.
    if (plan.leaves.size() == plan.leaves.capacity() || packs > plan.pack_room - plan.packs)
      throw std::invalid_argument("lay_out_wide: a node is reached twice (the tree is not a tree)");
    node.ref[lane] = plan.packs;
    plan.leaves.push_back(LeafJob{n.first, n.count, plan.packs});
    plan.packs += packs;
  }
}

// Depth first, first child first, as lay_out_depth_first walks the collapsed tree; the
// leaves published after each node. `plan` holds the nodes' memory and the leaves' room.
template <int W>
void plan_layout(const Bvh& bvh, bool collapse, Plan<W>& plan) {
  plan.out.nodes.clear();  // keeps its memory
  reserve_with_headroom(plan.out.nodes, bvh.nodes.size() / 2 + 1);  // a wide node per interior node at most: never grown
  if (bvh.root().is_leaf()) {  // one leaf: a root with a single lane
    plan.out.nodes.push_back(empty_wide_node<W>());
    plan_lane(plan, plan.out.nodes[0], 0, bvh, 0);
    plan.published.store(plan.leaves.size(), std::memory_order_release);
    return;
  }
  struct Pending {
    uint32_t node, parent, slot, depth;
  };
  std::vector<Pending> stack{{0, UINT32_MAX, 0, 1}};
  uint32_t max_depth = 1;
  uint32_t children[W];
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    const BvhNode& n = bvh.nodes[p.node];
    if (n.count > W)
      throw std::invalid_argument("a " + std::to_string(W) + "-wide layout got a node of " + std::to_string(n.count) +
                                  " children");
    uint32_t count = n.count;
    if (collapse) {
      count = open_children(bvh, p.node, W, children);
    } else {
      for (uint32_t c = 0; c < count; ++c) children[c] = n.first + c;
    }
    const uint32_t index = uint32_t(plan.out.nodes.size());
    plan.out.nodes.push_back(empty_wide_node<W>());
    for (uint32_t c = 0; c < count; ++c) plan_lane(plan, plan.out.nodes[index], int(c), bvh, children[c]);
    plan.published.store(plan.leaves.size(), std::memory_order_release);
    if (p.parent != UINT32_MAX) plan.out.nodes[p.parent].ref[p.slot] = index;
    max_depth = std::max(max_depth, p.depth);
    for (uint32_t c = count; c-- > 0;)
      if (!bvh.nodes[children[c]].is_leaf()) stack.push_back({children[c], index, c, p.depth + 1});
  }
  plan.out.stack_size = (W - 1) * max_depth + 1;
}

// The scene id of primitive j of the set: prims.ids[j], or {0, j} where the set is the
// scene's triangles in order (`in_order`: ids_in_scene_order), which spares the fill one
// random read a triangle.
struct SetIds {
  const PrimitiveSet& prims;
  bool in_order;
  PrimitiveId operator[](uint32_t j) const { return in_order ? PrimitiveId{0, j} : prims.ids[j]; }
};

// Whether primitive j of `prims` is triangle j of `scene` (id {0, j}) for every j: the set
// make_primitive_set makes where no triangle is dropped, the scene path's and the tools'.
// One parallel pass over the ids (8 bytes a triangle), where the fill would read each at a
// random place (conference@4, 1.3M triangles, LBVH's tree, 2 threads, AVX2: the layout
// made again in its memory 40.4-42.1 -> 38.7-39.4 ms, alternated runs).
bool ids_in_scene_order(const PrimitiveSet& prims, const TriangleScene& scene) {
  if (prims.size() != scene.triangles.size()) return false;
  const PrimitiveId* ids = prims.ids.data();
  uint64_t out_of_order = 0;
#pragma omp parallel for reduction(+ : out_of_order) schedule(static)
  for (int64_t j = 0; j < int64_t(prims.size()); ++j)
    out_of_order += ids[j].geom != 0 || ids[j].prim != uint32_t(j) ? 1 : 0;
  return out_of_order == 0;
}

// Each triangle a leaf gathers is a chain of dependent reads at random places (its
// primitive's id, unless the ids are in order; the triangle's vertex indices and reported
// id; the three positions), a cache miss each: the leaves a few ahead are fetched in
// stages, each stage reading what the one before fetched, so that the misses of many
// triangles overlap (conference, Q1's tree, 2 threads: the fill from 7.3 to 5.6 ms once
// its pages are touched).
struct GatherAhead {
  const Bvh& bvh;
  SetIds set_ids;
  const TriangleScene& scene;
  const std::vector<PrimitiveId>* reported_ids;
  static constexpr uint32_t kIds = 6, kTriangles = 4, kPositions = 2;  // leaves ahead

  // f(j) for each primitive j of the leaf (a position in the PrimitiveSet).
  template <typename Each>
  void each(const LeafJob& leaf, Each&& f) const {
    for (uint32_t i = 0; i < leaf.count; ++i) {
      const uint32_t j = bvh.prim_indices[leaf.first + i];
      if (j < set_ids.prims.size()) f(j);
    }
  }
  void ids(const LeafJob& leaf) const {
    if (!set_ids.in_order) each(leaf, [&](uint32_t j) { __builtin_prefetch(&set_ids.prims.ids[j]); });
  }
  void triangles(const LeafJob& leaf) const {
    each(leaf, [&](uint32_t j) {
      const uint32_t t = set_ids[j].prim;
      if (t >= scene.triangles.size()) return;
      __builtin_prefetch(&scene.triangles[t]);
      if (reported_ids) __builtin_prefetch(&(*reported_ids)[t]);
    });
  }
  void positions(const LeafJob& leaf) const {
    each(leaf, [&](uint32_t j) {
      const PrimitiveId id = set_ids[j];
      if (id.prim >= scene.triangles.size()) return;
      const Triangle& t = scene.triangles[id.prim];
      for (int v = 0; v < 3; ++v) __builtin_prefetch(&scene.positions[t[v]]);
    });
  }
};

// The packs of one leaf, gathered from the scene (leaf_triangles.cpp and wide_bvh.cpp's
// pack_leaf in one step: degenerate triangles and unused slots as NaN, never hit).
void fill_leaf(TrianglePack* packs, const LeafJob& leaf, const Bvh& bvh, SetIds set_ids, const TriangleScene& scene,
               const std::vector<PrimitiveId>* reported_ids) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (uint32_t i = 0; i < leaf.count; i += kPackWidth) {
    TrianglePack& pack = packs[i / kPackWidth];
    for (uint32_t slot = 0; slot < uint32_t(kPackWidth); ++slot) {
      Vec3 v[3] = {Vec3(nan), Vec3(nan), Vec3(nan)};
      PrimitiveId id{kInvalidId, kInvalidId};
      if (i + slot < leaf.count) {
        const uint32_t j = bvh.prim_indices[leaf.first + i + slot];
        if (j >= set_ids.prims.size())
          throw std::invalid_argument("lay_out_wide: a leaf names a primitive the set does not have");
        id = set_ids[j];
        if (id.prim >= scene.triangles.size())
          throw std::invalid_argument("lay_out_wide: a primitive is not in the scene");
        const Triangle& t = scene.triangles[id.prim];
        const Vec3 a = scene.positions[t[0]], b = scene.positions[t[1]], c = scene.positions[t[2]];
        if (!is_degenerate_triangle(a, b, c)) v[0] = a, v[1] = b, v[2] = c;
        if (reported_ids) id = (*reported_ids)[id.prim];
      }
      for (int k = 0; k < 3; ++k)
        for (int axis = 0; axis < 3; ++axis) pack.v[k][axis][slot] = v[k][axis];
      pack.id[slot] = id;
    }
  }
}

// How many leaves `bvh` has and how many packs they fill: the plan gives every leaf of the
// tree its packs, and collapsing keeps the leaves as they are.
struct LeafCount {
  size_t leaves = 0;
  uint32_t packs = 0;
};
LeafCount count_leaves(const Bvh& bvh) {
  uint64_t leaves = 0, packs = 0;
#pragma omp parallel for reduction(+ : leaves, packs) schedule(static)
  for (int64_t i = 0; i < int64_t(bvh.nodes.size()); ++i) {
    const BvhNode& n = bvh.nodes[size_t(i)];
    if (n.is_leaf()) ++leaves, packs += (n.count + kPackWidth - 1) / kPackWidth;
  }
  if (packs > UINT32_MAX) throw std::invalid_argument("lay_out_wide: more triangle packs than 32-bit references reach");
  return LeafCount{size_t(leaves), uint32_t(packs)};
}

// Fills the packs of plan.leaves[begin, end), fetching the leaves a few ahead (GatherAhead).
template <int W>
void fill_leaves(const Plan<W>& plan, size_t begin, size_t end, TrianglePack* packs, const Bvh& bvh, SetIds set_ids,
                 const TriangleScene& scene, const std::vector<PrimitiveId>* reported_ids) {
  const GatherAhead ahead{bvh, set_ids, scene, reported_ids};
  const LeafJob* leaves = plan.leaves.data();
  for (size_t l = begin; l < std::min(end, begin + GatherAhead::kIds); ++l) ahead.ids(leaves[l]);
  for (size_t l = begin; l < std::min(end, begin + GatherAhead::kTriangles); ++l) ahead.triangles(leaves[l]);
  for (size_t l = begin; l < std::min(end, begin + GatherAhead::kPositions); ++l) ahead.positions(leaves[l]);
  for (size_t l = begin; l < end; ++l) {
    if (l + GatherAhead::kIds < end) ahead.ids(leaves[l + GatherAhead::kIds]);
    if (l + GatherAhead::kTriangles < end) ahead.triangles(leaves[l + GatherAhead::kTriangles]);
    if (l + GatherAhead::kPositions < end) ahead.positions(leaves[l + GatherAhead::kPositions]);
    fill_leaf(packs + leaves[l].first_pack, leaves[l], bvh, set_ids, scene, reported_ids);
  }
}

}  // namespace

template <int W>
WideBvh<W> lay_out_wide(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene, bool collapse,
                        const std::vector<PrimitiveId>* reported_ids, WideBvh<W>* reuse) {
  if (reported_ids && reported_ids->size() != scene.triangles.size())
    throw std::invalid_argument("lay_out_wide: reported_ids needs one id per triangle of the scene");
  if (bvh.empty() || (bvh.root().is_leaf() && bvh.root().count == 0)) return WideBvh<W>();
  // The plan is a sequential walk (its time: one dependent read of the source tree a node);
  // while thread 0 makes it, the others fill the packs of the leaves it has planned, a chunk
  // at a time, and thread 0 joins them once it is done (conference, Q1's tree, 2 threads:
  // the walk 2.6 ms in an earlier layout's memory, 5-6 ms in fresh memory; the fill took
  // about as long again after it, before).
  LayoutArray<TrianglePack> packs;
  Plan<W> plan;
  if (reuse) {
    packs = std::move(reuse->packs);
    plan.out.nodes = std::move(reuse->nodes);
    *reuse = WideBvh<W>();
    packs.clear();
  }
  const LeafCount counted = count_leaves(bvh);
  const SetIds set_ids{prims, ids_in_scene_order(prims, scene)};
  reserve_with_headroom(packs, counted.packs);
  packs.resize(counted.packs);  // not zeroed (layout_memory.h): fill_leaf writes each pack whole
  plan.leaves.reserve(counted.leaves);
  plan.pack_room = counted.packs;
  constexpr size_t kChunk = 512;
  std::atomic<size_t> next_chunk{0};
  ParallelErrors errors;
#pragma omp parallel
  {
    if (omp_get_thread_num() == 0) {
      errors.capture([&] { plan_layout<W>(bvh, collapse, plan); });
      plan.planned.store(true, std::memory_order_release);
    }
    for (;;) {
      const size_t begin = next_chunk.fetch_add(1, std::memory_order_relaxed) * kChunk;
      size_t end = begin + kChunk;
      for (;;) {  // until the chunk is planned, or the plan is over and published final
        const bool over = plan.planned.load(std::memory_order_acquire);
        const size_t ready = plan.published.load(std::memory_order_acquire);
        if (ready >= end) break;
        if (over) {
          end = ready;
          break;
        }
        _mm_pause();
      }
      if (begin >= end) break;
      errors.capture([&] { fill_leaves(plan, begin, end, packs.data(), bvh, set_ids, scene, reported_ids); });
    }
  }
  errors.rethrow();
  WideBvh<W>& out = plan.out;
  out.packs = std::move(packs);
  if (out.packs.size() != plan.packs) out.packs.resize(plan.packs);  // a tree with unreachable leaves
  return std::move(plan.out);
}

template WideBvh<4> lay_out_wide<4>(const Bvh&, const PrimitiveSet&, const TriangleScene&, bool,
                                    const std::vector<PrimitiveId>*, WideBvh<4>*);
template WideBvh<8> lay_out_wide<8>(const Bvh&, const PrimitiveSet&, const TriangleScene&, bool,
                                    const std::vector<PrimitiveId>*, WideBvh<8>*);

}  // namespace kmbvh
