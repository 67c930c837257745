#include "pointillist/core/error.hpp"

#include <cerrno>
#include <cstring>

namespace pointillist {

std::string errno_message(const std::string& what) {
  const int err = errno;
  return what + ": " + std::strerror(err);
}

}  // namespace pointillist
