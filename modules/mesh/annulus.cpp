// SPDX-License-Identifier: MIT
#include "modules/mesh/annulus.h"

#include <algorithm>
#include <cmath>

#include "modules/base/error.h"

namespace plaf {
inline namespace mesh {

AnnulusParams parse_annulus_params(const ConfigNode& g) {
  AnnulusParams a;
  a.r_inner = g.get_positive("r_inner", a.r_inner);
  a.r_outer = g.get_positive("r_outer", a.r_outer);
  if (a.r_outer <= a.r_inner) throw ConfigError(g.where("r_outer") + ": must be larger than r_inner");
  a.angle_deg = g.get_in_range("angle_deg", a.angle_deg, 1e-6, 360.0);
  a.triangles = g.get_choice("cells", "quad", {"quad", "tri"}) == "tri";
  return a;
}

HybridMesh<2> mesh_annulus(const AnnulusParams& p, int order, const MetricField<2>& metric) {
  check_order(order);
  if (!(p.r_inner > 0) || !(p.r_outer > p.r_inner)) throw InputError("annulus: need 0 < r_inner < r_outer");
  const double span = p.angle_deg * M_PI / 180.0;
  const bool full = p.angle_deg >= 360.0;
  const double r_mid = 0.5 * (p.r_inner + p.r_outer);

  // 1. Element counts from metric lengths (mid-radius arc as a fine polyline; radial line).
  double arc_len = 0;
  const int samples = 256;
  for (int s = 0; s < samples; ++s) {
    const double t0 = span * s / samples, t1 = span * (s + 1) / samples;
    arc_len += metric_length<2>(metric, r_mid * Eigen::Vector2d(std::cos(t0), std::sin(t0)),
                                r_mid * Eigen::Vector2d(std::cos(t1), std::sin(t1)));
  }
  const double t_mid = 0.5 * span;
  const Eigen::Vector2d dir(std::cos(t_mid), std::sin(t_mid));
  const double radial_len = metric_length<2>(metric, p.r_inner * dir, p.r_outer * dir, 8);
  if (!std::isfinite(arc_len) || !std::isfinite(radial_len) || arc_len * radial_len * order * order > 2e8)
    throw InputError("annulus: the metric asks for more than 2e8 nodes; use a larger size");
  const int n_t = std::max(full ? 3 : 1, static_cast<int>(std::lround(arc_len)));
  const int n_r = std::max(1, static_cast<int>(std::lround(radial_len)));
  if (static_cast<double>(n_t) * n_r * order * order > 2e8)
    throw InputError("annulus: the metric asks for more than 2e8 nodes; use a larger size");

  // 2. Nodes on the structured lattice (a radial, b angular); a full annulus wraps in b.
  const int na = n_r * order + 1, nb = n_t * order + (full ? 0 : 1);
  HybridMesh<2> mesh;
  mesh.nodes.resize(static_cast<std::size_t>(na) * nb);
  for (int b = 0; b < nb; ++b)
    for (int a = 0; a < na; ++a) {
      const double r = p.r_inner + (p.r_outer - p.r_inner) * a / (na - 1);
      const double t = span * b / (n_t * order);
      mesh.nodes[static_cast<std::size_t>(b) * na + a] = Eigen::Vector2d(r * std::cos(t), r * std::sin(t));
    }
  auto id = [&](int a, int b) { return static_cast<NodeId>((b % nb) * na + a); };

  // 3. Cells: reference u along r, v along t, so det J = dr dt r > 0 (counter-clockwise).
  const LagrangeElement& quad = lagrange_element(CellType::Quadrilateral, order);
  const LagrangeElement& tri = lagrange_element(CellType::Triangle, order);
  CellBlock& block = mesh.block(p.triangles ? CellType::Triangle : CellType::Quadrilateral, order);
  block.connectivity.reserve(static_cast<std::size_t>(n_r) * n_t * (p.triangles ? 2 * tri.size() : quad.size()));
  for (int j = 0; j < n_t; ++j)
    for (int i = 0; i < n_r; ++i) {
      const int a0 = i * order, b0 = j * order;
      if (!p.triangles) {
        for (const Lattice& l : quad.lattice()) block.connectivity.push_back(id(a0 + l[0], b0 + l[1]));
      } else {
        // Split along the diagonal (0,0)-(Q,Q): (0,0),(Q,0),(Q,Q) and (0,0),(Q,Q),(0,Q).
        for (const Lattice& l : tri.lattice()) block.connectivity.push_back(id(a0 + l[0] + l[1], b0 + l[1]));
        for (const Lattice& l : tri.lattice()) block.connectivity.push_back(id(a0 + l[0], b0 + l[0] + l[1]));
      }
    }

  // 4. Boundary lines (Gmsh line order: ends, then interior), domain on the left.
  const int wall = mesh.add_tag("wall", BoundaryKind::Wall);
  const int farfield = mesh.add_tag("farfield", BoundaryKind::Farfield);
  auto add_line = [&](int tag, auto node_at /* s in 0..order -> id */) {
    CellBlock& bb = mesh.boundary_block(CellType::Line, order, tag);
    bb.connectivity.push_back(node_at(0));
    bb.connectivity.push_back(node_at(order));
    for (int s = 1; s < order; ++s) bb.connectivity.push_back(node_at(s));
  };
  for (int j = 0; j < n_t; ++j) {
    const int b0 = j * order;
    add_line(wall, [&](int s) { return id(0, b0 + order - s); });   // clockwise
    add_line(farfield, [&](int s) { return id(na - 1, b0 + s); });  // counter-clockwise
  }
  if (!full) {
    const int side = mesh.add_tag("side", BoundaryKind::Symmetry);
    for (int i = 0; i < n_r; ++i) {
      const int a0 = i * order;
      add_line(side, [&](int s) { return id(a0 + s, 0); });
      add_line(side, [&](int s) { return id(a0 + order - s, nb - 1); });
    }
  }
  return mesh;
}

}  // namespace mesh
}  // namespace plaf
