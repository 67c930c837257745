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
#include <cstring>
#include <memory>
#include <new>
#include <span>
#include <string>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/point_stream.hpp"
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
  ~InputFile() {
    if (!named_.empty()) unlink(named_.c_str());
    close(fd_);
  }
  // The same file under a name ending in `extension` (a symbolic link in the temporary folder,
  // removed when the harness exits normally), for readers that go by a file's extension
  // (open_point_stream).
  const std::string& named(const std::string& extension) {
    if (named_.empty()) {
      named_ = "/tmp/pointillist-fuzz-" + std::to_string(getpid()) + extension;
      unlink(named_.c_str());
      if (symlink(path_.c_str(), named_.c_str()) != 0) finding("symlink failed");
    }
    return named_;
  }
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
  std::string named_;
};

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

// Every point of `stream`, read `batch` at a time: positions and colours.
inline PointSet drain_stream(PointStream& stream, std::size_t batch) {
  PointSet all, part;
  stream.rewind();
  while (const std::size_t n = stream.read(part, batch)) {
    if (part.size() != n) finding("a stream batch of the wrong size");
    all.positions.insert(all.positions.end(), part.positions.begin(), part.positions.end());
    all.colors.insert(all.colors.end(), part.colors.begin(), part.colors.end());
  }
  return all;
}

// Differential check of a streamed reader: when the whole-file reader read `whole` from `path`,
// its stream must open and give the same positions and colours, bit for bit.
inline void expect_stream_matches(const std::string& path, const PointSet& whole) {
  std::unique_ptr<PointStream> stream;
  try {
    stream = open_point_stream(path);
  } catch (const Error& e) {
    finding(std::string("the stream refused what the whole reader read: ") + e.what());
  }
  if (stream->info().point_count != whole.size()) finding("the stream's point count differs");
  if (stream->info().is_mesh != whole.is_mesh()) finding("the stream's mesh flag differs");
  if (stream->info().origin != whole.origin) finding("the stream's origin differs");
  const PointSet streamed = drain_stream(*stream, 3);
  const auto same = [](const auto& a, const auto& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
  };
  if (!same(streamed.positions, whole.positions)) finding("the stream's positions differ");
  if (!same(streamed.colors, whole.colors)) finding("the stream's colours differ");
}

// A text reader's harness: `read(path)` on the input must fail only as readers may, keep the
// PointSet's promises, and when it reads, the stream of the same file (named with `extension`,
// which selects the reader) must give the same points.
template <class Read>
void check_reader_and_stream(InputFile& file, const std::uint8_t* data, std::size_t size,
                             const std::string& extension, Read&& read) {
  const std::string& path = file.write(data, size);
  PointSet whole;
  bool done = false;
  expect_reader_errors(path, [&] {
    whole = read(path);
    check_point_set(whole);
    done = true;
  });
  if (done) expect_stream_matches(file.named(extension), whole);
}

// Differential check of a face stream (open_face_stream) on `path`: it may refuse only as
// readers do; when the whole reader read the file (`read`, giving `whole`), the stream must open
// and give the same triangles, no more at any point.
inline void expect_face_stream_matches(const std::string& path, bool read, const PointSet& whole);

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

inline void expect_face_stream_matches(const std::string& path, bool read, const PointSet& whole) {
  bool opened = false, has_stream = false, streamed = false;
  std::vector<std::array<std::uint32_t, 3>> all;
  expect_reader_errors(path, [&] {
    // Windows of 64 bytes: most faces of a small file are cut by a window's end.
    const std::unique_ptr<FaceStream> faces = open_face_stream(path, 64);
    opened = true;
    if (!faces) return;  // no faces
    has_stream = true;
    std::vector<std::array<std::uint32_t, 3>> part;
    while (faces->read(part)) {
      all.insert(all.end(), part.begin(), part.end());
      if (read && all.size() > whole.triangles.size()) finding("the face stream gives more");
    }
    streamed = true;
  });
  if (read && !opened) finding("the face stream refused what the whole reader read");
  if (read && has_stream && !streamed) finding("the face stream refused faces the reader read");
  if (read && streamed && all != whole.triangles) {
    finding("the face stream's triangles differ from the whole reader's");
  }
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
