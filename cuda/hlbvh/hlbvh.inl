// HLBVH (Garanzha et al. 2011, docs/design.md §5): the LBVH radix tree below the 15-bit Morton
// prefix, binned SAH over the prefix groups above it, then SAH leaf collapse. Portable:
// included by binary_builders_cpu.cpp and _gpu.cu, after lbvh.inl.
#pragma once

#include <thrust/copy.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/scan.h>

#include "hlbvh_steps.h"

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

struct IsSet {
  KMBVH_HD bool operator()(uint32_t x) const { return x != 0; }
};

struct InnerNodeId {
  uint32_t n;
  KMBVH_HD uint32_t operator()(uint32_t inner) const { return n + inner; }
};

// Replaces the tree above the prefix groups by a binned SAH build over the groups, level by
// level, reusing the replaced inner nodes' ids.
inline void rebuild_top(BinaryTreeView& tree, Buffer<uint32_t>& parent, Buffer<Cluster>& clusters,
                        Buffer<uint32_t>& free_nodes, uint32_t cluster_count) {
  Buffer<TopSegment> segments(1), next;
  Buffer<uint32_t> mid, counts, offsets;
  tree.root = read(free_nodes, 0);
  write(segments, 0, TopSegment{0, cluster_count, tree.root});
  write(parent, tree.root, kNoParent);
  uint32_t level = 1, free_base = 1;
  while (level > 0) {
    grow_to(mid, level);
    grow_to(counts, level);
    grow_to(offsets, level);
    for_each_index(level, ChooseTopSplit{ptr(segments), ptr(clusters), ptr(mid)});
    for_each_index(level, CountTopChildren{ptr(segments), ptr(mid), ptr(counts)});
    thrust::exclusive_scan(launch(), counts.begin(), counts.begin() + level, offsets.begin());
    const uint32_t total = read(offsets, level - 1) + read(counts, level - 1);
    grow_to(next, total);
    for_each_index(level, LinkTopSegment{ptr(segments), ptr(mid), ptr(offsets), ptr(clusters), ptr(free_nodes),
                                         free_base, tree, ptr(next)});
    std::swap(segments, next);
    free_base += total;
    level = total;
  }
}

inline Bvh build_hlbvh(const PrimitiveSet& prims, const BinaryBuildParams& params, BuildInfo* info) {
  const auto n = static_cast<uint32_t>(prims.size());
  if (n < 2) return Bvh::single_leaf(prims.bounds(), n);
  PhaseClock clock(info);
  const InputBoxes boxes(prims.boxes);
  MortonRadixTree radix;
  CollapseState state(n);
  build_morton_radix_tree(boxes, n, radix, state, params, RadixTreeParts{true, true, true}, clock);
  BinaryTreeView tree = radix.view();

  // The groups of equal 15-bit prefix, their subtrees' roots, and the inner nodes above them.
  Buffer<uint32_t> starts(n), index(n);
  for_each_index(n, MarkClusterStarts{ptr(radix.codes), ptr(starts)});
  thrust::inclusive_scan(launch(), starts.begin(), starts.end(), index.begin());
  const uint32_t cluster_count = read(index, n - 1);
  if (cluster_count > 1) {
    Buffer<uint32_t> cluster_first(cluster_count), top(n - 1), free_nodes(cluster_count - 1);
    Buffer<Cluster> clusters(cluster_count);
    for_each_index(n, RecordClusterStarts{ptr(starts), ptr(index), ptr(cluster_first)});
    for_each_index(cluster_count, DescribeCluster{ptr(cluster_first), cluster_count, tree, ptr(clusters)});
    for_each_index(n - 1, FindClusterRoots{ptr(index), ptr(radix.range_first), ptr(radix.range_last), tree,
                                           ptr(clusters), ptr(top)});
    const auto ids = thrust::make_transform_iterator(thrust::counting_iterator<uint32_t>(0), InnerNodeId{n});
    thrust::copy_if(launch_and_read(), ids, ids + (n - 1), top.begin(), free_nodes.begin(), IsSet{});
    release(starts, index, cluster_first, top, radix.codes, radix.range_first, radix.range_last);
    clock.lap("groups");
    rebuild_top(tree, radix.parent, clusters, free_nodes, cluster_count);
    collapse(tree, state, params.max_leaf_size, params.sah, /*refit=*/true);
    clock.lap("top levels");
  }
  Bvh bvh = lay_out(tree, state.view());
  clock.lap("layout");
  return bvh;
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
