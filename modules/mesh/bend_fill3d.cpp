// SPDX-License-Identifier: MIT
// The fill bent with a curved outer front (bend_fill3d.h).
#include "modules/mesh/bend_fill3d.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "modules/elements/lagrange.h"
#include "modules/elements/validity.h"
#include "modules/geometry/predicates.h"
#include "modules/geometry/aabb_tree.h"

namespace plaf {
inline namespace mesh {

namespace {

// A boundary triangle of the fill: its vertices and the displacement of each of its nodes from
// its linear position (face order Q, Gmsh order).
struct Face {
  std::array<NodeId, 3> v;
  std::vector<Eigen::Vector3d> d;
  double h = 0;      // longest edge
  double reach = 0;  // where its displacement fades out
  bool curved = false;
};

double smoothstep_down(double t) {
  return t >= 1 ? 0.0 : 1 - t * t * (3 - 2 * t);
}

}  // namespace

FillBending bend_fill_3d(HybridMesh<3>& mesh, std::size_t block, std::size_t first_cell, double reach) {
  FillBending s;
  if (block >= mesh.cells.size()) return s;
  const CellBlock& b = mesh.cells[block];
  const int q = b.order;
  if (b.type != CellType::Tetrahedron || q < 2 || first_cell >= b.size()) return s;
  const int np = b.nodes_per_cell();
  std::vector<Eigen::Vector3d>& x = mesh.nodes;
  auto at = [&](NodeId id) -> Eigen::Vector3d& { return x[static_cast<std::size_t>(id)]; };

  // Nodes of the fill's boundary: every node of another cell (the layers') or of a boundary facet
  // or curve. They stay; every other node of a fill tetrahedron is the fill's own.
  std::vector<std::uint8_t> outer(x.size(), 0);
  for (const auto* group : {&mesh.boundary, &mesh.curves})
    for (const CellBlock& f : *group)
      for (NodeId id : f.connectivity) outer[static_cast<std::size_t>(id)] = 1;
  for (std::size_t k = 0; k < mesh.cells.size(); ++k) {
    const CellBlock& cb = mesh.cells[k];
    const std::size_t end = k == block ? first_cell : cb.size();
    const std::size_t n = static_cast<std::size_t>(cb.nodes_per_cell());
    for (std::size_t i = 0; i < end * n; ++i) outer[static_cast<std::size_t>(cb.connectivity[i])] = 1;
  }

  // 1. The fill's boundary triangles: faces of a fill tetrahedron whose nodes are all outer (at
  // order 2 a face of three front edges that is no front triangle would pass; it is interior, met
  // twice, and dropped).
  const LagrangeElement& tet = lagrange_element(CellType::Tetrahedron, q);
  const LagrangeElement& tri = lagrange_element(CellType::Triangle, q);
  const LagrangeElement& tri1 = lagrange_element(CellType::Triangle, 1);
  std::vector<double> lin(3);
  std::map<std::array<NodeId, 3>, Face> faces;
  for (std::size_t c = first_cell; c < b.size(); ++c) {
    const NodeId* n = b.cell(c);
    for (int f = 0; f < 4; ++f) {
      const std::vector<int>& fn = tet.facet_nodes(f);
      if (!std::all_of(fn.begin(), fn.end(), [&](int k) { return outer[static_cast<std::size_t>(n[k])] != 0; }))
        continue;
      Face face;
      for (std::size_t i = 0; i < 3; ++i) face.v[i] = n[fn[i]];  // the face's first nodes are its vertices
      std::array<NodeId, 3> key = face.v;
      std::sort(key.begin(), key.end());
      const auto [it, added] = faces.emplace(key, Face{});
      if (!added) {  // interior after all
        it->second.v = {-1, -1, -1};
        continue;
      }
      const Eigen::Vector3d &a = at(face.v[0]), &bb = at(face.v[1]), &cc = at(face.v[2]);
      face.h = std::max({(a - bb).norm(), (bb - cc).norm(), (cc - a).norm()});
      face.reach = reach * face.h;
      face.d.resize(fn.size());
      const double tol = 1e-12 * face.h;
      for (std::size_t k = 0; k < fn.size(); ++k) {
        const std::array<double, 3> xi = tri.ref_node(static_cast<int>(k));
        tri1.eval(xi.data(), lin.data());
        face.d[k] = at(n[fn[k]]) - (lin[0] * a + lin[1] * bb + lin[2] * cc);
        face.curved = face.curved || face.d[k].norm() > tol;
      }
      it->second = std::move(face);
    }
  }
  std::vector<Face> bnd;
  double radius = 0;  // the largest reach of a curved triangle
  Eigen::AlignedBox3d curved_box;
  for (auto& [key, f] : faces) {
    if (f.v[0] < 0) continue;
    if (!(f.h > 0)) continue;  // a degenerate triangle bends nothing and has no reach
    if (f.curved) {
      ++s.curved_faces;
      radius = std::max(radius, f.reach);
      for (NodeId v : f.v) curved_box.extend(at(v));
    }
    bnd.push_back(std::move(f));
  }
  if (s.curved_faces == 0 || !(radius > 0)) return s;
  curved_box.min().array() -= radius;
  curved_box.max().array() += radius;
  // A straight triangle holds its neighbourhood within min(its reach, radius): every triangle's
  // reach is then within the box query below (a node within the box, radius around it; the
  // triangles kept are those within 2 radius of a curved one).
  std::vector<Eigen::Vector3d> pts;
  std::vector<std::array<int, 3>> tris;
  std::vector<const Face*> of;
  for (Face& f : bnd) {
    f.reach = std::min(f.reach, radius);
    Eigen::AlignedBox3d box;
    for (NodeId v : f.v) box.extend(at(v));
    box.min().array() -= radius;
    box.max().array() += radius;
    if (!box.intersects(curved_box)) continue;
    const int base = static_cast<int>(pts.size());
    for (NodeId v : f.v) pts.push_back(at(v));
    tris.push_back({base, base + 1, base + 2});
    of.push_back(&f);
  }
  const TriangleTree tree(pts, tris);

  // Voxels of side `radius` that a curved triangle's reach overlaps: a node elsewhere stays.
  const auto voxel = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d r = (p - curved_box.min()) / radius;
    return std::array<long, 3>{static_cast<long>(std::floor(r[0])), static_cast<long>(std::floor(r[1])),
                               static_cast<long>(std::floor(r[2]))};
  };
  std::set<std::array<long, 3>> near;
  for (const Face& f : bnd) {
    if (!f.curved) continue;
    Eigen::AlignedBox3d box;
    for (NodeId v : f.v) box.extend(at(v));
    const std::array<long, 3> lo = voxel(box.min().array() - f.reach), hi = voxel(box.max().array() + f.reach);
    for (long i = lo[0]; i <= hi[0]; ++i)
      for (long j = lo[1]; j <= hi[1]; ++j)
        for (long k = lo[2]; k <= hi[2]; ++k) near.insert({i, j, k});
  }

  // 2. D at every node of the fill's own, at its place on the linear fill (all computed before any
  // moves, so the order of the nodes does not matter).
  std::vector<std::uint8_t> done(x.size(), 0);
  std::vector<std::pair<NodeId, Eigen::Vector3d>> moves;
  std::vector<int> cand;
  std::vector<double> phi(static_cast<std::size_t>(tri.size()));
  for (std::size_t c = first_cell; c < b.size(); ++c) {
    const NodeId* n = b.cell(c);
    for (int k = 0; k < np; ++k) {
      const std::size_t id = static_cast<std::size_t>(n[k]);
      if (outer[id] || done[id]) continue;
      done[id] = 1;
      const Eigen::Vector3d& p = x[id];
      if (!curved_box.contains(p) || !near.count(voxel(p))) continue;
      cand.clear();
      tree.query(Eigen::AlignedBox3d(p.array() - radius, p.array() + radius), cand);
      Eigen::Vector3d num = Eigen::Vector3d::Zero();
      double den = 0;
      bool bent = false;
      for (int t : cand) {
        const Face& f = *of[static_cast<std::size_t>(t)];
        const auto& tr = tree.triangle(t);
        Eigen::Vector3d bary;
        const Eigen::Vector3d cp = closest_point_on_triangle(p, tr[0], tr[1], tr[2], &bary);
        const double delta = (p - cp).norm();
        const double sf = smoothstep_down(delta / f.reach);
        if (sf <= 0) continue;
        const double w = sf / (delta * delta + 1e-12 * f.h * f.h);
        den += w;
        if (!f.curved) continue;
        const double xi[2] = {bary[1], bary[2]};
        tri.eval(xi, phi.data());
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        for (std::size_t j = 0; j < f.d.size(); ++j) d += phi[j] * f.d[j];
        num += w * sf * d;
        bent = true;
      }
      if (!bent || den <= 0) continue;
      moves.emplace_back(n[k], num / den);
    }
  }
  if (moves.empty()) return s;

  // 3. The guard: no cell the map touches may turn invalid. The fill cells with a moved node are
  // certified before and after; a cell valid before and not after gets its moved nodes back, until
  // none is left (each round returns at least one node, and with every node back each cell is as
  // it was), so no cell valid before is invalid after. (A cell invalid before may stay so, its
  // vertices moved: the untangler's work, untangle3d.h.)
  std::vector<std::uint8_t> moved(x.size(), 0);
  for (const auto& [id, d] : moves) moved[static_cast<std::size_t>(id)] = 1;
  std::vector<std::size_t> touched;
  for (std::size_t c = first_cell; c < b.size(); ++c) {
    const NodeId* n = b.cell(c);
    if (std::any_of(n, n + np, [&](NodeId id) { return moved[static_cast<std::size_t>(id)] != 0; }))
      touched.push_back(c);
  }
  JacobianCertifier certifier;
  std::vector<double> coords(static_cast<std::size_t>(3 * np));
  auto valid = [&](std::size_t c) {
    const NodeId* n = b.cell(c);
    for (int j = 0; j < np; ++j)
      for (int d = 0; d < 3; ++d) coords[static_cast<std::size_t>(3 * j + d)] = at(n[j])[d];
    return certifier.certify(CellType::Tetrahedron, q, coords.data()).valid;
  };
  // A cell's corners spanning a positive volume (exact orient3d). A curved cell can be certified
  // with its corner tetrahedron inverted, which `gmsh -check` and solvers that measure cells by
  // their vertices reject (the published BWB at h0 1e-5 L: a fill cell inverted before the map,
  // bent so, then untangled by its high-order nodes alone); the map may not invert any cell's
  // corners, whether the cell was valid before or not.
  auto corners = [&](std::size_t c) {
    const NodeId* n = b.cell(c);
    return positive_tet(at(n[0]), at(n[1]), at(n[2]), at(n[3]));
  };
  std::vector<std::uint8_t> was_valid(touched.size()), had_corners(touched.size());
  for (std::size_t t = 0; t < touched.size(); ++t) {
    was_valid[t] = valid(touched[t]) ? 1 : 0;
    had_corners[t] = corners(touched[t]) ? 1 : 0;
    s.invalid_before += was_valid[t] ? 0 : 1;
  }
  std::vector<Eigen::Vector3d> from(moves.size());
  for (std::size_t m = 0; m < moves.size(); ++m) {
    from[m] = at(moves[m].first);
    at(moves[m].first) += moves[m].second;
  }
  std::vector<std::size_t> move_of(x.size(), 0);
  for (std::size_t m = 0; m < moves.size(); ++m) move_of[static_cast<std::size_t>(moves[m].first)] = m;
  for (;;) {
    std::size_t returned = 0;
    s.invalid_after = 0;
    for (std::size_t t = 0; t < touched.size(); ++t) {
      const bool kept_corners = !had_corners[t] || corners(touched[t]);
      if (kept_corners && valid(touched[t])) continue;
      if (kept_corners && !was_valid[t]) {
        ++s.invalid_after;
        continue;
      }
      const NodeId* n = b.cell(touched[t]);
      for (int j = 0; j < np; ++j) {
        const std::size_t id = static_cast<std::size_t>(n[j]);
        if (!moved[id]) continue;
        moved[id] = 0;
        at(n[j]) = from[move_of[id]];
        ++returned;
      }
    }
    s.nodes_returned += returned;
    if (returned == 0) break;
  }
  for (std::size_t m = 0; m < moves.size(); ++m)
    if (moved[static_cast<std::size_t>(moves[m].first)]) {
      ++s.nodes_moved;
      s.max_shift = std::max(s.max_shift, moves[m].second.norm());
    }
  return s;
}

}  // namespace mesh
}  // namespace plaf
