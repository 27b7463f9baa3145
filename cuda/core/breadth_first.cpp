#include "breadth_first.h"

#include <utility>

#include "huge_pages.h"

namespace kmbvh {

std::vector<BvhNode> breadth_first_nodes(const BvhNode* in, size_t count, std::vector<uint32_t>& source) {
  std::vector<BvhNode> out;
  breadth_first_nodes(in, count, source, out);
  return out;
}

void breadth_first_nodes(const BvhNode* in, size_t count, std::vector<uint32_t>& source, std::vector<BvhNode>& out) {
  out.clear();
  if (count == 0) return;
  reserve_on_huge_pages(out, count);
  source.clear();  // source[i]: the input index of output node i
  reserve_on_huge_pages(source, count);
  out.push_back(in[0]);
  source.push_back(0);
  for (size_t q = 0; q < out.size(); ++q) {
    const BvhNode& original = in[source[q]];
    if (original.is_leaf()) continue;
    out[q].first = static_cast<uint32_t>(out.size());
    for (uint32_t c = 0; c < original.count; ++c) {
      out.push_back(in[original.first + c]);
      source.push_back(original.first + c);
    }
  }
}

Bvh reorder_breadth_first(Bvh in) {
  Bvh out;
  out.prim_indices = std::move(in.prim_indices);
  std::vector<uint32_t> source;
  out.nodes = breadth_first_nodes(in.nodes.data(), in.nodes.size(), source);
  return out;
}

}  // namespace kmbvh
