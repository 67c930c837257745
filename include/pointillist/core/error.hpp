// Error types. Bad input, bad options and failed I/O throw one of these; the message says what
// was wrong and where (path, line or byte offset, element, property, expected vs found) and,
// where it helps, what to do about it. Only `main` catches.
#pragma once

#include <stdexcept>
#include <string>

namespace pointillist {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The content of a file is not what its format requires (malformed header, truncated data, ...).
class FormatError : public Error {
 public:
  using Error::Error;
};

// The operating system refused (cannot open, cannot write, cannot rename, disk full, ...).
class IoError : public Error {
 public:
  using Error::Error;
};

// A command-line value or an Options field is out of range or inconsistent.
class OptionError : public Error {
 public:
  using Error::Error;
};

// "what: strerror(errno)" for the current errno, e.g. "cannot open scan.ply: No such file".
std::string errno_message(const std::string& what);

}  // namespace pointillist
