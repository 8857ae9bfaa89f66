// SPDX-License-Identifier: MIT
// Prismatic layers in 2D (see grow_layers.h for the steps and the paper's sections).
#include "layers/grow_layers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"
#include "modules/elements/validity.h"

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
  enum class Kind { Regular, Concave, Convex, Stopped } kind = Kind::Regular;
  std::vector<Vec> normals;                  // fan normals n_0 (left panel) .. n_m (right panel); one otherwise
  std::vector<Vec> tops;                     // P_k
  std::vector<std::vector<NodeId>> columns;  // Q node ids (j = 1..Q) per top
};

class LoopLayer {
 public:
  LoopLayer(HybridMesh<2>& mesh, const MetricField<2>& metric, const LayerParams& p, int q)
      : mesh_(mesh), metric_(metric), p_(p), q_(q) {}

  // The layer's height along unit normal n at x (Sec. II.B): the metric size, or the distance
  // to unit metric length along the normal.
  double height(const Vec& x, const Vec& n) const {
    const double h = metric_.evaluate(x).size_along(n);
    if (!p_.integrate_height) return h;
    // Unit metric length along x + s n: fixed point s <- s / L(s) on L(s), the metric length of
    // the segment (3-point Gauss).
    double s = h;
    for (int it = 0; it < 8; ++it) {
      const double l = metric_length<2>(metric_, x, Vec(x + s * n), 3);
      if (std::abs(l - 1) < 1e-10) break;
      s /= l;
    }
    return s;
  }

  NodeId add_node(const Vec& x) {
    mesh_.nodes.push_back(x);
    return static_cast<NodeId>(mesh_.nodes.size() - 1);
  }

  // Column of Q nodes from base (excluded) to top (included), uniform.
  std::vector<NodeId> column(const Vec& base, const Vec& top) {
    std::vector<NodeId> c;
    for (int j = 1; j <= q_; ++j) c.push_back(add_node(base + (static_cast<double>(j) / q_) * (top - base)));
    return c;
  }

  HybridMesh<2>& mesh_;
  const MetricField<2>& metric_;
  const LayerParams& p_;
  int q_;
};

struct BuiltLayer {
  std::vector<NodeId> triangles;          // transition triangles next to stopped nodes, Gmsh order
  std::vector<std::size_t> triangle_seq;  // per triangle: the sequence index of its base's start
  std::vector<NodeId> cells;              // quads, Gmsh order
  std::vector<std::size_t> cell_seq;      // per cell: the sequence index of its first base node
  std::vector<int> cell_span;             // per cell: how many sequence indices its base spans
  FrontLoop top;
  std::vector<std::size_t> top_seq;  // per new front element: the sequence index it grew from
  std::vector<int> top_span;         // ... and how many sequence indices its base spans
  double max_clipped_rel = 0;
  bool linear = true;
};

// Segments of a front loop's polyline through all its nodes (linear and high-order), with the
// index of the element each belongs to.
struct Segment {
  Vec a, b;
  std::size_t element;
  std::size_t index;  // position along its polyline
  bool mine;          // on the new front being checked (else an obstacle)
};

void polyline(const FrontLoop& l, const std::vector<Vec>& x, int q, bool mine, std::vector<Segment>& out) {
  std::size_t index = 0;
  for (std::size_t e = 0; e < l.size(); ++e) {
    const NodeId* el = l.elements.data() + e * static_cast<std::size_t>(q + 1);
    NodeId prev = el[0];
    for (int k = 1; k <= q; ++k) {
      const NodeId next = k < q ? el[1 + k] : el[1];
      out.push_back({x[prev], x[next], e, index++, mine});
      prev = next;
    }
  }
}

// Exact (predicates.h): rounding never hides a crossing nor invents one.
bool cross(const Segment& s, const Segment& t) {
  return segments_cross_properly(s.a, s.b, t.a, t.b);
}

// Elements of the new front that cross an obstacle segment or a non-adjacent segment of the new
// front itself: a sweep over x, O((n + k) log n).
std::vector<std::size_t> crossings(std::vector<Segment> segs, std::size_t mine_count) {
  std::sort(segs.begin(), segs.end(),
            [](const Segment& a, const Segment& b) { return std::min(a.a.x(), a.b.x()) < std::min(b.a.x(), b.b.x()); });
  std::vector<std::size_t> hits;
  std::vector<const Segment*> active;
  for (const Segment& s : segs) {
    const double x0 = std::min(s.a.x(), s.b.x());
    std::erase_if(active, [&](const Segment* t) { return std::max(t->a.x(), t->b.x()) < x0; });
    for (const Segment* t : active) {
      if (!s.mine && !t->mine) continue;
      if (s.mine && t->mine) {
        const std::size_t d = s.index > t->index ? s.index - t->index : t->index - s.index;
        if (d <= 1 || d + 1 >= mine_count) continue;  // neighbours share a node
      }
      if (std::max(s.a.y(), s.b.y()) < std::min(t->a.y(), t->b.y()) ||
          std::max(t->a.y(), t->b.y()) < std::min(s.a.y(), s.b.y()))
        continue;
      if (cross(s, *t)) {
        if (s.mine) hits.push_back(s.element);
        if (t->mine) hits.push_back(t->element);
      }
    }
    active.push_back(&s);
  }
  std::sort(hits.begin(), hits.end());
  hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
  return hits;
}

// One layer on one loop; `scale` multiplies the height of every node of the loop sequence.
BuiltLayer build_layer(LoopLayer& g, const CurvedFront<2>& front0, const Geometry2D& geometry, const FrontLoop& loop,
                       bool first_layer, const std::vector<double>& scale, const std::vector<std::uint8_t>& stopped) {
  const int q = g.q_;
  const std::size_t ne = loop.size();
  const std::size_t n = ne * static_cast<std::size_t>(q);
  const auto& x = g.mesh_.nodes;
  auto el = [&](std::size_t e) { return loop.elements.data() + e * static_cast<std::size_t>(q + 1); };
  // 1. The loop as a sequence of nodes: element e's start, then its interior nodes.
  std::vector<NodeId> seq(n);
  for (std::size_t e = 0; e < ne; ++e) {
    seq[e * q] = el(e)[0];
    for (int k = 1; k < q; ++k) seq[e * q + k] = el(e)[1 + k];
  }
  // By value: add_node appends to the node array, which may move it.
  auto at = [&](std::size_t i) -> Vec { return x[seq[i % n]]; };
  std::vector<Vec> panel(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec d = at(i + 1) - at(i);
    if (!(d.norm() > 0)) throw MesherError("layers: two consecutive front nodes coincide on loop " + loop.tag);
    panel[i] = d.normalized();
  }
  // 2. Normals: the spline's on the first layer, averaged panel normals afterwards.
  const SplineLoop* spline = first_layer && loop.geometry_loop >= 0
                                 ? &geometry.loops[static_cast<std::size_t>(loop.geometry_loop)].loop
                                 : nullptr;
  std::vector<Vec> normal(n);
  std::vector<double> turning(n, 0.0);
  const double corner_rad = g.p_.corner_angle_deg * M_PI / 180;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec& before = panel[(i + n - 1) % n];
    turning[i] = signed_angle(before, panel[i]);
    normal[i] = (left_normal(before) + left_normal(panel[i])).normalized();
    const NodeId id = seq[i];
    const bool vertex = i % q == 0;
    const bool corner = vertex && std::abs(turning[i]) > corner_rad;
    if (spline && !corner && static_cast<std::size_t>(id) < front0.params.size())
      normal[i] = spline->normal(front0.params[id]);
  }
  if (g.p_.smooth_normals) {
    std::vector<Vec> s = normal;
    for (std::size_t i = 0; i < n; ++i)
      if (!(i % q == 0 && std::abs(turning[i]) > corner_rad))
        s[i] = (normal[(i + n - 1) % n] + 2 * normal[i] + normal[(i + 1) % n]).normalized();
    normal = s;
  }

  // 3. Tops of the linear nodes: regular, concave (merged normal) or convex (fan).
  std::vector<VertexTop> vt(ne);
  for (std::size_t e = 0; e < ne; ++e) {
    const std::size_t i = e * q;
    const Vec c = at(i);
    VertexTop& v = vt[e];
    const Vec n_left = left_normal(panel[(i + n - 1) % n]), n_right = left_normal(panel[i]);
    if (stopped[e]) {
      v.kind = VertexTop::Kind::Stopped;
      continue;  // no top, no column: the node does not move
    }
    if (turning[i] > corner_rad) {
      // Concave (left turn). Sec. II.B makes the intersection of the neighbours' normals the
      // vertex of a single element spanning both panels; with panels long against the layer
      // height that vertex lies far out and distorts the neighbours, so we use the robust merged
      // normal instead: the bisector, long enough (h / cos(half angle)) that both panels' layers
      // keep the height h — the intersection of the two offset panels.
      v.kind = VertexTop::Kind::Concave;
      const Vec m = (n_left + n_right).normalized();
      const double h = g.height(c, m) * scale[i];
      v.normals = {m};
      v.tops = {c + h / std::max(m.dot(n_left), 0.1) * m};
    } else if (turning[i] < -corner_rad) {
      // Convex (right turn), Fig. 4: normals dividing the corner angle equally.
      v.kind = VertexTop::Kind::Convex;
      const int m = std::max(1, static_cast<int>(std::ceil(-turning[i] / (g.p_.fan_angle_deg * M_PI / 180) - 1e-9)));
      // One height for the whole fan: unequal neighbouring heights would fold the kites, and at
      // the corner point itself the metric's frame belongs to one side only (the wall normal is
      // one-sided there), so the size along the other side's normal can be the size along the
      // wall. Every fan normal takes the smaller of the two sides' heights.
      const double h_corner = std::min(g.height(c, n_left), g.height(c, n_right)) * scale[i];
      for (int k = 0; k <= m; ++k) {
        const Vec nk = rotate(n_left, turning[i] * k / m);
        v.normals.push_back(nk);
        v.tops.push_back(c + h_corner * nk);
      }
    } else {
      v.normals = {normal[i]};
      v.tops = {c + g.height(c, normal[i]) * scale[i] * normal[i]};
    }
    for (const Vec& t : v.tops) v.columns.push_back(g.column(c, t));
  }
  auto right_column = [&](std::size_t e) -> const std::vector<NodeId>& { return vt[e % ne].columns.back(); };
  auto left_column = [&](std::size_t e) -> const std::vector<NodeId>& { return vt[e % ne].columns.front(); };
  auto right_top = [&](std::size_t e) { return vt[e % ne].tops.back(); };
  auto left_top = [&](std::size_t e) { return vt[e % ne].tops.front(); };

  BuiltLayer out;
  out.top.tag = loop.tag;
  out.top.kind = loop.kind;
  out.top.geometry_loop = loop.geometry_loop;
  const LagrangeElement& quad = lagrange_element(CellType::Quadrilateral, q);
  std::vector<NodeId> grid(static_cast<std::size_t>((q + 1) * (q + 1)));
  auto g_at = [&](int u, int v) -> NodeId& { return grid[static_cast<std::size_t>(v * (q + 1) + u)]; };
  auto emit_cell = [&](std::size_t seq_first, int span) {
    for (const Lattice& l : quad.lattice()) out.cells.push_back(g_at(l[0], l[1]));
    out.cell_seq.push_back(seq_first);
    out.cell_span.push_back(span);
  };
  auto emit_front = [&](NodeId a, NodeId b, const std::vector<NodeId>& interior, std::size_t seq_first, int span) {
    out.top_seq.push_back(seq_first);
    out.top_span.push_back(span);
    out.top.elements.push_back(a);
    out.top.elements.push_back(b);
    out.top.elements.insert(out.top.elements.end(), interior.begin(), interior.end());
    out.top.corner.push_back(0);
  };

  for (std::size_t e = 0; e < ne; ++e) {
    // 4a. The fan at the start vertex of element e (kites between adjacent fan normals).
    const VertexTop& v = vt[e];
    const std::size_t iv = e * q;
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
      g_at(0, 0) = seq[iv];
      for (int j = 1; j <= q; ++j) {
        g_at(j, 0) = v.columns[k + 1][j - 1];
        g_at(0, j) = v.columns[k][j - 1];
      }
      for (int vv = 1; vv <= q; ++vv)
        for (int u = 1; u <= q; ++u) {
          const double s = static_cast<double>(u) / q, t = static_cast<double>(vv) / q;
          g_at(u, vv) = g.add_node((1 - s) * (1 - t) * c + s * (1 - t) * pk1 + s * t * xk + (1 - s) * t * pk);
        }
      emit_cell(iv, 1);
      std::vector<NodeId> inner;
      for (int u = 1; u < q; ++u) inner.push_back(g_at(u, q));
      emit_front(g_at(0, q), g_at(q, q), inner, iv, 1);
      inner.clear();
      for (int vv = q - 1; vv >= 1; --vv) inner.push_back(g_at(q, vv));
      emit_front(g_at(q, q), g_at(q, 0), inner, iv, 1);
    }

    // 4b. Elements next to stopped nodes (isotropic_stop: node): both stopped, the element
    // stays in the front; one stopped, a transition triangle from the element to the moving
    // node's top, x(xi, eta) = (1 - eta) base(xi / (1 - eta)) + eta P, P the top (a collapsed
    // quadrilateral: the base stays curved, the two other sides straight).
    const bool a_stopped = vt[e].kind == VertexTop::Kind::Stopped;
    const bool b_stopped = vt[(e + 1) % ne].kind == VertexTop::Kind::Stopped;
    if (a_stopped || b_stopped) {
      const NodeId* base = el(e);
      if (a_stopped && b_stopped) {
        emit_front(base[0], base[1], std::vector<NodeId>(base + 2, base + q + 1), iv, q);
        continue;
      }
      const LagrangeElement& tri = lagrange_element(CellType::Triangle, q);
      const LagrangeElement& line = lagrange_element(CellType::Line, q);
      const Vec apex = a_stopped ? left_top(e + 1) : right_top(e);
      const std::vector<NodeId>& column = a_stopped ? left_column(e + 1) : right_column(e);
      double phi[max_order + 1];
      auto base_at = [&](double s) {
        line.eval(&s, phi);
        Vec p = Vec::Zero();
        for (int k = 0; k <= q; ++k) p += phi[k] * x[base[k]];
        return p;
      };
      std::vector<NodeId> ids;
      std::vector<NodeId> hyp(static_cast<std::size_t>(q + 1), -1);  // hypotenuse, by eta index j
      for (const Lattice& l : tri.lattice()) {
        const int i = l[0], j = l[1];
        NodeId id;
        if (j == 0) {
          id = i == 0 ? base[0] : i == q ? base[1] : base[1 + i];
        } else if (a_stopped && i + j == q) {
          id = column[static_cast<std::size_t>(j - 1)];  // the moving end's column
        } else if (!a_stopped && i == 0) {
          id = column[static_cast<std::size_t>(j - 1)];
        } else {
          const double xi = static_cast<double>(i) / q, eta = static_cast<double>(j) / q;
          id = g.add_node((1 - eta) * base_at(xi / (1 - eta)) + eta * apex);
        }
        if ((a_stopped && i == 0) || (!a_stopped && i + j == q)) hyp[static_cast<std::size_t>(j)] = id;
        ids.push_back(id);
      }
      out.triangles.insert(out.triangles.end(), ids.begin(), ids.end());
      out.triangle_seq.push_back(iv);
      // The hypotenuse is the new front: stopped node -> top (a stopped) or top -> stopped node.
      std::vector<NodeId> inner;
      if (a_stopped) {
        for (int j = 1; j < q; ++j) inner.push_back(hyp[static_cast<std::size_t>(j)]);
        emit_front(base[0], column.back(), inner, iv, q);
      } else {
        for (int j = q - 1; j >= 1; --j) inner.push_back(hyp[static_cast<std::size_t>(j)]);
        emit_front(column.back(), base[1], inner, iv, q);
      }
      continue;
    }

    // 4c. The regular element e: tops of its high-order nodes, attenuated (Fig. 5).
    const Vec a_top = right_top(e), b_top = left_top(e + 1);
    std::vector<Vec> tops(static_cast<std::size_t>(q + 1));
    std::vector<double> heights(static_cast<std::size_t>(q + 1), 0.0);
    for (int k = 1; k < q; ++k) {
      const std::size_t i = iv + k;
      heights[static_cast<std::size_t>(k)] = g.height(at(i), normal[i]) * scale[i];
      tops[static_cast<std::size_t>(k)] = at(i) + heights[static_cast<std::size_t>(k)] * normal[i];
    }
    // A straight element grows a straight top: its high-order tops are the linear interpolation
    // of its vertex tops (the attenuation target, Fig. 5), whatever the vertex normals. Offsets
    // along panel normals would bend it wherever the vertex normals are tilted (next to a fan),
    // only for the attenuation to straighten it again over several layers.
    bool straight = true;
    const Vec a0 = at(iv), b0 = at(iv + q);
    for (int k = 1; k < q && straight; ++k)
      straight = (at(iv + k) - (a0 + (static_cast<double>(k) / q) * (b0 - a0))).norm() <= 1e-12 * (b0 - a0).norm();
    // Next to a concave corner the offsets of the high-order nodes run into the corner's merged
    // normal (at 90 degrees, one h along the wall from the corner they meet its top): the top
    // is taken straight there too.
    straight = straight || vt[e].kind == VertexTop::Kind::Concave || vt[(e + 1) % ne].kind == VertexTop::Kind::Concave;
    double clipped = 0;
    if (straight)
      for (int k = 1; k < q; ++k)
        tops[static_cast<std::size_t>(k)] = a_top + (static_cast<double>(k) / q) * (b_top - a_top);
    else
      clipped = attenuate(tops, a_top, b_top, heights, g.p_.f_atten);
    if (clipped > 0) out.linear = false;
    out.max_clipped_rel = std::max(out.max_clipped_rel, clipped);
    const NodeId* base = el(e);
    for (int u = 0; u <= q; ++u) g_at(u, 0) = u == 0 ? base[0] : u == q ? base[1] : base[1 + u];
    for (int j = 1; j <= q; ++j) {
      g_at(0, j) = right_column(e)[j - 1];
      g_at(q, j) = left_column(e + 1)[j - 1];
    }
    for (int u = 1; u < q; ++u) {
      const Vec b = x[base[1 + u]];
      const Vec top = tops[static_cast<std::size_t>(u)];
      for (int j = 1; j <= q; ++j) g_at(u, j) = g.add_node(b + (static_cast<double>(j) / q) * (top - b));
    }
    emit_cell(iv, q);
    std::vector<NodeId> inner;
    for (int u = 1; u < q; ++u) inner.push_back(g_at(u, q));
    emit_front(g_at(0, q), g_at(q, q), inner, iv, q);
  }
  return out;
}

}  // namespace

double attenuate(std::vector<Vec>& tops, const Vec& a, const Vec& b, const std::vector<double>& heights,
                 double f_atten) {
  const std::size_t q = tops.size() - 1;
  double clipped = 0;
  for (std::size_t k = 1; k < q; ++k) {
    const Vec target = a + (static_cast<double>(k) / static_cast<double>(q)) * (b - a);
    Vec d = target - tops[k];
    const double need = d.norm(), limit = f_atten * heights[k];
    if (need > limit) {
      d *= limit / need;
      clipped = std::max(clipped, need / heights[k]);
    }
    tops[k] += d;
  }
  return clipped;
}

LayerResult grow_layers(const CurvedFront<2>& front, const Geometry2D& geometry, const MetricField<2>& metric,
                        const LayerParams& p) {
  check_order(front.order);
  const int q = front.order;
  LayerResult r;
  r.mesh.nodes = front.nodes;
  CellBlock quads{CellType::Quadrilateral, q, -1, {}};
  CellBlock tris{CellType::Triangle, q, -1, {}};  // transition cells next to stopped nodes
  std::vector<FrontLoop> loops;
  for (const FrontLoop& l : front.loops) {
    if (l.kind != BoundaryKind::Wall) continue;
    const int tag = r.mesh.add_tag(l.tag, l.kind);
    CellBlock& b = r.mesh.boundary_block(CellType::Line, q, tag);
    b.connectivity.insert(b.connectivity.end(), l.elements.begin(), l.elements.end());
    loops.push_back(l);
  }
  std::vector<bool> growing(loops.size(), true);
  JacobianCertifier certifier;
  LoopLayer g(r.mesh, metric, p, q);
  std::vector<double> coords;
  std::vector<double> loop_clip(loops.size(), 0.0);
  std::vector<bool> loop_linear(loops.size(), false);
  // One layer of loop li: build, certify every new cell, check collisions; shrink the heights
  // around failures and retry. False when it still fails after the shrink attempts.
  auto try_layer = [&](LoopLayer& gen, std::size_t li, int layer, std::vector<double>& scale,
                       const std::vector<std::uint8_t>& stopped, LayerStats& st, BuiltLayer& built) {
    const FrontLoop& loop = loops[li];
    const std::size_t n = loop.size() * static_cast<std::size_t>(q);
    bool accepted = false;
    for (int attempt = 0; attempt <= p.shrink_attempts && !accepted; ++attempt) {
      const std::size_t nodes_before = r.mesh.nodes.size();
      built = build_layer(gen, front, geometry, loop, layer == 1, scale, stopped);
      // Certify every new cell; shrink the heights under the invalid ones.
      const int npc = num_nodes(CellType::Quadrilateral, q);
      coords.resize(static_cast<std::size_t>(npc) * 2);
      std::vector<std::size_t> bad;
      for (std::size_t c = 0; c * npc < built.cells.size(); ++c) {
        for (int k = 0; k < npc; ++k)
          for (int d = 0; d < 2; ++d)
            coords[static_cast<std::size_t>(2 * k + d)] = r.mesh.nodes[built.cells[c * npc + k]][d];
        if (!certifier.certify(CellType::Quadrilateral, q, coords.data()).valid) bad.push_back(c);
      }
      std::string why = "invalid cells";
      std::vector<std::pair<std::size_t, int>> shrink;  // (sequence index, span) to shrink
      for (std::size_t c : bad) shrink.push_back({built.cell_seq[c], built.cell_span[c]});
      Vec where = bad.empty() ? Vec::Zero() : r.mesh.nodes[built.cells[bad[0] * static_cast<std::size_t>(npc)]];
      const int tpc = num_nodes(CellType::Triangle, q);
      for (std::size_t c = 0; c * tpc < built.triangles.size(); ++c) {
        for (int k = 0; k < tpc; ++k)
          for (int d = 0; d < 2; ++d)
            coords[static_cast<std::size_t>(2 * k + d)] = r.mesh.nodes[built.triangles[c * tpc + k]][d];
        if (!certifier.certify(CellType::Triangle, q, coords.data()).valid) {
          if (shrink.empty()) where = r.mesh.nodes[built.triangles[c * tpc]];
          shrink.push_back({built.triangle_seq[c], q});
        }
      }
      if (shrink.empty()) {
        // Collisions: the new front may not cross another loop's front nor itself.
        std::vector<Segment> segs;
        polyline(built.top, r.mesh.nodes, q, true, segs);
        const std::size_t mine = segs.size();
        for (std::size_t lj = 0; lj < loops.size(); ++lj)
          if (lj != li) polyline(loops[lj], r.mesh.nodes, q, false, segs);
        const std::vector<std::size_t> hits = crossings(std::move(segs), mine);
        for (std::size_t h : hits) shrink.push_back({built.top_seq[h], built.top_span[h]});
        if (!hits.empty()) {
          why = "front crossings (a collision)";
          where = r.mesh.nodes[built.top.elements[hits[0] * static_cast<std::size_t>(q + 1)]];
        }
      }
      if (shrink.empty()) {
        accepted = true;
        break;
      }
      r.mesh.nodes.resize(nodes_before);
      for (const auto& [first, span] : shrink)
        for (int s2 = -1; s2 <= span + 1; ++s2) {
          const std::size_t i = (first + n - 1 + static_cast<std::size_t>(s2 + 1)) % n;
          scale[i] *= 0.5;
        }
      st.shrinks += shrink.size();
      r.events.push_back("layer " + std::to_string(layer) + ", loop " + loop.tag + ": " +
                         std::to_string(shrink.size()) + " " + why + " (first at " + std::to_string(where.x()) +
                         ", " + std::to_string(where.y()) + "), heights halved around them");
    }
    return accepted;
  };
  for (int layer = 1; layer <= p.max_layers; ++layer) {
    LayerStats st;
    st.layer = layer;
    st.first_cell = quads.size();
    bool any = false, all_linear = true;
    for (std::size_t li = 0; li < loops.size(); ++li) {
      if (!growing[li]) continue;
      const FrontLoop& loop = loops[li];
      const std::size_t n = loop.size() * static_cast<std::size_t>(q);
      // Isotropic stop: where the metric is isotropic at a front node, a layer would be as tall
      // as the metric's size in every direction: no more anisotropic layer is wanted there.
      std::vector<std::uint8_t> stopped(loop.size(), 0);
      if (p.isotropic_stop != "off") {
        std::size_t iso = 0, total = 0;
        for (std::size_t e = 0; e < loop.size(); ++e) {
          const Vec c = r.mesh.nodes[loop.elements[e * static_cast<std::size_t>(q + 1)]];
          const auto d = metric.evaluate(c).decompose();
          ++total;
          if (d.sizes[0] >= 0.999 * d.sizes[1]) {
            ++iso;
            stopped[e] = p.isotropic_stop == "node" ? 1 : 0;
          }
        }
        if (p.isotropic_stop == "node" && iso == total) {
          growing[li] = false;
          r.events.push_back("layer " + std::to_string(layer) + ", loop " + loop.tag +
                             ": stopped, the metric is isotropic at every node");
          continue;
        }
        if ((p.isotropic_stop == "all" && iso == total) || (p.isotropic_stop == "any" && iso > 0)) {
          growing[li] = false;
          r.events.push_back("layer " + std::to_string(layer) + ", loop " + loop.tag +
                             ": stopped, the metric is isotropic at " + std::to_string(iso) + " of " +
                             std::to_string(total) + " nodes");
          continue;
        }
      }
      std::vector<double> scale(n, 1.0);
      BuiltLayer built;
      if (!try_layer(g, li, layer, scale, stopped, st, built)) {
        growing[li] = false;
        r.events.push_back("layer " + std::to_string(layer) + ", loop " + loop.tag +
                           ": stopped, cells still invalid or colliding after " + std::to_string(p.shrink_attempts) +
                           " shrinks");
        continue;
      }
      loop_clip[li] = built.max_clipped_rel;
      loop_linear[li] = built.linear;
      any = true;
      quads.connectivity.insert(quads.connectivity.end(), built.cells.begin(), built.cells.end());
      tris.connectivity.insert(tris.connectivity.end(), built.triangles.begin(), built.triangles.end());
      st.transition_cells += built.triangles.size() / static_cast<std::size_t>(num_nodes(CellType::Triangle, q));
      st.max_clipped_rel = std::max(st.max_clipped_rel, built.max_clipped_rel);
      all_linear = all_linear && built.linear;
      loops[li] = std::move(built.top);
    }
    if (!any) break;
    st.cells = quads.size() - st.first_cell;
    st.linear = all_linear;
    r.layers.push_back(st);
    if (st.linear && r.linear_after < 0) r.linear_after = layer;
    if (st.linear && p.stop_when_linear) break;
  }
  // The fill (Sec. II.C) starts from a linear front. A loop that stopped, or ran out of layers,
  // while its front is still curved gets one closing layer with straight tops (unlimited
  // attenuation), tall enough to clear its curved front: heights of 1.5, 3, then 6 times the
  // attenuation move still needed (at least the metric height). The paper stops the layers once
  // the front is linear and does not meet this case; a taller last cell is the robust choice
  // (a valid mesh over metric conformity there).
  if (p.close_linear) {
    LayerParams pl = p;
    pl.f_atten = std::numeric_limits<double>::infinity();
    LoopLayer gl(r.mesh, metric, pl, q);
    LayerStats st;
    st.layer = static_cast<int>(r.layers.size()) + 1;
    st.first_cell = quads.size();
    bool any = false;
    for (std::size_t li = 0; li < loops.size(); ++li) {
      if (loop_linear[li]) continue;
      const std::size_t n = loops[li].size() * static_cast<std::size_t>(q);
      const std::vector<std::uint8_t> stopped(loops[li].size(), 0);
      bool closed = false;
      for (double factor : {1.5, 3.0, 6.0}) {
        std::vector<double> scale(n, std::max(1.0, factor * loop_clip[li]));
        BuiltLayer built;
        if (!try_layer(gl, li, st.layer, scale, stopped, st, built) || !built.linear) continue;
        quads.connectivity.insert(quads.connectivity.end(), built.cells.begin(), built.cells.end());
        tris.connectivity.insert(tris.connectivity.end(), built.triangles.begin(), built.triangles.end());
        r.events.push_back("layer " + std::to_string(st.layer) + ", loop " + loops[li].tag +
                           ": a closing layer with straight tops (heights x" + std::to_string(scale[0]) + ")");
        loops[li] = std::move(built.top);
        loop_linear[li] = closed = any = true;
        break;
      }
      if (!closed)
        r.events.push_back("layer " + std::to_string(st.layer) + ", loop " + loops[li].tag +
                           ": no valid closing layer; the front stays curved");
    }
    if (any) {
      st.cells = quads.size() - st.first_cell;
      st.linear = std::all_of(loop_linear.begin(), loop_linear.end(), [](bool b) { return b; });
      r.layers.push_back(st);
      if (st.linear && r.linear_after < 0) r.linear_after = st.layer;
    }
  }
  if (!quads.connectivity.empty()) r.mesh.cells.push_back(std::move(quads));
  if (!tris.connectivity.empty()) r.mesh.cells.push_back(std::move(tris));
  r.outer.order = q;
  r.outer.nodes = r.mesh.nodes;
  r.outer.loops = loops;
  return r;
}

}  // namespace plaf::layers
