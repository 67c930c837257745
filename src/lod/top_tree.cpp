// build_top_tree (see sphere_tree.hpp): a balanced top over subtree roots. Each range of roots
// that must sit `d` levels below its node is cut into 2-4 contiguous groups of nearly equal size,
// each able to sit d - 1 levels below its own node (between 2^(d-1) and 4^(d-1) roots), so all
// roots end on one level and keep their order.
#include <string>
#include <vector>

#include "node_bounds.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {
namespace {

struct Range {
  std::size_t begin = 0, end = 0;  // roots [begin, end)
  std::uint32_t depth = 0;         // levels below this node to the roots
};

std::size_t pow_of(std::size_t base, std::uint32_t exponent) {
  std::size_t v = 1;
  for (std::uint32_t i = 0; i < exponent; ++i) v *= base;
  return v;
}

}  // namespace

SphereTree build_top_tree(std::span<const SphereNode> roots, bool has_colors) {
  const std::size_t count = roots.size();
  if (count == 0 || count > (std::size_t{1} << 20)) {
    throw Error("cannot build the top of a hierarchy over " + std::to_string(count) +
                " subtrees (1 to 2^20 are possible)");
  }
  std::uint32_t depth = 0;
  while (pow_of(4, depth) < count) ++depth;

  // Breadth-first: each node's range, split into its children's ranges as the level is laid out.
  SphereTree tree;
  tree.has_colors = has_colors;
  tree.depth = depth;
  std::vector<Range> ranges{{0, count, depth}};
  std::vector<std::uint32_t> level_begin{0};
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    const Range r = ranges[i];
    SphereNode node{};
    if (r.depth == 0) {
      node = roots[r.begin];
      node.first_child = 0;
      tree.nodes.push_back(node);
      continue;
    }
    const std::size_t c = r.end - r.begin;
    const std::size_t below = pow_of(4, r.depth - 1);
    const std::size_t k = std::max<std::size_t>(2, (c + below - 1) / below);
    node.first_child = static_cast<std::uint32_t>(ranges.size());
    node.child_count = static_cast<std::uint8_t>(k);
    tree.nodes.push_back(node);
    for (std::size_t g = 0; g < k; ++g) {
      ranges.push_back({r.begin + c * g / k, r.begin + c * (g + 1) / k, r.depth - 1});
    }
  }
  // Interior attributes bottom-up (children come after their parent).
  for (std::size_t i = tree.nodes.size(); i-- > 0;) {
    if (ranges[i].depth == 0) continue;
    SphereNode& node = tree.nodes[i];
    lod_detail::combine_children({&tree.nodes[node.first_child], node.child_count}, node);
  }
  return tree;
}

}  // namespace pointillist
