// SPDX-License-Identifier: MIT
// The cells of one layer (PartLayerBuilder::columns_and_cells, layer3d_builder.h): prisms, their
// cut into tetrahedra (Dompierre's rule), the cells of a layer with stops, and the fans' cells.
#include "layers/layer3d_builder.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>

#include <Eigen/Eigenvalues>

#include "layers/front_collisions_3d.h"
#include "modules/base/error.h"
#include "modules/elements/validity.h"
#include "modules/geometry/aabb_tree.h"
#include "modules/geometry/predicates.h"

namespace plaf::layers::grow3d {

auto PartLayerBuilder::at(int d, int level) -> NodeId {
  const std::size_t b = static_cast<std::size_t>(dirs_[static_cast<std::size_t>(d)].base);
  if (level == 0 || stopped_dir(static_cast<std::size_t>(d))) return part_.ids[b];
  NodeId& id = col_[static_cast<std::size_t>(d) * static_cast<std::size_t>(q_) + static_cast<std::size_t>(level) - 1];
  if (id < 0) {
    mesh_.nodes.push_back(x_[b] + (static_cast<double>(level) / q_) * (top_[static_cast<std::size_t>(d)] - x_[b]));
    id = static_cast<NodeId>(mesh_.nodes.size() - 1);
  }
  return id;
}

auto PartLayerBuilder::fan_point(std::vector<std::pair<int, int>> weights) -> NodeId {
  std::sort(weights.begin(), weights.end());
  // One direction given twice (a fade's collapsed section): that column's node.
  for (std::size_t k = 1; k < weights.size();)
    if (weights[k].first == weights[k - 1].first) {
      weights[k - 1].second += weights[k].second;
      weights.erase(weights.begin() + static_cast<std::ptrdiff_t>(k));
    } else {
      ++k;
    }
  if (weights.size() == 1) return at(weights[0].first, weights[0].second);
  const auto it = fan_points_.find(weights);
  if (it != fan_points_.end()) return it->second;
  const std::size_t base = static_cast<std::size_t>(dirs_[static_cast<std::size_t>(weights[0].first)].base);
  Vec x = x_[base];
  for (const auto& [dir, w] : weights) x += (static_cast<double>(w) / q_) * (top_[static_cast<std::size_t>(dir)] - x_[base]);
  mesh_.nodes.push_back(x);
  const NodeId id = static_cast<NodeId>(mesh_.nodes.size() - 1);
  fan_points_.emplace(weights, id);
  return id;
}

void PartLayerBuilder::columns_and_cells() {
  const std::size_t nd = dirs_.size();
  const std::size_t q = static_cast<std::size_t>(q_);
  col_.assign(nd * q, -1);
  out_.keep.assign(nd, Vec::Zero());
  for (std::size_t d = 0; d < nd; ++d)
    if (fanned_ ? dirs_[d].fan && (corner_node_.count(dirs_[d].base) || zone_.count(dirs_[d].base))
                : part_.keep[d].squaredNorm() > 0)
      out_.keep[d] = dirs_[d].d;
  out_.top.resize(nd);
  for (std::size_t d = 0; d < nd; ++d) out_.top[d] = at(static_cast<int>(d), q_);
  out_.stack.resize(nd);
  for (std::size_t d = 0; d < nd; ++d) {
    const std::size_t b = static_cast<std::size_t>(dirs_[d].base);
    out_.stack[d] = (part_.stack.size() == part_.size() ? part_.stack[b] : 0.0) +
                    (mesh_.nodes[static_cast<std::size_t>(out_.top[d])] - x_[b]).norm();
  }
  const Part& nw = next();
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
  const LagrangeElement& qe = lagrange_element(CellType::Quadrilateral, q_);
  const LagrangeElement& pe = lagrange_element(CellType::Prism, q_);
  std::vector<int> tri_of_prism_node;
  for (const Lattice& lat : pe.lattice()) tri_of_prism_node.push_back(te.find({lat[0], lat[1], 0}));
  std::vector<NodeId>& prisms = out_.built.cells[0];
  std::vector<NodeId>& tets = out_.built.cells[1];
  const std::size_t grown = fanned_ ? part_.nt() : nw.num_faces();  // faces grown from an old face
  const bool tetra = fanned_ || any_stop_;
  const std::size_t npt = static_cast<std::size_t>(num_nodes(CellType::Tetrahedron, q_));
  for (std::size_t f = 0; f < grown; ++f) {
    const int* fl = nw.face(f);
    if (tetra) {
      // The first layer of a part with fans is all tetrahedra (grow_layers_3d.h, step 6), and
      // so is a layer with stopped columns: a prism over a face with a stopped vertex is a
      // pyramid (two stopped, a tetrahedron), which only tetrahedra meet conformingly, and a
      // quadrilateral shared with a whole prism must be cut alike. The cut's tetrahedron
      // holding both ends of a collapsed column has no volume and is dropped; in a layer with
      // stops every cut cell's nodes follow layer_node (heights affine over the cell).
      std::array<long, 6> rank{};
      for (int k = 0; k < 3; ++k) {
        rank[static_cast<std::size_t>(k)] = base_rank(dirs_[static_cast<std::size_t>(fl[k])].base);
        rank[static_cast<std::size_t>(k + 3)] = top_rank(fl[k]);
      }
      const std::size_t before = tets.size();
      if (any_stop_ && !fanned_)
        transition_tets(fl, column_order(rank), tets);
      else
        split_tets(fl, column_order(rank), tets);
      for (std::size_t k = before; k < tets.size(); k += npt) out_.cell_face[1].push_back(static_cast<int>(f));
    } else {
      for (int k = 0; k < pe.size(); ++k)
        prisms.push_back(at(fl[tri_of_prism_node[static_cast<std::size_t>(k)]], pe.lattice()[static_cast<std::size_t>(k)][2]));
      out_.cell_face[0].push_back(static_cast<int>(f));
    }
  }
  if (fanned_) fan_cells();
  // Symmetry facets of the grown faces: a triangle's rim edge gives a quadrilateral (u from the
  // edge's second vertex to its first, v up the layer: facing the cells, as the wall does), or
  // its two triangles where the layer is tetrahedra.
  for (const auto& re : nw.rim) {
    const std::size_t f = static_cast<std::size_t>(re[0]);
    if (f >= grown) continue;
    const int* fl = nw.face(f);
    const int tag = planes_[static_cast<std::size_t>(re[2])].tag;
    if (tetra) {
      // The side of a first-layer prism cut into tetrahedra: the two triangles of its cut
      // (column_order's rule on the quadrilateral (u from the edge's second vertex to its first,
      // v up the layer)).
      const std::vector<int>& en = te.edge_nodes(re[1]);
      auto node = [&](int u, int v) { return at(fl[en[static_cast<std::size_t>(q_ - u)]], v); };
      const int d0 = fl[en[static_cast<std::size_t>(q_)]], d1 = fl[en[0]];  // u = 0 and u = Q
      const long r00 = base_rank(dirs_[static_cast<std::size_t>(d0)].base), rq0 = base_rank(dirs_[static_cast<std::size_t>(d1)].base);
      const long rqq = top_rank(d1), r0q = top_rank(d0);
      for (const QuadCorners& h : quad_cut(q_, r00, rq0, rqq, r0q)) {
        Corner corner[3];
        for (int k = 0; k < 3; ++k)
          corner[k] = {h[static_cast<std::size_t>(k)][0] == 0 ? d0 : d1, h[static_cast<std::size_t>(k)][1] == 0 ? 0 : 1};
        if (collapsed(corner, 3)) continue;  // a stopped column's side of no area
        for (const Lattice& lat : te.lattice()) {
          const auto [u, v] = quad_point(h, lat, q_);
          const int w[3] = {q_ - lat[0] - lat[1], lat[0], lat[1]};
          const int d = fl[en[static_cast<std::size_t>(q_ - u)]];
          out_.sym_tris.push_back(any_stop_ ? layer_node(corner, w, 3, d) : node(u, v));
        }
        out_.sym_tri_tag.push_back(tag);
      }
    } else {
      const std::vector<int>& en = te.edge_nodes(re[1]);
      for (const Lattice& lat : qe.lattice()) out_.sym_quads.push_back(at(fl[en[static_cast<std::size_t>(q_ - lat[0])]], lat[1]));
      out_.sym_quad_tag.push_back(tag);
    }
  }
}

auto PartLayerBuilder::collapsed(const Corner* c, int n) -> bool {
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      if (corner_node(c[a]) == corner_node(c[b])) return true;
  return false;
}

auto PartLayerBuilder::layer_node(const Corner* corners, const int* w, int n, int d) -> NodeId {
  bool bottom = true, top = true;
  for (int k = 0; k < n; ++k) {
    if (w[k] == 0) continue;
    const bool st = stopped_dir(static_cast<std::size_t>(corners[k].d));
    bottom = bottom && (corners[k].level == 0 || st);
    top = top && (corners[k].level == 1 || st);
  }
  if (bottom) return at(d, 0);
  if (top) return at(d, q_);
  LiftedKey key;
  key.fill(-1);
  for (int k = 0, m = 0; k < n; ++k)
    if (w[k] > 0) key[static_cast<std::size_t>(m++)] = static_cast<std::int64_t>(corner_node(corners[k])) * 64 + w[k];
  std::sort(key.begin(), key.end());
  const auto it = lifted_.find(key);
  if (it != lifted_.end()) return it->second;
  Vec x = x_[static_cast<std::size_t>(dirs_[static_cast<std::size_t>(d)].base)];
  double up = 0;  // the point's level in the layer, 0 to 1
  for (int k = 0; k < n; ++k) {
    const std::size_t dk = static_cast<std::size_t>(corners[k].d);
    x += (static_cast<double>(w[k]) / q_) *
         (mesh_.nodes[static_cast<std::size_t>(corner_node(corners[k]))] - x_[static_cast<std::size_t>(dirs_[dk].base)]);
    if (corners[k].level == 1 && !stopped_dir(dk)) up += static_cast<double>(w[k]) / q_;
  }
  x += up * off_lift_[static_cast<std::size_t>(d)];  // the pull: a closing layer's, or a layer with stops' gentle one
  mesh_.nodes.push_back(x);
  const NodeId id = static_cast<NodeId>(mesh_.nodes.size() - 1);
  lifted_.emplace(std::move(key), id);
  return id;
}

void PartLayerBuilder::transition_tets(const int* fl, const std::array<int, 3>& r, std::vector<NodeId>& tets) {
  const LagrangeElement& tet = lagrange_element(CellType::Tetrahedron, q_);
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
  for (const auto& c : prism_cut(r)) {
    Corner corner[4];
    for (int k = 0; k < 4; ++k) corner[k] = {fl[c[static_cast<std::size_t>(k)][0]], c[static_cast<std::size_t>(k)][1]};
    if (collapsed(corner, 4)) continue;
    for (const Lattice& lat : tet.lattice()) {
      const int w[4] = {q_ - lat[0] - lat[1] - lat[2], lat[0], lat[1], lat[2]};
      Eigen::Vector3i pt = Eigen::Vector3i::Zero();
      for (int k = 0; k < 4; ++k) pt += w[k] * lat_of(c[static_cast<std::size_t>(k)]);
      pt /= q_;
      tets.push_back(layer_node(corner, w, 4, fl[te.find({pt[0], pt[1], 0})]));
    }
  }
}

auto PartLayerBuilder::column_order(const std::array<long, 6>& rank) -> std::array<int, 3> {
  int wins[3] = {0, 0, 0};
  for (int x = 0; x < 3; ++x)
    for (int y = x + 1; y < 3; ++y) {
      const long lo = std::min(std::min(rank[static_cast<std::size_t>(x)], rank[static_cast<std::size_t>(y)]),
                               std::min(rank[static_cast<std::size_t>(x + 3)], rank[static_cast<std::size_t>(y + 3)]));
      const bool x_first = lo == rank[static_cast<std::size_t>(x)] || lo == rank[static_cast<std::size_t>(y + 3)];
      ++wins[x_first ? x : y];
    }
  std::array<int, 3> r{};
  for (int k = 0; k < 3; ++k) r[static_cast<std::size_t>(2 - wins[k])] = k;
  if (wins[r[0]] != 2 || wins[r[2]] != 0)  // only with ranks that are not distinct
    throw MesherError("layers: a prism's diagonals close a cycle (its vertices' ranks are not distinct)");
  return r;
}

auto PartLayerBuilder::lat_of(const PrismCorner& vl) const -> Eigen::Vector3i {
  return Eigen::Vector3i(vl[0] == 1 ? q_ : 0, vl[0] == 2 ? q_ : 0, vl[1] * q_);
}

auto PartLayerBuilder::prism_cut(const std::array<int, 3>& r) const -> std::array<std::array<PrismCorner, 4>, 3> {
  const int s = r[0], m = r[1], t = r[2];
  std::array<std::array<PrismCorner, 4>, 3> cells = {{{{{s, 0}, {m, 0}, {t, 0}, {t, 1}}},
                                                      {{{s, 0}, {m, 0}, {m, 1}, {t, 1}}},
                                                      {{{s, 0}, {s, 1}, {m, 1}, {t, 1}}}}};
  for (auto& c : cells) {
    const Eigen::Vector3i a = lat_of(c[0]), b = lat_of(c[1]), cc = lat_of(c[2]), dd = lat_of(c[3]);
    const Eigen::Matrix3d m3 = (Eigen::Matrix3d() << (b - a).cast<double>(), (cc - a).cast<double>(), (dd - a).cast<double>()).finished();
    if (m3.determinant() < 0) std::swap(c[2], c[3]);
  }
  return cells;
}

void PartLayerBuilder::split_tets(const int* fl, const std::array<int, 3>& r, std::vector<NodeId>& tets) {
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
  prism_tets([&](int a, int b, int c) { return at(fl[te.find({a, b, 0})], c); }, r, tets);
}

auto PartLayerBuilder::base_rank(int l) const -> long {
  const auto it = zone_level_.find(l);
  const long level = it == zone_level_.end() ? (1L << 20) : it->second;
  return level * static_cast<long>(part_.size()) + l;
}

auto PartLayerBuilder::sector_point(const FanEdge& fe, int s, int c, int an, int bn, int den) -> NodeId {
  const int g = std::gcd(std::gcd(an, bn), den);
  an /= g, bn /= g, den /= g;
  const int arc = fe.arcs[static_cast<std::size_t>(c)];
  const auto key = std::make_tuple(arc, s, an, bn, den);
  const auto it = sector_points_.find(key);
  if (it != sector_points_.end()) return it->second;
  const std::vector<int>& a = arcs_[static_cast<std::size_t>(arc)];
  const std::size_t d0 = static_cast<std::size_t>(a[static_cast<std::size_t>(s * q_)]);
  const std::size_t d1 = static_cast<std::size_t>(a[static_cast<std::size_t>((s + 1) * q_)]);
  const Vec& x = x_[static_cast<std::size_t>(dirs_[d0].base)];
  const double sa = static_cast<double>(an) / (static_cast<double>(den) * q_), sb = static_cast<double>(bn) / (static_cast<double>(den) * q_);
  mesh_.nodes.push_back(x + sa * (top_[d1] - x) + sb * (top_[d0] - x));
  const NodeId id = static_cast<NodeId>(mesh_.nodes.size() - 1);
  sector_points_.emplace(key, id);
  return id;
}

void PartLayerBuilder::fan_cells() {
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
  const LagrangeElement& tet = lagrange_element(CellType::Tetrahedron, q_);
  for (const FanEdge& fe : fan_edges_)
    for (int s = 0; s < 2 * fe.k; ++s) {
      auto node = [&](int a, int b, int c) {
        const std::vector<int>& arc = arcs_[static_cast<std::size_t>(fe.arcs[static_cast<std::size_t>(c)])];
        const int d0 = arc[static_cast<std::size_t>(s * q_)], d1 = arc[static_cast<std::size_t>((s + 1) * q_)];
        if (a + b == q_) return at(arc[static_cast<std::size_t>(s * q_ + a)], q_);
        if (a == 0 && b == 0) return part_.ids[static_cast<std::size_t>(fe.nodes[static_cast<std::size_t>(c)])];
        if (b == 0) return at(d1, a);
        if (a == 0) return at(d0, b);
        return fan_point({{d0, b}, {d1, a}});
      };
      const bool c0 = closed_at(fe, s, 0), c1 = closed_at(fe, s, q_);
      if (c0 && c1) continue;
      if (c0 || c1) {
        fade_cells(fe, s, c0 ? 0 : q_, node);
      } else {
        const std::vector<int>& arc0 = arcs_[static_cast<std::size_t>(fe.arcs.front())];
        const std::vector<int>& arc1 = arcs_[static_cast<std::size_t>(fe.arcs.back())];
        const std::size_t a_at = static_cast<std::size_t>((s + 1) * q_), b_at = static_cast<std::size_t>(s * q_);
        const std::array<long, 6> rank = {base_rank(fe.nodes.front()), top_rank(arc0[a_at]), top_rank(arc0[b_at]),
                                          base_rank(fe.nodes.back()),  top_rank(arc1[a_at]), top_rank(arc1[b_at])};
        prism_tets(node, column_order(rank), out_.built.cells[1]);
        for (int k = 0; k < 3; ++k) out_.cell_face[1].push_back(fe.left);
      }
      // The section on a symmetry plane at an open end (a closed end is a fade zone's node,
      // never on a plane): a sector closed at its other end has the same face there.
      for (int end = 0; end < 2; ++end) {
        if (fe.plane[end] < 0 || (end == 0 ? c0 : c1)) continue;
        for (const Lattice& lat : te.lattice())
          out_.sym_tris.push_back(end == 0 ? node(lat[0], lat[1], 0) : node(lat[1], lat[0], q_));
        out_.sym_tri_tag.push_back(planes_[static_cast<std::size_t>(fe.plane[end])].tag);
      }
    }
  const Part& nw = next();
  for (const auto& [v, f] : corner_tets_) {
    const int* fl = nw.face(static_cast<std::size_t>(f));
    for (const Lattice& lat : tet.lattice()) {
      const int w[4] = {q_ - lat[0] - lat[1] - lat[2], lat[0], lat[1], lat[2]};
      if (w[0] == q_) {
        out_.built.cells[1].push_back(part_.ids[static_cast<std::size_t>(v)]);
      } else if (w[0] == 0) {
        out_.built.cells[1].push_back(at(fl[te.find({w[2], w[3], 0})], q_));
      } else {
        std::vector<std::pair<int, int>> weights;
        for (int k = 1; k < 4; ++k)
          if (w[k] > 0) weights.push_back({fl[k - 1], w[k]});
        out_.built.cells[1].push_back(weights.size() == 1 ? at(weights[0].first, weights[0].second) : fan_point(weights));
      }
    }
    out_.cell_face[1].push_back(out_.face_origin[static_cast<std::size_t>(f)]);
  }
}

}  // namespace plaf::layers::grow3d
