// SPDX-License-Identifier: MIT
// The 2D front specifics of the layers (see grow_layers_2d.h for the steps and the paper's
// sections; the generic core is layer_core.cpp).
#include "layers/grow_layers_2d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "layers/front_crossings_2d.h"
#include "modules/base/error.h"
#include "modules/elements/lagrange.h"

namespace plaf::layers {

namespace {

using Vec = Eigen::Vector2d;

Vec left_normal(const Vec& t) {
  return Vec(-t.y(), t.x());
}
double signed_angle(const Vec& a, const Vec& b) {
  return std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
}
Vec rotate(const Vec& v, double a) {
  return Vec(std::cos(a) * v.x() - std::sin(a) * v.y(), std::sin(a) * v.x() + std::cos(a) * v.y());
}

// Where a linear node's layer ends: one top for regular and concave nodes, a fan for convex ones.
struct VertexTop {
  // Merged: a regular vertex whose top is its concave neighbour's (merge_at_concave).
  enum class Kind { Regular, Concave, Convex, Stopped, Merged } kind = Kind::Regular;
  std::vector<Vec> normals;                  // fan normals n_0 (left panel) .. n_m (right panel); one otherwise
  std::vector<Vec> tops;                     // P_k
  std::vector<std::vector<NodeId>> columns;  // Q node ids (j = 1..Q) per top
  double h = 0;                              // its metric height before scaling (HighOrderHeights)
  std::size_t merged_into = 0;               // Merged: the concave vertex whose top it shares
};

// One built layer of one loop: the generic part, the new front and, per cell and per new front
// element, the span of the loop's node sequence it grew from (what a failure shrinks).
struct LoopLayer {
  BuiltLayer built;                       // cells[0] quads, cells[1] transition triangles
  std::vector<std::size_t> cell_seq;      // per quad: the sequence index of its first base node
  std::vector<int> cell_span;             // per quad: how many sequence indices its base spans
  std::vector<std::size_t> triangle_seq;  // per triangle: the sequence index of its base's start
  FrontLoop top;
  std::vector<std::size_t> top_seq;  // per new front element: the sequence index it grew from
  // Per quad, triangle and new front element: the concave corners whose tops its ends share
  // (merge_at_concave; -1: none), whose heights a failure there scales too: the shared top is the
  // corner's, outside the element's own span.
  std::vector<std::array<long, 2>> cell_extra, triangle_extra, top_extra;
  std::vector<int> top_span;         // ... and how many sequence indices its base spans
};

// Builds one layer on one loop: the loop as a sequence of its nodes (element e's start, then its
// interior nodes), normals, the tops of the linear nodes, then the cells element by element.
class LoopLayerBuilder {
 public:
  LoopLayerBuilder(HybridMesh<2>& mesh, const MetricField<2>& metric, const LayerParams& p, int q,
                   const CurvedFront<2>& front0, const FrontLoop& loop, bool first_layer,
                   const std::vector<double>& scale, const std::vector<std::uint8_t>& stopped, double f_atten)
      : mesh_(mesh), metric_(metric), p_(p), q_(q), front0_(front0), loop_(loop), first_layer_(first_layer),
        scale_(scale), stopped_(stopped), f_atten_(f_atten), ne_(loop.size()), n_(ne_ * static_cast<std::size_t>(q)),
        quad_(lagrange_element(CellType::Quadrilateral, q)),
        grid_(static_cast<std::size_t>((q + 1) * (q + 1))) {}

  LoopLayer build() {
    sequence_and_normals();
    vertex_tops();
    out_.top.tag = loop_.tag;
    out_.top.kind = loop_.kind;
    out_.top.geometry_loop = loop_.geometry_loop;
    for (std::size_t e = 0; e < ne_; ++e) {
      extra_ = {-1, -1};
      for (int end = 0; end < 2; ++end) {
        const VertexTop& v = vt_[(e + static_cast<std::size_t>(end)) % ne_];
        if (v.kind == VertexTop::Kind::Merged) extra_[static_cast<std::size_t>(end)] = static_cast<long>(v.merged_into * q_);
      }
      fan(e);
      const bool a_stopped = vt_[e].kind == VertexTop::Kind::Stopped;
      const bool b_stopped = vt_[(e + 1) % ne_].kind == VertexTop::Kind::Stopped;
      if (a_stopped && b_stopped)
        emit_front(el(e)[0], el(e)[1], std::vector<NodeId>(el(e) + 2, el(e) + q_ + 1), e * q_, q_);
      else if ((vt_[e].kind == VertexTop::Kind::Merged && vt_[e].merged_into == (e + 1) % ne_) ||
               (vt_[(e + 1) % ne_].kind == VertexTop::Kind::Merged && vt_[(e + 1) % ne_].merged_into == e))
        collapsed(e);
      else if (a_stopped || b_stopped)
        transition(e, a_stopped);
      else
        regular(e);
    }
    return std::move(out_);
  }

 private:
  const NodeId* el(std::size_t e) const { return loop_.elements.data() + e * static_cast<std::size_t>(q_ + 1); }
  // By value: add_node appends to the node array, which may move it.
  Vec at(std::size_t i) const { return mesh_.nodes[seq_[i % n_]]; }
  double height(const Vec& x, const Vec& n) const { return layer_height<2>(metric_, x, n, p_.integrate_height); }
  NodeId add_node(const Vec& x) {
    mesh_.nodes.push_back(x);
    return static_cast<NodeId>(mesh_.nodes.size() - 1);
  }
  // Column of Q nodes from base (excluded) to top (included), uniform; its top the existing node
  // top_id when given (a merged vertex's: its concave corner's top).
  std::vector<NodeId> column(const Vec& base, const Vec& top, NodeId top_id = -1) {
    std::vector<NodeId> c;
    for (int j = 1; j <= q_; ++j)
      c.push_back(j == q_ && top_id >= 0 ? top_id : add_node(base + (static_cast<double>(j) / q_) * (top - base)));
    return c;
  }
  NodeId& g_at(int u, int v) { return grid_[static_cast<std::size_t>(v * (q_ + 1) + u)]; }
  bool is_corner(std::size_t i) const { return i % q_ == 0 && std::abs(turning_[i]) > corner_rad_; }

  // 1-2. The node sequence, panel directions, turning angles and normals: the reference normal on
  // the first layer, averaged panel normals afterwards (optionally smoothed).
  void sequence_and_normals() {
    seq_.resize(n_);
    for (std::size_t e = 0; e < ne_; ++e) {
      seq_[e * q_] = el(e)[0];
      for (int k = 1; k < q_; ++k) seq_[e * q_ + k] = el(e)[1 + k];
    }
    panel_.resize(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      const Vec d = at(i + 1) - at(i);
      if (!(d.norm() > 0)) throw MesherError("layers: two consecutive front nodes coincide on loop " + loop_.tag);
      panel_[i] = d.normalized();
    }
    normal_.resize(n_);
    turning_.assign(n_, 0.0);
    for (std::size_t i = 0; i < n_; ++i) {
      const Vec& before = panel_[(i + n_ - 1) % n_];
      turning_[i] = signed_angle(before, panel_[i]);
      normal_[i] = (left_normal(before) + left_normal(panel_[i])).normalized();
      const NodeId id = seq_[i];
      if (first_layer_ && !is_corner(i) && static_cast<std::size_t>(id) < front0_.normals.size())
        normal_[i] = front0_.normals[static_cast<std::size_t>(id)];
    }
    if (p_.smooth_normals) {
      std::vector<Vec> s = normal_;
      for (std::size_t i = 0; i < n_; ++i)
        if (!is_corner(i)) s[i] = (normal_[(i + n_ - 1) % n_] + 2 * normal_[i] + normal_[(i + 1) % n_]).normalized();
      normal_ = s;
    }
  }

  // 2. Tops of the linear nodes: regular, concave (merged normal) or convex (fan), then the
  // merges next to concave corners (merge_at_concave), then each top's column of Q nodes.
  void vertex_tops() {
    vt_.assign(ne_, VertexTop{});
    for (std::size_t e = 0; e < ne_; ++e) {
      const std::size_t i = e * q_;
      const Vec c = at(i);
      VertexTop& v = vt_[e];
      const Vec n_left = left_normal(panel_[(i + n_ - 1) % n_]), n_right = left_normal(panel_[i]);
      if (stopped_[e]) {
        v.kind = VertexTop::Kind::Stopped;
        continue;  // no top, no column: the node does not move
      }
      if (turning_[i] > corner_rad_) {
        // Concave (left turn). Sec. II.B makes the intersection of the neighbours' normals the
        // vertex of a single element spanning both panels; with panels long against the layer
        // height that vertex lies far out and distorts the neighbours, so we use the robust
        // merged normal instead: the bisector, long enough (h / cos(half angle)) that both
        // panels' layers keep the height h — the intersection of the two offset panels.
        v.kind = VertexTop::Kind::Concave;
        const Vec m = (n_left + n_right).normalized();
        v.h = height(c, m);
        const double h = v.h * scale_[i];
        v.normals = {m};
        v.tops = {c + h / std::max(m.dot(n_left), 0.1) * m};
      } else if (turning_[i] < -corner_rad_ && first_layer_) {
        // Convex (right turn), Fig. 4: normals dividing the corner angle equally. On the first
        // layer only, as in 3D (grow_layers_3d.h, step 6): a fan's outer vertices X_k turn by up
        // to fan_angle_deg, and fanning them again on every later layer multiplied tiny kites at
        // the corner until they folded (NLR 7301's blunt trailing edge at h0 = 1e-5 c). A later
        // front's convex vertex grows along its averaged normal, which lies inside the cone of
        // its panels' normals, so both neighbouring quadrilaterals open outward.
        v.kind = VertexTop::Kind::Convex;
        const int m =
            std::max(1, static_cast<int>(std::ceil(-turning_[i] / (p_.fan_angle_deg * M_PI / 180) - 1e-9)));
        // One height for the whole fan: unequal neighbouring heights would fold the kites, and at
        // the corner point itself the metric's frame belongs to one side only (the wall normal is
        // one-sided there), so the size along the other side's normal can be the size along the
        // wall. Every fan normal takes the smaller of the two sides' heights.
        v.h = std::min(height(c, n_left), height(c, n_right));
        const double h_corner = v.h * scale_[i];
        for (int k = 0; k <= m; ++k) {
          const Vec nk = rotate(n_left, turning_[i] * k / m);
          v.normals.push_back(nk);
          v.tops.push_back(c + h_corner * nk);
        }
      } else {
        v.normals = {normal_[i]};
        v.h = height(c, normal_[i]);
        v.tops = {c + v.h * scale_[i] * normal_[i]};
      }
    }
    merge_at_concave();
    for (std::size_t e = 0; e < ne_; ++e) {
      VertexTop& v = vt_[e];
      const Vec c = at(e * q_);
      if (v.kind == VertexTop::Kind::Merged) continue;  // after its concave vertex's column exists
      for (const Vec& t : v.tops) {
        v.columns.push_back(column(c, t));
        out_.built.columns.push_back({c[0], c[1], 0.0, (t - c).norm(), scale_[e * q_]});
      }
    }
    for (std::size_t e = 0; e < ne_; ++e) {
      VertexTop& v = vt_[e];
      if (v.kind != VertexTop::Kind::Merged) continue;
      const Vec c = at(e * q_);
      v.columns = {column(c, v.tops[0], vt_[v.merged_into].columns.front().back())};
      out_.built.columns.push_back({c[0], c[1], 0.0, (v.tops[0] - c).norm(), scale_[e * q_]});
    }
  }

  // 2b. Next to a concave corner the top of a regular neighbour can land on the corner's top, or
  // beyond it: at a right-angled corner whose neighbouring element is L long, the two tops are
  // |L - h| apart for a layer h high (the 30P-30N's cove corner: 4e-5 apart at h = 5e-3 c, a
  // near-duplicate node Gmsh's check rejects), and for h > L the element's quadrilateral folds.
  // Sec. II.B makes the intersection of the neighbours' normals the vertex of a single element
  // there; the robust reading: when the neighbour's top lies within kMergeShare of the smaller
  // height from the corner's, or its element's top would run against its base, the neighbour's top
  // becomes the corner's, the element between them a triangle (base and apex: collapsed()), and
  // the new front loses that element. Only regular neighbours merge, each into one corner.
  void merge_at_concave() {
    if (ne_ < 4) return;
    constexpr double kMergeShare = 0.25;
    for (std::size_t e = 0; e < ne_; ++e) {
      if (vt_[e].kind != VertexTop::Kind::Concave) continue;
      const Vec c = at(e * q_), top = vt_[e].tops[0];
      for (const std::size_t n : {(e + 1) % ne_, (e + ne_ - 1) % ne_}) {
        VertexTop& w = vt_[n];
        if (w.kind != VertexTop::Kind::Regular) continue;
        const Vec cn = at(n * q_);
        const double h = std::min((w.tops[0] - cn).norm(), (top - c).norm());
        // The element's base runs from the corner to n (n after e) or from n to the corner.
        const Vec base = n == (e + 1) % ne_ ? Vec(cn - c) : Vec(c - cn);
        const Vec top_edge = n == (e + 1) % ne_ ? Vec(w.tops[0] - top) : Vec(top - w.tops[0]);
        if ((w.tops[0] - top).norm() < kMergeShare * h || top_edge.dot(base) <= 0) {
          w.kind = VertexTop::Kind::Merged;
          w.merged_into = e;
          w.tops = {top};
        }
      }
    }
  }

  const std::vector<NodeId>& right_column(std::size_t e) const { return vt_[e % ne_].columns.back(); }
  const std::vector<NodeId>& left_column(std::size_t e) const { return vt_[e % ne_].columns.front(); }
  Vec right_top(std::size_t e) const { return vt_[e % ne_].tops.back(); }
  Vec left_top(std::size_t e) const { return vt_[e % ne_].tops.front(); }

  void emit_cell(std::size_t seq_first, int span) {
    for (const Lattice& l : quad_.lattice()) out_.built.cells[0].push_back(g_at(l[0], l[1]));
    out_.cell_seq.push_back(seq_first);
    out_.cell_extra.push_back(extra_);
    out_.cell_span.push_back(span);
  }
  void emit_front(NodeId a, NodeId b, const std::vector<NodeId>& interior, std::size_t seq_first, int span) {
    out_.top_seq.push_back(seq_first);
    out_.top_extra.push_back(extra_);
    out_.top_span.push_back(span);
    out_.top.elements.push_back(a);
    out_.top.elements.push_back(b);
    out_.top.elements.insert(out_.top.elements.end(), interior.begin(), interior.end());
    out_.top.corner.push_back(0);
  }

  // 4a. The fan at the start vertex of element e: kites between adjacent fan normals.
  void fan(std::size_t e) {
    const VertexTop& v = vt_[e];
    const std::size_t iv = e * q_;
    for (std::size_t k = 0; k + 1 < v.tops.size(); ++k) {
      const Vec& pk = v.tops[k];
      const Vec& pk1 = v.tops[k + 1];
      // X_k: perpendiculars to n_k at P_k and to n_k+1 at P_k+1 intersect.
      const Vec tk = left_normal(v.normals[k]), tk1 = left_normal(v.normals[k + 1]);
      Eigen::Matrix2d a;
      a.col(0) = tk;
      a.col(1) = -tk1;
      const Vec st = a.colPivHouseholderQr().solve(pk1 - pk);
      const Vec xk = pk + st[0] * tk;
      const Vec c = at(iv);
      // Kite lattice: (0,0) C, (Q,0) P_k+1, (Q,Q) X_k, (0,Q) P_k; bilinear.
      g_at(0, 0) = seq_[iv];
      for (int j = 1; j <= q_; ++j) {
        g_at(j, 0) = v.columns[k + 1][static_cast<std::size_t>(j - 1)];
        g_at(0, j) = v.columns[k][static_cast<std::size_t>(j - 1)];
      }
      for (int vv = 1; vv <= q_; ++vv)
        for (int u = 1; u <= q_; ++u) {
          const double s = static_cast<double>(u) / q_, t = static_cast<double>(vv) / q_;
          g_at(u, vv) = add_node((1 - s) * (1 - t) * c + s * (1 - t) * pk1 + s * t * xk + (1 - s) * t * pk);
        }
      emit_cell(iv, 1);
      std::vector<NodeId> inner;
      for (int u = 1; u < q_; ++u) inner.push_back(g_at(u, q_));
      emit_front(g_at(0, q_), g_at(q_, q_), inner, iv, 1);
      inner.clear();
      for (int vv = q_ - 1; vv >= 1; --vv) inner.push_back(g_at(q_, vv));
      emit_front(g_at(q_, q_), g_at(q_, 0), inner, iv, 1);
    }
  }

  // 4b. Element e with exactly one stopped end (isotropic_stop: node): a transition triangle from
  // the element to the moving node's top, x(xi, eta) = (1 - eta) base(xi / (1 - eta)) + eta P, P
  // the top (a collapsed quadrilateral: the base stays curved, the two other sides straight).
  void transition(std::size_t e, bool a_stopped) {
    const std::size_t iv = e * q_;
    const NodeId* base = el(e);
    const LagrangeElement& tri = lagrange_element(CellType::Triangle, q_);
    const Vec apex = a_stopped ? left_top(e + 1) : right_top(e);
    const std::vector<NodeId>& col = a_stopped ? left_column(e + 1) : right_column(e);
    std::vector<NodeId> ids;
    std::vector<NodeId> hyp(static_cast<std::size_t>(q_ + 1), -1);  // hypotenuse, by eta index j
    for (const Lattice& l : tri.lattice()) {
      const int i = l[0], j = l[1];
      NodeId id;
      if (j == 0) {
        id = i == 0 ? base[0] : i == q_ ? base[1] : base[1 + i];
      } else if (a_stopped && i + j == q_) {
        id = col[static_cast<std::size_t>(j - 1)];  // the moving end's column
      } else if (!a_stopped && i == 0) {
        id = col[static_cast<std::size_t>(j - 1)];
      } else {
        const double xi = static_cast<double>(i) / q_, eta = static_cast<double>(j) / q_;
        id = add_node((1 - eta) * base_point(base, xi / (1 - eta)) + eta * apex);
      }
      if ((a_stopped && i == 0) || (!a_stopped && i + j == q_)) hyp[static_cast<std::size_t>(j)] = id;
      ids.push_back(id);
    }
    out_.built.cells[1].insert(out_.built.cells[1].end(), ids.begin(), ids.end());
    out_.triangle_seq.push_back(iv);
    out_.triangle_extra.push_back(extra_);
    // The hypotenuse is the new front: stopped node -> top (a stopped) or top -> stopped node.
    std::vector<NodeId> inner;
    if (a_stopped) {
      for (int j = 1; j < q_; ++j) inner.push_back(hyp[static_cast<std::size_t>(j)]);
      emit_front(base[0], col.back(), inner, iv, q_);
    } else {
      for (int j = q_ - 1; j >= 1; --j) inner.push_back(hyp[static_cast<std::size_t>(j)]);
      emit_front(col.back(), base[1], inner, iv, q_);
    }
  }

  // 4b'. Element e whose two ends share one top (merge_at_concave): a triangle from the element
  // to that top, x(xi, eta) = (1 - eta) base(xi / (1 - eta)) + eta P, its sides the two end
  // columns; it adds nothing to the new front.
  void collapsed(std::size_t e) {
    const std::size_t iv = e * q_;
    const NodeId* base = el(e);
    const LagrangeElement& tri = lagrange_element(CellType::Triangle, q_);
    const Vec apex = right_top(e);
    const std::vector<NodeId>& col_a = right_column(e);
    const std::vector<NodeId>& col_b = left_column(e + 1);
    std::vector<NodeId> ids;
    for (const Lattice& l : tri.lattice()) {
      const int i = l[0], j = l[1];
      if (j == 0)
        ids.push_back(i == 0 ? base[0] : i == q_ ? base[1] : base[1 + i]);
      else if (i == 0)
        ids.push_back(col_a[static_cast<std::size_t>(j - 1)]);
      else if (i + j == q_)
        ids.push_back(col_b[static_cast<std::size_t>(j - 1)]);
      else {
        const double xi = static_cast<double>(i) / q_, eta = static_cast<double>(j) / q_;
        ids.push_back(add_node((1 - eta) * base_point(base, xi / (1 - eta)) + eta * apex));
      }
    }
    out_.built.cells[1].insert(out_.built.cells[1].end(), ids.begin(), ids.end());
    out_.triangle_seq.push_back(iv);
    out_.triangle_extra.push_back(extra_);
  }
  // The point at xi in [0, 1] of the curved element with nodes `base` (Gmsh line order).
  Vec base_point(const NodeId* base, double xi) const {
    const LagrangeElement& line = lagrange_element(CellType::Line, q_);
    double phi[max_order + 1];
    line.eval(&xi, phi);
    Vec p = Vec::Zero();
    for (int k = 0; k <= q_; ++k) p += phi[k] * mesh_.nodes[base[k]];
    return p;
  }

  // 4c. The regular element e: tops of its high-order nodes, attenuated (Fig. 5), and its quad.
  void regular(std::size_t e) {
    const std::size_t iv = e * q_;
    const Vec a_top = right_top(e), b_top = left_top(e + 1);
    std::vector<Vec> tops(static_cast<std::size_t>(q_ + 1));
    std::vector<double> heights(static_cast<std::size_t>(q_ + 1), 0.0);
    for (int k = 1; k < q_; ++k) {
      const std::size_t i = iv + k;
      const double s = static_cast<double>(k) / q_;
      heights[static_cast<std::size_t>(k)] =
          (p_.high_order_heights != layers::HighOrderHeights::Own ? (1 - s) * vt_[e].h + s * vt_[(e + 1) % ne_].h
                                                                           : height(at(i), normal_[i])) *
          scale_[i];
      tops[static_cast<std::size_t>(k)] = at(i) + heights[static_cast<std::size_t>(k)] * normal_[i];
    }
    // A straight element grows a straight top: its high-order tops are the linear interpolation
    // of its vertex tops (the attenuation target, Fig. 5), whatever the vertex normals. Offsets
    // along panel normals would bend it wherever the vertex normals are tilted (next to a fan),
    // only for the attenuation to straighten it again over several layers.
    bool straight = true;
    const Vec a0 = at(iv), b0 = at(iv + q_);
    for (int k = 1; k < q_ && straight; ++k) {
      const Vec x = at(iv + k), lin = a0 + (static_cast<double>(k) / q_) * (b0 - a0);
      straight = (x - lin).norm() <= straight_tolerance((b0 - a0).norm(), std::max(x.cwiseAbs().maxCoeff(), lin.cwiseAbs().maxCoeff()));
    }
    // Next to a concave corner the offsets of the high-order nodes run into the corner's merged
    // normal (at 90 degrees, one h along the wall from the corner they meet its top): the top
    // is taken straight there too.
    straight = straight || vt_[e].kind == VertexTop::Kind::Concave ||
               vt_[(e + 1) % ne_].kind == VertexTop::Kind::Concave || vt_[e].kind == VertexTop::Kind::Merged ||
               vt_[(e + 1) % ne_].kind == VertexTop::Kind::Merged;
    double clipped = 0;
    if (straight)
      for (int k = 1; k < q_; ++k)
        tops[static_cast<std::size_t>(k)] = a_top + (static_cast<double>(k) / q_) * (b_top - a_top);
    else
      clipped = attenuate(tops, a_top, b_top, heights, f_atten_);
    if (q_ == 1 && std::isfinite(f_atten_)) clipped = std::max(clipped, chord_sag_need(e, a_top, b_top));
    if (clipped > 0) out_.built.linear = false;
    out_.built.max_clipped_rel = std::max(out_.built.max_clipped_rel, clipped);
    const NodeId* base = el(e);
    for (int u = 0; u <= q_; ++u) g_at(u, 0) = u == 0 ? base[0] : u == q_ ? base[1] : base[1 + u];
    for (int j = 1; j <= q_; ++j) {
      g_at(0, j) = right_column(e)[static_cast<std::size_t>(j - 1)];
      g_at(q_, j) = left_column(e + 1)[static_cast<std::size_t>(j - 1)];
    }
    for (int u = 1; u < q_; ++u) {
      const Vec b = mesh_.nodes[base[1 + u]];
      const Vec top = tops[static_cast<std::size_t>(u)];
      for (int j = 1; j <= q_; ++j) g_at(u, j) = add_node(b + (static_cast<double>(j) / q_) * (top - b));
    }
    emit_cell(iv, q_);
    std::vector<NodeId> inner;
    for (int u = 1; u < q_; ++u) inner.push_back(g_at(u, q_));
    emit_front(g_at(0, q_), g_at(q_, q_), inner, iv, q_);
  }

  // Order 1 (no high-order node carries the wall's curvature): the chords of a linear front lie
  // off the curve they stand for by their sag, about L tan(theta / 4) / 2 for a chord of length
  // L between end normals theta apart (a circular arc), while the metric is the curve's (its wall
  // distance is to the splines). Where the layer height h is below the sag the metric seen from the
  // front is not the front's own (a first layer of h0 = 1e-6 c on chords sagging 1e-5 c puts its
  // chords' midpoints inside the wall law's finest sizes), and the advancing front fed with it
  // ran away in slivers. So at order 1 an element counts as curved, like an attenuated one of
  // higher order (Fig. 5), until sag <= f_atten h; the returned need is sag / h (0 once met), and
  // with stop_when_linear the layers go on until every chord is that flat against its height.
  double chord_sag_need(std::size_t e, const Vec& a_top, const Vec& b_top) const {
    // Next to a concave corner the merged normal turns by half the corner on a straight panel
    // (no sag): regular() grows such an element straight, and so it counts.
    if (vt_[e].kind == VertexTop::Kind::Concave || vt_[(e + 1) % ne_].kind == VertexTop::Kind::Concave ||
        vt_[e].kind == VertexTop::Kind::Merged || vt_[(e + 1) % ne_].kind == VertexTop::Kind::Merged)
      return 0;
    const Vec& na = vt_[e].normals.back();
    const Vec& nb = vt_[(e + 1) % ne_].normals.front();
    const double theta = std::abs(signed_angle(na, nb));
    const double sag = 0.5 * (b_top - a_top).norm() * std::tan(0.25 * theta);
    const double h = std::min((a_top - at(e)).norm(), (b_top - at(e + 1)).norm());
    if (!(h > 0) || sag <= f_atten_ * h) return 0;
    return sag / h;
  }

  HybridMesh<2>& mesh_;
  const MetricField<2>& metric_;
  const LayerParams& p_;
  const int q_;
  const CurvedFront<2>& front0_;
  const FrontLoop& loop_;
  const bool first_layer_;
  const std::vector<double>& scale_;
  const std::vector<std::uint8_t>& stopped_;
  const double f_atten_;
  const std::size_t ne_, n_;
  const double corner_rad_ = p_.corner_angle_deg * M_PI / 180;
  const LagrangeElement& quad_;
  std::vector<NodeId> grid_;
  std::vector<NodeId> seq_;
  std::vector<Vec> panel_, normal_;
  std::vector<double> turning_;
  std::vector<VertexTop> vt_;
  std::array<long, 2> extra_ = {-1, -1};  // the element being built's LoopLayer::*_extra entry
  LoopLayer out_;
};

// The wall loops of a 2D front as the parts of the generic layer core.
class LoopFronts final : public FrontGrower<2> {
 public:
  LoopFronts(HybridMesh<2>& mesh, const CurvedFront<2>& front0, std::vector<FrontLoop> loops,
             const MetricField<2>& metric, const LayerParams& p)
      : mesh_(mesh), front0_(front0), loops_(std::move(loops)), metric_(metric), p_(p), q_(front0.order) {}

  std::array<CellType, 2> cell_types() const override { return {CellType::Quadrilateral, CellType::Triangle}; }
  std::size_t num_parts() const override { return loops_.size(); }
  std::string part_name(std::size_t part) const override { return "loop " + loops_[part].tag; }
  std::size_t num_sites(std::size_t part) const override { return loops_[part].size() * static_cast<std::size_t>(q_); }
  std::size_t num_stop_points(std::size_t part) const override { return loops_[part].size(); }
  std::vector<Vec> stop_points(std::size_t part) const override {
    std::vector<Vec> v;
    const FrontLoop& l = loops_[part];
    for (std::size_t e = 0; e < l.size(); ++e) v.push_back(mesh_.nodes[l.elements[e * static_cast<std::size_t>(q_ + 1)]]);
    return v;
  }
  // Half of each chord of the loop's elements to each end.
  std::vector<double> stop_point_measure(std::size_t part) const override {
    const std::vector<Vec> v = stop_points(part);
    std::vector<double> m(v.size(), 0.0);
    for (std::size_t e = 0; e < v.size(); ++e) {
      const double half = 0.5 * (v[(e + 1) % v.size()] - v[e]).norm();
      m[e] += half;
      m[(e + 1) % v.size()] += half;
    }
    return m;
  }
  // The proximity rule (layer_core.h, step 1), its focal half: where the front is concave its
  // columns converge, and a column's layer may take at most kFocalShare of the distance to where
  // it meets a neighbour (graded_room, shared with the 3D front so that an extruded section grows
  // the section's layers; the E387's cove under the attenuation study's tallest stacks). Each
  // stop point's direction is the mean of its two chords' unit normals (the 3D front's
  // angle-weighted one on an extrusion). Gaps between facing walls are left to the front
  // crossings (collisions) in 2D: `share` is unused.
  std::vector<double> stop_point_room(std::size_t part, double /*share*/) const override {
    const std::vector<Vec> x = stop_points(part);
    const std::size_t n = x.size();
    std::vector<Vec> unit(n, Vec::Zero());
    std::vector<std::vector<std::pair<std::size_t, double>>> edges(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t prev = (k + n - 1) % n, next = (k + 1) % n;
      const Vec a = x[k] - x[prev], b = x[next] - x[k];
      if (a.norm() > 0 && b.norm() > 0) {
        const Vec m = left_normal(a.normalized()) + left_normal(b.normalized());
        if (m.norm() > 0) unit[k] = m.normalized();
      }
      edges[k] = {{prev, a.norm()}, {next, b.norm()}};
    }
    const double inf = std::numeric_limits<double>::infinity();
    return graded_room<2>(x, unit, edges, std::vector<double>(n, 0.0), std::vector<double>(n, inf));
  }
  BuiltLayer build(std::size_t part, int layer, const std::vector<double>& scale,
                   const std::vector<std::uint8_t>& stopped, double f_atten) override {
    pending_ = LoopLayerBuilder(mesh_, metric_, p_, q_, front0_, loops_[part], layer == 1, scale, stopped, f_atten)
                   .build();
    return std::move(pending_.built);
  }
  std::vector<std::size_t> collisions(std::size_t part) const override {
    std::vector<FrontSegment> segs;
    append_polyline(pending_.top, mesh_.nodes, q_, true, segs);
    const std::size_t mine = segs.size();
    for (std::size_t other = 0; other < loops_.size(); ++other)
      if (other != part) append_polyline(loops_[other], mesh_.nodes, q_, false, segs);
    std::vector<std::size_t> hits = front_crossings(std::move(segs), mine);
    const std::vector<std::size_t> folds = unclosable_elements(part);
    hits.insert(hits.end(), folds.begin(), folds.end());
    std::sort(hits.begin(), hits.end());
    hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
    return hits;
  }
  // The new front's elements that a straight-topped closing layer could not cover: a closing
  // cell's sides run along its end columns and its top is the chord lifted, so its Jacobian keeps
  // its sign for a tall enough top only where the base advances along its chord, x'(xi) . (b - a)
  // > 0 (the element is a graph over its chord). An element that turns back (an S or a hook; seen
  // at a leading edge after many shrunk layers, whose closing cells stayed invalid at any height)
  // grown from a base that did not is refused like a crossing, so a front that could be closed
  // stays closable (layer_core.h). A wall element that is no graph (one element around a cap
  // narrower than the mesh) is the geometry's; its layers are not held to it.
  std::vector<std::size_t> unclosable_elements(std::size_t part) const {
    std::vector<std::size_t> out;
    if (q_ < 2) return out;
    const FrontLoop& top = pending_.top;
    const FrontLoop& base = loops_[part];
    const std::size_t npe = static_cast<std::size_t>(q_ + 1);
    for (std::size_t e = 0; e < top.size(); ++e) {
      if (pending_.top_span[e] != q_) continue;  // a fan kite's or a transition's: straight
      const std::size_t b = pending_.top_seq[e] / static_cast<std::size_t>(q_);
      if (!advances_along_chord(top.elements.data() + e * npe) && advances_along_chord(base.elements.data() + b * npe))
        out.push_back(e);
    }
    return out;
  }
  // Whether the element's tangent keeps a component along its chord of at least a tenth of the
  // chord (the mean), sampled at 4Q + 1 points.
  bool advances_along_chord(const NodeId* n) const {
    const LagrangeElement& line = lagrange_element(CellType::Line, q_);
    double dphi[max_order + 1];
    const Vec chord = mesh_.nodes[n[1]] - mesh_.nodes[n[0]];
    const double c2 = chord.squaredNorm();
    if (!(c2 > 0)) return false;
    const int samples = 4 * q_;
    for (int k = 0; k <= samples; ++k) {
      const double xi = static_cast<double>(k) / samples;
      line.eval_grad(&xi, dphi);
      Vec d = Vec::Zero();
      for (int i = 0; i <= q_; ++i) d += dphi[i] * mesh_.nodes[n[i]];
      if (d.dot(chord) < 0.1 * c2) return false;
    }
    return true;
  }
  Vec front_point(std::size_t e) const override {
    return mesh_.nodes[pending_.top.elements[e * static_cast<std::size_t>(q_ + 1)]];
  }
  // Heights are scaled over the failing cell's or element's span of the node sequence and one
  // node beyond either end.
  void rescale(std::size_t part, const std::vector<LayerFailure>& failures, double factor,
               std::vector<double>& scale) const override {
    const std::size_t n = num_sites(part);
    for (const LayerFailure& f : failures) {
      std::size_t first;
      int span;
      std::array<long, 2> extra;
      if (f.block == LayerFailure::kFrontElement) {
        first = pending_.top_seq[f.index];
        span = pending_.top_span[f.index];
        extra = pending_.top_extra[f.index];
      } else if (f.block == 0) {
        first = pending_.cell_seq[f.index];
        span = pending_.cell_span[f.index];
        extra = pending_.cell_extra[f.index];
      } else {
        first = pending_.triangle_seq[f.index];
        span = q_;
        extra = pending_.triangle_extra[f.index];
      }
      for (int s2 = -1; s2 <= span + 1; ++s2) scale[(first + n - 1 + static_cast<std::size_t>(s2 + 1)) % n] *= factor;
      for (long x : extra)
        if (x >= 0) scale[static_cast<std::size_t>(x)] *= factor;
    }
  }
  void accept(std::size_t part) override { loops_[part] = std::move(pending_.top); }
  const std::vector<FrontLoop>& loops() const { return loops_; }

 private:
  HybridMesh<2>& mesh_;
  const CurvedFront<2>& front0_;
  std::vector<FrontLoop> loops_;
  const MetricField<2>& metric_;
  const LayerParams& p_;
  const int q_;
  LoopLayer pending_;
};

}  // namespace

double attenuate(std::vector<Vec>& tops, const Vec& a, const Vec& b, const std::vector<double>& heights,
                 double f_atten) {
  const std::size_t q = tops.size() - 1;
  if (q < 2) return 0;
  check_order(static_cast<int>(q));  // the targets below hold at most max_order + 1 nodes
  Vec targets[max_order + 1];
  for (std::size_t k = 1; k < q; ++k) targets[k] = a + (static_cast<double>(k) / static_cast<double>(q)) * (b - a);
  return attenuate<2>(tops.data() + 1, targets + 1, heights.data() + 1, q - 1, f_atten);
}

namespace {

LayerResult<2> grow_layers_once(const CurvedFront<2>& front, const MetricField<2>& metric, const LayerParams& p) {
  const int q = front.order;
  LayerResult<2> r;
  r.mesh.nodes = front.nodes;
  std::vector<FrontLoop> walls;
  std::vector<int> wall_source;
  for (std::size_t k = 0; k < front.loops.size(); ++k) {
    const FrontLoop& l = front.loops[k];
    if (l.kind != BoundaryKind::Wall) continue;
    const int tag = r.mesh.add_tag(l.tag, l.kind);
    CellBlock& b = r.mesh.boundary_block(CellType::Line, q, tag);
    b.connectivity.insert(b.connectivity.end(), l.elements.begin(), l.elements.end());
    walls.push_back(l);
    wall_source.push_back(static_cast<int>(k));
  }
  LoopFronts fronts(r.mesh, front, std::move(walls), metric, p);
  grow_fronts<2>(fronts, metric, p, q, r);
  r.outer.order = q;
  r.outer.nodes = r.mesh.nodes;
  r.outer.loops = fronts.loops();
  // The fill's boundary: the grown loops' outer fronts, then the loops that did not grow.
  r.fill_front.nodes = r.mesh.nodes;
  std::vector<std::uint8_t> grown(front.loops.size(), 0);
  for (std::size_t k = 0; k < r.outer.loops.size(); ++k) {
    r.fill_front.loops.push_back(linear_loop(r.outer, r.outer.loops[k], true, wall_source[k]));
    grown[static_cast<std::size_t>(wall_source[k])] = 1;
  }
  for (std::size_t k = 0; k < front.loops.size(); ++k)
    if (!grown[k]) r.fill_front.loops.push_back(linear_loop(front, front.loops[k], false, static_cast<int>(k)));
  return r;
}

}  // namespace

LayerResult<2> grow_layers(const CurvedFront<2>& front, const MetricField<2>& metric, const LayerParams& p) {
  check_order(front.order);
  LayerResult<2> r = grow_layers_once(front, metric, p);
  // The last resort of the closing guarantee (grow_layers_2d.h): a front that no closing layer
  // could make linear (a closing cell invalid at every height, e.g. where many shrunk layers met
  // a blunt trailing edge) is grown again from the wall with at most half as many layers, down to
  // one, and the fill gets the first front that closes. Layers are cheap (the whole stack in
  // 0.02-0.3 s on the shipped airfoils); an invalid mesh is not.
  LayerParams fewer = p;
  std::vector<std::string> earlier;
  // The limit falls strictly every round (the table may hold a partial closing row, so its size
  // alone need not shrink): the loop ends.
  while (p.close_linear && r.linear_after < 0 && r.layers.size() > 1 &&
         std::min(fewer.max_layers - 1, static_cast<int>(r.layers.size() / 2)) >= 1) {
    fewer.max_layers = std::min(fewer.max_layers - 1, static_cast<int>(r.layers.size() / 2));
    earlier.insert(earlier.end(), r.events.begin(), r.events.end());
    earlier.push_back("the front could not be closed after " + std::to_string(r.layers.size()) +
                      " layers; grown again with at most " + std::to_string(fewer.max_layers));
    r = grow_layers_once(front, metric, fewer);
  }
  if (!earlier.empty()) r.events.insert(r.events.begin(), earlier.begin(), earlier.end());
  return r;
}

}  // namespace plaf::layers
