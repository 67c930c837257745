// Small helpers shared by the subcommands.
#pragma once

#include <span>
#include <string>

#include "pointillist/core/math.hpp"

namespace pointillist::cli {

// "1.23 MB"-style size.
std::string human_bytes(double bytes);

// The extension of `path` (".png", with the dot) in lower case; empty without one.
std::string lowercase_extension(const std::string& path);

// The inputs for a summary line or a window title: the first three (file names only with
// `file_names`), then "and N more".
std::string input_names(std::span<const std::string> inputs, bool file_names = false);

// For batch commands (convert, generate): freed memory stays with the process for reuse
// instead of going back to the system (no mmap for large blocks, no trimming). Memory the
// system hands out is zeroed page by page on first touch, which costs about 3.5 s a GB on
// this kind of virtual machine; a chunked conversion frees and reallocates the same buffers for
// every chunk (measured: 10 M points in chunks 30.6 s -> 23.6 s, system time 10.8 s -> 3.8 s,
// the same peak). The peak resident memory is unchanged; it is simply not given back early.
void keep_freed_memory();

// For `convert` and `generate` (argv[1]), when POINTILLIST_HUGE_PAGES=1: memory in 2 MB pages
// where the system offers them on request (transparent huge pages in "madvise" mode, glibc 2.35
// or later): glibc's allocator only asks for them when started with
// GLIBC_TUNABLES=glibc.malloc.hugetlb=1, so the process starts itself again once with that
// added (same arguments, same process id). Off by default since 2026-11-29: on this virtual
// machine, where the kernel compacts memory to find 2 MB pages for a process that asks (the
// "madvise" defrag mode), they cost more than they saved in most alternating runs of one
// sitting: 7 M mesh to .ptl 1.13x the wall time, to .qs 1.18x, 5 M cloud 1.10x, 1.21x with
// qsplat_make's runs in between; less often they saved (20 M cloud 0.98x, the dragon 0.90x,
// `generate` 0.93x), and in earlier sittings they halved the dragon's time. Nothing happens
// when the tunable is already given, when the kernel's mode is "always" or "never", or when
// starting again fails (the command then simply runs as it is).
void use_huge_pages(char** argv);

// Eight well-separated face colours (spec §4.1), so that any blending of two faces shows:
// `generate --scene T*` colours face label l with kLabelPalette[l % 8], samples and --reference
// image alike, and `compare --labels` reads the labels back from them.
inline constexpr Rgb8 kLabelPalette[8] = {{230, 25, 75},  {60, 180, 75},  {0, 130, 200},
                                          {255, 225, 25}, {245, 130, 48}, {145, 30, 180},
                                          {70, 240, 240}, {240, 50, 230}};

}  // namespace pointillist::cli
