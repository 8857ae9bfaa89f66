// SPDX-License-Identifier: MIT
// Test surfaces shared by the surface3d suites: the icosahedron and icospheres on the unit
// sphere. Header-only; include it as "tests/surface3d/test_surfaces.h".
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "modules/geometry/tri_surface.h"

namespace plaf::test {

// The regular icosahedron on the unit sphere, counter-clockwise seen from outside.
inline TriangleSoup icosahedron_soup() {
  const double g = (1 + std::sqrt(5.0)) / 2;
  TriangleSoup s;
  s.source = "icosahedron";
  s.points = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
              {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (auto& p : s.points) p.normalize();
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  return s;
}

// The unit sphere from the icosahedron with each face split into m^2 triangles (20 m^2 in all),
// outward. A lattice point of a face is named by its weights on the icosahedron's vertices, so
// the faces sharing an edge find the same point.
inline TriangleSoup icosphere_soup(int m) {
  const TriangleSoup ico = icosahedron_soup();
  TriangleSoup s;
  s.source = "icosphere";
  std::map<std::vector<std::pair<int, int>>, int> index;
  auto point = [&](const std::array<int, 3>& f, int i, int j) {
    const int w[3] = {m - i - j, i, j};
    std::vector<std::pair<int, int>> key;
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k)
      if (w[k] > 0) {
        key.emplace_back(f[k], w[k]);
        x += w[k] * ico.points[static_cast<std::size_t>(f[k])];
      }
    std::sort(key.begin(), key.end());
    const auto [it, fresh] = index.try_emplace(key, static_cast<int>(s.points.size()));
    if (fresh) s.points.push_back(x.normalized());
    return it->second;
  };
  for (const auto& f : ico.triangles)
    for (int i = 0; i < m; ++i)
      for (int j = 0; i + j < m; ++j) {
        s.triangles.push_back({point(f, i, j), point(f, i + 1, j), point(f, i, j + 1)});
        if (i + j + 2 <= m) s.triangles.push_back({point(f, i + 1, j), point(f, i + 1, j + 1), point(f, i, j + 1)});
      }
  return s;
}

}  // namespace plaf::test
