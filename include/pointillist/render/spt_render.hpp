// Rendering a Sequential Point Tree (Dachsbacher, Vogelgsang & Stamminger, SIGGRAPH 2003): level
// of detail chosen by one sequential, branch-free pass over contiguous arrays instead of a
// recursive traversal, feeding the same splat rasterizers as the QSplat traversal.
#pragma once

#include <cstdint>
#include <span>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/sequential_point_tree.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/selection.hpp"
#include "pointillist/render/settings.hpp"
#include "pointillist/render/splat_stream.hpp"

namespace pointillist {

struct SptSelectionStats {
  std::uint64_t splats = 0;           // splats written to the stream
  std::uint64_t entries_scanned = 0;  // list entries tested (the prefixes of the visible ranges)
  std::uint64_t entries_total = 0;    // list length (all ranges)
  std::uint64_t chunks_culled = 0;    // chunks outside the view frustum, skipped whole
  std::uint64_t chunks_total = 0;
  std::uint64_t culled_backface = 0;  // selected entries dropped for facing away
  std::uint64_t culled_frustum = 0;   // selected entries behind the eye or outside the image

  // The counts as a frame reports them: nodes visited = entries scanned, frustum culls = chunks
  // culled + entries dropped outside the view.
  SelectionStats as_selection() const {
    return {.splats = splats, .nodes_visited = entries_scanned,
            .culled_frustum = chunks_culled + culled_frustum, .culled_backface = culled_backface};
  }
  SptSelectionStats& operator+=(const SptSelectionStats& o) {
    splats += o.splats;
    entries_scanned += o.entries_scanned;
    entries_total += o.entries_total;
    chunks_culled += o.chunks_culled;
    chunks_total += o.chunks_total;
    culled_backface += o.culled_backface;
    culled_frustum += o.culled_frustum;
    return *this;
  }
};

struct SptRenderOptions {
  // Allowed error in pixels: a node is drawn while its geometric error e_g projects to at most
  // this many pixels (e_g·f / r ≤ epsilon_px, f the focal length in pixels). 1 draws about as much
  // detail as QSplat's 1-pixel threshold; larger is faster and coarser. > 0.
  float epsilon_px = 1.0f;
  // Skip chunks whose bounding sphere lies outside the view frustum (the extension of the paper
  // this project adds). Turn off only to measure what it saves.
  bool chunk_culling = true;
  // Hybrid point/polygon lists (HybridLod::suppress_below, one per entry): an entry in its
  // interval is left out while (r + ρ)·ε < s, ρ its radius (0 for leaves), where the triangles
  // around its leaves are drawn instead, unless it is seen within about 3° of edge-on. Empty:
  // none left out.
  std::span<const float> suppress_below;
};

// Chooses the entries of `tree` to draw for `camera` and writes them as splats into `stream`:
// for every range (the top list, then each chunk whose bounding sphere meets the frustum), the
// prefix of entries with r_max > r_lo (r_lo: the smallest eye distance to the range's sphere) is
// scanned, and entry i is drawn iff its eye distance r = |c_i − eye| satisfies
// error_i ≤ r·ε < parent_error_i, with ε = epsilon_px / f, and it faces the eye
// (n_i·(eye − c_i) ≥ 0, when settings.backface_culling). A drawn entry becomes a splat of
// diameter d_i·f / z (z its depth along the view direction), shaded as the QSplat traversal
// shades, and is dropped when z ≤ 0 or it lies entirely outside the image. Stream order: ranges
// in list order, entries in list order: the same for any thread count. Throws OptionError for a
// non-positive or non-finite epsilon_px.
void select_splats_spt(const SequentialPointTree& tree, const CameraFrame& camera,
                       const RenderSettings& settings, const SptRenderOptions& options,
                       ThreadPool& pool, SplatStream& stream, SptSelectionStats& stats);

// select_splats_spt, then rasterize_splats into `frame` (as render() does for a SphereTree).
// frame.stats: splats; nodes_visited = entries scanned; culled_frustum = chunks culled + entries
// dropped outside the view; culled_backface as above; times as render(). `stats`, when given,
// receives the selection details.
void render_spt(const SequentialPointTree& tree, const Camera& camera,
                const RenderSettings& settings, const SptRenderOptions& options, ThreadPool& pool,
                Frame& frame, SptSelectionStats* stats = nullptr);

}  // namespace pointillist
