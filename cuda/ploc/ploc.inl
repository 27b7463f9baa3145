// PLOC (Meister and Bittner 2018, docs/design.md §5): bottom-up clustering in Morton order,
// iterations of ploc_steps.h until one cluster is left, then SAH leaf collapse. Portable:
// included by binary_builders_cpu.cpp and _gpu.cu.
#pragma once

#include <thrust/scan.h>
#include <thrust/sequence.h>

#include "../binary/binary_params.h"
#include "../binary/finish_binary.h"
#include "../core/primitive_set.h"
#include "../morton/morton_order.h"
#include "ploc_steps.h"
#if KMBVH_BACKEND_CPU
#include "iteration_cpu.h"
#endif

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// Leaf i (position i in Morton order): its primitive's box, into the columns the first
// iteration searches.
struct SetLeafBoxes {
  BinaryTreeView tree;
  BoxColumns columns;
  KMBVH_HD void operator()(uint32_t i) const { columns.set(i, tree.box(i)); }
};

// The nearest-neighbour search, sized by the radius (its window is a local array).
inline void find_nearest(uint32_t count, uint32_t radius, BoxColumns box, uint32_t* nearest) {
  if (radius <= 16)
    for_each_index(count, FindNearest<16>{box, count, radius, nearest});
  else if (radius <= 64)
    for_each_index(count, FindNearest<64>{box, count, radius, nearest});
  else
    for_each_index(count, FindNearest<1024>{box, count, radius, nearest});
}

// One iteration as the GPU runs it, a step a launch: the neighbours, the merges counted and
// scanned, the survivors compacted, their boxes gathered into `box` for the next one and the
// new nodes' boxes retired into its tails (ClusterBoxes).
// Returns the merges and the clusters left.
inline MergeCounts ploc_iteration(uint32_t count, uint32_t radius, bool paired, BoxColumns box,
                                  uint32_t* nearest, Buffer<MergeCounts>& counts, Buffer<MergeCounts>& offsets,
                                  MergeAndCompact merge) {
  if (paired)
    for_each_index(count, PairNeighbours{count, nearest});
  else
    find_nearest(count, radius, box, nearest);
  for_each_index(count, CountMerges{nearest, ptr(counts)});
  thrust::exclusive_scan(launch(), counts.begin(), counts.begin() + count, offsets.begin(), MergeCounts{},
                         AddMergeCounts{});
  const MergeCounts total = AddMergeCounts{}(read(offsets, count - 1), read(counts, count - 1));
  merge.offsets = ptr(offsets);
  for_each_index(count, merge);
  for_each_index(total.kept, GatherClusterBoxes{merge.next_clusters, merge.boxes()});
  for_each_index(total.merges, RetireFreshBoxes{merge.boxes()});
  return total;
}

inline Bvh build_ploc(const PrimitiveSet& prims, const BinaryBuildParams& params, BuildInfo* info) {
  const auto n = static_cast<uint32_t>(prims.size());
  if (n < 2) return Bvh::single_leaf(prims.bounds(), n);
  PhaseClock clock(info);
  const InputBoxes boxes(prims.boxes);
  // The clusters' boxes as columns (ClusterBoxes: the live clusters', then the inner nodes'),
  // which first hold the Morton codes and the sort's scratch (20 of their 24 bytes a
  // primitive), so that the clustering takes the memory the sort leaves.
  Buffer<float> box_columns(6 * size_t(n));
  Buffer<uint32_t> order;
  unsigned long long* const codes = reinterpret_cast<unsigned long long*>(ptr(box_columns));
  morton_order(boxes.data(), n, codes, order, codes + n);
  clock.lap("morton");

  Buffer<uint32_t> left(n - 1), right(n - 1);
  BinaryTreeView tree;
  tree.n = n;
  tree.left = ptr(left);
  tree.right = ptr(right);
  tree.prim_box = boxes.data();
  tree.order = ptr(order);

  // The rest of the clustering's memory is one buffer of n boxes: this iteration's new
  // nodes' boxes in its first half (an iteration merges at most half its clusters), the
  // clusters' ids, the next iteration's and the nearest neighbours in its second (3n ids,
  // 12n bytes, fit in n - n/2 boxes); once the clustering has ended, the tree's inner
  // boxes, so that they take the memory the working arrays leave whatever the pool's
  // ranges. 60 bytes a primitive at the peak with the tree's order and children, where
  // separate arrays of inner boxes and of new ones held 72.
  Buffer<Aabb> work(n);
  Aabb* const fresh = ptr(work);
  uint32_t* const ids = reinterpret_cast<uint32_t*>(ptr(work) + n / 2);
  uint32_t *clusters = ids, *next_clusters = ids + n, *const nearest = ids + 2 * size_t(n);
  const BoxColumns cluster_box{ptr(box_columns), n};
  for_each_index(n, SetLeafBoxes{tree, cluster_box});
#if KMBVH_BACKEND_CPU
  // An iteration in one parallel region (iteration_cpu.h), with no counts to scan.
  const bool fused = params.ploc_radius <= kPlocCpuMaxRadius;
#else
  const bool fused = false;
#endif
  Buffer<MergeCounts> counts(fused ? 0 : n), offsets(fused ? 0 : n);
  thrust::sequence(launch(), clusters, clusters + n);  // leaf i: position i
  uint32_t count = n, next_inner = n;
  bool stalled = false;
  while (count > 1) {
    if (info) ++info->levels;
    if (stalled && info) ++info->forced_splits;
    const MergeAndCompact merge{clusters, cluster_box, nearest, nullptr, next_inner, tree, next_clusters, fresh};
    MergeCounts total;
#if KMBVH_BACKEND_CPU
    if (fused) total = ploc_iteration_cpu(count, params.ploc_radius, stalled, cluster_box, nearest, merge);
#endif
    if (!fused)
      total = ploc_iteration(count, params.ploc_radius, stalled, cluster_box, nearest, counts, offsets, merge);
    std::swap(clusters, next_clusters);
    next_inner += total.merges;
    stalled = !stalled && ploc_stalled(total.merges, count);
    count = total.kept;
  }
  tree.root = 2 * n - 2;  // the last of the n - 1 merges
  release(counts, offsets);
  tree.inner_box = ptr(work);
  for_each_index(n - 1, InnerBoxesFromColumns{cluster_box, tree.inner_box});
  release(box_columns);
  clock.lap("clustering");
  // Made now, in the memory the columns leave.
  Buffer<uint32_t> parent;
  set_parents(tree, parent);
  CollapseState state(n);
  collapse(tree, state, params.max_leaf_size, params.sah, /*refit=*/false);
  clock.lap("collapse");
  Bvh bvh = lay_out(tree, state.view());
  clock.lap("layout");
  return bvh;
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
