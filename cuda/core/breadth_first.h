// Node order of a finished tree: breadth-first from the root (the paper's finishing step),
// children of a node kept contiguous. Leaves keep their primitive ranges.
#pragma once

#include <vector>

#include "bvh.h"

namespace kmbvh {

// `nodes` must satisfy Bvh's rules (children after parents, reachable from nodes[0]).
Bvh reorder_breadth_first(Bvh bvh);

// nodes[0, count) in breadth-first order, in a new array. `source` is scratch space (the
// input index of each output node), which a caller building again may keep.
std::vector<BvhNode> breadth_first_nodes(const BvhNode* nodes, size_t count, std::vector<uint32_t>& source);
// The same into `out`, whose memory it keeps (emptied first).
void breadth_first_nodes(const BvhNode* nodes, size_t count, std::vector<uint32_t>& source, std::vector<BvhNode>& out);

}  // namespace kmbvh
