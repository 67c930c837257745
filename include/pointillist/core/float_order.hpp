// Floats as unsigned integers in the same order, for radix sorts and searches over floats.
#pragma once

#include <bit>
#include <cstdint>

namespace pointillist {

// The key of f: negative floats (all bits flipped) below positive ones (sign bit set), -0 just
// below +0, infinities at the ends; NaN keys lie outside that range. Without a branch.
constexpr std::uint32_t ordered_key(float f) {
  const auto u = std::bit_cast<std::uint32_t>(f);
  return u ^ (static_cast<std::uint32_t>(static_cast<std::int32_t>(u) >> 31) | 0x80000000u);
}

// The float whose ordered_key is k.
constexpr float from_ordered_key(std::uint32_t k) {
  return std::bit_cast<float>((k & 0x80000000u) ? (k & 0x7fffffffu) : ~k);
}

}  // namespace pointillist
