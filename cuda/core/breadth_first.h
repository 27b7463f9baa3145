// Node order of a finished tree: breadth-first from the root (the paper's finishing step),
// children of a node kept contiguous. Leaves keep their primitive ranges.
#pragma once

#include "bvh.h"

namespace kmbvh {

// `nodes` must satisfy Bvh's rules (children after parents, reachable from nodes[0]).
Bvh reorder_breadth_first(Bvh bvh);

}  // namespace kmbvh
