// Whole-file loading for the readers: a read-only memory map of a plain file, or the inflated
// contents of a gzip file (used by the readers and writers of io and format).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

namespace pointillist {

// gzip files start with these two bytes (RFC 1952).
bool has_gzip_magic(std::string_view bytes);

class FileBytes {
 public:
  FileBytes() = default;
  FileBytes(FileBytes&& other) noexcept;
  FileBytes& operator=(FileBytes&& other) noexcept;
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;
  ~FileBytes();

  std::string_view view() const { return {data_, size_}; }
  // True when the file was gzip-compressed; offsets into view() are then decompressed offsets.
  bool was_compressed() const { return was_compressed_; }
  std::uint64_t file_size() const { return file_size_; }

  // How a mapped file will be read: Whole, all of it from start to end (the mapping is filled at
  // once and read ahead); Parts, only the parts asked for (a paged model: each page is read from
  // disk when first touched, so opening a model larger than memory reads its header, not all of
  // it).
  enum class Use { Whole, Parts };
  // Maps `path` read-only (reads it whole where mmap fails). Throws IoError.
  static FileBytes map(const std::string& path, Use use = Use::Whole);
  // The inflated contents of `compressed` (a gzip file read from `path`). `on_compressed_bytes`
  // (may be empty) hears how many compressed bytes were consumed, in chunks. Throws FormatError
  // for corrupt or truncated data.
  // `limit` (may be empty): see GzipInflater::set_limit.
  static FileBytes inflate(const FileBytes& compressed, const std::string& path,
                           const std::function<void(std::uint64_t)>& on_compressed_bytes = {},
                           std::function<std::uint64_t(std::string_view)> limit = {});
  // map(), then inflate() when the file starts with the gzip magic bytes.
  static FileBytes load(const std::string& path,
                        const std::function<void(std::uint64_t)>& on_compressed_bytes = {});

  // Unmaps a mapped file's pages from this process once their contents were copied out: the
  // file stays in the kernel's page cache and a later read maps its pages again. Without it,
  // every page of a model a render ever touched would count as the process's resident memory.
  // No effect on bytes read into a buffer (inflated or unmappable files).
  void forget() const;

 private:
  friend class GzipInflater;
  void release();

  const char* data_ = "";
  std::size_t size_ = 0;
  void* map_ = nullptr;  // munmap'd in the destructor
  std::size_t map_size_ = 0;
  std::unique_ptr<char[]> buffer_;
  bool was_compressed_ = false;
  std::uint64_t file_size_ = 0;
};

// Inflates a gzip file into one buffer. One thread calls run() while others may read the part
// already inflated (wait_for): decompression and parsing then overlap.
class GzipInflater {
 public:
  // `compressed` must outlive the inflater. Sizes the buffer from the gzip trailer (bounded by
  // the largest possible deflate ratio, so a corrupt trailer cannot ask for absurd memory).
  GzipInflater(std::string_view compressed, std::string path);

  // Inflates everything. With `may_grow`, the buffer grows as needed (only safe when no other
  // thread reads it); without, run() stops early and overflowed() turns true when it is full.
  // Always marks the stream finished, also when it throws FormatError (corrupt or truncated data).
  void run(bool may_grow, const std::function<void(std::uint64_t)>& on_compressed_bytes);

  // Blocks until at least `bytes` bytes are inflated or run() has finished; returns the number
  // of valid bytes and whether run() has finished.
  std::size_t wait_for(std::size_t bytes, bool& finished);

  // Makes run() return soon (a reader has failed, or has all it needs).
  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }

  // Bounds the inflated size by what the file's own header says it can hold, so that a small
  // file inflating to gigabytes (a "gzip bomb") fails in a moment: run() calls `limit` with the
  // bytes inflated so far (at most once a megabyte, until it answers) and it returns the most
  // bytes the file can need, or UINT64_MAX while it cannot tell yet (the header is incomplete).
  // Inflating past the bound throws FormatError naming the file and the decompressed byte.
  // Call before run().
  void set_limit(std::function<std::uint64_t(std::string_view)> limit) {
    limit_fn_ = std::move(limit);
  }

  const char* data() const { return buffer_.get(); }
  std::size_t capacity() const { return capacity_; }
  bool overflowed() const { return overflowed_; }
  // Bytes inflated when run() stopped (the buffer may be larger).
  std::size_t inflated() const { return available_; }
  // The buffer as FileBytes (call after run() has returned).
  FileBytes release(std::uint64_t file_size);

 private:
  void publish(std::size_t available, bool finished);

  std::string_view in_;
  std::string path_;
  std::unique_ptr<char[]> buffer_;
  std::size_t capacity_ = 0;
  bool overflowed_ = false;
  std::atomic<bool> cancelled_{false};
  std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t available_ = 0;  // guarded by mutex_
  bool finished_ = false;      // guarded by mutex_
  std::function<std::uint64_t(std::string_view)> limit_fn_;
};

}  // namespace pointillist
