// The partition of a level by cluster: the final assignment counts per piece,
// PlaceClusters turns counts into cursors, ScatterPiece moves primitives. Checked on a
// hand-made level of two segments, one of them spread over several pieces.
#include <gtest/gtest.h>

#include <numeric>
#include <vector>

#include "cuda/kmeans/assign.h"
#include "cuda/kmeans/emit.h"
#include "cuda/kmeans/params.h"
#include "cuda/kmeans/partition.h"
#include "cuda/kmeans/setup.h"
#include "support/printers.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

struct HostLevel {
  std::vector<Aabb> boxes, boxes_out, reps;
  std::vector<uint32_t> ids, ids_out, final_ids;
  std::vector<uint8_t> cluster_of;
  std::vector<Segment> segments;
  std::vector<SegmentSizes> offsets;
  std::vector<Piece> pieces;
  std::vector<uint32_t> counters, counts, begin, cluster_segment;
  std::vector<ClusterSums> sums;
  std::vector<OrderedBounds> bounds;

  ClusterArrays clusters() {
    return {reps.data(), sums.data(), counts.data(), bounds.data(), begin.data(), cluster_segment.data()};
  }
  // PlaceClusters as the level loop runs it: one exclusive scan over every counter first.
  void place() {
    std::vector<uint32_t> scanned(counters.size());
    std::exclusive_scan(counters.begin(), counters.end(), scanned.begin(), 0u);
    for (uint32_t p = 0; p < pieces.size(); ++p)
      PlaceClusters{segments.data(), pieces.data(), scanned.data(), counters.data(), clusters()}(p);
  }
  LevelView view() {
    return {boxes.data(), ids.data(), cluster_of.data(), segments.data(), pieces.data(), counters.data(), clusters(),
            /*per_node=*/false};
  }
};

// Two segments: [0, 50) with k = 3 and [50, 1000) with k = 8, pieces of 128.
HostLevel make_level() {
  HostLevel l;
  const uint32_t n = 1000;
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3 p(test::random_unit(1, 1, i), test::random_unit(1, 2, i), test::random_unit(1, 3, i));
    l.boxes.push_back(Aabb(p * 10.0f, p * 10.0f + Vec3(0.1f)));
  }
  l.ids.resize(n);
  std::iota(l.ids.begin(), l.ids.end(), 0u);
  Segment a, b;
  a.begin = 0;
  a.count = 50;
  a.k = 3;
  b.begin = 50;
  b.count = 950;
  b.k = 8;
  l.segments = {a, b};
  for (Segment& s : l.segments)
    for (uint32_t i = s.begin; i < s.begin + s.count; ++i) s.box.grow(l.boxes[i]);

  const SizesOfSegment sizes{128};
  l.offsets = {SegmentSizes{}, sizes(a)};
  const SegmentSizes total = AddSegmentSizes{}(l.offsets[1], sizes(b));
  l.pieces.resize(total.pieces);
  l.counters.resize(total.counters);
  l.counts.assign(total.clusters, 0);
  l.begin.resize(total.clusters);
  l.cluster_segment.resize(total.clusters);
  l.sums.resize(total.clusters);
  l.bounds.assign(total.clusters, OrderedBounds::empty());
  l.reps.resize(total.clusters);
  for (uint32_t s = 0; s < 2; ++s)
    SetupSegment{l.segments.data(), l.offsets.data(), sizes, l.cluster_segment.data()}(s);
  for (uint32_t p = 0; p < total.pieces; ++p)
    SetupPiece{l.segments.data(), l.offsets.data(), 2, sizes, l.pieces.data()}(p);
  for (const Segment& s : l.segments)
    for (uint32_t c = 0; c < s.k; ++c) l.reps[s.cluster_base + c] = l.boxes[s.begin + 7 * c];
  l.cluster_of.resize(n);
  l.boxes_out.resize(n);
  l.ids_out.resize(n);
  l.final_ids.resize(n);
  return l;
}

TEST(Partition, PiecesCoverSegments) {
  HostLevel l = make_level();
  EXPECT_EQ(l.segments[0].piece_count, 1u);
  EXPECT_EQ(l.segments[1].piece_count, 8u);  // ceil(950 / 128)
  uint32_t covered = 0;
  for (uint32_t i = 0; i < l.pieces.size(); ++i) {
    const Piece& p = l.pieces[i];
    const Segment& s = l.segments[p.segment];
    // Piece q of its segment, in order; its counters cluster-major after the segment's.
    const uint32_t q = i - s.piece_base;
    ASSERT_LT(q, s.piece_count);
    EXPECT_EQ(p.begin, s.begin + 128 * q);
    EXPECT_EQ(p.counter_base, l.offsets[p.segment].counters + q);
    EXPECT_GE(p.begin, s.begin);
    EXPECT_LE(p.end, s.begin + s.count);
    EXPECT_LE(p.end - p.begin, 128u);
    covered += p.end - p.begin;
  }
  EXPECT_EQ(covered, 1000u);
}

TEST(Partition, GroupsByClusterStablyAndCountsMatch) {
  HostLevel l = make_level();
  for (uint32_t p = 0; p < l.pieces.size(); ++p) AssignPiece<8, ClusterMetric::Means, AssignPass::Final>{l.view()}(p);
  const std::vector<uint8_t> assigned = l.cluster_of;
  l.place();
  for (uint32_t p = 0; p < l.pieces.size(); ++p)
    ScatterPiece<8>{l.boxes.data(), l.ids.data(), l.cluster_of.data(), l.segments.data(), l.pieces.data(),
                    l.counters.data(), l.boxes_out.data(), l.ids_out.data(), l.final_ids.data()}(p);

  for (const Segment& s : l.segments) {
    // Expected: within the segment, cluster 0's primitives in input order, then cluster 1's...
    std::vector<uint32_t> expected;
    for (uint32_t c = 0; c < s.k; ++c) {
      const uint32_t slot = s.cluster_base + c;
      uint32_t count = 0;
      Aabb box;
      EXPECT_EQ(l.begin[slot], s.begin + uint32_t(expected.size()));
      for (uint32_t i = s.begin; i < s.begin + s.count; ++i)
        if (assigned[i] == c) {
          expected.push_back(i);
          ++count;
          box.grow(l.boxes[i]);
        }
      EXPECT_EQ(l.counts[slot], count);
      if (count) {
        EXPECT_EQ(l.bounds[slot].to_aabb(), box);
      }
    }
    ASSERT_EQ(expected.size(), s.count);
    for (uint32_t j = 0; j < s.count; ++j) {
      EXPECT_EQ(l.ids_out[s.begin + j], expected[j]);
      EXPECT_EQ(l.final_ids[s.begin + j], expected[j]);
      EXPECT_EQ(l.boxes_out[s.begin + j], l.boxes[expected[j]]);
    }
  }
}

TEST(Partition, SingleClusterIsSplitByIndex) {
  HostLevel l = make_level();
  // Every representative of segment 1 the same: all its primitives tie into cluster 0.
  const Segment& s = l.segments[1];
  for (uint32_t c = 0; c < s.k; ++c) l.reps[s.cluster_base + c] = l.reps[s.cluster_base];
  for (uint32_t p = 0; p < l.pieces.size(); ++p) AssignPiece<8, ClusterMetric::Means, AssignPass::Final>{l.view()}(p);
  EXPECT_EQ(l.counts[s.cluster_base], s.count);
  uint32_t forced = 0;
  for (uint32_t i = 0; i < 2; ++i) DetectSingleCluster{l.segments.data(), l.clusters(), &forced}(i);
  EXPECT_EQ(l.segments[0].split_by_index, 0u);
  ASSERT_EQ(l.segments[1].split_by_index, 1u);
  EXPECT_EQ(forced, 1u);  // counted on the device, read once a build
  // The pass runs over every piece (the level loop does not wait for the count), and leaves
  // the segments clustering did split as they are.
  const std::vector<uint8_t> cluster_of = l.cluster_of;
  const std::vector<uint32_t> counts = l.counts;
  for (uint32_t p = 0; p < l.pieces.size(); ++p)
    AssignPiece<8, ClusterMetric::Means, AssignPass::SplitByIndex>{l.view()}(p);
  const Segment& a = l.segments[0];
  for (uint32_t i = a.begin; i < a.begin + a.count; ++i) EXPECT_EQ(l.cluster_of[i], cluster_of[i]);
  for (uint32_t c = 0; c < a.k; ++c) EXPECT_EQ(l.counts[a.cluster_base + c], counts[a.cluster_base + c]);
  // k runs of (almost) equal length, in order.
  uint32_t total = 0;
  for (uint32_t c = 0; c < s.k; ++c) {
    EXPECT_GE(l.counts[s.cluster_base + c], s.count / s.k);
    EXPECT_LE(l.counts[s.cluster_base + c], s.count / s.k + 1);
    total += l.counts[s.cluster_base + c];
  }
  EXPECT_EQ(total, s.count);
  for (uint32_t i = s.begin + 1; i < s.begin + s.count; ++i) EXPECT_LE(l.cluster_of[i - 1], l.cluster_of[i]);
}

// The sizes CountChildren adds up for the next level (ChildCounts::next) are those of the
// segments EmitChildren writes: the next set-up takes them without reading its own scan's
// total back, so a difference would leave its buffers short.
TEST(Partition, CountedSizesOfTheNextLevelAreThoseOfTheSegmentsEmitted) {
  for (const char* preset : {"Q2", "QA"})
    for (bool wide : {false, true}) {
      HostLevel l = make_level();
      for (uint32_t p = 0; p < l.pieces.size(); ++p)
        AssignPiece<8, ClusterMetric::Means, AssignPass::Final>{l.view()}(p);
      l.place();
      for (uint32_t s = 0; s < 2; ++s) l.segments[s].node = s;
      NodeRules rules = node_rules(*kmeans_preset(preset));
      rules.max_leaf_size = 20;  // some clusters leaves, some split again
      rules.wide = wide;
      const SizesOfSegment sizes{16};
      std::vector<ChildCounts> counts(2), offsets(3);
      for (uint32_t s = 0; s < 2; ++s) CountChildren{l.segments.data(), l.clusters(), rules, sizes, counts.data()}(s);
      for (uint32_t s = 0; s < 2; ++s) offsets[s + 1] = AddChildCounts{}(offsets[s], counts[s]);
      const ChildCounts total = offsets[2];
      std::vector<BvhNode> nodes(2 + total.nodes);
      std::vector<Segment> next(total.segments);
      for (uint32_t s = 0; s < 2; ++s)
        EmitChildren<8>{l.segments.data(), l.clusters(), rules, offsets.data(), 2, nodes.data(), next.data()}(s);
      SegmentSizes emitted;
      for (const Segment& seg : next) emitted = AddSegmentSizes{}(emitted, sizes(seg));
      const std::string what = std::string(preset) + (wide ? " wide" : "");
      ASSERT_GT(total.segments, 0u) << what;
      EXPECT_EQ(total.next.clusters, emitted.clusters) << what;
      EXPECT_EQ(total.next.pieces, emitted.pieces) << what;
      EXPECT_EQ(total.next.counters, emitted.counters) << what;
    }
}

}  // namespace
}  // namespace kmbvh
