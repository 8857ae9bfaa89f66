// SPDX-License-Identifier: MIT
// Internal to the analytic bodies (analytic.h): MeshBuilder, which assembles an initial
// triangulation with its features and tags; the cube lattice the box and the ellipsoid are cut
// from; and the shared argument checks. Not part of the surface3d API.
//
// MeshBuilder collects points, triangles grouped in patches (each patch consistently oriented by
// construction, reversed as a whole when that order is inward), feature edges and corners, then
// builds the TriSurface with its properties: faces tagged "wall", feature edges with their curve
// and kind, their vertices VertexFeature::Curve unless marked as corners, and open edges (only
// allowed on symmetry planes, EdgeFeature::Boundary) tagged "symmetry".
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "modules/base/format.h"
#include "modules/geometry/tri_surface.h"

namespace plaf::analytic_detail {

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kEps = std::numeric_limits<double>::epsilon();

// A number as the error messages print it: plaf::num (modules/base/format.h).
using plaf::num;

// Refuses h <= 0, non-finite h, and an h so small for a body of the given size that the initial
// mesh would be enormous (surely a unit mistake).
void check_h(const std::string& body, double h, double size);

class MeshBuilder {
 public:
  int add_point(const Eigen::Vector3d& p) {
    points_.push_back(p);
    return static_cast<int>(points_.size()) - 1;
  }
  const Eigen::Vector3d& point(int i) const { return points_[i]; }

  // Triangles of the current patch: all consistently oriented among themselves.
  void add_triangle(int a, int b, int c) { patch_.push_back({a, b, c}); }
  // Quad a, b, c, d in cyclic order: split along its shorter diagonal.
  void add_quad(int a, int b, int c, int d);
  // Closes the current patch, reversing its triangles when its construction order is inward.
  void end_patch(bool reverse);

  void mark_edge(int a, int b, int curve, EdgeFeature feature) {
    features_[{std::min(a, b), std::max(a, b)}] = {curve, feature};
  }
  void mark_polyline(const std::vector<int>& v, int curve, EdgeFeature feature) {
    for (std::size_t k = 0; k + 1 < v.size(); ++k) mark_edge(v[k], v[k + 1], curve, feature);
  }
  void mark_corner(int v, VertexFeature f) { corners_[v] = f; }
  void set_symmetry() { symmetry_ = true; }

  // The surface; MesherError (naming `name`) if the triangles are not manifold, a feature edge
  // is not an edge, or an open edge is not on a symmetry plane.
  TriSurface build(const std::string& name) const;

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::array<int, 3>> triangles_, patch_;
  std::map<std::pair<int, int>, std::pair<int, EdgeFeature>> features_;
  std::map<int, VertexFeature> corners_;
  bool symmetry_ = false;
};

// Cube lattice: the surface points of the lattice {0..n[0]} x {0..n[1]} x {0..n[2]}, each face a
// structured grid of quads split along the shorter diagonal, outward oriented for a map that
// preserves the orientation of the cube. build_cube returns the vertex ids keyed by lattice index.
struct CubeLattice {
  std::array<int, 3> n;
  std::unordered_map<long long, int> ids;
  long long key(int i, int j, int k) const { return (static_cast<long long>(k) * (n[1] + 1) + j) * (n[0] + 1) + i; }
  int id(int i, int j, int k) const { return ids.at(key(i, j, k)); }
};

template <class Map>
CubeLattice build_cube(MeshBuilder& mb, const std::array<int, 3>& n, const Map& map) {
  CubeLattice lat{n, {}};
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i) {
        if (i != 0 && i != n[0] && j != 0 && j != n[1] && k != 0 && k != n[2]) continue;
        lat.ids[lat.key(i, j, k)] = mb.add_point(map(i, j, k));
      }
  for (int a = 0; a < 3; ++a) {
    // Axes b, c follow a cyclically, so (b, c) is counter-clockwise seen from +a.
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      for (int q = 0; q < n[b]; ++q)
        for (int r = 0; r < n[c]; ++r) {
          std::array<int, 4> quad;
          const std::array<std::array<int, 2>, 4> br = {{{q, r}, {q + 1, r}, {q + 1, r + 1}, {q, r + 1}}};
          for (int m = 0; m < 4; ++m) {
            std::array<int, 3> ijk{};
            ijk[a] = side == 0 ? 0 : n[a];
            ijk[b] = br[m][0];
            ijk[c] = br[m][1];
            quad[m] = lat.id(ijk[0], ijk[1], ijk[2]);
          }
          if (side == 0)
            mb.add_quad(quad[0], quad[3], quad[2], quad[1]);
          else
            mb.add_quad(quad[0], quad[1], quad[2], quad[3]);
        }
    }
  }
  return lat;
}

}  // namespace plaf::analytic_detail
