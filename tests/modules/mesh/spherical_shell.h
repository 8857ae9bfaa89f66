// SPDX-License-Identifier: MIT
// A curved spherical shell of prisms, built independently of the layer stage, as the reference
// mesh for everything downstream of the layers (conformity, quality, writers, Gmsh's checks).
//
// The wall is a geodesic sphere: each face of a base polyhedron (icosahedron or octahedron) is
// cut into n^2 triangles of order Q whose nodes are the lattice points of the flat face,
// projected onto the unit sphere; a node on a shared edge or vertex is built once, keyed by its
// integer weights on the base vertices. The wall is extruded radially through L layers of equal
// height to radius 1 + t: node (s, k) sits at (1 + t k / (L Q)) d_s for the unit direction d_s of
// surface node s and k = 0 .. L Q. A prism of layer l takes its triangle's nodes at levels
// l Q .. (l + 1) Q, so the radius is linear along its axis and its order-Q map is exactly
// x(u, v, w) = r(w) N(u, v), N the order-Q interpolant of the directions: the prism volumes add
// up to ((1 + t)^3 - 1) V_N, with V_N the volume of the cones over the wall's interpolant, which
// lies between 4/3 pi (1 - delta)^3 and 4/3 pi (1 + delta)^3 for delta the largest deviation of
// |N| from 1 (a radial graph between two spheres; half of it for the half shell).
//
// The half shell (octahedron base, the faces above z = 0) ends on the symmetry plane z = 0: the
// prisms' side faces there are quadrilaterals, and the wall's rim is a curve (order-Q lines).
// Tags (HybridMesh order): "wall" (Wall, the prisms' bottom triangles, facing the origin),
// "layers_outer" (Named, their top triangles), "symmetry" (Symmetry, quadrilaterals and the rim).
// Boundary facets are the cells' own faces (lagrange.h), so they face out of the shell.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include "modules/elements/lagrange.h"
#include "modules/mesh/hybrid_mesh.h"

namespace plaf::test {

enum class ShellBase { Icosahedron, Octahedron };

struct ShellOptions {
  int order = 2;
  int subdivisions = 2;    // n: each base face is cut into n^2 triangles
  double thickness = 0.3;  // t: outer radius 1 + t
  int layers = 2;          // L
  ShellBase base = ShellBase::Icosahedron;
  bool half = false;  // octahedron only: the faces above z = 0
};

struct SphericalShell {
  HybridMesh<3> mesh;
  std::size_t wall_triangles = 0;  // F
  std::size_t wall_edges = 0;      // of the wall's triangles, each once
  std::size_t rim_edges = 0;       // wall edges on z = 0 (half shell)
  double exact_volume = 0;         // 4/3 pi ((1 + t)^3 - 1), halved for the half shell
  double radius_deviation = 0;     // delta: max | |N| - 1 | over the wall, sampled densely
  double wall_edge_max = 0;        // the longest chord between adjacent wall vertices
};

namespace shell_detail {

// The faces (outward, counter-clockwise seen from outside) of a convex polyhedron inscribed in
// the unit sphere whose edges all have length `edge`: the triples of mutually adjacent vertices.
inline std::vector<std::array<int, 3>> faces_of(const std::vector<Eigen::Vector3d>& v, double edge) {
  const auto adjacent = [&](int a, int b) { return std::abs((v[a] - v[b]).norm() - edge) < 1e-9; };
  std::vector<std::array<int, 3>> faces;
  const int n = static_cast<int>(v.size());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      for (int c = b + 1; c < n; ++c)
        if (adjacent(a, b) && adjacent(b, c) && adjacent(c, a)) {
          const bool outward = (v[b] - v[a]).cross(v[c] - v[a]).dot(v[a]) > 0;
          faces.push_back(outward ? std::array<int, 3>{a, b, c} : std::array<int, 3>{a, c, b});
        }
  return faces;
}

}  // namespace shell_detail

inline SphericalShell spherical_shell(const ShellOptions& o) {
  using Eigen::Vector3d;
  SphericalShell out;
  const int q = o.order, n = o.subdivisions, levels = o.layers * q + 1;
  const int fine = n * q;  // lattice points per base edge, minus one

  // 1. The base polyhedron on the unit sphere.
  std::vector<Vector3d> base;
  double edge = 0;
  if (o.base == ShellBase::Icosahedron) {
    const double g = (1 + std::sqrt(5.0)) / 2;
    for (double s1 : {-1.0, 1.0})
      for (double s2 : {-1.0, 1.0}) {
        base.push_back(Vector3d(0, s1, s2 * g).normalized());
        base.push_back(Vector3d(s1, s2 * g, 0).normalized());
        base.push_back(Vector3d(s2 * g, 0, s1).normalized());
      }
    edge = 2 / std::sqrt(1 + g * g);
  } else {
    for (int d = 0; d < 3; ++d)
      for (double s : {-1.0, 1.0}) {
        Vector3d x = Vector3d::Zero();
        x[d] = s;
        base.push_back(x);
      }
    edge = std::sqrt(2.0);
  }
  std::vector<std::array<int, 3>> faces = shell_detail::faces_of(base, edge);
  if (o.half)
    faces.erase(std::remove_if(faces.begin(), faces.end(),
                               [&](const std::array<int, 3>& f) {
                                 return base[f[0]].z() < 0 || base[f[1]].z() < 0 || base[f[2]].z() < 0;
                               }),
                faces.end());

  // 2. Wall nodes (unit directions), keyed by their weights on the base vertices, and the wall
  //    triangles in Gmsh order.
  std::map<std::vector<std::pair<int, int>>, int> surface_id;
  std::vector<Vector3d> directions;
  const auto surface_node = [&](const std::array<int, 3>& f, const std::array<int, 3>& w) {
    std::vector<std::pair<int, int>> key;
    for (int k = 0; k < 3; ++k)
      if (w[k] > 0) key.emplace_back(f[k], w[k]);
    std::sort(key.begin(), key.end());
    auto [it, fresh] = surface_id.emplace(key, static_cast<int>(directions.size()));
    if (fresh) {
      Vector3d x = Vector3d::Zero();
      for (const auto& [vertex, weight] : key) x += weight * base[vertex];
      directions.push_back(x.normalized());
    }
    return it->second;
  };
  const std::vector<Lattice> tri_lattice = gmsh_lattice(CellType::Triangle, q);
  std::vector<std::vector<int>> wall;  // surface node ids per wall triangle, Gmsh order
  for (const auto& f : faces) {
    // Sub-triangles by their corners in (B, C)-weights of the face (A, B, C), units of 1/n.
    std::vector<std::array<std::array<int, 2>, 3>> subs;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        subs.push_back({{{i, j}, {i + 1, j}, {i, j + 1}}});
        if (i + j + 2 <= n) subs.push_back({{{i + 1, j}, {i + 1, j + 1}, {i, j + 1}}});
      }
    for (const auto& p : subs) {
      std::vector<int> ids;
      for (const Lattice& l : tri_lattice) {
        const int b = q * p[0][0] + l[0] * (p[1][0] - p[0][0]) + l[1] * (p[2][0] - p[0][0]);
        const int c = q * p[0][1] + l[0] * (p[1][1] - p[0][1]) + l[1] * (p[2][1] - p[0][1]);
        ids.push_back(surface_node(f, {fine - b - c, b, c}));
      }
      wall.push_back(ids);
    }
  }

  // 3. Nodes: every surface node at every radial level.
  HybridMesh<3>& m = out.mesh;
  const auto id = [&](int s, int k) { return static_cast<NodeId>(s * levels + k); };
  m.nodes.resize(directions.size() * static_cast<std::size_t>(levels));
  for (std::size_t s = 0; s < directions.size(); ++s)
    for (int k = 0; k < levels; ++k)
      m.nodes[static_cast<std::size_t>(id(static_cast<int>(s), k))] =
          (1 + o.thickness * k / (levels - 1)) * directions[s];

  // 4. Prisms, and their faces on the wall, the outer front and the symmetry plane.
  const int wall_tag = m.add_tag("wall", BoundaryKind::Wall);
  const int outer_tag = m.add_tag("layers_outer", BoundaryKind::Named);
  const int symmetry_tag = o.half ? m.add_tag("symmetry", BoundaryKind::Symmetry) : -1;
  const LagrangeElement& prism = lagrange_element(CellType::Prism, q);
  const LagrangeElement& tri = lagrange_element(CellType::Triangle, q);
  CellBlock& cells = m.block(CellType::Prism, q);
  for (const std::vector<int>& t : wall)
    for (int layer = 0; layer < o.layers; ++layer) {
      std::vector<NodeId> c;
      for (const Lattice& l : prism.lattice()) c.push_back(id(t[tri.find({l[0], l[1], 0})], layer * q + l[2]));
      cells.connectivity.insert(cells.connectivity.end(), c.begin(), c.end());
      for (int f = 0; f < prism.num_facets(); ++f) {
        const std::vector<int>& local = prism.facet_nodes(f);
        int tag = -1;
        if (f == 0 && layer == 0) tag = wall_tag;
        if (f == 1 && layer == o.layers - 1) tag = outer_tag;
        if (f >= 2 && o.half) {
          bool on_plane = true;
          for (int v = 0; v < 4; ++v) on_plane = on_plane && m.nodes[static_cast<std::size_t>(c[local[v]])].z() == 0;
          if (on_plane) tag = symmetry_tag;
        }
        if (tag < 0) continue;
        CellBlock& b = m.boundary_block(f < 2 ? CellType::Triangle : CellType::Quadrilateral, q, tag);
        for (int k : local) b.connectivity.push_back(c[k]);
      }
    }

  // 5. The wall's edges, its rim on z = 0 as a curve, its longest edge chord.
  std::map<std::pair<int, int>, int> edges;
  for (const std::vector<int>& t : wall)
    for (int e = 0; e < 3; ++e) {
      const std::vector<int>& en = tri.edge_nodes(e);
      const int a = t[en.front()], b = t[en.back()];
      ++edges[{std::min(a, b), std::max(a, b)}];
      out.wall_edge_max = std::max(out.wall_edge_max, (directions[a] - directions[b]).norm());
      if (o.half && directions[a].z() == 0 && directions[b].z() == 0) {
        CellBlock& rim = m.curve_block(q, symmetry_tag);
        rim.connectivity.push_back(id(a, 0));
        rim.connectivity.push_back(id(b, 0));
        for (std::size_t k = 1; k + 1 < en.size(); ++k) rim.connectivity.push_back(id(t[en[k]], 0));
      }
    }
  out.wall_triangles = wall.size();
  out.wall_edges = edges.size();
  for (const auto& [key, uses] : edges) out.rim_edges += uses == 1 ? 1 : 0;

  // 6. The exact volume and the wall interpolant's deviation from the sphere (sampled on a
  //    lattice of 24 per side of every wall triangle).
  const double t = o.thickness;
  out.exact_volume = 4.0 / 3.0 * std::numbers::pi * ((1 + t) * (1 + t) * (1 + t) - 1) * (o.half ? 0.5 : 1.0);
  constexpr int samples = 24;
  std::vector<double> phi(static_cast<std::size_t>(tri.size()));
  for (const std::vector<int>& w : wall)
    for (int j = 0; j <= samples; ++j)
      for (int i = 0; i + j <= samples; ++i) {
        const double xi[2] = {static_cast<double>(i) / samples, static_cast<double>(j) / samples};
        tri.eval(xi, phi.data());
        Vector3d x = Vector3d::Zero();
        for (int k = 0; k < tri.size(); ++k) x += phi[static_cast<std::size_t>(k)] * directions[w[k]];
        out.radius_deviation = std::max(out.radius_deviation, std::abs(x.norm() - 1));
      }
  return out;
}

}  // namespace plaf::test
