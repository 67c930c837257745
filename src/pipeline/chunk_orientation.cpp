// OrientationStitcher (see chunk_orientation.hpp).
#include "chunk_orientation.hpp"

#include <deque>

namespace pointillist::chunking {

void OrientationStitcher::add_chunk(std::size_t chunk, std::vector<double> votes) {
  if (first_.size() <= chunk) first_.resize(chunk + 1, votes_.size());
  first_[chunk] = votes_.size();
  votes_.insert(votes_.end(), votes.begin(), votes.end());
}

void OrientationStitcher::relate(std::size_t chunk_a, std::uint32_t a, std::size_t chunk_b,
                                 std::uint32_t b, bool agree) {
  std::size_t u = first_[chunk_a] + a, v = first_[chunk_b] + b;
  if (u == v) return;
  if (u > v) std::swap(u, v);
  edges_[{u, v}] += agree ? 1 : -1;
}

void OrientationStitcher::solve() {
  const std::size_t n = votes_.size();
  std::vector<std::vector<std::pair<std::size_t, bool>>> next(n);  // (piece, opposite)
  for (const auto& [edge, weight] : edges_) {
    if (weight == 0) continue;  // as many points say one thing as the other: no link
    next[edge.first].push_back({edge.second, weight < 0});
    next[edge.second].push_back({edge.first, weight < 0});
  }
  flip_.assign(n, 0);
  std::vector<std::uint8_t> seen(n, 0);
  std::vector<std::size_t> members;
  std::deque<std::size_t> queue;
  for (std::size_t start = 0; start < n; ++start) {
    if (seen[start]) continue;
    // Relative flips by breadth-first search from the lowest piece, then the surface's vote.
    members.clear();
    seen[start] = 1;
    queue.push_back(start);
    while (!queue.empty()) {
      const std::size_t u = queue.front();
      queue.pop_front();
      members.push_back(u);
      for (const auto& [v, opposite] : next[u]) {
        if (seen[v]) continue;
        seen[v] = 1;
        flip_[v] = flip_[u] ^ (opposite ? 1 : 0);
        queue.push_back(v);
      }
    }
    double vote = 0;
    for (const std::size_t u : members) vote += flip_[u] ? -votes_[u] : votes_[u];
    if (vote < 0) {
      for (const std::size_t u : members) flip_[u] ^= 1;
    }
    if (members.size() > 1) ++stitched_;
  }
}

}  // namespace pointillist::chunking
