// A tree over primitives that come in groups (the meshes of an Embree scene), built the way
// Embree builds a dynamic scene: a tree per group, and a top tree over the groups' boxes,
// joined into one Bvh for the layout (docs/design.md §7, "Dynamic scenes"). At a later
// commit each group's tree is refitted or built again on its own (a mesh that moved as a
// whole keeps its tree as good as built; one that deforms is built again), and only the
// top tree, a leaf per group, is built over them anew. A single tree over all primitives,
// refitted, spoils wherever the groups move apart.
#pragma once

#include <cstdint>
#include <vector>

#include "builder_registry.h"

namespace kmbvh {

// Where group g of a set of `primitives` ends: the next group's first primitive, or the set's end.
inline uint32_t group_end(const std::vector<uint32_t>& first, size_t g, size_t primitives) {
  return g + 1 < first.size() ? first[g + 1] : uint32_t(primitives);
}

struct GroupedBvh {
  std::vector<uint32_t> first;  // group g: primitives [first[g], first[g + 1]) of the set, the last to its end
  std::vector<Bvh> trees;       // group g's tree, its leaves indexing the group's own primitives from 0
  std::vector<double> built_sah;  // each tree's SAH cost when it was built
  // The working memory of the threads that build small groups at once (rebuild_groups),
  // kept for the next builds as a scene keeps its context.
  std::vector<BuildContext> thread_contexts;
  size_t groups() const { return trees.size(); }
  size_t group_size(size_t g, size_t primitives) const { return group_end(first, g, primitives) - first[g]; }
};

// Group g's primitives, [first[g], first[g + 1]) of `prims` (the last group to its end).
PrimitiveSet group_primitives(const PrimitiveSet& prims, const std::vector<uint32_t>& first, size_t g);

// Each group's tree built by `config`. `first`: the groups' first primitives in `prims`,
// ascending from 0, each group non-empty. Throws std::invalid_argument for a `first` that
// is not, and as run_builder throws. `info` sums the group builds' counters; `context`
// serves each group's build in turn.
GroupedBvh build_grouped(const BuilderConfig& config, const PrimitiveSet& prims, const std::vector<uint32_t>& first,
                         BuildInfo* info = nullptr, BuildContext* context = nullptr);

// The trees of the groups `which` built again from `prims` (the whole set, as build_grouped
// took it). A group of more than a thread's share of their primitives is built with every
// thread (`context`), the others at once, each by one thread with a context of its own
// (`thread_contexts`): a k-means build of a mesh's 50-70k triangles runs 1.5 times as fast
// on two threads as on one, so two such builds at once, a thread each, beat one after the
// other on both. Each tree is the one its group's build gives alone (the builders'
// trees do not depend on the thread count). Each new tree is written into its group's old
// tree's memory (BuildContext::lend_tree), so a group built again at every commit faults in
// no fresh pages for it; where a build throws, its group's tree is left empty.
void rebuild_groups(GroupedBvh& grouped, const std::vector<size_t>& which, const BuilderConfig& config,
                    const PrimitiveSet& prims, BuildInfo* info = nullptr, BuildContext* context = nullptr);

// The one tree the layout takes, written into `out` (whose memory it reuses): a top tree
// over the groups' root boxes (sweep SAH, each group a leaf of its own), each leaf replaced
// by its group's root, each group's other nodes after it, group by group; leaves index the
// whole set. One group: its tree as it is.
void join_groups(const GroupedBvh& grouped, Bvh& out);

// The groups of an Embree scene's flattened triangles: where the geometry id changes.
std::vector<uint32_t> groups_by_geometry(const std::vector<PrimitiveId>& ids);

}  // namespace kmbvh
