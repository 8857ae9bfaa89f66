// SPDX-License-Identifier: MIT
// Test surfaces shared by the surface3d suites (and bench/bench_features): the icosahedron and
// icospheres on the unit sphere, and bodies made of voxels. Header-only and free of doctest;
// include it as "tests/surface3d/test_surfaces.h".
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
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

// A body made of unit voxels, scaled by `scale`: the faces between a voxel and empty space (except
// the open ones, given as {voxel, axis, sign}), each split into k x k squares of two triangles.
// Points live on the integer lattice of spacing 1 / k, so the faces of neighbouring voxels share
// their points exactly.
inline TriangleSoup voxel_soup(const std::vector<std::array<int, 3>>& voxels, int k, double scale = 1.0,
                               const std::set<std::array<int, 3>>& open_faces = {}) {
  TriangleSoup soup;
  soup.source = "voxels";
  std::map<std::array<int, 3>, int> index;
  const auto point = [&](const std::array<int, 3>& q) {
    const auto [it, inserted] = index.emplace(q, static_cast<int>(soup.points.size()));
    if (inserted) soup.points.emplace_back(Eigen::Vector3i(q[0], q[1], q[2]).cast<double>() * (scale / k));
    return it->second;
  };
  const std::set<std::array<int, 3>> filled(voxels.begin(), voxels.end());
  for (std::size_t n = 0; n < voxels.size(); ++n) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int sign = -1; sign <= 1; sign += 2) {
        std::array<int, 3> neighbour = voxels[n];
        neighbour[static_cast<std::size_t>(axis)] += sign;
        if (filled.count(neighbour) || open_faces.count({static_cast<int>(n), axis, sign})) continue;
        // Outward normal sign * e_axis: with b, c the next axes (e_b x e_c = e_axis) the square
        // (p0, p0 + u, p0 + u + v, p0 + v) is counter-clockwise from outside for u x v = normal.
        const std::size_t a = static_cast<std::size_t>(axis), b = (a + 1) % 3, c = (a + 2) % 3;
        std::array<int, 3> p0 = {voxels[n][0], voxels[n][1], voxels[n][2]}, u = {0, 0, 0}, v = {0, 0, 0};
        for (auto& x : p0) x *= k;
        if (sign > 0) {
          p0[a] += k;
          u[b] = 1;
          v[c] = 1;
        } else {
          u[c] = 1;
          v[b] = 1;
        }
        const auto at = [&](int i, int j) {
          std::array<int, 3> q = p0;
          for (std::size_t d = 0; d < 3; ++d) q[d] += i * u[d] + j * v[d];
          return point(q);
        };
        for (int i = 0; i < k; ++i)
          for (int j = 0; j < k; ++j) {
            const int pa = at(i, j), pb = at(i + 1, j), pc = at(i + 1, j + 1), pd = at(i, j + 1);
            soup.triangles.push_back({pa, pb, pc});
            soup.triangles.push_back({pa, pc, pd});
          }
      }
    }
  }
  return soup;
}

// A slab of thickness 2t from x = 0 to 1, both long edges rounded (semicircles of 8 segments,
// 22.5 degrees each), extruded along z over m cells of length / m and closed by flat caps fanned
// from their centres; the straight sides in n segments. Outward.
inline TriangleSoup rounded_slab_soup(double t, double length, int n, int m) {
  std::vector<Eigen::Vector2d> profile;  // counter-clockwise seen from +z
  for (int i = 0; i < n; ++i) profile.push_back({static_cast<double>(i) / n, -t});
  for (int k = 0; k < 8; ++k) {
    const double a = -M_PI / 2 + k * M_PI / 8;
    profile.push_back({1 + t * std::cos(a), t * std::sin(a)});
  }
  for (int i = n; i > 0; --i) profile.push_back({static_cast<double>(i) / n, t});
  for (int k = 0; k < 8; ++k) {
    const double a = M_PI / 2 + k * M_PI / 8;
    profile.push_back({t * std::cos(a), t * std::sin(a)});
  }
  const int np = static_cast<int>(profile.size());
  TriangleSoup soup;
  soup.source = "rounded slab";
  for (int j = 0; j <= m; ++j)
    for (const Eigen::Vector2d& p : profile) soup.points.push_back({p.x(), p.y(), length * j / m});
  auto at = [&](int i, int j) { return j * np + (i % np); };
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < np; ++i) {
      soup.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      soup.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  const int c0 = static_cast<int>(soup.points.size());
  soup.points.push_back({0.5, 0, 0});
  soup.points.push_back({0.5, 0, length});
  for (int i = 0; i < np; ++i) {
    soup.triangles.push_back({c0, at(i + 1, 0), at(i, 0)});
    soup.triangles.push_back({c0 + 1, at(i, m), at(i + 1, m)});
  }
  return soup;
}

}  // namespace plaf::test
