// SPDX-License-Identifier: MIT
// The build of one layer on one part (PartLayerBuilder, layer3d_builder.h): its steps in order, the
// local stops, the node normals and their relaxation, the curvature blend and the counts.
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

void finish_part(Part& p, int q) {
  const std::size_t n = p.size();
  p.is_vertex.assign(n, 0);
  p.tv.assign(n, {0, 0, 0, 0});
  p.tw.assign(n, {0, 0, 0, 0});
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q);
  for (std::size_t f = 0; f < p.num_faces(); ++f) {
    const int* fl = p.face(f);
    for (int k = 0; k < p.face_size(f); ++k) {
      const Lattice& lat = te.lattice()[static_cast<std::size_t>(k)];
      // From the lattice's integers: an edge node's weight on the opposite vertex is exactly 0
      // (1 - 1/3 - 2/3 is 1.1e-16 in doubles, which tied a Q3 edge node to that vertex, so the
      // edge between two stopped columns grew a top of its own).
      const double u = static_cast<double>(lat[0]) / q, v = static_cast<double>(lat[1]) / q;
      const std::size_t l = static_cast<std::size_t>(fl[k]);
      p.tv[l] = {fl[0], fl[1], fl[2], fl[0]};
      p.tw[l] = {static_cast<double>(q - lat[0] - lat[1]) / q, u, v, 0};
      if (k < p.face_vertices(f)) p.is_vertex[l] = 1;
    }
  }
  p.vertices.clear();
  for (std::size_t l = 0; l < n; ++l)
    if (p.is_vertex[l]) p.vertices.push_back(static_cast<int>(l));
  p.node_face_start.assign(n + 1, 0);
  for (std::size_t f = 0; f < p.num_faces(); ++f)
    for (int k = 0; k < p.face_size(f); ++k) ++p.node_face_start[static_cast<std::size_t>(p.face(f)[k]) + 1];
  for (std::size_t l = 0; l < n; ++l) p.node_face_start[l + 1] += p.node_face_start[l];
  p.node_face.resize(static_cast<std::size_t>(p.node_face_start[n]));
  std::vector<int> fill(p.node_face_start.begin(), p.node_face_start.end() - 1);
  for (std::size_t f = 0; f < p.num_faces(); ++f)
    for (int k = 0; k < p.face_size(f); ++k)
      p.node_face[static_cast<std::size_t>(fill[static_cast<std::size_t>(p.face(f)[k])]++)] = static_cast<int>(f);
}

auto PartLayerBuilder::build() -> PartLayer {
  const std::size_t n = part_.size();
  x_.resize(n);
  for (std::size_t l = 0; l < n; ++l) x_[l] = mesh_.nodes[static_cast<std::size_t>(part_.ids[l])];
  stops();
  normals();
  relax_normals();
  if (first_ && std::isfinite(f_atten_) && !any_stop_) fans();
  check_cusps();
  if (!fanned_) {
    dirs_.resize(n);
    for (std::size_t l = 0; l < n; ++l)
      dirs_[l] = {static_cast<int>(l), nn_[l].n, nn_[l].stretch, is_concave(nn_[l].kind), false};
    out_.face_origin.resize(part_.num_faces());
    for (std::size_t f = 0; f < part_.num_faces(); ++f) out_.face_origin[f] = static_cast<int>(f);
  }
  blend();
  if (counts_ != nullptr) count();
  tops();
  columns_and_cells();
  return std::move(out_);
}

void PartLayerBuilder::stops() {
  const std::size_t n = part_.size();
  stop_.assign(n, 0);
  for (std::size_t k = 0; k < stopped_.size() && k < part_.vertices.size(); ++k)
    if (stopped_[k]) stop_[static_cast<std::size_t>(part_.vertices[k])] = 1;
  for (std::size_t l = 0; l < n; ++l) {
    if (part_.is_vertex[l]) continue;
    bool all = true;
    for (int k = 0; k < 4; ++k)
      if (part_.tw[l][static_cast<std::size_t>(k)] > 0) all = all && stop_[static_cast<std::size_t>(part_.tv[l][static_cast<std::size_t>(k)])];
    stop_[l] = all ? 1 : 0;
  }
  any_stop_ = std::any_of(stop_.begin(), stop_.end(), [](std::uint8_t b) { return b != 0; });
  // About Q^2 lifted nodes per face (its cut's edges and faces through the layer): no rehash.
  if (any_stop_) lifted_.reserve(part_.nt() * static_cast<std::size_t>(q_ * q_));
}

void PartLayerBuilder::normals() {
  const std::size_t n = part_.size();
  const std::vector<std::array<int, 3>> subs = sub_triangles(q_);
  ent_start_.assign(n + 1, 0);
  for (std::size_t f = 0; f < part_.num_faces(); ++f)
    for (const auto& s : subs)
      for (int k : s) ++ent_start_[static_cast<std::size_t>(part_.face(f)[k]) + 1];
  for (std::size_t l = 0; l < n; ++l) ent_start_[l + 1] += ent_start_[l];
  ent_n_.resize(static_cast<std::size_t>(ent_start_[n]));
  ent_w_.resize(ent_n_.size());
  ent_f_.resize(ent_n_.size());
  std::vector<int> fill(ent_start_.begin(), ent_start_.end() - 1);
  for (std::size_t f = 0; f < part_.num_faces(); ++f)
    for (const auto& s : subs) {
      const int* fl = part_.face(f);
      const Vec a = x_[static_cast<std::size_t>(fl[s[0]])], b = x_[static_cast<std::size_t>(fl[s[1]])],
                c = x_[static_cast<std::size_t>(fl[s[2]])];
      const Vec nn = (b - a).cross(c - a);
      if (!(nn.norm() > 0)) {
        throw MesherError("layers: a degenerate front triangle in surface " + part_.name + " at " +
                          std::to_string(a.x()) + ", " + std::to_string(a.y()) + ", " + std::to_string(a.z()));
      }
      const Vec un = nn.normalized();
      const Vec pts[3] = {a, b, c};
      for (int k = 0; k < 3; ++k) {
        const Vec e1 = pts[(k + 1) % 3] - pts[k], e2 = pts[(k + 2) % 3] - pts[k];
        const std::size_t l = static_cast<std::size_t>(fl[s[static_cast<std::size_t>(k)]]);
        const std::size_t e = static_cast<std::size_t>(fill[l]++);
        ent_n_[e] = un;
        ent_w_[e] = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
        ent_f_[e] = static_cast<int>(f);
      }
    }
  nn_.assign(n, NodeNormal{});
  const double corner_rad = p_.corner_angle_deg * M_PI / 180;
  std::vector<Vec> fv, to_nb;
  std::vector<double> w;
  for (std::size_t l = 0; l < n; ++l) {
    fv.assign(ent_n_.begin() + static_cast<std::ptrdiff_t>(ent_begin(l)), ent_n_.begin() + static_cast<std::ptrdiff_t>(ent_end(l)));
    w.assign(ent_w_.begin() + static_cast<std::ptrdiff_t>(ent_begin(l)), ent_w_.begin() + static_cast<std::ptrdiff_t>(ent_end(l)));
    to_nb.clear();
    for (int k = part_.node_face_start[l]; k < part_.node_face_start[l + 1]; ++k) {
      const std::size_t f = static_cast<std::size_t>(part_.node_face[static_cast<std::size_t>(k)]);
      for (int v = 0; v < part_.face_vertices(f); ++v)
        if (static_cast<std::size_t>(part_.face(f)[v]) != l) to_nb.push_back(x_[static_cast<std::size_t>(part_.face(f)[v])] - x_[l]);
    }
    // A corner's columns keep their direction (radial from the corner) while every face around
    // sees it at less than 80 degrees: the faces' average would lean the corner patch's nodes
    // toward its centre, a little every layer, until the patch's triangles collapse (measured
    // on a box with 20-degree fans: slivers at the corners by layer 5). A ridge's kites take
    // the faces' average, as the 2D kites do.
    const Vec& kept = part_.keep[l];
    if (!first_ && kept.squaredNorm() > 0) {
      double worst = 1;
      for (const Vec& f : fv) worst = std::min(worst, kept.dot(f));
      if (worst > std::cos(80 * M_PI / 180)) {
        nn_[l] = NodeNormal{kept, 1, worst, NodeClass::Smooth};
        continue;
      }
    }
    NodeNormal r;
    try {
      r = normal_at(l, fv, w, to_nb, corner_rad);
    } catch (const MesherError& e) {
      // A cusp (no direction sees every face): the direction that sees them best (the largest
      // smallest cosine, negative here: Aubry and Loehner's "most normal" direction), counted;
      // the cells it folds fail certification, shrink, and where even the floor fails the
      // column stops (layer_core.h, step 3) -- a cusp is no error for the whole run.
      cusp_.emplace_back(l, e.what());
      r.n = most_normal(fv);
      if (r.n.isZero()) r.n = fv.front();
      r.kind = NodeClass::ConvexRidge;
    }
    // The first layer starts from the reference normal where the surface is smooth (Sec. II.B).
    const std::size_t id = static_cast<std::size_t>(part_.ids[l]);
    if (first_ && r.kind == NodeClass::Smooth && id < front0_.normals.size()) r.n = front0_.normals[id];
    r.n = in_plane(l, r.n);
    nn_[l] = r;
  }
}

void PartLayerBuilder::relax_normals() {
  if (!p_.smooth_normals || first_) return;
  const std::size_t n = part_.size();
  const double floor = std::cos(75 * M_PI / 180);
  std::vector<Vec> next(n);
  std::vector<double> next_cosine(n);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t l = 0; l < n; ++l) {
      next[l] = nn_[l].n;
      next_cosine[l] = nn_[l].min_cosine;
      if (nn_[l].kind != NodeClass::Smooth || part_.keep[l].squaredNorm() > 0 || stop_[l]) continue;
      Vec sum = Vec::Zero();
      int count = 0;
      for (int k = part_.node_face_start[l]; k < part_.node_face_start[l + 1]; ++k) {
        const std::size_t f = static_cast<std::size_t>(part_.node_face[static_cast<std::size_t>(k)]);
        for (int v = 0; v < part_.face_size(f); ++v) {
          const std::size_t m = static_cast<std::size_t>(part_.face(f)[v]);
          if (m == l) continue;
          sum += nn_[m].n;
          ++count;
        }
      }
      if (count == 0) continue;
      const Vec mid = nn_[l].n + sum / count;
      if (!(mid.norm() > 1e-12)) continue;
      // In its symmetry planes (skipped where the projection is too short to trust: in_plane
      // would end the run there, and the node keeps its own normal).
      const Vec planar = in_planes(mid.normalized(), part_.plane[l], planes_);
      if (!(planar.norm() > 1e-3)) continue;
      const Vec c = planar.normalized();
      double worst = 1;
      for (std::size_t e = ent_begin(l); e < ent_end(l); ++e) worst = std::min(worst, c.dot(ent_n_[e]));
      if (worst >= std::min(nn_[l].min_cosine, floor)) {
        next[l] = c;
        next_cosine[l] = worst;
      }
    }
    for (std::size_t l = 0; l < n; ++l) {
      nn_[l].n = next[l];
      nn_[l].min_cosine = next_cosine[l];
    }
  }
}

void PartLayerBuilder::check_cusps() {
  for (const auto& [l, what] : cusp_) {
    const bool fan = fanned_ && fan_node_[l] && !corner_node_.count(static_cast<int>(l));
    if (!fan) ++cusps_;
  }
}

auto PartLayerBuilder::normal_at(std::size_t l, const std::vector<Vec>& f, const std::vector<double>& w, const std::vector<Vec>& to_nb, double corner_rad) const -> NodeNormal {
  try {
    return node_normal(f, w, to_nb, corner_rad);
  } catch (const MesherError& e) {
    // Name the node: a cusp is a defect of the surface there (a fold, a notch).
    throw MesherError(std::string(e.what()) + " at " + std::to_string(x_[l].x()) + ", " + std::to_string(x_[l].y()) +
                      ", " + std::to_string(x_[l].z()) + " on surface " + part_.name +
                      "; check the surface mesh there (surface.* in the report)");
  }
}

auto PartLayerBuilder::in_plane(std::size_t l, const Vec& d) const -> Vec {
  if (part_.plane[l][0] < 0) return d;
  const Vec inplane = in_planes(d, part_.plane[l], planes_);
  if (!(inplane.norm() > 1e-3))
    throw MesherError("layers: surface " + part_.name + " meets its symmetry plane tangentially at " +
                      std::to_string(x_[l].x()) + ", " + std::to_string(x_[l].y()) + ", " + std::to_string(x_[l].z()));
  return inplane.normalized();
}

auto PartLayerBuilder::side_normal(int f, int l) const -> Vec {
  Vec s = Vec::Zero();
  for (std::size_t e = ent_begin(static_cast<std::size_t>(l)); e < ent_end(static_cast<std::size_t>(l)); ++e)
    if (ent_f_[e] == f) s += ent_w_[e] * ent_n_[e];
  return s.normalized();
}

auto PartLayerBuilder::add_dir(int base, const Vec& d, double stretch, bool concave, bool fan) -> int {
  dirs_.push_back({base, in_plane(static_cast<std::size_t>(base), d.normalized()), stretch, concave, fan});
  return static_cast<int>(dirs_.size()) - 1;
}

void PartLayerBuilder::blend() {
  const Part& nw = next();
  auto convex = [&](int d) {
    const Dir& r = dirs_[static_cast<std::size_t>(d)];
    const NodeClass k = nn_[static_cast<std::size_t>(r.base)].kind;
    return !r.fan && k != NodeClass::Smooth && !is_concave(k);
  };
  std::vector<std::uint8_t> blend(dirs_.size(), 0);
  for (std::size_t f = 0; f < nw.num_faces(); ++f) {
    const int* fl = nw.face(f);
    bool c = false;
    for (int v = 0; v < nw.face_vertices(f); ++v) c = c || convex(fl[v]);
    if (c)
      for (int k = nw.face_vertices(f); k < nw.face_size(f); ++k) blend[static_cast<std::size_t>(fl[k])] = 1;
  }
  for (std::size_t d = 0; d < dirs_.size(); ++d) {
    Dir& r = dirs_[d];
    const NodeClass kind = nn_[static_cast<std::size_t>(r.base)].kind;
    if (nw.is_vertex[d] || r.fan || r.concave) continue;
    Vec m = Vec::Zero();
    for (int k = 0; k < 4; ++k) m += nw.tw[d][static_cast<std::size_t>(k)] * dirs_[static_cast<std::size_t>(nw.tv[d][static_cast<std::size_t>(k)])].d;
    m = in_planes(m, part_.plane[static_cast<std::size_t>(r.base)], planes_);
    if (!(m.norm() > 1e-6)) continue;
    m.normalize();
    if (blend[d] && kind == NodeClass::Smooth) {
      r.d = m;
      continue;
    }
    // Everywhere else (ridge nodes too) a high-order node keeps its own normal within
    // kMaxBend of the blend. The paper grows each node along its normal and pulls its top
    // toward the chord by at most f_atten h (Sec. II.B); a node whose normal leans further from
    // its face's vertex directions than that bends its face more with every layer, so the sag
    // grows with the heights instead of fading. Measured on the published ONERA M6 (h0 8.06e-6
    // c): where the trailing edge's ridge fades into the rounded tip, a ridge edge's middle
    // node grew along its own bisector 40 degrees from the blend of the tip corner's merged
    // normal and its other end's; the edge's sag went from 0.2 % of its length at the wall to
    // 21 % at layer 35, 195 cells stayed curved to the last layer and, grown to its metric's
    // 46 layers, three of the fill's tetrahedra on that front inverted. Half the paper's
    // f_atten (0.2) keeps the net pull at least 0.1 h (the front linear after layer 41); a
    // layer rebuilt with f_atten halved (layer_core.h) or a user's smaller f_atten pulls less
    // than this lean, and its sag fades only where the node's own normal leans less.
    constexpr double kMaxBend = 0.1;
    const double bend = std::atan2(m.cross(r.d).norm(), m.dot(r.d));
    if (bend > kMaxBend) {
      // Turned from m toward the node's own normal by kMaxBend (straight to m where the two are
      // opposite, as on the line two symmetry planes share).
      const Vec u = r.d - r.d.dot(m) * m;
      r.d = u.norm() > 1e-9 ? Vec(std::cos(kMaxBend) * m + std::sin(kMaxBend) * u.normalized()) : m;
    }
  }
}

void PartLayerBuilder::count() {
  std::size_t classes[6] = {0, 0, 0, 0, 0, 0}, sym = 0;
  for (std::size_t l = 0; l < part_.size(); ++l) {
    if (part_.is_vertex[l]) ++classes[static_cast<int>(nn_[l].kind)];
    if (part_.plane[l][0] >= 0) ++sym;
  }
  counts_->clear();
  for (int k = 0; k < 6; ++k)
    counts_->push_back({std::string("nodes.") + node_class_name(static_cast<NodeClass>(k)), classes[k]});
  counts_->push_back({"nodes.symmetry", sym});
  counts_->push_back({"merges", classes[static_cast<int>(NodeClass::ConcaveRidge)] +
                                    classes[static_cast<int>(NodeClass::ConcaveCorner)]});
  counts_->push_back({"ridge_fans.edges", fan_edges_.size()});
  std::size_t sectors = 0;
  for (const FanEdge& fe : fan_edges_) sectors += static_cast<std::size_t>(fe.k);
  counts_->push_back({"ridge_fans.sectors", sectors});
  counts_->push_back({"ridge_fans.fades", fades_});
  counts_->push_back({"ridge_fans.narrowed", narrowed_});
  counts_->push_back({"corner_fans", corner_fans_});
  counts_->push_back({"nodes.cusp", cusps_});
}

}  // namespace plaf::layers::grow3d
