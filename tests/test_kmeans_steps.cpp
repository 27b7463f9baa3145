// Each step of the k-means builder alone: distance, initialisation, assignment,
// the mean and median updates, and the agglomerative merge order, against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <vector>

#include "cuda/core/counter_rng.h"
#include "cuda/kmeans/agglomerate.h"
#include "cuda/kmeans/assign.h"
#include "cuda/kmeans/initialise.h"
#include "cuda/kmeans/update_means.h"
#include "cuda/kmeans/update_medians.h"
#include "support/printers.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

std::vector<Aabb> random_boxes(uint32_t n, uint32_t seed) {
  std::vector<Aabb> boxes(n);
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3 lo(test::random_unit(seed, 1, 3 * i), test::random_unit(seed, 1, 3 * i + 1),
                  test::random_unit(seed, 1, 3 * i + 2));
    const Vec3 size(test::random_unit(seed, 2, 3 * i), test::random_unit(seed, 2, 3 * i + 1),
                    test::random_unit(seed, 2, 3 * i + 2));
    boxes[i] = Aabb(lo * 10.0f, lo * 10.0f + size);
  }
  return boxes;
}

TEST(Distance, SquaredSixDimensional) {
  const Aabb a({0, 0, 0}, {1, 1, 1});
  const Aabb b({1, 2, 3}, {2, 3, 5});
  // lo differences 1, 2, 3; hi differences 1, 2, 4
  EXPECT_FLOAT_EQ(squared_box_distance(a, b), 1 + 4 + 9 + 1 + 4 + 16);
  EXPECT_FLOAT_EQ(box_distance<ClusterMetric::Means>(a, b), 35);
  EXPECT_FLOAT_EQ(squared_box_distance(a, a), 0);
  EXPECT_FLOAT_EQ(squared_box_distance(a, b), squared_box_distance(b, a));
}

TEST(Distance, ManhattanSixDimensional) {
  const Aabb a({0, 0, 0}, {1, 1, 1});
  const Aabb b({-1, 2, 3}, {2, 3, 5});
  EXPECT_FLOAT_EQ(manhattan_box_distance(a, b), 1 + 2 + 3 + 1 + 2 + 4);
  EXPECT_FLOAT_EQ(box_distance<ClusterMetric::Medians>(a, b), 13);
}

TEST(Initialise, FirstIsRandomPrimitiveAndEachNextIsFarthestCandidate) {
  const auto boxes = random_boxes(500, 3);
  for (uint32_t k : {2u, 8u, 16u}) {
    for (uint32_t p : {1u, 5u, 20u}) {
      const uint32_t seed = 9, stream = node_stream(0, 500);
      std::vector<Aabb> reps(k);
      initialise_representatives<ClusterMetric::Means>(boxes.data(), 500, k, p, seed, stream, reps.data());
      EXPECT_EQ(reps[0], boxes[counter_uniform(seed, stream, candidate_draw(0, 0, p), 500)]);
      for (uint32_t r = 1; r < k; ++r) {
        // Recompute every candidate's distance to its nearest earlier representative.
        float best = -1.0f;
        Aabb expected;
        for (uint32_t c = 0; c < p; ++c) {
          const Aabb& cand = boxes[counter_uniform(seed, stream, candidate_draw(r, c, p), 500)];
          float nearest = INFINITY;
          for (uint32_t j = 0; j < r; ++j) nearest = std::min(nearest, squared_box_distance(cand, reps[j]));
          if (nearest > best) {
            best = nearest;
            expected = cand;
          }
        }
        EXPECT_EQ(reps[r], expected) << "k=" << k << " p=" << p << " r=" << r;
      }
    }
  }
}

TEST(Initialise, DrawsDependOnlyOnSeedAndNode) {
  const auto boxes = random_boxes(300, 4);
  std::vector<Aabb> a(8), b(8), c(8);
  initialise_representatives<ClusterMetric::Means>(boxes.data(), 300, 8, 5, 1, 77, a.data());
  initialise_representatives<ClusterMetric::Means>(boxes.data(), 300, 8, 5, 1, 77, b.data());
  initialise_representatives<ClusterMetric::Means>(boxes.data(), 300, 8, 5, 2, 77, c.data());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

template <ClusterMetric M>
void check_nearest_against_brute_force() {
  const auto boxes = random_boxes(2000, 5);
  for (uint32_t k : {2u, 3u, 8u, 13u, 64u}) {
    std::vector<Aabb> reps(boxes.begin(), boxes.begin() + k);
    reps[k - 1] = reps[0];  // a duplicate: ties must go to the lower index
    RepresentativeTable<64, M> table;
    table.load(reps.data(), k);
    for (const Aabb& b : boxes) {
      uint32_t expected = 0;
      for (uint32_t j = 1; j < k; ++j)
        if (box_distance<M>(b, reps[j]) < box_distance<M>(b, reps[expected])) expected = j;
      ASSERT_EQ(table.nearest(b), expected) << "k=" << k;
    }
  }
}

TEST(Assign, NearestRepresentativeMatchesBruteForceMeans) { check_nearest_against_brute_force<ClusterMetric::Means>(); }
TEST(Assign, NearestRepresentativeMatchesBruteForceMedians) {
  check_nearest_against_brute_force<ClusterMetric::Medians>();
}

// Boxes whose coordinates come from a palette of the cases that decide ties and NaNs:
// zeros of both signs, overflowing magnitudes, infinities, NaN, and repeats.
std::vector<Aabb> awkward_boxes(uint32_t n, uint32_t seed) {
  const float palette[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 1e30f, -1e30f, FLT_MAX, -FLT_MAX, INFINITY, -INFINITY, NAN};
  const uint32_t size = sizeof(palette) / sizeof(palette[0]);
  std::vector<Aabb> boxes(n);
  for (uint32_t i = 0; i < n; ++i) {
    float c[6];
    for (uint32_t d = 0; d < 6; ++d) {
      const uint32_t pick = counter_uniform(seed, 7, 6 * i + d, size + 4);
      c[d] = pick < size ? palette[pick] : test::random_unit(seed, 8, 6 * i + d);
    }
    boxes[i] = Aabb(Vec3(c[0], c[1], c[2]), Vec3(c[3], c[4], c[5]));
  }
  return boxes;
}

// The host's SSE2 paths (assign.h) against the scalar definitions they replace, bit for bit:
// the trees of the CPU and GPU backends and of the subtree path must stay the same.
template <ClusterMetric M>
void check_vector_nearest_is_scalar() {
  const auto plain = random_boxes(500, 11);
  const auto awkward = awkward_boxes(3000, 12);
  for (uint32_t k : {1u, 2u, 3u, 4u, 5u, 8u, 13u, 16u, 64u}) {
    for (const auto* reps_from : {&plain, &awkward}) {
      std::vector<Aabb> reps(reps_from->begin() + 7, reps_from->begin() + 7 + k);
      if (k > 2) reps[k - 1] = reps[1];  // a tie
      RepresentativeTable<64, M> table;
      table.load(reps.data(), k);
      for (const auto* boxes : {&plain, &awkward})
        for (const Aabb& b : *boxes) ASSERT_EQ(table.nearest(b), table.nearest_scalar(b)) << "k=" << k << " " << b;
    }
  }
}

TEST(Assign, HostNearestIsTheScalarDefinitionMeans) {
  if (!KMBVH_HOST_SSE2) GTEST_SKIP() << "no SSE2 path on this host";
  check_vector_nearest_is_scalar<ClusterMetric::Means>();
}
TEST(Assign, HostNearestIsTheScalarDefinitionMedians) {
  if (!KMBVH_HOST_SSE2) GTEST_SKIP() << "no SSE2 path on this host";
  check_vector_nearest_is_scalar<ClusterMetric::Medians>();
}

TEST(Assign, AccumulatorsAreTheScalarDefinitions) {
  auto same_bits = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof(a)) == 0; };
  for (const auto& boxes : {random_boxes(1000, 13), awkward_boxes(1000, 14)}) {
    constexpr uint32_t k = 5;
    BoundsAccumulator<8> bounds;
    SumAccumulator<8> sums;
    bounds.clear(k);
    sums.clear(k);
    Aabb expected_box[k];
    double expected_sum[k][6] = {};
    for (uint32_t c = 0; c < k; ++c) expected_box[c] = Aabb::empty();
    for (uint32_t i = 0; i < boxes.size(); ++i) {
      const uint32_t c = i % k;
      bounds.add(c, boxes[i]);
      sums.add(c, boxes[i]);
      expected_box[c].grow(boxes[i]);
      for (int d = 0; d < 3; ++d) {
        expected_sum[c][d] += boxes[i].lo[d];
        expected_sum[c][3 + d] += boxes[i].hi[d];
      }
    }
    for (uint32_t c = 0; c < k; ++c) {
      const Aabb box = bounds.box(c);
      EXPECT_TRUE(same_bits(box, expected_box[c])) << box << " against " << expected_box[c];
      EXPECT_TRUE(same_bits(sums.sum[c], expected_sum[c])) << "cluster " << c;
    }
  }
}

TEST(UpdateMeans, FixedPointMeanEqualsExactMean) {
  const auto boxes = random_boxes(1000, 6);
  Aabb frame_box;
  for (const Aabb& b : boxes) frame_box.grow(b);
  const FixedPointFrame frame = FixedPointFrame::of(frame_box);
  // Sum in several pieces, as the kernel does, in any order.
  ClusterSums sums{};
  for (size_t begin = 0; begin < boxes.size(); begin += 137) {
    SumAccumulator<1> acc;
    acc.clear(1);
    const size_t end = std::min(boxes.size(), begin + 137);
    for (size_t i = begin; i < end; ++i) acc.add(0, boxes[i]);
    acc.publish(0, uint32_t(end - begin), frame, false, sums);
  }
  double exact[6] = {};
  for (const Aabb& b : boxes)
    for (int d = 0; d < 3; ++d) {
      exact[d] += b.lo[d];
      exact[3 + d] += b.hi[d];
    }
  for (int d = 0; d < 6; ++d) {
    const double mean = exact[d] / boxes.size();
    EXPECT_NEAR(frame.decode_mean(sums.s[d], uint32_t(boxes.size()), d % 3), mean, 1e-5 * frame_box.extent()[d % 3]);
  }
}

TEST(UpdateMeans, FlatFrameAxisDecodesToItsValue) {
  const FixedPointFrame frame = FixedPointFrame::of(Aabb({1, 2, 3}, {4, 2, 5}));  // y is flat
  EXPECT_EQ(frame.encode(2.0 * 10, 10, 1), 0ull);
  EXPECT_FLOAT_EQ(frame.decode_mean(0, 10, 1), 2.0f);
}

TEST(UpdateMeans, UpdateKeepsRepresentativeOfEmptyCluster) {
  Segment seg;
  seg.box = Aabb({0, 0, 0}, {1, 1, 1});
  Aabb reps[2] = {Aabb({0.5f, 0.5f, 0.5f}, {0.6f, 0.6f, 0.6f}), Aabb({0.1f, 0.1f, 0.1f}, {0.2f, 0.2f, 0.2f})};
  ClusterSums sums[2] = {};
  uint32_t counts[2] = {0, 1};
  uint32_t cluster_segment[2] = {0, 0};
  const FixedPointFrame frame = FixedPointFrame::of(seg.box);
  for (int d = 0; d < 3; ++d) {
    sums[1].s[d] = frame.encode(0.25, 1, d);
    sums[1].s[3 + d] = frame.encode(0.75, 1, d);
  }
  ClusterArrays clusters{reps, sums, counts, nullptr, nullptr, cluster_segment};
  UpdateMeans update{&seg, clusters};
  update(0);
  update(1);
  EXPECT_EQ(reps[0], Aabb({0.5f, 0.5f, 0.5f}, {0.6f, 0.6f, 0.6f}));
  EXPECT_NEAR(reps[1].lo.x, 0.25f, 1e-6);
  EXPECT_NEAR(reps[1].hi.z, 0.75f, 1e-6);
}

TEST(UpdateMedians, SelectMatchesNthElement) {
  for (uint32_t n : {1u, 2u, 3u, 10u, 101u, 1000u}) {
    for (uint32_t seed = 0; seed < 3; ++seed) {
      auto boxes = random_boxes(n, 10 + seed);
      // Many equal keys as well: identical boxes must not make it quadratic or wrong.
      for (uint32_t i = 0; i < n; i += 3) boxes[i] = boxes[0];
      for (int d = 0; d < 6; ++d) {
        std::vector<float> values;
        for (const Aabb& b : boxes) values.push_back(box_component(b, d));
        for (uint32_t rank : {0u, (n - 1) / 2, n - 1}) {
          std::vector<float> sorted = values;
          std::nth_element(sorted.begin(), sorted.begin() + rank, sorted.end());
          auto work = boxes;
          EXPECT_EQ(select_component(work.data(), n, d, rank), sorted[rank]) << "n=" << n << " d=" << d;
        }
      }
    }
  }
}

TEST(UpdateMedians, RepresentativeIsComponentwiseLowerMedian) {
  std::vector<Aabb> members = {Aabb({0, 5, 1}, {1, 6, 9}), Aabb({3, 1, 2}, {4, 2, 3}), Aabb({2, 0, 0}, {5, 7, 4}),
                               Aabb({1, 1, 1}, {2, 2, 2})};
  Aabb rep;
  uint32_t count = 4, begin = 0, segment = 0;
  Segment seg;
  ClusterArrays clusters{&rep, nullptr, &count, nullptr, &begin, &segment};
  UpdateMedians{members.data(), &seg, clusters}(0);
  // lower medians (rank 1 of 4) per component
  EXPECT_EQ(rep, Aabb({1, 1, 1}, {2, 2, 3}));
}

// The greedy merge, written the obvious way: all pairs every step, the key compared as
// (area, weight), ties to the smallest (a, b).
template <uint32_t KMax>
TreeletMerges<KMax> merge_brute_force(const std::vector<Aabb>& boxes, const std::vector<uint32_t>& weights) {
  TreeletMerges<KMax> out;
  const uint32_t j = uint32_t(boxes.size());
  out.leaves = j;
  std::vector<Aabb> box = boxes;
  std::vector<uint32_t> weight = weights;
  std::vector<uint32_t> ref(j);
  std::vector<bool> alive(j, true);
  for (uint32_t s = 0; s < j; ++s) ref[s] = s;
  for (uint32_t m = 0; m + 1 < j; ++m) {
    uint32_t best_a = 0, best_b = 0;
    float best_area = INFINITY;
    uint32_t best_weight = UINT32_MAX;
    for (uint32_t a = 0; a < j; ++a)
      for (uint32_t b = a + 1; b < j; ++b) {
        if (!alive[a] || !alive[b]) continue;
        const float area = join(box[a], box[b]).surface_area();
        const uint32_t w = weight[a] + weight[b];
        if (area < best_area || (area == best_area && w < best_weight)) {
          best_area = area;
          best_weight = w;
          best_a = a;
          best_b = b;
        }
      }
    out.left[m] = uint8_t(ref[best_a]);
    out.right[m] = uint8_t(ref[best_b]);
    out.box[m] = join(box[best_a], box[best_b]);
    box[best_a] = out.box[m];
    weight[best_a] += weight[best_b];
    ref[best_a] = j + m;
    alive[best_b] = false;
  }
  return out;
}

TEST(Agglomerate, MergeOrderMatchesBruteForce) {
  for (uint32_t j = 2; j <= 64; ++j) {
    for (uint32_t seed = 0; seed < 5; ++seed) {
      auto boxes = random_boxes(j, 100 * j + seed);
      std::vector<uint32_t> weights(j);
      for (uint32_t i = 0; i < j; ++i) weights[i] = 1 + counter_uniform(seed, j, i, 20);
      if (seed == 3)  // ties everywhere: a grid of equal boxes
        for (uint32_t i = 0; i < j; ++i)
          boxes[i] = Aabb(Vec3(float(i % 4), float(i / 4), 0), Vec3(float(i % 4) + 1, float(i / 4) + 1, 1));
      if (seed == 4)  // identical boxes: only the weights decide
        for (uint32_t i = 0; i < j; ++i) boxes[i] = boxes[0];
      TreeletMerges<64> fast;
      agglomerate<64>(boxes.data(), weights.data(), j, fast);
      const TreeletMerges<64> slow = merge_brute_force<64>(boxes, weights);
      for (uint32_t m = 0; m + 1 < j; ++m) {
        ASSERT_EQ(fast.left[m], slow.left[m]) << "j=" << j << " seed=" << seed << " merge " << m;
        ASSERT_EQ(fast.right[m], slow.right[m]) << "j=" << j << " seed=" << seed << " merge " << m;
        ASSERT_EQ(fast.box[m], slow.box[m]);
      }
      if (j > 8) continue;
      TreeletMerges<8> narrow;  // the width the k = 8 presets build with
      agglomerate<8>(boxes.data(), weights.data(), j, narrow);
      for (uint32_t m = 0; m + 1 < j; ++m) {
        ASSERT_EQ(narrow.left[m], slow.left[m]) << "KMax 8, j=" << j << " seed=" << seed << " merge " << m;
        ASSERT_EQ(narrow.right[m], slow.right[m]) << "KMax 8, j=" << j << " seed=" << seed << " merge " << m;
        ASSERT_EQ(narrow.box[m], slow.box[m]);
      }
    }
  }
}

TEST(Agglomerate, IdenticalBoxesMakeABalancedTreelet) {
  std::vector<Aabb> boxes(64, Aabb({0, 0, 0}, {1, 1, 1}));
  std::vector<uint32_t> weights(64, 10);
  TreeletMerges<64> merges;
  agglomerate<64>(boxes.data(), weights.data(), 64, merges);
  // Depth of the treelet from the root merge (62).
  std::vector<uint32_t> depth(63, 0);
  uint32_t deepest = 0;
  for (int m = 62; m >= 0; --m)
    for (uint32_t ref : {merges.left[m], merges.right[m]}) {
      const uint32_t d = depth[m] + 1;
      deepest = std::max(deepest, d);
      if (ref >= 64) depth[ref - 64] = d;
    }
  EXPECT_EQ(deepest, 6u);  // log2(64)
}

TEST(Agglomerate, RootBoxIsUnionOfAll) {
  const auto boxes = random_boxes(20, 77);
  const std::vector<uint32_t> weights(20, 1);
  TreeletMerges<32> merges;
  agglomerate<32>(boxes.data(), weights.data(), 20, merges);
  Aabb all;
  for (const Aabb& b : boxes) all.grow(b);
  EXPECT_EQ(merges.box[18], all);
}

}  // namespace
}  // namespace kmbvh
