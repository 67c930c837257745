// Sharp features of a model converted in chunks, found part by part (feature_parts.hpp) on the
// written file's decoded leaves, so that they are those of the conversion in one piece:
//   1. the pages are walked once for their tree: each page's child pages in the order of their
//      roots, a depth-first rank, and the depth of its first level. A leaf's key, (its depth, its
//      page's rank, its record), orders the leaves as the file's breadth-first node order does
//      (at one depth, nodes lie in the order of their paths from the root, which the depth-first
//      order of the pages keeps), which is the order compute_features sees them in one piece;
//   2. each subtree below the top page is a part; its halo is found by walking the pages from
//      the top, skipping every page whose root spheres lie too far from the part's box (a leaf's
//      disc lies inside each enclosing sphere);
//   3. the spread pass: each part's own rows, with a halo one radius wide, add to the histogram
//      that decides the threshold, and give the largest drawn radius of the halo's sharp
//      neighbours of own splats;
//   4. the feature pass: each part with the full halo (feature_halo_reach with that radius), its
//      per-leaf results kept in the work folder; then the surfaces are joined;
//   5. the section: each page's block, pages of a part bottom-up so that an interior node's
//      surface id comes from its children's, the top page last; then the head, and the blocks
//      copied after it in page order.
#include "chunk_features.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "chunk_messages.hpp"
#include "chunk_stages.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/features/feature_parts.hpp"

namespace pointillist::chunking {
namespace {

constexpr std::uint32_t kMaxDepth = 63;
constexpr std::uint32_t kMaxRank = (1u << 26) - 1;

std::uint64_t leaf_key(std::uint32_t depth, std::uint32_t rank, std::uint32_t record) {
  return std::uint64_t{depth} << 58 | std::uint64_t{rank} << 32 | record;
}

// The page tree of a file and its parts.
struct Pages {
  const PtlV2File* file = nullptr;
  std::vector<std::vector<std::uint32_t>> children;  // child pages, in the order of their roots
  std::vector<std::uint32_t> rank, first_depth, part;
  std::vector<std::vector<std::uint32_t>> part_pages;  // part 0: the top page; then subtrees

  explicit Pages(const PtlV2File& f) : file(&f) {
    const std::uint32_t count = f.page_count();
    children.resize(count);
    for (std::uint32_t c = 1; c < count; ++c) children[f.page_info(c).parent_page].push_back(c);
    for (auto& list : children) {
      std::sort(list.begin(), list.end(), [&](std::uint32_t a, std::uint32_t b) {
        return f.page_info(a).first_root < f.page_info(b).first_root;
      });
    }
    rank.assign(count, 0);
    first_depth.assign(count, 0);
    part.assign(count, 0);
    part_pages.assign(1, {0});
    std::vector<std::uint32_t> stack{0};
    std::uint32_t next = 0;
    while (!stack.empty()) {
      const std::uint32_t p = stack.back();
      stack.pop_back();
      rank[p] = next++;
      if (p != 0 && f.page_info(p).parent_page == 0) {
        part[p] = static_cast<std::uint32_t>(part_pages.size());
        part_pages.push_back({});
      } else if (p != 0) {
        part[p] = part[f.page_info(p).parent_page];
      }
      if (p != 0) part_pages[part[p]].push_back(p);
      const std::uint32_t below = first_depth[p] + f.page_info(p).level_count;
      for (auto it = children[p].rbegin(); it != children[p].rend(); ++it) {
        first_depth[*it] = below;
        stack.push_back(*it);
      }
    }
    if (count - 1 > kMaxRank) {
      throw Error(f.path() + ": " + std::to_string(count) +
                  " pages are more than sharp features are found over (2^26)");
    }
  }
};

// The depth of each record of a decoded page below the page's first level.
std::vector<std::uint8_t> record_levels(const PtlV2Page& page) {
  std::vector<std::uint8_t> level(page.nodes.size(), 0);
  std::size_t begin = 0, size = 0;
  for (const std::uint8_t c : page.root_child_counts) size += c;
  std::uint8_t current = 0;
  while (begin < page.nodes.size() && size > 0) {
    const std::size_t end = std::min(page.nodes.size(), begin + size);
    std::size_t next = 0;
    for (std::size_t r = begin; r < end; ++r) {
      level[r] = current;
      if (r < page.last_level_begin) next += page.nodes[r].child_count;
    }
    begin = end, size = next, ++current;
  }
  return level;
}

struct Leaf {
  std::uint64_t key;
  Vec3f center, normal;
  float radius;  // decoded, not drawn
};

// Calls fn(record, key, node) for each leaf of page p.
template <class Fn>
void for_each_leaf(const Pages& pages, std::uint32_t p, const PtlV2Page& page, Fn&& fn) {
  const std::vector<std::uint8_t> level = record_levels(page);
  for (std::uint32_t r = 0; r < page.nodes.size(); ++r) {
    if (page.nodes[r].child_count != 0) continue;
    const std::uint32_t depth = pages.first_depth[p] + level[r];
    if (depth > kMaxDepth) {
      throw Error(pages.file->path() + ": a leaf " + std::to_string(depth) +
                  " levels deep is deeper than sharp features are found (63)");
    }
    fn(r, leaf_key(depth, pages.rank[p], r), page.nodes[r]);
  }
}

// The keys of part `part`'s own leaves, ascending.
std::vector<std::uint64_t> own_keys(const Pages& pages, std::uint32_t part) {
  std::vector<std::uint64_t> keys;
  PtlV2Page page;
  for (const std::uint32_t p : pages.part_pages[part]) {
    pages.file->decode_page(p, page);
    for_each_leaf(pages, p, page,
                  [&](std::uint32_t, std::uint64_t key, const SphereNode&) { keys.push_back(key); });
  }
  std::sort(keys.begin(), keys.end());
  return keys;
}

float box_distance(const Aabb& box, Vec3f c) { return std::sqrt(box.distance_squared(c)); }

// Calls fn(record, r) for each root r of child page `info` among the records of its parent
// `page`: consecutive interior records from info.first_root (as PtlV2File::decode_all links
// them). Returns how many it found (fewer than info.root_count: a damaged table).
template <class Fn>
std::uint32_t for_each_root(const PtlV2Page& page, const PtlV2PageInfo& info, Fn&& fn) {
  std::uint32_t found = 0;
  for (std::uint32_t v = info.first_root; v < page.nodes.size() && found < info.root_count; ++v) {
    if (page.nodes[v].child_count != 0) fn(v, found++);
  }
  return found;
}

// A part's own leaves and the halo around them, in key order.
struct PartSplats {
  std::vector<Vec3f> centers, normals;
  std::vector<float> radii;
  std::vector<std::uint64_t> keys;
  std::vector<std::uint8_t> owned;
  std::uint64_t own_count = 0;
  float r_own = 0;  // largest drawn radius of the own leaves
  FeaturePartInput input() const { return {centers, normals, radii, keys, owned}; }
};

// `reach(r_own)` is how far beyond the own box (plus a leaf's own drawn radius) the halo reaches.
template <class Reach>
PartSplats gather_part(const Pages& pages, std::uint32_t part, float scale, Reach&& reach) {
  const PtlV2File& f = *pages.file;
  std::vector<Leaf> own, halo;
  PtlV2Page page;
  for (const std::uint32_t p : pages.part_pages[part]) {
    f.decode_page(p, page);
    for_each_leaf(pages, p, page, [&](std::uint32_t, std::uint64_t key, const SphereNode& n) {
      own.push_back({key, n.center, n.normal, n.radius});
    });
  }
  PartSplats out;
  if (own.empty()) return out;
  Aabb box;
  for (const Leaf& l : own) {
    box.extend(l.center);
    out.r_own = std::max(out.r_own, l.radius * scale);
  }
  // Widened for rounding: more halo never changes the result.
  const float limit = reach(out.r_own) * 1.001f + 1e-30f;
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const std::uint32_t q = stack.back();
    stack.pop_back();
    f.decode_page(q, page);
    if (pages.part[q] != part) {
      for_each_leaf(pages, q, page, [&](std::uint32_t, std::uint64_t key, const SphereNode& n) {
        if (box_distance(box, n.center) < limit + scale * n.radius * 1.001f) {
          halo.push_back({key, n.center, n.normal, n.radius});
        }
      });
    }
    // A child page whose every root sphere (C, R) lies at dist(C, box) - scale R >= limit from
    // the box holds no leaf of the halo: dist(c, box) - scale r >= dist(C, box) - scale R.
    for (const std::uint32_t c : pages.children[q]) {
      if (pages.part[c] == part) continue;
      const PtlV2PageInfo& info = f.page_info(c);
      bool near = false;
      const std::uint32_t found = for_each_root(page, info, [&](std::uint32_t v, std::uint32_t) {
        const SphereNode& root = page.nodes[v];
        near = near || box_distance(box, root.center) - scale * root.radius * 1.001f < limit;
      });
      if (near || found < info.root_count) stack.push_back(c);
    }
  }
  std::sort(own.begin(), own.end(), [](const Leaf& a, const Leaf& b) { return a.key < b.key; });
  std::sort(halo.begin(), halo.end(), [](const Leaf& a, const Leaf& b) { return a.key < b.key; });
  std::size_t i = 0, j = 0;
  while (i < own.size() || j < halo.size()) {
    const bool take_own = j == halo.size() || (i < own.size() && own[i].key < halo[j].key);
    const Leaf& l = take_own ? own[i++] : halo[j++];
    out.centers.push_back(l.center);
    out.normals.push_back(l.normal);
    out.radii.push_back(l.radius);
    out.keys.push_back(l.key);
    out.owned.push_back(take_own ? 1 : 0);
  }
  out.own_count = own.size();
  return out;
}

// A part's per-leaf results on disk between the passes.
template <class T>
void put(std::ofstream& s, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  s.write(reinterpret_cast<const char*>(&n), sizeof n);
  s.write(reinterpret_cast<const char*>(v.data()), std::streamsize(n * sizeof(T)));
}
template <class T>
void get(std::ifstream& s, std::vector<T>& v, const std::string& path) {
  std::uint64_t n = 0;
  s.read(reinterpret_cast<char*>(&n), sizeof n);
  if (!s || n > (std::uint64_t{1} << 40) / sizeof(T)) {
    throw IoError(path + ": cannot read back the sharp features kept there; is the disk full?");
  }
  v.resize(n);
  s.read(reinterpret_cast<char*>(v.data()), std::streamsize(n * sizeof(T)));
  if (!s) throw IoError(path + ": cannot read back the sharp features kept there");
}

void save_part(const std::string& path, const FeaturePart& f) {
  std::ofstream s(path, std::ios::binary | std::ios::trunc);
  put(s, f.clip_mode);
  put(s, f.clip_offset);
  put(s, f.clip_planes);
  put(s, f.component);
  s.flush();
  if (!s) throw IoError(path + ": cannot keep sharp features there; is the disk full?");
}

void load_part(const std::string& path, FeaturePart& f) {
  std::ifstream s(path, std::ios::binary);
  get(s, f.clip_mode, path);
  get(s, f.clip_offset, path);
  get(s, f.clip_planes, path);
  get(s, f.component, path);
}

}  // namespace

void add_features_in_parts(ChunkJobs& jobs, PtlV2PartWriter* writer, const WorkFolder& folder,
                           const std::string& metadata, const FeatureOptions& options,
                           ThreadPool& pool, Progress& progress,
                           std::vector<std::string>& warnings) {
  const bool root = jobs.rank() == 0;
  // Every rank reads the file rank 0 wrote (synced to disk first, for a shared file system).
  std::string path;
  {
    MessageWriter w;
    step(jobs, [&] {
      validate_feature_options(options);
      if (!root) return;
      writer->sync();
      const std::string& temp = writer->temp_path();
      w.put_vector(std::vector<char>(temp.begin(), temp.end()));
    });
    jobs.broadcast(w.bytes());
    MessageReader m(w.bytes());
    const std::vector<char> chars = m.get_vector<char>();
    path.assign(chars.begin(), chars.end());
  }
  std::optional<TreeFeatures> summary;
  std::vector<PtlV2FeatureBlockEntry> entries;
  std::vector<std::uint64_t> block_at;
  const std::string blocks_path = folder.file("feature-blocks");
  std::unique_ptr<PtlV2File> file;
  std::optional<Pages> pages_holder;
  std::size_t parts = 0;
  std::vector<std::size_t> mine;  // this rank's parts
  step(jobs, [&] {
    file = PtlV2File::open(path);
    pages_holder.emplace(*file);
    parts = pages_holder->part_pages.size();
    for (std::size_t k = std::size_t(jobs.rank()); k < parts; k += std::size_t(jobs.size())) {
      mine.push_back(k);
    }
  });
  const Pages& pages = *pages_holder;
  const float scale = options.radius_scale;
  // One phase for the passes: each leaf twice, then each page (rank 0's parts and the pages).
  std::optional<ProgressPhase> phase(std::in_place, progress, "features",
                                     2 * file->leaf_count() + file->page_count());

  // Pass 1: the spread (rank 0 decides the threshold), and for each part the largest drawn
  // radius among the halo splats that are sharp neighbours of its own splats at the given
  // threshold (adaptation only lowers it): only those need their own rows in pass 2, so they
  // bound its halo, and an outlier's huge disc widens only the halos it reaches.
  SpreadHistogram spread;
  std::vector<float> r_sharp(parts, 0.0f);
  FeatureStats spread_stats;
  FeatureOptions decided = options;
  {
    MessageWriter w;
    step(jobs, [&] {
      for (const std::size_t k : mine) {
        const PartSplats s = gather_part(pages, std::uint32_t(k), scale, [](float r) { return r; });
        if (s.own_count == 0) continue;
        const FeaturePartSpread part = feature_part_spread(s.input(), options, pool);
        spread.add(part.histogram);
        r_sharp[k] = part.r_sharp;
        phase->advance(s.own_count);
      }
      w.put_vector(spread.slot);
      w.put_vector(spread.fine);
    });
    const std::vector<std::vector<char>> all = jobs.gather(w.bytes());
    MessageWriter decision;
    step(jobs, [&] {
      if (!root) return;
      for (std::size_t r = 1; r < all.size(); ++r) {
        MessageReader m(all[r]);
        SpreadHistogram theirs;
        theirs.slot = m.get_vector<std::uint32_t>();
        theirs.fine = m.get_vector<std::array<std::uint64_t, 256>>();
        for (const std::uint32_t slot : theirs.slot) {
          if (slot > theirs.fine.size()) throw Error("chunked conversion: a rank sent a bad histogram");
        }
        spread.add(theirs);
      }
      decided = adapt_sharp_threshold(options, spread, spread_stats);
      decision.put(decided);
      decision.put(spread_stats);
    });
    jobs.broadcast(decision.bytes());
    MessageReader m(decision.bytes());
    decided = m.get<FeatureOptions>();
    spread_stats = m.get<FeatureStats>();
  }

  // Pass 2: each part's features, kept on disk; rank 0 learns what the join needs.
  std::vector<FeaturePart> found(parts);
  std::vector<std::uint8_t> has(parts, 0);
  {
    MessageWriter w;
    step(jobs, [&] {
      for (const std::size_t k : mine) {
        const PartSplats s = gather_part(
            pages, std::uint32_t(k), scale,
            [&](float r_own) { return feature_halo_reach(r_own, std::max(r_own, r_sharp[k])); });
        if (s.own_count == 0) continue;
        FeaturePart f = compute_feature_part(s.input(), decided, pool);
        save_part(folder.file("features" + std::to_string(k)), f);
        w.put(std::uint64_t(k));
        w.put_vector(f.component_first);
        w.put_vector(f.component_size);
        w.put_vector(f.links);
        w.put(f.row_entries);
        w.put(f.stats);
        // Only what the join needs stays in memory.
        f.clip_mode = {}, f.clip_offset = {}, f.clip_planes = {}, f.component = {};
        found[k] = std::move(f);
        has[k] = 1;
        phase->advance(s.own_count);
      }
    });
    const std::vector<std::vector<char>> all = jobs.gather(w.bytes());
    step(jobs, [&] {
      if (!root) return;
      for (std::size_t r = 1; r < all.size(); ++r) {
        MessageReader m(all[r]);
        while (!m.done()) {
          const auto k = std::size_t(m.get<std::uint64_t>());
          if (k >= parts) throw Error("chunked conversion: a rank sent a part out of range");
          FeaturePart& f = found[k];
          f.component_first = m.get_vector<std::uint64_t>();
          f.component_size = m.get_vector<std::uint64_t>();
          f.links = m.get_vector<FeatureLink>();
          f.row_entries = m.get<std::uint64_t>();
          f.stats = m.get<FeatureStats>();
          has[k] = 1;
        }
      }
    });
  }
  step(jobs, [&] {
    if (!root) return;
    std::vector<const FeaturePart*> listed;
    std::vector<std::size_t> listed_part;
    for (std::size_t k = 0; k < parts; ++k) {
      if (!has[k]) continue;
      listed.push_back(&found[k]);
      listed_part.push_back(k);
    }
    // Each link goes to the part that owns its splat (the key's page rank names the page), where
    // that splat's surface is looked up.
    std::vector<std::uint32_t> page_of_rank(file->page_count());
    for (std::uint32_t p = 0; p < file->page_count(); ++p) page_of_rank[pages.rank[p]] = p;
    std::vector<std::uint32_t> listed_index(parts, 0);
    for (std::size_t l = 0; l < listed.size(); ++l) listed_index[listed_part[l]] = std::uint32_t(l);
    std::vector<std::vector<std::uint32_t>> incoming_from(parts);
    std::vector<std::vector<FeatureLink>> incoming(parts);
    for (std::size_t l = 0; l < listed.size(); ++l) {
      FeaturePart& f = found[listed_part[l]];
      for (const FeatureLink& link : f.links) {
        const auto rank = std::uint32_t((link.other >> 32) & kMaxRank);
        if (rank >= page_of_rank.size()) throw Error(path + ": a link to a page out of range");
        const std::uint32_t owner = pages.part[page_of_rank[rank]];
        incoming_from[owner].push_back(std::uint32_t(l));
        incoming[owner].push_back(link);
      }
      f.links = {};
    }
    std::vector<std::pair<PartSurface, PartSurface>> joined;
    for (std::size_t k = 0; k < parts; ++k) {
      if (incoming[k].empty()) continue;
      if (!has[k]) throw Error(path + ": a link to part " + std::to_string(k) + ", which has no leaves");
      FeaturePart results;
      load_part(folder.file("features" + std::to_string(k)), results);
      const std::vector<std::uint64_t> keys = own_keys(pages, std::uint32_t(k));
      const std::vector<std::uint32_t>& from = incoming_from[k];
      for (std::size_t a = 0, b = 0; a < from.size(); a = b) {
        while (b < from.size() && from[b] == from[a]) ++b;
        resolve_feature_links(from[a], std::span(incoming[k]).subspan(a, b - a), listed_index[k],
                              keys, results.component, joined);
      }
      incoming[k] = {}, incoming_from[k] = {};
    }
    const FeatureJoin join = join_feature_parts(listed, file->leaf_count(), joined);
    summary.emplace();
    summary->options = decided;
    summary->stats = joined_feature_stats(listed, join, spread_stats);
    summary->surface_count = static_cast<std::uint32_t>(join.segments);
    std::vector<const std::vector<std::uint32_t>*> ids(parts, nullptr);
    for (std::size_t l = 0; l < listed.size(); ++l) ids[listed_part[l]] = &join.surface[l];

    // The blocks: each part's pages bottom-up (children before parents: reverse depth-first
    // order), the top page last; written to a work file as they come.
    std::ofstream blocks(blocks_path, std::ios::binary | std::ios::trunc);
    entries.assign(file->page_count(), {});
    block_at.assign(file->page_count(), 0);
    std::uint64_t written = 0;
    // Per page: the common surface id of each root's children (its subtree's id).
    std::vector<std::vector<std::uint32_t>> root_ids(file->page_count());
    PtlV2Page page;
    TreeFeatures records;
    const auto encode_part = [&](std::size_t k) {
      FeaturePart results;
      std::vector<std::uint64_t> own_keys;
      const bool has_own = ids[k] != nullptr;
      std::vector<std::uint32_t> list = pages.part_pages[k];
      if (has_own) {
        load_part(folder.file("features" + std::to_string(k)), results);
        std::filesystem::remove(folder.file("features" + std::to_string(k)));
        own_keys = ::pointillist::chunking::own_keys(pages, std::uint32_t(k));
        if (own_keys.size() != results.component.size()) {
          throw Error(path + ": the sharp features of part " + std::to_string(k) +
                      " do not match its leaves");
        }
      }
      std::sort(list.begin(), list.end(),
                [&](std::uint32_t a, std::uint32_t b) { return pages.rank[a] > pages.rank[b]; });
      for (const std::uint32_t p : list) {
        file->decode_page(p, page);
        const std::size_t n = page.nodes.size();
        records.surface.assign(n, kMixedSurface);
        records.clip_mode.assign(n, ClipMode::None);
        records.clip_offset.assign(n + 1, 0);
        records.clip_planes.clear();
        std::vector<std::int64_t> leaf_index(n, -1);
        for_each_leaf(pages, p, page, [&](std::uint32_t r, std::uint64_t key, const SphereNode&) {
          const auto it = std::lower_bound(own_keys.begin(), own_keys.end(), key);
          leaf_index[r] = it - own_keys.begin();
          records.surface[r] = (*ids[k])[results.component[std::size_t(leaf_index[r])]];
        });
        // Interior records of the last level: their children are a child page's roots'.
        for (const std::uint32_t c : pages.children[p]) {
          for_each_root(page, file->page_info(c), [&](std::uint32_t v, std::uint32_t r) {
            records.surface[v] = root_ids[c].at(r);
          });
        }
        // Interior records with children in the page, last first (children follow parents).
        for (std::size_t r = std::min<std::size_t>(page.last_level_begin, n); r-- > 0;) {
          const SphereNode& nd = page.nodes[r];
          if (nd.child_count == 0) continue;
          std::uint32_t id = records.surface[nd.first_child];
          for (std::uint32_t c = 1; c < nd.child_count; ++c) {
            if (records.surface[nd.first_child + c] != id) id = kMixedSurface;
          }
          records.surface[r] = id;
        }
        // The roots' subtree ids, for the parent page.
        std::size_t child = 0;
        for (const std::uint8_t count : page.root_child_counts) {
          std::uint32_t id = count ? records.surface[child] : kMixedSurface;
          for (std::uint32_t c = 1; c < count; ++c) {
            if (records.surface[child + c] != id) id = kMixedSurface;
          }
          root_ids[p].push_back(id);
          child += count;
        }
        for (std::size_t r = 0; r < n; ++r) {
          if (leaf_index[r] >= 0) {
            const auto i = std::size_t(leaf_index[r]);
            records.clip_mode[r] = results.clip_mode[i];
            records.clip_planes.insert(records.clip_planes.end(),
                                       results.clip_planes.begin() + results.clip_offset[i],
                                       results.clip_planes.begin() + results.clip_offset[i + 1]);
          }
          records.clip_offset[r + 1] = static_cast<std::uint32_t>(records.clip_planes.size());
        }
        for (const std::uint32_t c : pages.children[p]) root_ids[c] = {};
        const PtlV2FeatureBlock block = encode_ptl_v2_feature_block(records);
        blocks.write(reinterpret_cast<const char*>(block.bytes.data()),
                     std::streamsize(block.bytes.size()));
        entries[p] = {block.bytes.size(), block.clipped, block.planes};
        block_at[p] = written;
        written += block.bytes.size();
        phase->advance(1);
      }
    };
    for (std::size_t k = 1; k < parts; ++k) encode_part(k);
    encode_part(0);
    blocks.flush();
    if (!blocks) throw IoError(blocks_path + ": cannot write sharp features there; is the disk full?");
    blocks.close();
    phase.reset();

    std::ostringstream meta;
    meta << metadata << "features: sharp threshold " << summary->options.sharp_threshold << ", "
         << summary->stats.clipped << " clipped splats, " << summary->stats.segments
         << " surfaces\n";
    const std::string noisy = noisy_features_warning(summary->stats, summary->options);
    if (!noisy.empty()) warnings.push_back("--features: " + noisy);
    const std::uint64_t leaves = file->leaf_count();
    file.reset();
    writer->commit_with_features(meta.str(), [&](std::uint64_t offset) {
      const std::vector<std::uint8_t> head = encode_ptl_v2_feature_head(*summary, leaves, entries);
      writer->write_at(offset, head.data(), head.size());
      std::uint64_t at = offset + head.size();
      std::ifstream in(blocks_path, std::ios::binary);
      std::vector<char> buffer;
      for (std::size_t p = 0; p < entries.size(); ++p) {
        buffer.resize(entries[p].size);
        in.seekg(std::streamoff(block_at[p]));
        in.read(buffer.data(), std::streamsize(buffer.size()));
        if (!in) throw IoError(blocks_path + ": cannot read back the sharp features kept there");
        writer->write_at(at, buffer.data(), buffer.size());
        at += buffer.size();
      }
      return at - offset;
    });
    std::filesystem::remove(blocks_path);
  });
}

}  // namespace pointillist::chunking
