// SPDX-License-Identifier: MIT
// Point welding for the surface readers (see read_surface_detail.h): clustering on a hash grid,
// renumbering, and weld_points (read_surface.h), which applies both.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "surface3d/read_surface.h"
#include "surface3d/read_surface_detail.h"

namespace plaf {

using Vec3 = Eigen::Vector3d;

double read_detail::bbox_diagonal(const std::vector<Vec3>& points) {
  if (points.empty()) return 0;
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

// The cells are at least tol wide, so a partner within tol is in one of the 27 cells around.
std::vector<int> read_detail::cluster_points(const std::vector<Vec3>& points, double tol) {
  const std::size_t n = points.size();
  std::vector<int> rep(n);
  double extent = 0;
  for (const Vec3& p : points)
    if (p.allFinite()) extent = std::max(extent, p.cwiseAbs().maxCoeff());
  // A floor on the cell size keeps the cell coordinates within 2^40 for any tol (also tol = 0,
  // exact equality).
  const double cell = std::max({tol, extent * 0x1p-40, std::numeric_limits<double>::min()});
  const double tol2 = tol * tol;
  struct KeyHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
      const auto h = static_cast<std::uint64_t>(k[0]) * 0x9E3779B97F4A7C15ULL ^
                     static_cast<std::uint64_t>(k[1]) * 0xC2B2AE3D27D4EB4FULL ^
                     static_cast<std::uint64_t>(k[2]) * 0x165667B19E3779F9ULL;
      return static_cast<std::size_t>(h ^ (h >> 29));
    }
  };
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<int>, KeyHash> grid;
  grid.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& p = points[i];
    rep[i] = static_cast<int>(i);
    if (!p.allFinite()) continue;  // never merged (the readers reject such points before)
    std::array<std::int64_t, 3> key;
    for (int d = 0; d < 3; ++d) key[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(std::floor(p[d] / cell));
    int best = -1;
    double best_d2 = 0;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find({key[0] + dx, key[1] + dy, key[2] + dz});
          if (it == grid.end()) continue;
          for (const int r : it->second) {
            const Vec3 diff = points[static_cast<std::size_t>(r)] - p;
            // The max-norm test keeps tol = 0 exact where the squared norm of a tiny difference
            // would underflow to zero.
            if (diff.cwiseAbs().maxCoeff() > tol) continue;
            const double d2 = diff.squaredNorm();
            if (d2 > tol2) continue;
            if (best < 0 || d2 < best_d2 || (d2 == best_d2 && r < best)) {
              best = r;
              best_d2 = d2;
            }
          }
        }
    if (best >= 0) {
      rep[i] = best;
    } else {
      grid[key].push_back(static_cast<int>(i));
    }
  }
  return rep;
}

void read_detail::renumber_and_compact(TriangleSoup& soup, const std::vector<int>* rep) {
  std::vector<int> new_index(soup.points.size(), -1);
  for (auto& t : soup.triangles)
    for (int& v : t) {
      if (rep) v = (*rep)[static_cast<std::size_t>(v)];
      new_index[static_cast<std::size_t>(v)] = 0;
    }
  std::vector<Vec3> kept;
  for (std::size_t i = 0; i < soup.points.size(); ++i)
    if (new_index[i] == 0) {
      new_index[i] = static_cast<int>(kept.size());
      kept.push_back(soup.points[i]);
    }
  for (auto& t : soup.triangles)
    for (int& v : t) v = new_index[static_cast<std::size_t>(v)];
  soup.points = std::move(kept);
}

std::size_t weld_points(TriangleSoup& soup, double tol) {
  const std::size_t before = soup.points.size();
  const std::vector<int> rep = read_detail::cluster_points(soup.points, std::max(tol, 0.0));
  read_detail::renumber_and_compact(soup, &rep);
  return before - soup.points.size();
}

}  // namespace plaf
