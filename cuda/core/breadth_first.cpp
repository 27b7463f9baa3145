#include "breadth_first.h"

#include <utility>

#include "huge_pages.h"

namespace kmbvh {

Bvh reorder_breadth_first(Bvh in) {
  Bvh out;
  out.prim_indices = std::move(in.prim_indices);
  if (in.nodes.empty()) return out;
  reserve_on_huge_pages(out.nodes, in.nodes.size());
  std::vector<uint32_t> source;  // source[i]: the input index of output node i
  reserve_on_huge_pages(source, in.nodes.size());
  out.nodes.push_back(in.nodes[0]);
  source.push_back(0);
  for (size_t q = 0; q < out.nodes.size(); ++q) {
    const BvhNode& original = in.nodes[source[q]];
    if (original.is_leaf()) continue;
    out.nodes[q].first = static_cast<uint32_t>(out.nodes.size());
    for (uint32_t c = 0; c < original.count; ++c) {
      out.nodes.push_back(in.nodes[original.first + c]);
      source.push_back(original.first + c);
    }
  }
  return out;
}

}  // namespace kmbvh
