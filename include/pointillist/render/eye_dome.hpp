// Eye-dome lighting (Boucheny 2009), the depth-only shading Potree and CloudCompare use for scans
// without normals or colours: after rasterization, each drawn pixel is darkened by how far its
// eight neighbours stand in front of it, in log depth, so silhouettes, creases and depth steps
// show without any normal.
#pragma once

#include "pointillist/core/thread_pool.hpp"
#include "pointillist/render/render.hpp"

namespace pointillist {

// For each pixel p with finite depth d_p, over its eight neighbours n (one pixel away) that are
// drawn: response = Σ max(0, log2 d_p − log2 d_n) / 8, and p's colour is multiplied by
// exp(−300 · strength · response) (Potree's constants). Pixels where nothing is drawn keep the
// background; a pixel whose neighbours are all at its depth or behind it is unchanged (a plane
// facing the camera stays as it was). Throws OptionError for a negative or non-finite strength;
// 0 changes nothing. The result does not depend on the thread count.
void apply_eye_dome_lighting(Frame& frame, float strength, ThreadPool& pool);

}  // namespace pointillist
