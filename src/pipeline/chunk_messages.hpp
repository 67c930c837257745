// The small messages between the ranks of a chunked conversion (private to pipeline): values
// and arrays of trivially copyable types, appended to and read from bytes in order.
#pragma once

#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "pointillist/core/error.hpp"

namespace pointillist::chunking {

class MessageWriter {
 public:
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const char* p = reinterpret_cast<const char*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  template <class T>
  void put_vector(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(std::uint64_t(values.size()));
    if (values.empty()) return;
    const char* p = reinterpret_cast<const char*>(values.data());
    bytes_.insert(bytes_.end(), p, p + values.size() * sizeof(T));
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  std::vector<char> bytes_;
};

class MessageReader {
 public:
  explicit MessageReader(const std::vector<char>& bytes) : bytes_(bytes) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    take(&value, sizeof(T));
    return value;
  }
  template <class T>
  std::vector<T> get_vector() {
    const auto n = get<std::uint64_t>();
    if (n > (bytes_.size() - at_) / sizeof(T)) short_message();
    std::vector<T> values(static_cast<std::size_t>(n));
    if (n > 0) take(values.data(), values.size() * sizeof(T));
    return values;
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  void take(void* out, std::size_t size) {
    if (size > bytes_.size() - at_) short_message();
    std::memcpy(out, bytes_.data() + at_, size);
    at_ += size;
  }
  [[noreturn]] static void short_message() {
    throw Error("chunked conversion: a message between the ranks is shorter than its contents "
                "(ranks of different pointillist builds?); run the same build on every rank");
  }
  const std::vector<char>& bytes_;
  std::size_t at_ = 0;
};

}  // namespace pointillist::chunking
