// SPDX-License-Identifier: MIT
// Implements equispaced Lagrange elements in Gmsh's node order (see lagrange.h). The simplex
// bases use the barycentric product form phi = prod_v F_{a_v}(lambda_v) with
// F_a(l) = prod_{s<a} (Q l - s)/(s + 1); tensor cells multiply 1D Lagrange polynomials.
#include "modules/elements/lagrange.h"

#include <memory>

#include "modules/base/error.h"

namespace plaf {
inline namespace elements {
namespace {

Lattice add(const Lattice& a, const Lattice& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
Lattice sub(const Lattice& a, const Lattice& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Lattice mul(const Lattice& a, int s) {
  return {a[0] * s, a[1] * s, a[2] * s};
}
Lattice div(const Lattice& a, int s) {
  return {a[0] / s, a[1] / s, a[2] / s};
}

using Points = std::vector<Lattice>;

// Interior points of the segment a->b of order p, from a to b.
void edge_interior(const Lattice& a, const Lattice& b, int p, Points& out) {
  const Lattice e = div(sub(b, a), p);
  for (int s = 1; s < p; ++s) out.push_back(add(a, mul(e, s)));
}

// All points of a triangle a,b,c of order p in Gmsh's recursive order.
void triangle_points(const Lattice& a, const Lattice& b, const Lattice& c, int p, Points& out) {
  if (p == 0) {
    out.push_back(a);
    return;
  }
  out.push_back(a);
  out.push_back(b);
  out.push_back(c);
  edge_interior(a, b, p, out);
  edge_interior(b, c, p, out);
  edge_interior(c, a, p, out);
  if (p >= 3) {
    const Lattice e1 = div(sub(b, a), p), e2 = div(sub(c, a), p);
    triangle_points(add(a, add(e1, e2)), add(a, add(mul(e1, p - 2), e2)), add(a, add(e1, mul(e2, p - 2))), p - 3, out);
  }
}

// Interior points of triangle a,b,c of order p (those strictly inside), in Gmsh's order.
void triangle_interior(const Lattice& a, const Lattice& b, const Lattice& c, int p, Points& out) {
  if (p < 3) return;
  const Lattice e1 = div(sub(b, a), p), e2 = div(sub(c, a), p);
  triangle_points(add(a, add(e1, e2)), add(a, add(mul(e1, p - 2), e2)), add(a, add(e1, mul(e2, p - 2))), p - 3, out);
}

void quad_points(const Lattice& a, const Lattice& b, const Lattice& c, const Lattice& d, int p, Points& out);

void quad_interior(const Lattice& a, const Lattice& b, const Lattice& d, int p, Points& out) {
  if (p < 2) return;
  const Lattice e1 = div(sub(b, a), p), e2 = div(sub(d, a), p);
  const Lattice a1 = add(a, add(e1, e2));
  quad_points(a1, add(a1, mul(e1, p - 2)), add(a1, add(mul(e1, p - 2), mul(e2, p - 2))), add(a1, mul(e2, p - 2)), p - 2,
              out);
}

// All points of a quadrilateral a,b,c,d (counter-clockwise) of order p in Gmsh's recursive order.
void quad_points(const Lattice& a, const Lattice& b, const Lattice& c, const Lattice& d, int p, Points& out) {
  if (p == 0) {
    out.push_back(a);
    return;
  }
  out.push_back(a);
  out.push_back(b);
  out.push_back(c);
  out.push_back(d);
  edge_interior(a, b, p, out);
  edge_interior(b, c, p, out);
  edge_interior(c, d, p, out);
  edge_interior(d, a, p, out);
  quad_interior(a, b, d, p, out);
}

void tet_points(const std::array<Lattice, 4>& v, int p, Points& out);

// Gmsh's tetrahedron: vertices, edges, faces, interior (a tetrahedron of order p - 4).
void tet_points(const std::array<Lattice, 4>& v, int p, Points& out) {
  if (p == 0) {
    out.push_back(v[0]);
    return;
  }
  const CellTopology& topo = topology(CellType::Tetrahedron);
  for (const Lattice& x : v) out.push_back(x);
  for (const auto& e : topo.edges) edge_interior(v[e[0]], v[e[1]], p, out);
  for (const auto& f : topo.faces) triangle_interior(v[f[0]], v[f[1]], v[f[2]], p, out);
  if (p >= 4) {
    const Lattice e1 = div(sub(v[1], v[0]), p), e2 = div(sub(v[2], v[0]), p), e3 = div(sub(v[3], v[0]), p);
    const Lattice a = add(v[0], add(e1, add(e2, e3)));
    tet_points({a, add(a, mul(e1, p - 4)), add(a, mul(e2, p - 4)), add(a, mul(e3, p - 4))}, p - 4, out);
  }
}

Points prism_points(int p) {
  const std::array<Lattice, 6> v = {Lattice{0, 0, 0}, {p, 0, 0}, {0, p, 0}, {0, 0, p}, {p, 0, p}, {0, p, p}};
  const CellTopology& topo = topology(CellType::Prism);
  Points out(v.begin(), v.end());
  for (const auto& e : topo.edges) edge_interior(v[e[0]], v[e[1]], p, out);
  for (const auto& f : topo.faces) {
    if (f.size() == 3)
      triangle_interior(v[f[0]], v[f[1]], v[f[2]], p, out);
    else
      quad_interior(v[f[0]], v[f[1]], v[f[3]], p, out);
  }
  // Interior: for each interior point of the triangle (Gmsh order), the interior line of w in
  // Gmsh's line order (ends first).
  // The triangle has interior points only from p = 3 on.
  if (p >= 3) {
    Points tri, line{{0, 0, 1}, {0, 0, p - 1}};
    triangle_interior({0, 0, 0}, {p, 0, 0}, {0, p, 0}, p, tri);
    edge_interior({0, 0, 1}, {0, 0, p - 1}, p - 2, line);
    for (const Lattice& t : tri)
      for (const Lattice& w : line) out.push_back({t[0], t[1], w[2]});
  }
  return out;
}

// ---- VTK orders --------------------------------------------------------------------------

Points vtk_quad_points(int p) {
  const Lattice a{0, 0, 0}, b{p, 0, 0}, c{p, p, 0}, d{0, p, 0};
  Points out{a, b, c, d};
  edge_interior(a, b, p, out);
  edge_interior(b, c, p, out);
  edge_interior(d, c, p, out);  // VTK runs the last two edges along +u and +v
  edge_interior(a, d, p, out);
  for (int j = 1; j < p; ++j)
    for (int i = 1; i < p; ++i) out.push_back({i, j, 0});
  return out;
}

Points vtk_tet_points(int p) {
  const std::array<Lattice, 4> v = {Lattice{0, 0, 0}, {p, 0, 0}, {0, p, 0}, {0, 0, p}};
  Points out(v.begin(), v.end());
  const int edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (const auto& e : edges) edge_interior(v[e[0]], v[e[1]], p, out);
  // Face interiors as VTK 9 orders them (checked against vtkLagrangeTetra up to Q = 4).
  const int faces[4][3] = {{0, 1, 3}, {2, 3, 1}, {0, 3, 2}, {0, 2, 1}};
  for (const auto& f : faces) triangle_interior(v[f[0]], v[f[1]], v[f[2]], p, out);
  if (p >= 4) {
    Points inner;
    tet_points({Lattice{1, 1, 1}, {p - 3, 1, 1}, {1, p - 3, 1}, {1, 1, p - 3}}, p - 4, inner);
    out.insert(out.end(), inner.begin(), inner.end());
  }
  return out;
}

Points vtk_wedge_points(int p) {
  const std::array<Lattice, 6> v = {Lattice{0, 0, 0}, {p, 0, 0}, {0, p, 0}, {0, 0, p}, {p, 0, p}, {0, p, p}};
  Points out(v.begin(), v.end());
  const int edges[9][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}};
  for (const auto& e : edges) edge_interior(v[e[0]], v[e[1]], p, out);
  triangle_interior(v[0], v[1], v[2], p, out);  // VTK orients both triangles alike
  triangle_interior(v[3], v[4], v[5], p, out);
  const int quads[3][4] = {{0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}};
  for (const auto& q : quads) {
    const Lattice e1 = div(sub(v[q[1]], v[q[0]]), p), e2 = div(sub(v[q[3]], v[q[0]]), p);
    for (int j = 1; j < p; ++j)
      for (int i = 1; i < p; ++i) out.push_back(add(v[q[0]], add(mul(e1, i), mul(e2, j))));
  }
  Points tri;
  triangle_interior(v[0], v[1], v[2], p, tri);
  for (int k = 1; k < p; ++k)
    for (const Lattice& t : tri) out.push_back({t[0], t[1], k});
  return out;
}

// F_a(l) = prod_{s<a} (Q l - s)/(s + 1) and its derivative, for a = 0..Q.
void simplex_factors(double l, int q, double* f, double* df) {
  f[0] = 1.0;
  df[0] = 0.0;
  for (int a = 1; a <= q; ++a) {
    const double t = (q * l - (a - 1)) / a;
    f[a] = f[a - 1] * t;
    df[a] = df[a - 1] * t + f[a - 1] * q / a;
  }
}

// L_i(u) = prod_{n != i} (Q u - n)/(i - n) and its derivative, for i = 0..Q.
void line_factors(double u, int q, double* l, double* dl) {
  for (int i = 0; i <= q; ++i) {
    double v = 1.0, d = 0.0;
    for (int n = 0; n <= q; ++n) {
      if (n == i) continue;
      const double t = (q * u - n) / (i - n), dt = static_cast<double>(q) / (i - n);
      d = d * t + v * dt;
      v *= t;
    }
    l[i] = v;
    dl[i] = d;
  }
}

}  // namespace

int ref_dim(CellType type) {
  switch (type) {
    case CellType::Line:
      return 1;
    case CellType::Triangle:
    case CellType::Quadrilateral:
      return 2;
    case CellType::Tetrahedron:
    case CellType::Prism:
      return 3;
  }
  return 0;
}

int num_vertices(CellType type) {
  switch (type) {
    case CellType::Line:
      return 2;
    case CellType::Triangle:
      return 3;
    case CellType::Quadrilateral:
      return 4;
    case CellType::Tetrahedron:
      return 4;
    case CellType::Prism:
      return 6;
  }
  return 0;
}

int num_nodes(CellType type, int q) {
  switch (type) {
    case CellType::Line:
      return q + 1;
    case CellType::Triangle:
      return (q + 1) * (q + 2) / 2;
    case CellType::Quadrilateral:
      return (q + 1) * (q + 1);
    case CellType::Tetrahedron:
      return (q + 1) * (q + 2) * (q + 3) / 6;
    case CellType::Prism:
      return (q + 1) * (q + 1) * (q + 2) / 2;
  }
  return 0;
}

const char* cell_name(CellType type) {
  switch (type) {
    case CellType::Line:
      return "line";
    case CellType::Triangle:
      return "triangle";
    case CellType::Quadrilateral:
      return "quadrilateral";
    case CellType::Tetrahedron:
      return "tetrahedron";
    case CellType::Prism:
      return "prism";
  }
  return "?";
}

void check_order(int order) {
  if (order < 1 || order > max_order)
    throw ConfigError("geometry order " + std::to_string(order) + " is outside 1.." + std::to_string(max_order));
}

const CellTopology& topology(CellType type) {
  // Gmsh's local edges and (outward-oriented) faces.
  static const CellTopology line{{{0, 1}}, {}};
  static const CellTopology tri{{{0, 1}, {1, 2}, {2, 0}}, {}};
  static const CellTopology quad{{{0, 1}, {1, 2}, {2, 3}, {3, 0}}, {}};
  static const CellTopology tet{{{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}},
                                {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {3, 1, 2}}};
  static const CellTopology prism{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 4}, {2, 5}, {3, 4}, {3, 5}, {4, 5}},
                                  {{0, 2, 1}, {3, 4, 5}, {0, 1, 4, 3}, {0, 3, 5, 2}, {1, 2, 5, 4}}};
  switch (type) {
    case CellType::Line:
      return line;
    case CellType::Triangle:
      return tri;
    case CellType::Quadrilateral:
      return quad;
    case CellType::Tetrahedron:
      return tet;
    case CellType::Prism:
      return prism;
  }
  return line;
}

std::vector<Lattice> gmsh_lattice(CellType type, int p) {
  check_order(p);
  Points out;
  switch (type) {
    case CellType::Line:
      out = {{0, 0, 0}, {p, 0, 0}};
      edge_interior({0, 0, 0}, {p, 0, 0}, p, out);
      break;
    case CellType::Triangle:
      triangle_points({0, 0, 0}, {p, 0, 0}, {0, p, 0}, p, out);
      break;
    case CellType::Quadrilateral:
      quad_points({0, 0, 0}, {p, 0, 0}, {p, p, 0}, {0, p, 0}, p, out);
      break;
    case CellType::Tetrahedron:
      tet_points({Lattice{0, 0, 0}, {p, 0, 0}, {0, p, 0}, {0, 0, p}}, p, out);
      break;
    case CellType::Prism:
      out = prism_points(p);
      break;
  }
  return out;
}

std::vector<Lattice> vtk_lattice(CellType type, int p) {
  check_order(p);
  switch (type) {
    case CellType::Line:
    case CellType::Triangle:
      return gmsh_lattice(type, p);
    case CellType::Quadrilateral:
      return vtk_quad_points(p);
    case CellType::Tetrahedron:
      return vtk_tet_points(p);
    case CellType::Prism:
      return vtk_wedge_points(p);
  }
  return {};
}

namespace {

// CGNS (SIDS "Unstructured Grid Element Numbering Conventions", with the cubic and quartic
// extensions of Yu and Wang): corners, edge interiors (each from its first corner to its second),
// face interiors, cell interior. A triangle face of order 3 holds its centroid; of order 4 the
// points nearest its first, second and third corner in the order given. A quadrilateral face's
// interior runs from the point next to its first corner A toward its second B, round in the
// face's own direction (order 4: the ring of eight, then the centre).
void cgns_triangle_interior(const Lattice& a, const Lattice& b, const Lattice& c, int p, Points& out) {
  if (p == 3) out.push_back(div(add(add(a, b), c), 3));
  if (p == 4)
    for (const auto& [x, y, z] : {std::array{a, b, c}, std::array{b, a, c}, std::array{c, a, b}})
      out.push_back(div(add(mul(x, 2), add(y, z)), 4));
}

void cgns_quad_interior(const Lattice& a, const Lattice& b, const Lattice& d, int p, Points& out) {
  static const std::vector<std::array<int, 2>> ring[5] = {
      {}, {}, {{1, 1}}, {{1, 1}, {2, 1}, {2, 2}, {1, 2}},
      {{1, 1}, {2, 1}, {3, 1}, {3, 2}, {3, 3}, {2, 3}, {1, 3}, {1, 2}, {2, 2}}};
  const Lattice u = div(sub(b, a), p), v = div(sub(d, a), p);
  for (const auto& [i, j] : ring[p]) out.push_back(add(a, add(mul(u, i), mul(v, j))));
}

}  // namespace

std::vector<Lattice> cgns_lattice(CellType type, int p) {
  check_order(p);
  const std::vector<Lattice> g = gmsh_lattice(type, 1);  // the corners, scaled to order p below
  Points c;
  for (const Lattice& x : g) c.push_back(mul(x, p));
  Points out = c;
  auto edges = [&](std::initializer_list<std::array<int, 2>> list) {
    for (const auto& [a, b] : list) edge_interior(c[static_cast<std::size_t>(a)], c[static_cast<std::size_t>(b)], p, out);
  };
  switch (type) {
    case CellType::Line:
      edges({{0, 1}});
      break;
    case CellType::Triangle:
      edges({{0, 1}, {1, 2}, {2, 0}});
      cgns_triangle_interior(c[0], c[1], c[2], p, out);
      break;
    case CellType::Quadrilateral:
      edges({{0, 1}, {1, 2}, {2, 3}, {3, 0}});
      cgns_quad_interior(c[0], c[1], c[3], p, out);
      break;
    case CellType::Tetrahedron:
      edges({{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}});
      // F1 (N1, N3, N2) with its interior in the order N1, N2, N3; F2 (N1, N2, N4); F3 (N2, N3, N4);
      // F4 (N3, N1, N4).
      cgns_triangle_interior(c[0], c[1], c[2], p, out);
      cgns_triangle_interior(c[0], c[1], c[3], p, out);
      cgns_triangle_interior(c[1], c[2], c[3], p, out);
      cgns_triangle_interior(c[2], c[0], c[3], p, out);
      if (p == 4) out.push_back({1, 1, 1});
      break;
    case CellType::Prism:
      edges({{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 4}, {2, 5}, {3, 4}, {4, 5}, {5, 3}});
      // The bottom triangle (N1, N3, N2; interior in the order N1, N2, N3), the quadrilaterals
      // F1 (N1, N2, N5, N4), F2 (N2, N3, N6, N5), F3 (N3, N1, N4, N6), the top (N4, N5, N6), then
      // the interior layer by layer upward, each as a triangle interior.
      cgns_triangle_interior(c[0], c[1], c[2], p, out);
      cgns_quad_interior(c[0], c[1], c[3], p, out);
      cgns_quad_interior(c[1], c[2], c[4], p, out);
      cgns_quad_interior(c[2], c[0], c[5], p, out);
      cgns_triangle_interior(c[3], c[4], c[5], p, out);
      for (int k = 1; k < p; ++k)
        cgns_triangle_interior({0, 0, k}, {p, 0, k}, {0, p, k}, p, out);
      break;
  }
  return out;
}

std::vector<int> lattice_permutation(const std::vector<Lattice>& from, const std::vector<Lattice>& to) {
  std::vector<int> perm(to.size(), -1);
  for (std::size_t k = 0; k < to.size(); ++k)
    for (std::size_t i = 0; i < from.size(); ++i)
      if (from[i] == to[k]) perm[k] = static_cast<int>(i);
  for (int p : perm)
    if (p < 0 || from.size() != to.size()) throw Error("two node orders of different lattice points");
  return perm;
}

LagrangeElement::LagrangeElement(CellType type, int order)
    : type_(type), order_(order), dim_(ref_dim(type)), lattice_(gmsh_lattice(type, order)) {
  const int p = order;
  // find() by table: the layers look up a node per cell node (every tetrahedron cut from a prism).
  const std::size_t side = static_cast<std::size_t>(p + 1);
  index_.assign(side * side * side, -1);
  for (std::size_t i = 0; i < lattice_.size(); ++i) {
    const Lattice& l = lattice_[i];
    index_[(static_cast<std::size_t>(l[0]) * side + static_cast<std::size_t>(l[1])) * side + static_cast<std::size_t>(l[2])] =
        static_cast<int>(i);
  }
  const CellTopology& topo = topology(type);
  auto index_all = [&](const Points& pts) {
    std::vector<int> idx;
    for (const Lattice& x : pts) idx.push_back(find(x));
    return idx;
  };
  for (const auto& e : topo.edges) {
    Points pts{lattice_[e[0]]};
    edge_interior(lattice_[e[0]], lattice_[e[1]], p, pts);
    pts.push_back(lattice_[e[1]]);
    edge_nodes_.push_back(index_all(pts));
  }
  if (type == CellType::Line) {
    facet_nodes_ = {{0}, {1}};
  } else if (dim_ == 2) {
    for (const auto& e : topo.edges) {
      Points pts{lattice_[e[0]], lattice_[e[1]]};
      edge_interior(lattice_[e[0]], lattice_[e[1]], p, pts);
      facet_nodes_.push_back(index_all(pts));  // Gmsh line order: ends first, then interior
    }
  } else {
    for (const auto& f : topo.faces) {
      Points pts;
      if (f.size() == 3)
        triangle_points(lattice_[f[0]], lattice_[f[1]], lattice_[f[2]], p, pts);
      else
        quad_points(lattice_[f[0]], lattice_[f[1]], lattice_[f[2]], lattice_[f[3]], p, pts);
      facet_nodes_.push_back(index_all(pts));
    }
  }
}

int LagrangeElement::find(const Lattice& l) const {
  const int side = order_ + 1;
  for (int d = 0; d < 3; ++d)
    if (l[static_cast<std::size_t>(d)] < 0 || l[static_cast<std::size_t>(d)] >= side) return -1;
  return index_[static_cast<std::size_t>((l[0] * side + l[1]) * side + l[2])];
}

std::array<double, 3> LagrangeElement::ref_node(int i) const {
  std::array<double, 3> x{0, 0, 0};
  for (int d = 0; d < dim_; ++d) x[d] = static_cast<double>(lattice_[i][d]) / order_;
  return x;
}

void LagrangeElement::eval(const double* xi, double* phi) const {
  // Values only: reuse the gradient path's factor tables (cheap: O(Q) per coordinate).
  const int q = order_;
  double f[3][max_order + 1], df[3][max_order + 1], f0[max_order + 1], df0[max_order + 1];
  switch (type_) {
    case CellType::Line:
      line_factors(xi[0], q, f[0], df[0]);
      for (int i = 0; i < size(); ++i) phi[i] = f[0][lattice_[i][0]];
      return;
    case CellType::Quadrilateral:
      line_factors(xi[0], q, f[0], df[0]);
      line_factors(xi[1], q, f[1], df[1]);
      for (int i = 0; i < size(); ++i) phi[i] = f[0][lattice_[i][0]] * f[1][lattice_[i][1]];
      return;
    case CellType::Triangle:
    case CellType::Prism:
      simplex_factors(xi[0], q, f[0], df[0]);
      simplex_factors(xi[1], q, f[1], df[1]);
      simplex_factors(1.0 - xi[0] - xi[1], q, f0, df0);
      if (type_ == CellType::Prism) line_factors(xi[2], q, f[2], df[2]);
      for (int i = 0; i < size(); ++i) {
        const Lattice& l = lattice_[i];
        phi[i] = f[0][l[0]] * f[1][l[1]] * f0[q - l[0] - l[1]];
        if (type_ == CellType::Prism) phi[i] *= f[2][l[2]];
      }
      return;
    case CellType::Tetrahedron:
      for (int d = 0; d < 3; ++d) simplex_factors(xi[d], q, f[d], df[d]);
      simplex_factors(1.0 - xi[0] - xi[1] - xi[2], q, f0, df0);
      for (int i = 0; i < size(); ++i) {
        const Lattice& l = lattice_[i];
        phi[i] = f[0][l[0]] * f[1][l[1]] * f[2][l[2]] * f0[q - l[0] - l[1] - l[2]];
      }
      return;
  }
}

void LagrangeElement::eval_grad(const double* xi, double* dphi) const {
  const int q = order_;
  double f[3][max_order + 1], df[3][max_order + 1], f0[max_order + 1], df0[max_order + 1];
  switch (type_) {
    case CellType::Line:
      line_factors(xi[0], q, f[0], df[0]);
      for (int i = 0; i < size(); ++i) dphi[i] = df[0][lattice_[i][0]];
      return;
    case CellType::Quadrilateral:
      line_factors(xi[0], q, f[0], df[0]);
      line_factors(xi[1], q, f[1], df[1]);
      for (int i = 0; i < size(); ++i) {
        const Lattice& l = lattice_[i];
        dphi[2 * i] = df[0][l[0]] * f[1][l[1]];
        dphi[2 * i + 1] = f[0][l[0]] * df[1][l[1]];
      }
      return;
    case CellType::Triangle:
    case CellType::Prism: {
      simplex_factors(xi[0], q, f[0], df[0]);
      simplex_factors(xi[1], q, f[1], df[1]);
      simplex_factors(1.0 - xi[0] - xi[1], q, f0, df0);
      const bool prism = type_ == CellType::Prism;
      if (prism) line_factors(xi[2], q, f[2], df[2]);
      for (int i = 0; i < size(); ++i) {
        const Lattice& l = lattice_[i];
        const int k = q - l[0] - l[1];
        const double a = f[0][l[0]], b = f[1][l[1]], c = f0[k];
        // d/du: lambda1 = u, lambda0 = 1 - u - v.
        const double du = df[0][l[0]] * b * c - a * b * df0[k];
        const double dv = a * df[1][l[1]] * c - a * b * df0[k];
        if (prism) {
          const double w = f[2][l[2]], dw = df[2][l[2]];
          dphi[3 * i] = du * w;
          dphi[3 * i + 1] = dv * w;
          dphi[3 * i + 2] = a * b * c * dw;
        } else {
          dphi[2 * i] = du;
          dphi[2 * i + 1] = dv;
        }
      }
      return;
    }
    case CellType::Tetrahedron:
      for (int d = 0; d < 3; ++d) simplex_factors(xi[d], q, f[d], df[d]);
      simplex_factors(1.0 - xi[0] - xi[1] - xi[2], q, f0, df0);
      for (int i = 0; i < size(); ++i) {
        const Lattice& l = lattice_[i];
        const int m = q - l[0] - l[1] - l[2];
        const double a = f[0][l[0]], b = f[1][l[1]], c = f[2][l[2]], z = f0[m];
        dphi[3 * i] = df[0][l[0]] * b * c * z - a * b * c * df0[m];
        dphi[3 * i + 1] = a * df[1][l[1]] * c * z - a * b * c * df0[m];
        dphi[3 * i + 2] = a * b * df[2][l[2]] * z - a * b * c * df0[m];
      }
      return;
  }
}

const LagrangeElement& lagrange_element(CellType type, int order) {
  check_order(order);
  // All 20 elements are built once, thread-safely, on first use; lookups never lock.
  using Table = std::array<std::array<std::unique_ptr<LagrangeElement>, max_order + 1>, 5>;
  static const Table table = [] {
    Table t;
    for (int c = 0; c < 5; ++c)
      for (int q = 1; q <= max_order; ++q) t[c][q] = std::make_unique<LagrangeElement>(static_cast<CellType>(c), q);
    return t;
  }();
  return *table[static_cast<int>(type)][order];
}

}  // namespace elements
}  // namespace plaf
