// What every libFuzzer harness shares: the input as a file a reader can open by path, the
// errors a reader may throw on bad input (everything else is a finding), the promises a
// PointSet read from an untrusted file keeps, and a small render of a model.
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <span>
#include <string>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/pipeline/model.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/render/sequence.hpp"

namespace pointillist::fuzz {

// A broken promise that is not a crash by itself (a wrong-sized array, an error message without
// the file's name): report it like one, so libFuzzer keeps the input.
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "pointillist fuzz finding: %s\n", what.c_str());
  std::abort();
}

// The fuzz input as a file: one memfd per process, rewritten for each input and opened by the
// readers as /proc/self/fd/N, so a crash or a timeout leaves no temporary file behind and no
// input touches the disk.
class InputFile {
 public:
  InputFile() : fd_(memfd_create("pointillist-fuzz", MFD_CLOEXEC)) {
    if (fd_ < 0) finding("memfd_create failed");
    path_ = "/proc/self/fd/" + std::to_string(fd_);
  }
  ~InputFile() { close(fd_); }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  // Replaces the file's contents with `data` and returns its path.
  const std::string& write(const std::uint8_t* data, std::size_t size) {
    if (ftruncate(fd_, 0) != 0) finding("ftruncate failed");
    std::size_t done = 0;
    while (done < size) {
      const ssize_t n = pwrite(fd_, data + done, size - done, static_cast<off_t>(done));
      if (n <= 0) finding("pwrite failed");
      done += static_cast<std::size_t>(n);
    }
    return path_;
  }

 private:
  int fd_;
  std::string path_;
};

// Runs `read` (which reads `path`), catching what a reader may throw for bad input: FormatError
// (whose message must name the file), IoError, OptionError, and std::bad_alloc when a reader
// legitimately refuses. Anything else escapes to libFuzzer as a finding.
template <class Read>
void expect_reader_errors(const std::string& path, Read&& read) {
  try {
    read();
  } catch (const FormatError& e) {
    if (std::string(e.what()).find(path) == std::string::npos)
      finding(std::string("FormatError without the file's name: ") + e.what());
  } catch (const IoError&) {
  } catch (const OptionError&) {
  } catch (const std::bad_alloc&) {
  }
}

// The promises of a point set returned by a reader (io/*.hpp): at least one point; every
// attribute array empty or one entry a point; finite positions, normals and radii; triangle
// corners index existing points.
inline void check_point_set(const PointSet& p) {
  const std::size_t n = p.size();
  if (n == 0) finding("reader returned no points");
  if (!p.normals.empty() && p.normals.size() != n) finding("normals of the wrong length");
  if (!p.colors.empty() && p.colors.size() != n) finding("colors of the wrong length");
  if (!p.radii.empty() && p.radii.size() != n) finding("radii of the wrong length");
  const auto finite = [](Vec3f v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (!finite(p.positions[i])) finding("non-finite position " + std::to_string(i));
    if (!p.normals.empty() && !finite(p.normals[i]))
      finding("non-finite normal " + std::to_string(i));
    if (!p.radii.empty() && !std::isfinite(p.radii[i]))
      finding("non-finite radius " + std::to_string(i));
  }
  for (const auto& t : p.triangles)
    for (std::uint32_t v : t)
      if (v >= n) finding("triangle corner " + std::to_string(v) + " out of range");
}

// Draws `model` once at 32x24 from its orbit camera, loading the pages the view needs first when
// it is paged (render_settled), on `pool`.
inline void render_small(const Model& model, ThreadPool& pool) {
  const SphereTreeView& tree = model.tree();
  const Camera camera = orbit_camera(tree.view_sphere, {.width = 32, .height = 24, .up = tree.up});
  Renderer renderer;
  const SceneInstance instance{.model = &model.renderable()};
  Frame frame;
  render_settled(renderer, std::span(&instance, 1), camera, {}, {}, pool, frame);
}

}  // namespace pointillist::fuzz
