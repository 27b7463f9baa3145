// A tree's boxes recomputed from its primitives, its topology kept: what a dynamic scene's
// commit does when only vertices moved (plugin/preload/scene_accel.h), instead of a build.
#pragma once

#include "bvh.h"
#include "primitive_set.h"

namespace kmbvh {

// Writes every node's box from the primitives' boxes, bottom-up: a leaf's is the union of
// its primitives', an interior node's the union of its children's. The children of every
// tree kmbvh builds come after their parent (breadth-first order), so one sweep from the
// last node to the root does it. `prims` holds the primitives the tree was built over, in
// the same order, their boxes moved.
void refit_in_place(Bvh& bvh, const PrimitiveSet& prims);
// The same with the primitives' boxes given as an array: boxes[i] for the tree's primitive
// i (a group's tree over a part of a set: grouped_build.h).
void refit_in_place(Bvh& bvh, const Aabb* boxes);

}  // namespace kmbvh
