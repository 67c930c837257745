#include "pointillist/core/progress.hpp"

namespace pointillist {
namespace {

class NoProgress final : public Progress {
 public:
  void begin_phase(std::string_view, std::uint64_t) override {}
  void advance(std::uint64_t) override {}
  void end_phase() override {}
};

}  // namespace

Progress& Progress::none() {
  static NoProgress sink;  // stateless: sharing it between threads and callers is harmless
  return sink;
}

}  // namespace pointillist
