// The level loop of the k-means builder, written once against Thrust and compiled twice
// (docs/design.md §3): by g++ with Thrust's OpenMP device system (kmeans_builder_cpu.cpp) and
// by nvcc for the GPU (kmeans_builder_gpu.cu). The including file defines
// KMBVH_BACKEND_NAMESPACE (so the two instantiations never collide) and
// KMBVH_PIECE_SIZE (primitives per work item of the per-primitive kernels).
//
// Per level (docs/design.md §4): set up the segments' clusters and pieces, initialise the
// representatives, run i Lloyd iterations (assign, update), assign once more, partition
// each segment by cluster, and emit the children: leaves, treelet nodes and the next
// level's segments.
//
// Two choices differ in form, not in result, from the paper's description:
// - Nodes below m * k primitives are split with k = 2 in the same level loop as the others
//   rather than after the main queue empties. A node's split depends only on its own
//   primitives and its own random stream (node_stream), so the tree is the same; the loop
//   just needs fewer levels.
// - There is no separate bottom-up refit: every box is exact when it is written (cluster
//   bounds come from the final assignment, treelet boxes are unions of those), which is
//   what a refit would produce. validate() recomputes the boxes from the primitives and
//   checks this on every tree. The finishing step is the breadth-first reorder.

#include <thrust/count.h>
#include <thrust/fill.h>
#include <thrust/scan.h>
#include <thrust/sequence.h>
#include <thrust/transform_scan.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <utility>

#include "../core/portable.h"
#include "../core/breadth_first.h"
#include "../core/build_context.h"
#include "../core/parallel_errors.h"
#include "agglomerate.h"
#include "assign.h"
#include "emit.h"
#include "kmeans_builder.h"
#include "partition.h"
#include "setup.h"
#include "update_means.h"
#include "update_medians.h"

#if !defined(KMBVH_PIECE_SIZE)
#error "define KMBVH_PIECE_SIZE before including kmeans_builder.inl"
#endif

// The CPU backend finishes one-piece nodes with the hand-written subtree path.
#if KMBVH_CPU_SUBTREES
#include "subtree_cpu.h"
#endif

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// The level loop's memory, kept in a BuildContext from one build to the next. Every buffer
// takes its memory from the workspace's pool, which keeps it; a build gives each buffer
// back as soon as it is done with it, so that the next (the finishing step's) can take
// the same memory, and a build asking for what the last one asked allocates nothing
// (memory_pool.h).
struct KMeansWorkspace : BuildContext::Workspace {
  MemoryPool scratch;  // every buffer's, and Thrust's temporaries
  Buffer<Aabb> boxes[2];
  Buffer<uint32_t> ids[2];
  Buffer<uint32_t> final_ids;
  Buffer<uint8_t> cluster_of;
  Buffer<Segment> segments, next_segments;
  Buffer<SegmentSizes> segment_offsets;
  Buffer<Piece> pieces;
  Buffer<uint32_t> piece_counters, counters_scanned;
  Buffer<Aabb> reps;
  Buffer<ClusterSums> sums;
  Buffer<uint32_t> counts;
  Buffer<OrderedBounds> bounds;
  Buffer<uint32_t> cluster_begin;
  Buffer<uint32_t> cluster_segment;
  Buffer<ChildCounts> child_counts, child_offsets;
  Buffer<uint32_t> forced;  // segments split by index, counted on the device
  Buffer<BvhNode> nodes;
  Buffer<BvhNode> subtree_nodes;  // the CPU subtree path's (split_subtrees)
  // Host memory of the finishing step: the nodes as built (the GPU's), and the breadth-first
  // order's scratch.
  std::vector<BvhNode> built_nodes;
  std::vector<uint32_t> order_scratch;

  // kept = false: a build's own workspace (no context). Its buffers then come from the
  // system's allocator, which takes their pages back when the finishing step frees them,
  // and its pool holds only Thrust's temporaries, for the build's length.
  explicit KMeansWorkspace(bool kept = true) {
    if (!kept) return;
    take_from_scratch(boxes[0], boxes[1], ids[0], ids[1], final_ids, cluster_of, segments, next_segments,
                      segment_offsets, pieces, piece_counters, counters_scanned, reps, sums, counts, bounds,
                      cluster_begin, cluster_segment, child_counts, child_offsets, forced, nodes, subtree_nodes);
  }
  template <typename... Buffers>
  void take_from_scratch(Buffers&... buffers) {
    (..., (buffers = Buffers(typename Buffers::allocator_type(&scratch))));
  }

  size_t bytes_held() const override {
    return built_nodes.capacity() * sizeof(BvhNode) + order_scratch.capacity() * sizeof(uint32_t) +
           scratch.bytes_held();
  }
};

template <uint32_t KMax, ClusterMetric M>
class KMeansLevels {
 public:
  KMeansLevels(const PrimitiveSet& prims, const KMeansParams& params, BuildInfo* info, KMeansWorkspace& ws)
      : params_(params), n_(static_cast<uint32_t>(prims.size())), info_(info), clock_(info), ws_(ws) {
    count_host_sync();  // the boxes' upload
    boxes_[0].assign(prims.boxes.begin(), prims.boxes.end());
    boxes_[1].resize(n_);
    ids_[0].resize(n_);
    thrust::sequence(launch(), ids_[0].begin(), ids_[0].end());
    // The zeros before the inclusive scans of set_up and emit, and the forced-split count.
    grow_to(segment_offsets_, 1);
    grow_to(child_offsets_, 1);
    forced_.resize(1);
    thrust::fill_n(launch(), segment_offsets_.begin(), 1, SegmentSizes{});
    thrust::fill_n(launch(), child_offsets_.begin(), 1, ChildCounts{});
    thrust::fill_n(launch(), forced_.begin(), 1, 0u);
    ids_[1].resize(n_);
    final_ids_.resize(n_);
    cluster_of_.resize(n_);
    nodes_.reserve(n_ / 2 + 16);
  }

  Bvh run() {
    const Aabb root_box = bounds_of(boxes_[0], n_);
    nodes_.resize(1);
    write(nodes_, 0, BvhNode::make_interior(root_box, 0, 0));
    node_count_ = 1;
    Segment root;
    root.count = n_;
    root.k = rules().child_k(n_);
    root.box = root_box;
    segments_.resize(1);
    write(segments_, 0, root);
    sizes_ = SizesOfSegment{KMBVH_PIECE_SIZE}(root);
    uint32_t segment_count = 1;
    clock_.lap("setup");

    while (segment_count > 0) {
#if KMBVH_CPU_SUBTREES
      if (params_.cpu_subtrees && (segment_count = split_subtrees(segment_count)) == 0) break;
#endif
      const uint64_t syncs = info_ ? info_->backend.host_syncs : 0;
      segment_count = split_level(segment_count);
      if (info_) ++info_->levels, info_->level_host_syncs += info_->backend.host_syncs - syncs;
      current_ = 1 - current_;
    }
    return finish();
  }

 private:
  NodeRules rules() const { return node_rules(params_); }

  LevelView view() {
    return {ptr(boxes_[current_]), ptr(ids_[current_]), ptr(cluster_of_), ptr(segments_),
            ptr(pieces_), ptr(piece_counters_), clusters(), rules().per_node_iterations()};
  }
  ClusterArrays clusters() {
    return {ptr(reps_), ptr(sums_), ptr(counts_), ptr(bounds_), ptr(cluster_begin_), ptr(cluster_segment_)};
  }

  // Splits every segment of the level; returns the number of segments of the next one.
  uint32_t split_level(uint32_t segment_count) {
    const uint32_t clusters = set_up(segment_count);
    for_each_index(segment_count, InitialiseSegment<M>{ptr(boxes_[current_]), ptr(segments_), ptr(reps_),
                                                       rules(), params_.seed});
    if (params_.seeding == Seeding::Cells) {
      // Each representative with members in its cell becomes their mean (seed_cells.h),
      // whatever the metric.
      clear_clusters(clusters, true);
      for_each_index(piece_count_, AssignPiece<KMax, M, AssignPass::CellSums>{view()});
      for_each_index(clusters, UpdateMeans{ptr(segments_), this->clusters()});
    }
    clock_.lap("initialise");

    for (uint32_t iteration = 0; iteration < params_.i; ++iteration) {
      if constexpr (M == ClusterMetric::Means) {
        clear_clusters(clusters, true);
        for_each_index(piece_count_, AssignPiece<KMax, M, AssignPass::Sums>{view()});
        clock_.lap("assign");
        for_each_index(clusters, UpdateMeans{ptr(segments_), this->clusters()});
        clock_.lap("update");
      } else {
        clear_clusters(clusters, false);
        for_each_index(piece_count_, AssignPiece<KMax, M, AssignPass::Final>{view()});
        clock_.lap("assign");
        partition(/*gather_only=*/true);
        for_each_index(clusters, UpdateMedians{ptr(boxes_[1 - current_]), ptr(segments_), this->clusters()});
        clock_.lap("update");
      }
      if (rules().per_node_iterations() && all_stable(segment_count, iteration)) break;
    }

    clear_clusters(clusters, false);
    for_each_index(piece_count_, AssignPiece<KMax, M, AssignPass::Final>{view()});
    clock_.lap("assign");
    // The guaranteed split, where clustering made none: counted on the device, and the pass
    // run whatever the count (its pieces of other segments return at once), so that the
    // host need not wait for the count.
    for_each_index(segment_count, DetectSingleCluster{ptr(segments_), this->clusters(), ptr(forced_)});
    for_each_index(piece_count_, AssignPiece<KMax, M, AssignPass::SplitByIndex>{view()});
    partition(/*gather_only=*/false);
    return emit(segment_count);
  }

  // Offsets of every segment's clusters, pieces and counters; returns the cluster count.
  // An inclusive scan after the zero at offsets[0] (written once, in the constructor) gives
  // every segment's offset. The total is known without reading it back: the previous
  // level's emit counted it (ChildCounts::next), or the host wrote the segments.
  uint32_t set_up(uint32_t segment_count) {
    const SizesOfSegment sizes{KMBVH_PIECE_SIZE};
    grow_to(segment_offsets_, segment_count + 1);
    thrust::transform_inclusive_scan(launch(), segments_.begin(), segments_.begin() + segment_count,
                                     segment_offsets_.begin() + 1, sizes, AddSegmentSizes{});
    const SegmentSizes total = sizes_;
    piece_count_ = total.pieces;
    grow_to(pieces_, total.pieces);
    counter_count_ = total.counters;
    grow_to(piece_counters_, total.counters);
    grow_to(counters_scanned_, total.counters);
    grow_to(reps_, total.clusters);
    grow_to(sums_, total.clusters);
    grow_to(counts_, total.clusters);
    grow_to(bounds_, total.clusters);
    grow_to(cluster_begin_, total.clusters);
    grow_to(cluster_segment_, total.clusters);
    for_each_index(segment_count, SetupSegment{ptr(segments_), ptr(segment_offsets_), sizes, ptr(cluster_segment_)});
    for_each_index(piece_count_, SetupPiece{ptr(segments_), ptr(segment_offsets_), segment_count, sizes, ptr(pieces_)});
    clock_.lap("setup");
    return total.clusters;
  }

  // Marks the segments whose Lloyd loop is done (level.h: MarkStable); true when that is
  // all of them. Stable segments keep their representatives: a mean update skips their
  // pieces (AssignPiece), a median update their clusters (UpdateMedians).
  bool all_stable(uint32_t segment_count, uint32_t iteration) {
    for_each_index(segment_count, MarkStable{ptr(segments_), rules(), iteration});
    return thrust::count_if(launch_and_read(), segments_.begin(), segments_.begin() + segment_count, IsUnstable{}) == 0;
  }

  void clear_clusters(uint32_t clusters, bool sums) {
    thrust::fill_n(launch(), counts_.begin(), clusters, 0u);
    if (sums)
      thrust::fill_n(launch(), sums_.begin(), clusters, ClusterSums{});
    else
      thrust::fill_n(launch(), bounds_.begin(), clusters, OrderedBounds::empty());
  }

  // Counting sort of every segment by cluster into the other buffer. A median update
  // only gathers the boxes; the level's last partition moves ids and output order too.
  void partition(bool gather_only) {
    thrust::exclusive_scan(launch(), piece_counters_.begin(), piece_counters_.begin() + counter_count_,
                           counters_scanned_.begin());
    for_each_index(piece_count_, PlaceClusters{ptr(segments_), ptr(pieces_), ptr(counters_scanned_),
                                               ptr(piece_counters_), clusters()});
    const int to = 1 - current_;
    for_each_index(piece_count_,
                   ScatterPiece<KMax>{ptr(boxes_[current_]), ptr(ids_[current_]), ptr(cluster_of_),
                                      ptr(segments_), ptr(pieces_), ptr(piece_counters_), ptr(boxes_[to]),
                                      gather_only ? nullptr : ptr(ids_[to]),
                                      gather_only ? nullptr : ptr(final_ids_)});
    clock_.lap("partition");
  }

  // The children's offsets as set_up's: an inclusive scan after a zero, and the total read
  // back, the level's one wait for the device: the nodes and segments it adds, and the
  // sizes of those segments for the next set_up.
  uint32_t emit(uint32_t segment_count) {
    grow_to(child_counts_, segment_count);
    grow_to(child_offsets_, segment_count + 1);
    for_each_index(segment_count, CountChildren{ptr(segments_), clusters(), rules(), SizesOfSegment{KMBVH_PIECE_SIZE},
                                                ptr(child_counts_)});
    thrust::inclusive_scan(launch(), child_counts_.begin(), child_counts_.begin() + segment_count,
                           child_offsets_.begin() + 1, AddChildCounts{});
    const ChildCounts total = read(child_offsets_, segment_count);
    nodes_.resize(node_count_ + total.nodes);
    grow_to(next_segments_, total.segments);
    // The two segment buffers trade places every level, so that a rebuild, whose levels may
    // put them the other way round, finds room in both.
    if (segments_.capacity() < next_segments_.capacity()) segments_.reserve(next_segments_.capacity());
    for_each_index(segment_count, EmitChildren<KMax>{ptr(segments_), clusters(), rules(), ptr(child_offsets_),
                                                     node_count_, ptr(nodes_), ptr(next_segments_)});
    node_count_ += total.nodes;
    sizes_ = total.next;
    std::swap(segments_, next_segments_);
    clock_.lap("agglomerate");
    return total.segments;
  }

#if KMBVH_CPU_SUBTREES
  // Takes the segments of one piece or less out of the level, and splits each one's whole
  // subtree in one work item (subtree_cpu.h); returns how many segments remain. The
  // backend's arrays are host memory here, so they are used directly.
  uint32_t split_subtrees(uint32_t segment_count) {
    Segment* segments = ptr(segments_);
    std::vector<Segment> small;
    uint32_t kept = 0;
    sizes_ = SegmentSizes{};  // of the segments kept
    for (uint32_t s = 0; s < segment_count; ++s) {
      if (segments[s].count <= KMBVH_PIECE_SIZE) {
        small.push_back(segments[s]);
      } else {
        sizes_ = AddSegmentSizes{}(sizes_, SizesOfSegment{KMBVH_PIECE_SIZE}(segments[s]));
        segments[kept++] = segments[s];
      }
    }
    if (small.empty()) return kept;
    std::vector<SubtreeNodes> done(small.size());
    Aabb* boxes = ptr(boxes_[current_]);
    uint32_t* ids = ptr(ids_[current_]);
    uint32_t* final_ids = ptr(final_ids_);
    // Each work item copies its subtree's nodes to the next free run of one array of huge
    // pages, kept in the workspace: 2n entries hold any subtrees of n primitives in all, and
    // only the entries used are touched. (A vector per subtree came from the malloc heap, on
    // 4 KiB pages: the largest source of page faults in a process's first build.)
    grow_to(subtree_nodes_, 2 * size_t(n_));
    BvhNode* const runs = ptr(subtree_nodes_);
    const size_t capacity = subtree_nodes_.size();
    uint32_t forced = 0;
    ParallelErrors errors;
    count_launch();
#pragma omp parallel reduction(+ : forced)
    {
      SubtreeSplitter<KMax, M> splitter(params_);
#pragma omp for schedule(dynamic, 1)
      for (int64_t t = 0; t < int64_t(small.size()); ++t)
        errors.capture([&] {
          const std::vector<BvhNode>& nodes = splitter.split(small[t], boxes, ids, final_ids, forced);
          const size_t first = subtree_used_.fetch_add(nodes.size(), std::memory_order_relaxed);
          if (first + nodes.size() > capacity) throw std::logic_error("k-means: subtree nodes beyond their bound");
          std::copy(nodes.begin(), nodes.end(), runs + first);
          done[t] = {small[t].node, first, uint32_t(nodes.size())};
        });
    }
    errors.rethrow();
    subtrees_.insert(subtrees_.end(), done.begin(), done.end());
    if (info_) info_->forced_splits += forced;
    clock_.lap("subtrees");
    return kept;
  }

  // Where each subtree's nodes go after the level loop's: its node i > 0 at offset + i - 1
  // (its node 0 is its segment's node). Returns the tree's node count.
  size_t place_subtrees(std::vector<uint32_t>& offset) const {
    offset.resize(subtrees_.size());
    size_t total = node_count_;
    for (size_t t = 0; t < subtrees_.size(); ++t) {
      offset[t] = static_cast<uint32_t>(total);
      total += subtrees_[t].count - 1;
    }
    return total;
  }

  // Writes the subtrees' nodes into `nodes`, after the level loop's, renumbered.
  void append_subtrees(BvhNode* nodes, const std::vector<uint32_t>& offset) {
    const BvhNode* runs = ptr(subtree_nodes_);
#pragma omp parallel for schedule(dynamic, 16)
    for (int64_t t = 0; t < int64_t(subtrees_.size()); ++t) {
      const SubtreeNodes& sub = subtrees_[t];
      const BvhNode* local = runs + sub.first;
      auto renumber = [&](BvhNode n) {
        if (!n.is_leaf()) n.first = offset[t] + n.first - 1;  // children are never local node 0
        return n;
      };
      const BvhNode root = renumber(local[0]);
      nodes[sub.root].first = root.first;
      nodes[sub.root].count = root.count;
      nodes[sub.root].leaf = root.leaf;
      for (uint32_t i = 1; i < sub.count; ++i) nodes[offset[t] + i - 1] = renumber(local[i]);
    }
    std::vector<SubtreeNodes>().swap(subtrees_);
    release(subtree_nodes_);
  }

  std::vector<SubtreeNodes> subtrees_;
  std::atomic<size_t> subtree_used_{0};  // entries of subtree_nodes_ handed out
#endif

  // Copies the tree out: the nodes in breadth-first order into the tree returned, from where
  // gather_nodes put them (as built, params.breadth_first: straight into the tree returned).
  // Each working buffer goes back to the pool as soon as it is done with, so that the
  // finishing step takes the same memory and does not raise the build's peak.
  Bvh finish() {
    release(boxes_[0], boxes_[1], ids_[0], ids_[1], cluster_of_, segments_, next_segments_, segment_offsets_,
            pieces_, piece_counters_, counters_scanned_, reps_, sums_, counts_, bounds_, cluster_begin_,
            cluster_segment_, child_counts_, child_offsets_);
    size_t total = node_count_;
#if KMBVH_CPU_SUBTREES
    std::vector<uint32_t> offset;
    total = place_subtrees(offset);
#endif
    Bvh bvh = output_tree();
    BvhNode* built = gather_nodes(bvh, total);
#if KMBVH_CPU_SUBTREES
    append_subtrees(built, offset);
#endif
    bvh.prim_indices.resize(n_);  // in the lent tree's memory, where there is one (output_tree)
    copy_to_host(ptr(final_ids_), n_, bvh.prim_indices.data());
    release(final_ids_);
    if (info_) info_->forced_splits += read(forced_, 0);
    release(forced_);
    if (params_.breadth_first) breadth_first_nodes(built, total, ws_.order_scratch, bvh.nodes);
    release(nodes_);
    clock_.lap("finish");
    return bvh;
  }

  // Room for all `total` nodes, the level loop's first: breadth first, the level loop's own
  // buffer on the CPU (host memory already: no copy, and no more memory), host memory of
  // the workspace on the GPU; as built, the tree returned.
  BvhNode* gather_nodes(Bvh& bvh, size_t total) {
#if KMBVH_BACKEND_CPU
    if (params_.breadth_first) {
      // Moved, not grown where it is: its room was reserved before the level loop's buffers,
      // and its pages past the level loop's nodes have never been touched, where the
      // buffers finish() has just given back lie touched and free (the pool's best fit
      // places it there). 12 bytes a triangle off a context's peak on conference.
      Buffer<BvhNode> all(nodes_.get_allocator());
      all.resize(total);
      std::copy_n(ptr(nodes_), node_count_, ptr(all));
      nodes_.swap(all);
      release(all);
      return ptr(nodes_);
    }
#endif
    std::vector<BvhNode>& built = params_.breadth_first ? ws_.built_nodes : bvh.nodes;
    grow_on_huge_pages(built, total);  // the workspace's is kept at its largest: no zero fill when it fits
    copy_to_host(ptr(nodes_), node_count_, built.data());
    return built.data();
  }


  const KMeansParams params_;
  const uint32_t n_;
  BuildInfo* info_;
  PhaseClock clock_;
  KMeansWorkspace& ws_;

  int current_ = 0;  // which of the double buffers holds the level's primitives
  Buffer<Aabb>* const boxes_ = ws_.boxes;
  Buffer<uint32_t>* const ids_ = ws_.ids;
  Buffer<uint32_t>& final_ids_ = ws_.final_ids;
  Buffer<uint8_t>& cluster_of_ = ws_.cluster_of;

  Buffer<Segment>& segments_ = ws_.segments;
  Buffer<Segment>& next_segments_ = ws_.next_segments;
  Buffer<SegmentSizes>& segment_offsets_ = ws_.segment_offsets;
  Buffer<Piece>& pieces_ = ws_.pieces;
  uint32_t piece_count_ = 0;
  Buffer<uint32_t>& piece_counters_ = ws_.piece_counters;
  Buffer<uint32_t>& counters_scanned_ = ws_.counters_scanned;
  uint32_t counter_count_ = 0;

  Buffer<Aabb>& reps_ = ws_.reps;
  Buffer<ClusterSums>& sums_ = ws_.sums;
  Buffer<uint32_t>& counts_ = ws_.counts;
  Buffer<OrderedBounds>& bounds_ = ws_.bounds;
  Buffer<uint32_t>& cluster_begin_ = ws_.cluster_begin;
  Buffer<uint32_t>& cluster_segment_ = ws_.cluster_segment;

  Buffer<ChildCounts>& child_counts_ = ws_.child_counts;
  Buffer<ChildCounts>& child_offsets_ = ws_.child_offsets;
  Buffer<uint32_t>& forced_ = ws_.forced;
  Buffer<BvhNode>& nodes_ = ws_.nodes;
  Buffer<BvhNode>& subtree_nodes_ = ws_.subtree_nodes;  // the CPU subtree path's runs
  uint32_t node_count_ = 0;
  SegmentSizes sizes_;  // what the current level's segments take in all (set_up)
};

template <ClusterMetric M>
Bvh build_with_metric(const PrimitiveSet& prims, const KMeansParams& params, BuildInfo* info, KMeansWorkspace& ws) {
  // Local arrays in the kernels are sized by the smallest bound that holds k.
  if (params.k <= 8) return KMeansLevels<8, M>(prims, params, info, ws).run();
  if (params.k <= 16) return KMeansLevels<16, M>(prims, params, info, ws).run();
  if (params.k <= 32) return KMeansLevels<32, M>(prims, params, info, ws).run();
  return KMeansLevels<64, M>(prims, params, info, ws).run();
}

// The build, in `context`'s workspace for this backend when there is one (`key`, one per
// backend), else in one of its own.
inline Bvh build(const PrimitiveSet& prims, const KMeansParams& params, BuildInfo* info, BuildContext* context,
                 const char* key) {
  const uint32_t n = static_cast<uint32_t>(prims.size());
  if (n <= params.max_leaf_size) return Bvh::single_leaf(prims.bounds(), n);
  const CountBackendSteps counting(info ? &info->backend : nullptr);
  KMeansWorkspace own(/*kept=*/false);
  KMeansWorkspace& ws = context ? context->workspace<KMeansWorkspace>(key) : own;
  const UsePool pool(ws.scratch);
  const UseContext current(context);
  if (params.metric == ClusterMetric::Means)
    return build_with_metric<ClusterMetric::Means>(prims, params, info, ws);
  return build_with_metric<ClusterMetric::Medians>(prims, params, info, ws);
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
