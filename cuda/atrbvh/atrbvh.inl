// ATRBVH (Domingues and Pedrini 2015, docs/design.md §5): the LBVH radix tree, restructured by
// agglomerative treelets (treelet_restructure.h) in `treelet_iterations` bottom-up passes,
// then SAH leaf collapse. Portable: included by binary_builders_cpu.cpp and _gpu.cu, after
// lbvh.inl.
#pragma once

#include <thrust/fill.h>

#include "../binary/climb.h"
#include "treelet_restructure.h"

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// The passes over a binary tree of one primitive a leaf whose boxes, counts and costs are
// set, then the SAH leaf collapse and the layout: ATRBVH's steps after its radix tree, and
// restructure_treelets' (restructure_tree.inl) after the tree it is given.
inline Bvh restructure_collapse_and_lay_out(const BinaryTreeView& tree, CollapseState& state,
                                            const BinaryBuildParams& params, BuildInfo* info, PhaseClock& clock) {
  Buffer<uint32_t> visits(tree.n - 1);
  for (uint32_t pass = 0; pass < params.treelet_iterations; ++pass) {
    if (info) ++info->levels;
    thrust::fill(launch(), visits.begin(), visits.end(), 0u);
    for_each_index(tree.n, climb_from_leaves(tree, ptr(visits), RestructureTreelet{tree, state.view(), params.sah,
                                                                                  params.max_leaf_size,
                                                                                  params.treelet_size}));
  }
  release(visits);
  clock.lap("restructure");
  collapse(tree, state, params.max_leaf_size, params.sah, /*refit=*/true);
  Bvh bvh = lay_out(tree, state.view());
  clock.lap("layout");
  return bvh;
}

inline Bvh build_atrbvh(const PrimitiveSet& prims, const BinaryBuildParams& params, BuildInfo* info) {
  const auto n = static_cast<uint32_t>(prims.size());
  if (n < 2) return Bvh::single_leaf(prims.bounds(), n);
  PhaseClock clock(info);
  const InputBoxes boxes(prims.boxes);
  MortonRadixTree radix;
  CollapseState state(n);
  build_morton_radix_tree(boxes, n, radix, state, params, RadixTreeParts{/*parents=*/false}, clock);
  release(radix.codes);
  BinaryTreeView tree = radix.view();
  set_parents(tree, radix.parent);  // in the Morton codes' memory: 8 bytes a primitive off the peak
  return restructure_collapse_and_lay_out(tree, state, params, info, clock);
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
