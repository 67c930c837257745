// Small helpers shared by the subcommands.
#pragma once

#include <string>

namespace pointillist::cli {

// "1.23 MB"-style size.
std::string human_bytes(double bytes);

}  // namespace pointillist::cli
