// A closed triangle mesh of a torus for tests: a grid of rows × columns vertices, two triangles
// per grid square, with colours.
#pragma once

#include <cmath>
#include <cstdint>

#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"

namespace pointillist::testing {

inline PointSet torus_mesh(std::uint32_t rows, std::uint32_t columns) {
  PointSet m;
  for (std::uint32_t i = 0; i < rows; ++i) {
    const float u = 2.0f * kPi * float(i) / float(rows);
    for (std::uint32_t j = 0; j < columns; ++j) {
      const float v = 2.0f * kPi * float(j) / float(columns);
      const float r = 1.0f + 0.35f * std::cos(v);
      m.positions.push_back({r * std::cos(u), 0.35f * std::sin(v), r * std::sin(u)});
      m.colors.push_back({std::uint8_t(40 + i % 200), std::uint8_t(90 + j % 150), 160});
    }
  }
  const auto at = [&](std::uint32_t i, std::uint32_t j) {
    return (i % rows) * columns + (j % columns);
  };
  for (std::uint32_t i = 0; i < rows; ++i) {
    for (std::uint32_t j = 0; j < columns; ++j) {
      m.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
      m.triangles.push_back({at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)});
    }
  }
  return m;
}

}  // namespace pointillist::testing
