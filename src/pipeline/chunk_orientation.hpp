// Normal orientation across chunks (private to pipeline). Each chunk orients the connected
// components of its own neighbour graph (chunk and halo) on its own: its "pieces". A surface that
// crosses chunks is cut into pieces of several chunks, which share the halo points; the stitcher
// joins pieces through the points they share (agreeing or opposite normals), then flips every
// joined surface as a whole by the vote orientation takes in one piece: the sum over its points of
// n·(p − centroid), positive = away from the centroid (prep/normal_orientation.cpp).
#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace pointillist::chunking {

class OrientationStitcher {
 public:
  // Chunk `chunk`'s pieces and each piece's vote over the chunk's own points (not its halo).
  // Chunks are added in order 0, 1, 2, ...
  void add_chunk(std::size_t chunk, std::vector<double> votes);
  // A point held by piece `a` of chunk `chunk_a` and piece `b` of chunk `chunk_b`, whose two
  // normals agree (dot >= 0) or not.
  void relate(std::size_t chunk_a, std::uint32_t a, std::size_t chunk_b, std::uint32_t b,
              bool agree);
  // Decides which pieces flip (after every chunk and relation is in).
  void solve();
  bool flipped(std::size_t chunk, std::uint32_t piece) const {
    return flip_[first_[chunk] + piece] != 0;
  }
  std::size_t piece_count() const { return votes_.size(); }
  // Joined surfaces that span more than one piece, after solve().
  std::size_t stitched_surfaces() const { return stitched_; }

 private:
  std::vector<std::size_t> first_;  // first piece of each chunk
  std::vector<double> votes_;
  std::map<std::pair<std::size_t, std::size_t>, std::int64_t> edges_;  // +1 agree, -1 opposite
  std::vector<std::uint8_t> flip_;
  std::size_t stitched_ = 0;
};

}  // namespace pointillist::chunking
