// A text file read from the start in windows of whole lines, plain or gzip (private to io): the
// streamed text readers' input (xyz_stream.cpp, the ASCII PLY stream in ply_ascii_stream.cpp).
#pragma once

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "pointillist/core/error.hpp"
#include "text_numbers.hpp"

namespace pointillist::io_detail {

// Bytes read at a time; a line longer than the window is refused.
constexpr std::size_t kTextWindowBytes = std::size_t{8} << 20;
// A file read from the start in windows of whole lines (zlib reads plain files as they are).
class LineWindow {
 public:
  explicit LineWindow(const std::string& path) : path_(path) { open(); }
  ~LineWindow() {
    if (file_) gzclose(file_);
  }
  LineWindow(const LineWindow&) = delete;
  LineWindow& operator=(const LineWindow&) = delete;

  void rewind() {
    if (!file_) open();
    if (gzrewind(file_) != 0) fail("cannot rewind");
    begin_ = end_ = 0;
    eof_ = false;
    lines_before_ = 0;
  }
  // Closes the file and frees the window until the next rewind (many inputs may be open at
  // once; each holds memory and a file only while it is read).
  void release() {
    done_when_released_ = bytes_done();
    if (file_) gzclose(file_);
    file_ = nullptr;
    std::vector<char>().swap(buffer_);
    begin_ = end_ = 0;
    eof_ = true;
  }
  // The next line [start, end) without its '\n', false at the end of the file. The pointers
  // hold until the next call.
  bool next_line(const char*& start, const char*& end) {
    if (!file_) return false;  // released
    if (buffer_.empty()) refill();
    for (;;) {
      const char* p = buffer_.data() + begin_;
      const char* stop = buffer_.data() + end_;
      const char* le = line_end(p, stop);
      if (le < stop || (eof_ && p < stop)) {
        start = p;
        end = le;
        begin_ = std::size_t(le - buffer_.data()) + (le < stop ? 1 : 0);
        return true;
      }
      if (eof_) return false;
      refill();
    }
  }
  // Where the window's bytes start in line numbers, for LineParser::set_window.
  std::string_view window() const { return {buffer_.data(), end_}; }
  std::size_t lines_before() const { return lines_before_; }
  // Compressed bytes consumed (the file's bytes for a plain file).
  std::uint64_t bytes_done() const {
    if (!file_) return done_when_released_;
    const z_off_t at = gzoffset(file_);
    return at < 0 ? 0 : std::uint64_t(at);
  }
  // Reads up to `bytes` from the start (whole lines unless the file is shorter).
  std::string prefix(std::size_t bytes) {
    rewind();
    std::string out(bytes, '\0');
    const int got = gzread(file_, out.data(), unsigned(bytes));
    if (got < 0) fail("cannot read");
    out.resize(std::size_t(got));
    if (out.size() == bytes) {
      const std::size_t nl = out.rfind('\n');
      out.resize(nl == std::string::npos ? 0 : nl + 1);
    }
    rewind();
    return out;
  }

 private:
  void open() {
    file_ = gzopen(path_.c_str(), "rb");
    if (!file_) {
      throw IoError(path_ + ": cannot open for reading: " + std::strerror(errno) +
                    " (check the path and its permissions)");
    }
    gzbuffer(file_, 1 << 20);
  }
  // Moves the unread bytes to the front and reads more after them. The window starts at 64 KB
  // and doubles at each refill up to kTextWindowBytes: a small file is not given 8 MB (the
  // fuzzers open thousands a second), a large one reaches the full window after a few.
  void refill() {
    if (buffer_.size() < kTextWindowBytes) {
      buffer_.resize(std::clamp<std::size_t>(2 * buffer_.size(), std::size_t{64} << 10,
                                             kTextWindowBytes));
    }
    lines_before_ += std::size_t(std::count(buffer_.data(), buffer_.data() + begin_, '\n'));
    if (end_ > begin_) std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
    if (end_ == buffer_.size() && buffer_.size() < kTextWindowBytes) {
      buffer_.resize(std::min(2 * buffer_.size(), kTextWindowBytes));  // a long line
    }
    if (end_ == buffer_.size()) {
      throw FormatError(path_ + ": line " + std::to_string(lines_before_ + 1) +
                        ": longer than " + std::to_string(kTextWindowBytes >> 20) +
                        " MB; is this a point text file?");
    }
    const int got = gzread(file_, buffer_.data() + end_, unsigned(buffer_.size() - end_));
    if (got < 0) fail("cannot read");
    if (got == 0) eof_ = true;
    end_ += std::size_t(got);
  }
  [[noreturn]] void fail(const char* what) const {
    int code = 0;
    const char* message = gzerror(file_, &code);
    throw IoError(path_ + ": " + what + ": " +
                  (code == Z_ERRNO ? std::strerror(errno) : message) +
                  (code == Z_DATA_ERROR ? " (the compressed data is damaged)" : ""));
  }

  std::string path_;
  gzFile file_ = nullptr;
  std::vector<char> buffer_;
  std::size_t begin_ = 0, end_ = 0;
  bool eof_ = false;
  std::size_t lines_before_ = 0;  // lines before buffer_[0]
  std::uint64_t done_when_released_ = 0;
};

}  // namespace pointillist::io_detail
