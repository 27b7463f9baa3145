// One PLOC iteration on the CPU in one parallel region, where the GPU makes four launches
// and a scan (ploc.inl): the nearest neighbours (find_nearest_cpu.h, or positions paired
// after a stalled iteration), then each thread counts the merges and survivors of its
// share of the positions, and after a barrier merges and compacts its share at the offsets
// of the shares before it (MergeAndCompact::at), and after another gathers the boxes of the
// survivors it wrote into the columns (GatherClusterBoxes) and retires its new nodes' boxes
// (RetireFreshBoxes). No per-position counts, no scan over them, one fork and join an
// iteration; iterations of few clusters (the top of the tree) run on one thread. The same
// tree as the GPU's steps.
#pragma once

#include <omp.h>

#include <algorithm>
#include <vector>

#include "../core/backend_counters.h"
#include "find_nearest_cpu.h"
#include "ploc_steps.h"

namespace kmbvh {

constexpr uint32_t kPlocCpuMaxRadius = 32;
constexpr uint32_t kPlocCpuBlock = 256;
constexpr uint32_t kPlocClustersPerThread = 4096;  // fewer: one thread (no fork, no barrier)

// The iteration's totals: pairs merged and clusters left. `merge` writes the next clusters,
// whose boxes then replace the clusters' in `box`; its offsets are not read.
inline MergeCounts ploc_iteration_cpu(uint32_t count, uint32_t radius, bool paired, BoxColumns box,
                                      uint32_t* nearest, const MergeAndCompact& merge) {
  count_launch();
  const int threads =
      int(std::max<uint32_t>(1, std::min<uint32_t>(uint32_t(omp_get_max_threads()), count / kPlocClustersPerThread)));
  std::vector<MergeCounts> shares(size_t(threads) + 1);
  const FindNearestInBlocks<kPlocCpuMaxRadius, kPlocCpuBlock> find{box, count, radius, nearest};
  const PairNeighbours pair{count, nearest};
  const uint32_t blocks = (count + kPlocCpuBlock - 1) / kPlocCpuBlock;
#pragma omp parallel num_threads(threads)
  {
    // The shares are those of the threads the region really has (inside another region,
    // with nesting off, one).
    const uint32_t t = uint32_t(omp_get_thread_num()), parts = uint32_t(omp_get_num_threads());
    if (paired) {
#pragma omp for schedule(static)
      for (uint32_t i = 0; i < count; ++i) pair(i);
    } else {
#pragma omp for schedule(static)
      for (uint32_t b = 0; b < blocks; ++b) find(b);
    }
    const uint32_t begin = uint32_t(uint64_t(count) * t / parts), end = uint32_t(uint64_t(count) * (t + 1) / parts);
    MergeCounts mine;
    for (uint32_t i = begin; i < end; ++i) mine = AddMergeCounts{}(mine, merge_counts(nearest, i));
    shares[t + 1] = mine;
#pragma omp barrier
    MergeCounts before;
    for (uint32_t u = 0; u < t; ++u) before = AddMergeCounts{}(before, shares[u + 1]);
    const MergeCounts first = before;
    for (uint32_t i = begin; i < end; ++i) {
      merge.at(i, before);
      before = AddMergeCounts{}(before, merge_counts(nearest, i));
    }
    if (t + 1 == parts) shares[0] = before;  // the last share ends at the totals
    // Once every share has merged (the columns are read until then), each gathers the boxes
    // of the survivors it wrote.
#pragma omp barrier
    const GatherClusterBoxes gather{merge.next_clusters, merge.boxes()};
    for (uint32_t k = first.kept; k < before.kept; ++k) gather(k);
    const RetireFreshBoxes retire{merge.boxes()};
    for (uint32_t m = first.merges; m < before.merges; ++m) retire(m);
  }
  return shares[0];
}

}  // namespace kmbvh
