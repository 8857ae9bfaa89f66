// SPDX-License-Identifier: MIT
// Box surfaces for the 3D fill tests (tetgen_fill_test, optimize_3d_test): the faces of an
// axis-aligned box as the triangles of a LinearFront<3>; and how a fill's tets use a front.
#pragma once

#include <array>
#include <algorithm>
#include <map>
#include <vector>
#include <string>

#include <Eigen/Core>

#include "modules/geometry/predicates.h"
#include "modules/mesh/linear_front.h"

namespace plaf::test {

enum class Normals { In, Out };

// Adds the surface of the box lo + [0, size.x] x [0, size.y] x [0, size.z] to the front, n[d]
// intervals along axis d, each face square split into two triangles whose normals point into the
// box (In: the box is the region to fill, an outer box) or out of it (Out: the box is a body, the
// region to fill is around it), tagged with a new tag `name`. Only the surface lattice points
// become nodes.
inline void add_box(LinearFront<3>& f, const Eigen::Vector3d& lo, const Eigen::Vector3d& size, std::array<int, 3> n,
                    Normals normals, const std::string& name) {
  std::map<std::array<int, 3>, NodeId> ids;
  auto id = [&](int i, int j, int k) {
    const auto [it, fresh] = ids.emplace(std::array<int, 3>{i, j, k}, static_cast<NodeId>(f.nodes.size()));
    if (fresh)
      f.nodes.push_back(lo + Eigen::Vector3d(size.x() * i / n[0], size.y() * j / n[1], size.z() * k / n[2]));
    return it->second;
  };
  const int tag = static_cast<int>(f.tags.size());
  f.tags.push_back({name, normals == Normals::In ? BoundaryKind::Farfield : BoundaryKind::Wall});
  // p, q, r, s counter-clockwise seen from outside the box (outward right-hand normal).
  auto quad = [&](NodeId p, NodeId q, NodeId r, NodeId s) {
    if (normals == Normals::Out) {
      f.triangles.push_back({p, q, r});
      f.triangles.push_back({p, r, s});
    } else {
      f.triangles.push_back({p, r, q});
      f.triangles.push_back({p, s, r});
    }
    f.triangle_tag.insert(f.triangle_tag.end(), {tag, tag});
  };
  const int nx = n[0], ny = n[1], nz = n[2];
  for (int u = 0; u < nx; ++u)
    for (int v = 0; v < ny; ++v) {
      quad(id(u, v, 0), id(u, v + 1, 0), id(u + 1, v + 1, 0), id(u + 1, v, 0));      // z = 0, outward -z
      quad(id(u, v, nz), id(u + 1, v, nz), id(u + 1, v + 1, nz), id(u, v + 1, nz));  // z = 1, outward +z
    }
  for (int u = 0; u < nx; ++u)
    for (int v = 0; v < nz; ++v) {
      quad(id(u, 0, v), id(u + 1, 0, v), id(u + 1, 0, v + 1), id(u, 0, v + 1));      // y = 0, outward -y
      quad(id(u, ny, v), id(u, ny, v + 1), id(u + 1, ny, v + 1), id(u + 1, ny, v));  // y = 1, outward +y
    }
  for (int u = 0; u < ny; ++u)
    for (int v = 0; v < nz; ++v) {
      quad(id(0, u, v), id(0, u, v + 1), id(0, u + 1, v + 1), id(0, u + 1, v));      // x = 0, outward -x
      quad(id(nx, u, v), id(nx, u + 1, v), id(nx, u + 1, v + 1), id(nx, u, v + 1));  // x = 1, outward +x
    }
}

// The cube lo + [0, side]^3 with n intervals per edge.
inline void add_cube(LinearFront<3>& f, const Eigen::Vector3d& lo, double side, int n, Normals normals,
                     const std::string& name) {
  add_box(f, lo, Eigen::Vector3d::Constant(side), {n, n, n}, normals, name);
}

// The tets' faces, each sorted, with the vertices opposite it (one per tet holding it).
using FaceApexes = std::map<std::array<NodeId, 3>, std::vector<NodeId>>;
inline FaceApexes face_apexes(const std::vector<std::array<NodeId, 4>>& tets) {
  FaceApexes apexes;
  for (const auto& t : tets)
    for (int k = 0; k < 4; ++k) {
      std::array<NodeId, 3> face{t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
      std::sort(face.begin(), face.end());
      apexes[face].push_back(t[k]);
    }
  return apexes;
}

// Of the front's triangles: those that are not a face of exactly one tet, and those whose tet
// lies behind them (not on their right-hand normal's side, linear_front.h; exact orient3d).
struct FrontUse {
  std::size_t not_once = 0, behind = 0;
};
inline FrontUse front_use(const LinearFront<3>& f, const std::vector<Eigen::Vector3d>& nodes, const FaceApexes& apexes) {
  FrontUse u;
  for (const auto& t : f.triangles) {
    std::array<NodeId, 3> face = t;
    std::sort(face.begin(), face.end());
    const auto it = apexes.find(face);
    if (it == apexes.end() || it->second.size() != 1) {
      ++u.not_once;
      continue;
    }
    if (!(orient3d(f.nodes[t[0]], f.nodes[t[1]], f.nodes[t[2]], nodes[static_cast<std::size_t>(it->second[0])]) < 0))
      ++u.behind;
  }
  return u;
}

}  // namespace plaf::test
