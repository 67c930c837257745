// Text point cloud reader (XYZ, PTS, CSV, TXT). The lines before the first point line are read
// on the calling thread: they fix the delimiter, the column layout and the origin. The body is
// then parsed like an ascii PLY body: with a pool, cut into pieces at line starts, a first
// parallel pass counts each piece's point lines so every piece knows the index of its first
// point, and a second pass parses the pieces into the shared arrays.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>

#include "pointillist/core/file_bytes.hpp"
#include "xyz_lines.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/xyz.hpp"

namespace pointillist {

using namespace io_detail;
using namespace xyz_detail;

PointSet read_xyz(const std::string& path, Progress& progress, const XyzReadOptions& options) {
  // Check the option before touching the file, so a typo is reported as such.
  if (!options.columns.empty())
    layout_from_names(split_names(options.columns), true, options.columns);
  FileBytes raw = FileBytes::map(path);
  const std::uint64_t file_size = raw.file_size();
  ReadProgress read_progress(progress, file_size);
  FileBytes bytes = inflate_if_gzipped(std::move(raw), path, read_progress);
  const bool gzip = bytes.was_compressed();
  const std::string_view data = bytes.view();
  if (data.empty()) throw FormatError(path + ": line 1: file is empty (expected lines x y z ...)");

  Preamble pre = read_preamble(path, data, options);
  const char* begin = pre.body;
  const char* end = data.data() + data.size();
  read_progress.begin_part(file_size - (gzip ? file_size / 2 : 0),
                           static_cast<std::uint64_t>(end - data.data()));
  read_progress.advance(static_cast<std::uint64_t>(begin - data.data()));
  const LineParser parser(path, data, pre.layout, pre.delimiter, pre.first_line,
                          pre.first_count);

  // The origin comes from the first point.
  LineValues first;
  GroupStats unused[2];
  {
    const char* le = line_end(begin, end);
    parser.parse(skip_blanks(begin, le), le, first, unused);
  }
  const std::array<double, 3> origin = text_origin(first.xyz);

  // Pieces start at line starts, so each holds whole lines.
  constexpr std::size_t kMinPieceBytes = 1 << 20;
  const auto bytes_left = static_cast<std::size_t>(end - begin);
  std::size_t piece_count = 1;
  if (options.pool && options.pool->thread_count() >= 2 && bytes_left >= 2 * kMinPieceBytes)
    piece_count = std::min<std::size_t>(options.pool->thread_count() * 4,
                                        bytes_left / kMinPieceBytes);
  std::vector<const char*> cuts{begin};
  for (std::size_t k = 1; k < piece_count; ++k) {
    const char* guess = std::max(begin + bytes_left * k / piece_count, cuts.back());
    const char* nl = line_end(guess, end);
    cuts.push_back(nl < end ? nl + 1 : end);
  }
  cuts.push_back(end);
  const auto run = [&](const std::function<void(std::size_t)>& fn) {
    if (piece_count == 1)
      fn(0);
    else
      options.pool->run(piece_count, fn);
  };

  std::vector<std::uint64_t> firsts(piece_count + 1, 0);
  run([&](std::size_t k) { firsts[k + 1] = count_point_lines(cuts[k], cuts[k + 1]); });
  for (std::size_t k = 0; k < piece_count; ++k) firsts[k + 1] += firsts[k];
  const auto n = static_cast<std::size_t>(firsts[piece_count]);

  PointSet points;
  std::vector<Vec3f> group_values[2];
  const Group kinds[2] = {pre.layout.a, pre.layout.b};
  points.positions.resize(n);
  Outputs out;
  out.positions = points.positions.data();
  for (int g = 0; g < 2; ++g) {
    if (kinds[g] == Group::None) continue;
    group_values[g].resize(n);
    out.group[g] = group_values[g].data();
  }

  std::vector<std::array<GroupStats, 2>> piece_stats(piece_count);
  run([&](std::size_t k) {
    std::size_t i = static_cast<std::size_t>(firsts[k]);
    GroupStats* stats = piece_stats[k].data();
    const char* reported = cuts[k];
    for (const char* p = cuts[k]; p < cuts[k + 1];) {
      const char* le = line_end(p, cuts[k + 1]);
      const char* t = skip_blanks(p, le);
      p = le + 1;
      if (!is_point_line(t, le)) continue;
      LineValues v;
      parser.parse(t, le, v, stats);
      parser.check_fits_float(t, v.xyz, origin);
      out.positions[i] = {static_cast<float>(v.xyz[0] - origin[0]),
                          static_cast<float>(v.xyz[1] - origin[1]),
                          static_cast<float>(v.xyz[2] - origin[2])};
      for (int g = 0; g < 2; ++g)
        if (out.group[g]) out.group[g][i] = {v.group[g][0], v.group[g][1], v.group[g][2]};
      if ((++i & 0xffff) == 0) {
        read_progress.advance(static_cast<std::uint64_t>(std::min(p, cuts[k + 1]) - reported));
        reported = std::min(p, cuts[k + 1]);
      }
    }
    read_progress.advance(static_cast<std::uint64_t>(cuts[k + 1] - reported));
  });

  GroupStats stats[2];
  for (const auto& s : piece_stats) {
    stats[0].merge(s[0]);
    stats[1].merge(s[1]);
  }
  Layout& layout = pre.layout;
  resolve_groups(layout, stats);
  for (int g = 0; g < 2; ++g) {
    const Group kind = g ? layout.b : layout.a;
    store_group(kind, stats[g], group_values[g], points, options.read_colors);
    if (kind == Group::Colors && !options.read_colors) {
      for (Slot& s : layout.slots)
        if (s >= (g ? kB0 : kA0) && s < (g ? kB0 + 3 : kA0 + 3)) s = kSkip;
    }
  }
  points.comments.push_back("columns: " + columns_text(layout, pre.first_count) + " (from " +
                            pre.layout_source + ")");
  points.origin = origin;
  read_progress.finish();
  return points;
}

}  // namespace pointillist
