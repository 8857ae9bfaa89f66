// SPDX-License-Identifier: MIT
// The surface's distance to its body (fidelity.h).
#include "surface3d/fidelity.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/elements/lagrange.h"
#include "modules/geometry/aabb_tree.h"

namespace plaf {

namespace {

// The lattice points (i, j), i + j <= n, of the unit triangle, and its n^2 sub-triangles.
struct SubLattice {
  std::vector<std::array<double, 2>> xi;
  std::vector<std::array<int, 3>> tris;
  explicit SubLattice(int n) {
    std::vector<std::vector<int>> at(static_cast<std::size_t>(n + 1));
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i + j <= n; ++i) {
        at[static_cast<std::size_t>(i)].push_back(static_cast<int>(xi.size()));
        xi.push_back({static_cast<double>(i) / n, static_cast<double>(j) / n});
      }
    auto id = [&](int i, int j) { return at[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]; };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        tris.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        if (i + j + 1 < n) tris.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
  }
};

}  // namespace

std::vector<Eigen::Vector3d> reference_samples(const TriSurface& input, const ReferenceGeometry<3>& reference) {
  const SubLattice lat(4);
  std::vector<Eigen::Vector3d> out;
  for (const auto f : input.mesh.faces()) {
    const auto fv = input.face_vertices(f);
    const Eigen::Vector3d a = input.mesh.point(fv[0]), b = input.mesh.point(fv[1]), c = input.mesh.point(fv[2]);
    for (const auto& x : lat.xi) out.push_back(reference.project(a + x[0] * (b - a) + x[1] * (c - a)));
  }
  return out;
}

FidelityReport measure_fidelity(const TriSurface& surface, const ReferenceGeometry<3>& reference,
                                const std::vector<Eigen::Vector3d>& samples) {
  FidelityReport r;
  const int q = std::max(1, surface.order);
  const SubLattice lat(2 * q);
  const LagrangeElement& e = lagrange_element(CellType::Triangle, q);
  std::vector<double> phi(static_cast<std::size_t>(e.size()));
  std::vector<std::vector<double>> basis;
  for (const auto& x : lat.xi) {
    e.eval(x.data(), phi.data());
    basis.push_back(phi);
  }
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> tris;
  for (const auto f : surface.mesh.faces()) {
    std::vector<Eigen::Vector3d> nodes = surface.triangle_nodes(f);
    if (static_cast<int>(nodes.size()) != e.size()) {  // straight: its order-Q lattice
      const Eigen::Vector3d a = nodes[0], b = nodes[1], c = nodes[2];
      nodes.clear();
      for (const Lattice& l : e.lattice())
        nodes.push_back(a + (static_cast<double>(l[0]) / q) * (b - a) + (static_cast<double>(l[1]) / q) * (c - a));
    }
    const int first = static_cast<int>(points.size());
    for (const auto& w : basis) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < nodes.size(); ++k) x += w[k] * nodes[k];
      const double d = (x - reference.project(x)).norm();
      if (d > r.to_reference) {
        r.to_reference = d;
        r.worst_on_mesh = x;
      }
      points.push_back(x);
    }
    for (const auto& t : lat.tris) tris.push_back({first + t[0], first + t[1], first + t[2]});
  }
  r.mesh_samples = points.size();
  r.reference_samples = samples.size();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  if (!tris.empty()) {
    const TriangleTree tree(points, tris);
    for (const Eigen::Vector3d& p : samples) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      const double d = std::sqrt(tree.closest(p).distance2);
      if (d > r.to_mesh) {
        r.to_mesh = d;
        r.worst_on_reference = p;
      }
    }
  }
  r.diagonal = samples.empty() ? 0 : (hi - lo).norm();
  r.hausdorff = std::max(r.to_reference, r.to_mesh);
  r.worst = r.to_mesh >= r.to_reference ? r.worst_on_reference : r.worst_on_mesh;
  r.relative = r.diagonal > 0 ? r.hausdorff / r.diagonal : 0;
  return r;
}

}  // namespace plaf
