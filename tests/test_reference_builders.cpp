// The paper's reference builders and PLOC: valid trees on random and degenerate
// sets, the same tree for any thread count, parameters honoured; the sweep SAH builder
// picks the cheapest split at every node (exhaustive check); LBVH's radix tree matches an
// independent reference; the CPU radix sort matches std::stable_sort.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <functional>
#include <random>
#include <set>
#include <tuple>

#include "adapters/builder_registry.h"
#include "cuda/binary/radix_tree.h"
#include "cuda/ploc/find_nearest_cpu.h"
#include "cuda/ploc/iteration_cpu.h"
#include "cuda/ploc/ploc_steps.h"
#include "cuda/core/radix_sort_cpu.h"
#include "cuda/core/threads.h"
#include "cuda/metrics/tree_stats.h"
#include "cuda/sweep_sah/sweep_sah.h"
#include "support/same_tree.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

const char* const kReferenceBuilders[] = {"sweep-sah", "lbvh", "hlbvh", "atrbvh", "ploc"};

using test::same_tree;

void expect_valid(const BuilderConfig& config, const PrimitiveSet& prims, const std::string& what) {
  const Bvh bvh = run_builder(config, prims);
  const ValidationReport r = validate(bvh, prims, validation_limits(config));
  EXPECT_TRUE(r.ok()) << config.label() << " on " << what << ": " << r.summary();
}

class ReferenceBuilder : public ::testing::TestWithParam<const char*> {};

TEST_P(ReferenceBuilder, ValidOnRandomScenes) {
  const BuilderConfig config = parse_builder(GetParam());
  expect_valid(config, make_primitive_set(test::random_triangles(20000, 61)), "random");
  expect_valid(config, make_primitive_set(test::clustered_triangles(20000, 62)), "clustered");
}

TEST_P(ReferenceBuilder, ValidOnDegenerateSets) {
  const BuilderConfig config = parse_builder(GetParam());
  for (uint32_t n : {0u, 1u, 2u, 3u, 9u}) expect_valid(config, make_primitive_set(test::random_triangles(n, 63)), "tiny");
  expect_valid(config, make_primitive_set(test::identical_triangles(100000)), "identical");
  expect_valid(config, make_primitive_set(test::shared_centroid_triangles(20000)), "shared centroid");
  expect_valid(config, make_primitive_set(test::zero_area_triangles(20000, 64)), "zero area");
}

TEST_P(ReferenceBuilder, SameTreeWithOneAndTwoThreads) {
  const BuilderConfig config = parse_builder(GetParam());
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(50000, 65));
  set_thread_count(1);
  const Bvh one = run_builder(config, prims);
  set_thread_count(2);
  const Bvh two = run_builder(config, prims);
  set_thread_count(0);
  EXPECT_TRUE(same_tree(one, two)) << config.label();
}

TEST_P(ReferenceBuilder, HonoursMaxLeafSize) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(5000, 66));
  for (uint32_t m : {1u, 4u, 32u}) {
    BuilderConfig config = parse_builder(GetParam());
    config.max_leaf_size = m;
    const Bvh bvh = run_builder(config, prims);
    EXPECT_TRUE(validate(bvh, prims, validation_limits(config)).ok()) << config.label() << " m=" << m;
    if (m == 1) {
      EXPECT_EQ(tree_stats(bvh).max_leaf_size, 1u);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Builders, ReferenceBuilder, ::testing::ValuesIn(kReferenceBuilders),
                         [](const auto& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

TEST(ReferenceBuilders, ParametersOfPlocAndAtrbvh) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(10000, 67));
  for (uint32_t radius : {1u, 4u, 64u}) {
    BuilderConfig config = parse_builder("ploc");
    config.binary.ploc_radius = radius;
    expect_valid(config, prims, "radius " + std::to_string(radius));
  }
  for (uint32_t size : {3u, 9u, 16u})
    for (uint32_t iterations : {0u, 1u, 3u}) {
      BuilderConfig config = parse_builder("atrbvh");
      config.binary.treelet_size = size;
      config.binary.treelet_iterations = iterations;
      expect_valid(config, prims, "treelets");
    }
  BinaryBuildParams bad;
  bad.treelet_size = 2;
  EXPECT_THROW(build_atrbvh(prims, bad), std::invalid_argument);
  bad = BinaryBuildParams{};
  bad.max_leaf_size = 33;
  EXPECT_THROW(build_lbvh(prims, bad), std::invalid_argument);
}

TEST(Ploc, StaysLogarithmicOnEqualAndNestedBoxes) {
  // Chains of nearest neighbours would make PLOC quadratic (one merge per iteration).
  for (const TriangleScene& scene : {test::identical_triangles(100000), test::shared_centroid_triangles(100000)}) {
    const PrimitiveSet prims = make_primitive_set(scene);
    BuildInfo info;
    const Bvh bvh = build_ploc(prims, BinaryBuildParams{}, Backend::Cpu, &info);
    EXPECT_TRUE(validate(bvh, prims, {}).ok()) << scene.name;
    // Every two iterations the clusters at least halve, or over the top clusters lose at
    // least 1/64 (ploc_stalled): about 900 iterations at most here, where a chain merging
    // one pair an iteration would take 100,000.
    uint32_t bound = 0;
    for (uint32_t count = uint32_t(prims.size()); count > 1; bound += 2)
      count = count > kPlocTopClusters ? (count + 1) / 2
                                       : count - (count + kPlocTopStallFraction - 1) / kPlocTopStallFraction;
    EXPECT_LE(info.levels, bound) << scene.name;
  }
}

// The CPU's blocked nearest-neighbour search (a running minimum over the pairs) must pick
// what the GPU's per-cluster search picks, ties included: scenes, a grid of equal boxes
// (every area tied), boxes whose merged areas overflow to infinity or NaN (a whole row of
// them too), and counts that end inside a block and inside the first window.
std::vector<Aabb> grid_boxes(uint32_t n) {
  std::vector<Aabb> boxes;
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3 at(float(i % 7), float(i / 7 % 5), float(i / 35));
    boxes.push_back(Aabb(at, at + Vec3(0.5f, 0.5f, 0.5f)));
  }
  return boxes;
}
std::vector<Aabb> overflowing_boxes(uint32_t n) {
  // Every other box far out on x and flat in y: two of them merge to a box flat in y and
  // often infinitely wide, a NaN area; a far one and a near one to an area that overflows
  // to infinity or not; two near ones to a small area.
  std::vector<Aabb> boxes;
  std::mt19937 random(70);
  std::uniform_real_distribution<float> far(1e38f, 3e38f), near(0.0f, 0.5f);  // far's sign drawn apart
  for (uint32_t i = 0; i < n; ++i) {
    const bool far_away = i % 2 == 0;
    const float x = far_away ? (random() % 2 ? far(random) : -far(random)) : 0.0f;
    const Vec3 at = far_away ? Vec3(x, 0.0f, 0.0f) : Vec3(near(random), near(random), near(random));
    boxes.push_back(Aabb(at, at + Vec3(0.01f, far_away ? 0.0f : 0.01f, 0.01f)));
  }
  return boxes;
}

// A box whose merged areas with all of the next ones are NaN (it far out on +x, they on -x,
// all flat in y), and nothing before it.
std::vector<Aabb> nan_row_boxes(uint32_t n) {
  std::vector<Aabb> boxes;
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3 at(i == 0 ? 3e38f : -3e38f + float(i) * 1e32f, 0.0f, float(i));
    boxes.push_back(Aabb(at, at + Vec3(0.0f, 0.0f, 0.5f)));
  }
  return boxes;
}

TEST(Ploc, BlockedSearchPicksTheSameNeighbours) {
  std::vector<std::pair<std::string, std::vector<Aabb>>> inputs;
  for (const TriangleScene& scene : {test::clustered_triangles(3000, 72), test::identical_triangles(3000)})
    inputs.emplace_back(scene.name, make_primitive_set(scene).boxes);
  inputs.emplace_back("grid", grid_boxes(3000));
  inputs.emplace_back("overflowing", overflowing_boxes(3000));
  inputs.emplace_back("NaN row", nan_row_boxes(100));
  for (uint32_t n : {2u, 3u, 17u, 63u, 65u, 100u})
    inputs.emplace_back("clustered, " + std::to_string(n), std::vector<Aabb>(inputs[0].second.begin(),
                                                                             inputs[0].second.begin() + n));
  for (const auto& [name, boxes] : inputs) {
    const auto n = uint32_t(boxes.size());
    std::vector<float> columns(6 * size_t(n));
    const BoxColumns box{columns.data(), n};
    for (uint32_t i = 0; i < n; ++i) box.set(i, boxes[i]);
    for (uint32_t radius : {1u, 3u, 5u, 16u, 31u, 32u}) {
      std::vector<uint32_t> per_cluster(n), blocked(n);
      const FindNearest<32> one{box, n, radius, per_cluster.data()};
      for (uint32_t i = 0; i < n; ++i) one(i);
      const FindNearestInBlocks<32, 64> blocks{box, n, radius, blocked.data()};
      for (uint32_t b = 0; b * 64 < n; ++b) blocks(b);
      EXPECT_EQ(per_cluster, blocked) << name << " radius " << radius;
    }
  }
}

// PLOC's clustering as the GPU runs it, a step at a time (the per-cluster search or the
// positional pairs, the counts, their exclusive scan, the merge, the boxes gathered and the
// new ones retired), or as the CPU runs it (ploc_iteration_cpu: one parallel region), from
// the leaves' boxes in their order to one cluster.
struct PlocRun {
  std::vector<uint32_t> left, right, clusters, next_clusters, nearest, order;
  std::vector<Aabb> box, fresh;  // the inner nodes', out of the columns at the end; an iteration's new ones
  std::vector<float> columns;
  uint32_t iterations = 0, paired = 0;

  PlocRun(const std::vector<Aabb>& leaves, bool fused) {
    const auto n = uint32_t(leaves.size());
    left.resize(n - 1), right.resize(n - 1), box.resize(n - 1), fresh.resize(n / 2), order.resize(n);
    clusters.resize(n), next_clusters.resize(n), nearest.resize(n);
    columns.resize(6 * size_t(n));
    BinaryTreeView tree;
    tree.n = n, tree.left = left.data(), tree.right = right.data();
    tree.prim_box = leaves.data(), tree.order = order.data();
    const BoxColumns cluster_box{columns.data(), n};
    for (uint32_t i = 0; i < n; ++i) order[i] = i, cluster_box.set(i, leaves[i]), clusters[i] = i;
    uint32_t count = n, next_inner = n;
    bool stalled = false;
    // Every third iteration's neighbours are paired by position too (as after a stall).
    for (; count > 1; ++iterations) {
      const bool pair = stalled || iterations % 3 == 2;
      paired += pair;
      MergeAndCompact merge{clusters.data(), cluster_box, nearest.data(), nullptr, next_inner, tree,
                            next_clusters.data(), fresh.data()};
      MergeCounts total;
      if (fused) {
        total = ploc_iteration_cpu(count, 16, pair, cluster_box, nearest.data(), merge);
      } else {
        for (uint32_t i = 0; i < count; ++i) {
          if (pair)
            PairNeighbours{count, nearest.data()}(i);
          else
            FindNearest<16>{cluster_box, count, 16, nearest.data()}(i);
        }
        std::vector<MergeCounts> counts(count), offsets(count);
        CountMerges counter{nearest.data(), counts.data()};
        for (uint32_t i = 0; i < count; ++i) counter(i);
        for (uint32_t i = 0; i < count; ++i) {
          offsets[i] = total;
          total = AddMergeCounts{}(total, counts[i]);
        }
        merge.offsets = offsets.data();
        for (uint32_t i = 0; i < count; ++i) merge(i);
        const GatherClusterBoxes gather{next_clusters.data(), merge.boxes()};
        for (uint32_t k = 0; k < total.kept; ++k) gather(k);
        const RetireFreshBoxes retire{merge.boxes()};
        for (uint32_t m = 0; m < total.merges; ++m) retire(m);
      }
      std::swap(clusters, next_clusters);
      next_inner += total.merges;
      stalled = !stalled && ploc_stalled(total.merges, count);
      count = total.kept;
    }
    const InnerBoxesFromColumns out{cluster_box, box.data()};
    for (uint32_t q = 0; q + 1 < n; ++q) out(q);
  }
};

// The CPU's fused iteration leaves what the GPU's steps leave, iteration by iteration up to
// the root: the same inner nodes and boxes, at one and two threads (shares split
// inside pairs and between a cluster and its neighbours), searched and paired.
TEST(Ploc, FusedIterationIsTheStepByStepIteration) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(20000, 73));
  std::vector<Aabb> leaves(prims.boxes.begin(), prims.boxes.end());
  std::sort(leaves.begin(), leaves.end(), [](const Aabb& a, const Aabb& b) { return a.lo.x < b.lo.x; });
  const PlocRun steps(leaves, false);
  EXPECT_GT(steps.paired, 3u);
  for (const int threads : {1, 2}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    set_thread_count(threads);
    const PlocRun fused(leaves, true);
    set_thread_count(0);
    EXPECT_EQ(fused.iterations, steps.iterations);
    EXPECT_EQ(fused.left, steps.left);
    EXPECT_EQ(fused.right, steps.right);
    EXPECT_TRUE(std::equal(fused.box.begin(), fused.box.end(), steps.box.begin(), [](const Aabb& a, const Aabb& b) {
      return a.lo.x == b.lo.x && a.lo.y == b.lo.y && a.lo.z == b.lo.z && a.hi.x == b.hi.x && a.hi.y == b.hi.y &&
             a.hi.z == b.hi.z;
    }));
  }
}

TEST(ReferenceBuilders, RestructuringLowersLbvhCost) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(30000, 68));
  const double lbvh = validate(run_builder(parse_builder("lbvh"), prims), prims, {}).sah_recomputed;
  const double atrbvh = validate(run_builder(parse_builder("atrbvh"), prims), prims, {}).sah_recomputed;
  EXPECT_LT(atrbvh, lbvh);
}

TEST(ReferenceBuilders, CudaBackendWithoutDeviceIsAClearError) {
  if (cuda_device_available()) GTEST_SKIP() << "a CUDA device is present";
  BuilderConfig config = parse_builder("lbvh");
  config.backend = Backend::Cuda;
  EXPECT_THROW(run_builder(config, make_primitive_set(test::random_triangles(100, 69))), std::runtime_error);
}

// --- sweep SAH: the cheapest of all centroid-sorted splits, checked exhaustively ---------

void collect(const Bvh& bvh, uint32_t node, std::vector<uint32_t>& out) {
  const BvhNode& n = bvh.nodes[node];
  if (n.is_leaf()) {
    out.insert(out.end(), bvh.prim_indices.begin() + n.first, bvh.prim_indices.begin() + n.first + n.count);
    return;
  }
  for (uint32_t c = 0; c < n.count; ++c) collect(bvh, n.first + c, out);
}

double cheapest_split(const PrimitiveSet& prims, std::vector<uint32_t> ids) {
  double best = INFINITY;
  for (int a = 0; a < 3; ++a) {
    std::sort(ids.begin(), ids.end(), [&](uint32_t x, uint32_t y) {
      const float cx = prims.boxes[x].center()[a], cy = prims.boxes[y].center()[a];
      return cx < cy || (cx == cy && x < y);
    });
    for (size_t s = 1; s < ids.size(); ++s) {
      Aabb left, right;
      for (size_t i = 0; i < s; ++i) left.grow(prims.boxes[ids[i]]);
      for (size_t i = s; i < ids.size(); ++i) right.grow(prims.boxes[ids[i]]);
      best = std::min(best, double(left.surface_area()) * s + double(right.surface_area()) * (ids.size() - s));
    }
  }
  return best;
}

TEST(SweepSah, EveryNodeTakesTheCheapestSplitOrLeaf) {
  for (uint32_t seed = 0; seed < 4; ++seed) {
    TriangleScene scene = seed == 3 ? test::clustered_triangles(150, 70) : test::random_triangles(150, 71 + seed);
    if (seed == 2)  // duplicates: equal centroids on every axis
      for (uint32_t t = 0; t < 40; ++t) scene.triangles[t] = scene.triangles[0];
    const PrimitiveSet prims = make_primitive_set(scene);
    SweepSahParams params;
    const Bvh bvh = build_sweep_sah(prims, params);
    ASSERT_TRUE(validate(bvh, prims, {}).ok());
    for (uint32_t i = 0; i < bvh.nodes.size(); ++i) {
      const BvhNode& n = bvh.nodes[i];
      std::vector<uint32_t> ids;
      collect(bvh, i, ids);
      if (ids.size() < 2) continue;
      const double best = cheapest_split(prims, ids);
      const double area = n.box.surface_area();
      const bool leaf_is_cheaper = ids.size() <= params.max_leaf_size &&
                                   params.sah.intersection * ids.size() * area <=
                                       params.sah.traversal * area + params.sah.intersection * best;
      EXPECT_EQ(n.is_leaf(), leaf_is_cheaper) << "node " << i << " of " << ids.size() << " primitives";
      if (n.is_leaf()) continue;
      const BvhNode &l = bvh.nodes[n.first], &r = bvh.nodes[n.first + 1];
      std::vector<uint32_t> left_ids, right_ids;
      collect(bvh, n.first, left_ids);
      collect(bvh, n.first + 1, right_ids);
      const double chosen =
          double(l.box.surface_area()) * left_ids.size() + double(r.box.surface_area()) * right_ids.size();
      EXPECT_NEAR(chosen, best, 1e-9 * best) << "node " << i;
    }
  }
}

TEST(SweepSah, EqualBoxesSplitInTheMiddle) {
  const PrimitiveSet prims = make_primitive_set(test::identical_triangles(4096));
  const Bvh bvh = build_sweep_sah(prims, {});
  EXPECT_EQ(tree_stats(bvh).max_depth, 9u);  // 4096 / 8 leaves of 8: log2(512)
}

// --- LBVH: the radix tree of distinct sorted codes is unique -----------------------------

using Range = std::tuple<uint32_t, uint32_t, uint32_t>;  // first, last, first of the right child

void reference_radix_tree(const std::vector<unsigned long long>& keys, uint32_t lo, uint32_t hi, std::set<Range>& out) {
  if (lo == hi) return;
  const int bit = 63 - __builtin_clzll(keys[lo] ^ keys[hi]);  // highest differing bit
  uint32_t split = lo + 1;
  while (!((keys[split] >> bit) & 1)) ++split;
  out.insert({lo, hi, split});
  reference_radix_tree(keys, lo, split - 1, out);
  reference_radix_tree(keys, split, hi, out);
}

TEST(Lbvh, RadixTreeMatchesAnIndependentReference) {
  std::mt19937_64 rng(5);
  for (uint32_t n : {2u, 3u, 17u, 256u, 1000u}) {
    std::set<unsigned long long> distinct;
    while (distinct.size() < n) distinct.insert(rng() >> 4);
    const std::vector<unsigned long long> keys(distinct.begin(), distinct.end());
    std::vector<uint32_t> left(n - 1), right(n - 1), parent(2 * n - 1), other_end(n - 1, kNotYet), root(1);
    std::vector<uint32_t> visited(n - 1, 0);
    BinaryTreeView tree;
    tree.n = n;
    tree.left = left.data();
    tree.right = right.data();
    tree.parent = parent.data();
    // Leaves in a shuffled order: the tree must not depend on which climbs first.
    std::vector<uint32_t> leaves(n);
    for (uint32_t i = 0; i < n; ++i) leaves[i] = i;
    std::shuffle(leaves.begin(), leaves.end(), rng);
    const auto build = build_radix_tree(keys.data(), tree, other_end.data(), root.data(),
                                        [&](uint32_t node) { ++visited[node - n]; });
    for (uint32_t leaf : leaves) build(leaf);
    EXPECT_GE(root[0], n);  // the root is an inner node
    for (uint32_t v : visited) EXPECT_EQ(v, 1u);  // every inner node visited once

    std::set<Range> got;
    std::function<std::pair<uint32_t, uint32_t>(uint32_t)> span = [&](uint32_t node) -> std::pair<uint32_t, uint32_t> {
      if (node < n) return {node, node};
      const auto l = span(left[node - n]), r = span(right[node - n]);
      EXPECT_EQ(l.second + 1, r.first);
      got.insert({l.first, r.second, r.first});
      return {l.first, r.second};
    };
    const auto all = span(root[0]);
    EXPECT_EQ(all.first, 0u);
    EXPECT_EQ(all.second, n - 1);
    std::set<Range> expected;
    reference_radix_tree(keys, 0, n - 1, expected);
    EXPECT_EQ(got, expected) << "n=" << n;
  }
}

// --- the CPU radix sort ---------------------------------------------------------------------

TEST(RadixSort, MatchesStableSort) {
  std::mt19937_64 rng(6);
  // Morton codes' 60 bits, and a width that is no multiple of the sort's digit.
  for (const int key_bits : {60, 37}) {
    for (size_t n : {size_t(0), size_t(1), size_t(2), size_t(1000), size_t(200000)}) {
      std::vector<uint64_t> keys(n), key_scratch(n);
      std::vector<uint32_t> values(n), value_scratch(n);
      for (size_t i = 0; i < n; ++i) {
        keys[i] = (rng() >> (64 - key_bits)) & (i % 3 == 0 ? 0xffull : ~0ull);  // many duplicates too
        values[i] = uint32_t(i);
      }
      std::vector<std::pair<uint64_t, uint32_t>> expected(n);
      for (size_t i = 0; i < n; ++i) expected[i] = {keys[i], values[i]};
      std::stable_sort(expected.begin(), expected.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      set_thread_count(2);
      radix_sort_pairs(keys.data(), values.data(), n, key_bits, key_scratch.data(), value_scratch.data());
      set_thread_count(0);
      for (size_t i = 0; i < n; ++i) {
        ASSERT_EQ(keys[i], expected[i].first) << key_bits << " bits, " << i;
        ASSERT_EQ(values[i], expected[i].second) << key_bits << " bits, " << i;
      }
    }
  }
}

// Called from inside another OpenMP region, where its own region gets one thread (nesting
// off) while omp_get_max_threads says two: the whole array is still sorted.
TEST(RadixSort, SortsWholeInsideAnotherParallelRegion) {
  const size_t n = 200000;
  std::mt19937_64 rng(7);
  std::vector<uint64_t> keys(n), key_scratch(n);
  std::vector<uint32_t> values(n), value_scratch(n);
  for (size_t i = 0; i < n; ++i) keys[i] = rng() >> 4, values[i] = uint32_t(i);
  set_thread_count(2);
  int max_threads_inside = 0;
#pragma omp parallel num_threads(2)
#pragma omp single
  {
    max_threads_inside = omp_get_max_threads();
    radix_sort_pairs(keys.data(), values.data(), n, 60, key_scratch.data(), value_scratch.data());
  }
  set_thread_count(0);
  EXPECT_EQ(max_threads_inside, 2);  // the case: the sort is told of two threads and gets one
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  std::vector<uint32_t> seen(values);
  std::sort(seen.begin(), seen.end());
  for (size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i], uint32_t(i));
}

}  // namespace
}  // namespace kmbvh
