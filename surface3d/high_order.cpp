// SPDX-License-Identifier: MIT
// High-order surface triangles: node placement on the reference, certification against the flat
// triangle, straightening of invalid triangles, area and the HybridMesh view (high_order.h).
#include "surface3d/high_order.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/elements/lagrange.h"
#include "modules/metric/metric.h"

namespace plaf {
namespace {

using FaceHandle = TriMesh::FaceHandle;
using EdgeHandle = TriMesh::EdgeHandle;
using HalfedgeHandle = TriMesh::HalfedgeHandle;

// The fractions of a node's displacement (from its flat position) kept by the straightening steps.
constexpr double pullback_steps[] = {0.75, 0.5, 0.25, 0.0};

// The three half-edges of face f in the order of its vertices (v0 -> v1, v1 -> v2, v2 -> v0),
// which is Gmsh's edge order of the triangle.
std::array<HalfedgeHandle, 3> face_halfedges(const TriMesh& m, FaceHandle f) {
  const HalfedgeHandle h0 = m.halfedge_handle(f);
  const HalfedgeHandle h1 = m.next_halfedge_handle(h0);
  return {h0, h1, m.next_halfedge_handle(h1)};
}

// The straight edge's equispaced interior points k / q, k = 1..q-1, from a to b.
Eigen::Vector3d edge_point(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int k, int q) {
  return a + (b - a) * (static_cast<double>(k) / q);
}

// Node positions as flat + t (curved - flat), with a factor t per edge and per face that only
// decreases (1: curved, 0: flat). Keeps the curved positions so that every step is measured
// from them, and writes the current positions into the surface's properties.
class Curving {
 public:
  Curving(TriSurface& s, const ReferenceGeometry<3>& reference, int q) : s_(s), m_(s.mesh), q_(q) {
    const std::size_t ne = m_.n_edges(), nf = m_.n_faces();
    edge_curved_.resize(ne);
    edge_t_.assign(ne, 1.0);
    face_curved_.resize(nf);
    face_t_.assign(nf, 1.0);
    place_edges(reference);
    place_faces(reference);
  }

  bool is_feature(EdgeHandle e) const {
    return m_.property(s_.edge_curve, e) >= 0 || m_.property(s_.edge_feature, e) != EdgeFeature::Smooth;
  }

  // Lowers the factor of edge e to at most t and rewrites its nodes; true if it changed.
  bool pull_edge(EdgeHandle e, double t) {
    const auto i = static_cast<std::size_t>(e.idx());
    if (edge_t_[i] <= t) return false;
    edge_t_[i] = t;
    const HalfedgeHandle h = m_.halfedge_handle(e, 0);
    const Eigen::Vector3d a = m_.point(m_.from_vertex_handle(h)), b = m_.point(m_.to_vertex_handle(h));
    std::vector<Eigen::Vector3d>& nodes = m_.property(s_.edge_nodes, e);
    for (int k = 1; k < q_; ++k) {
      const Eigen::Vector3d flat = edge_point(a, b, k, q_);
      nodes[static_cast<std::size_t>(k - 1)] = flat + t * (edge_curved_[i][static_cast<std::size_t>(k - 1)] - flat);
    }
    return true;
  }

  void pull_face(FaceHandle f, double t) {
    const auto i = static_cast<std::size_t>(f.idx());
    if (face_t_[i] <= t) return;
    face_t_[i] = t;
    const std::vector<Eigen::Vector3d> flat = flat_face_nodes(f);
    std::vector<Eigen::Vector3d>& nodes = m_.property(s_.face_nodes, f);
    for (std::size_t k = 0; k < nodes.size(); ++k) nodes[k] = flat[k] + t * (face_curved_[i][k] - flat[k]);
  }

 private:
  void place_edges(const ReferenceGeometry<3>& reference) {
    const int num_curves = reference.num_curves();
    for (const EdgeHandle e : m_.edges()) {
      const int curve = m_.property(s_.edge_curve, e);
      const HalfedgeHandle h = m_.halfedge_handle(e, 0);
      const Eigen::Vector3d a = m_.point(m_.from_vertex_handle(h)), b = m_.point(m_.to_vertex_handle(h));
      if (curve >= num_curves)
        throw MesherError("curve_surface: edge " + std::to_string(e.idx()) + " from " + point_text(a) +
                          " lies on curve " + std::to_string(curve) + " but the reference geometry has " +
                          std::to_string(num_curves) + " curves");
      std::vector<Eigen::Vector3d>& curved = edge_curved_[static_cast<std::size_t>(e.idx())];
      curved.clear();
      for (int k = 1; k < q_; ++k) {
        const Eigen::Vector3d p = edge_point(a, b, k, q_);
        const Eigen::Vector3d x = curve >= 0 ? reference.project_to_curve(p, curve) : reference.project(p);
        if (!x.allFinite())
          throw MesherError("curve_surface: the reference geometry projects the point " + point_text(p) + " of edge " +
                            std::to_string(e.idx()) + " to a non-finite point");
        curved.push_back(x);
      }
      m_.property(s_.edge_nodes, e) = curved;
    }
  }

  // Face nodes: the flat lattice point moved by the blended displacements of the three curved
  // edges, then projected. Edge i (vertices a -> b) contributes (l_a + l_b)^2 d_i(l_b / (l_a + l_b))
  // at barycentric coordinates l, where d_i(s) is the edge's displacement from its chord (the
  // order-q interpolant of its nodes' displacements): it is d_i on edge i, vanishes on the other
  // two edges (d_i(0) = d_i(1) = 0) and at the opposite vertex, and for q = 2 reproduces the
  // quadratic Lagrange interior exactly.
  // Only the tangential part of each node's displacement is blended (its component along the
  // reference normal at the node removed): the projection restores the normal part anyway, and
  // blending it too shifts the face nodes sideways by O(h^3) (normals differ by O(h) across the
  // triangle), which on the sphere limits the area error to O(h^4) at Q = 4. On a smooth surface
  // the edge nodes' displacements are normal, so the face nodes are the projected lattice points;
  // nodes of a feature-curve edge, pulled along the surface toward their curve, carry the face
  // nodes with them.
  void place_faces(const ReferenceGeometry<3>& reference) {
    const int n_face = num_nodes(CellType::Triangle, q_) - 3 * q_;
    const LagrangeElement& tri = lagrange_element(CellType::Triangle, q_);
    const LagrangeElement& line = lagrange_element(CellType::Line, q_);
    std::vector<int> line_interior;  // Gmsh index of the line node at k / q, k = 1..q-1
    for (int k = 1; k < q_; ++k) line_interior.push_back(line.find({k, 0, 0}));
    std::vector<double> phi(static_cast<std::size_t>(line.size()));
    constexpr std::array<std::array<int, 2>, 3> edge_ends = {{{0, 1}, {1, 2}, {2, 0}}};
    for (const FaceHandle f : m_.faces()) {
      std::vector<Eigen::Vector3d>& curved = face_curved_[static_cast<std::size_t>(f.idx())];
      curved.clear();
      if (n_face > 0) {
        // s_.triangle_nodes: vertices and oriented edge nodes (face nodes still flat or empty).
        const std::vector<Eigen::Vector3d> nodes = s_.triangle_nodes(f);
        std::array<std::vector<Eigen::Vector3d>, 3> disp;
        for (int i = 0; i < 3; ++i)
          for (int k = 1; k < q_; ++k) {
            const Eigen::Vector3d& a = nodes[static_cast<std::size_t>(edge_ends[i][0])];
            const Eigen::Vector3d& b = nodes[static_cast<std::size_t>(edge_ends[i][1])];
            const Eigen::Vector3d& x = nodes[static_cast<std::size_t>(3 + i * (q_ - 1) + k - 1)];
            const Eigen::Vector3d d = x - edge_point(a, b, k, q_);
            Eigen::Vector3d n = reference.normal(x);
            n = n.allFinite() && n.norm() > 0 ? n.normalized() : Eigen::Vector3d::Zero();
            disp[i].push_back(d - d.dot(n) * n);
          }
        for (int j = 3 * q_; j < tri.size(); ++j) {
          const std::array<double, 3> r = tri.ref_node(j);
          const std::array<double, 3> l = {1 - r[0] - r[1], r[0], r[1]};
          Eigen::Vector3d x = nodes[0] * l[0] + nodes[1] * l[1] + nodes[2] * l[2];
          for (int i = 0; i < 3; ++i) {
            const double la = l[static_cast<std::size_t>(edge_ends[i][0])];
            const double lb = l[static_cast<std::size_t>(edge_ends[i][1])];
            const double sum = la + lb;  // > 0 at interior lattice points
            const double u = lb / sum;
            line.eval(&u, phi.data());
            for (int k = 1; k < q_; ++k)
              x += sum * sum * phi[static_cast<std::size_t>(line_interior[static_cast<std::size_t>(k - 1)])] *
                   disp[i][static_cast<std::size_t>(k - 1)];
          }
          const Eigen::Vector3d y = reference.project(x);
          if (!y.allFinite())
            throw MesherError("curve_surface: the reference geometry projects the point " + point_text(x) +
                              " of face " + std::to_string(f.idx()) + " to a non-finite point");
          curved.push_back(y);
        }
      }
      m_.property(s_.face_nodes, f) = curved;
    }
  }

  std::vector<Eigen::Vector3d> flat_face_nodes(FaceHandle f) const {
    const auto fv = s_.face_vertices(f);
    const Eigen::Vector3d p0 = m_.point(fv[0]), p1 = m_.point(fv[1]), p2 = m_.point(fv[2]);
    const LagrangeElement& tri = lagrange_element(CellType::Triangle, q_);
    std::vector<Eigen::Vector3d> out;
    for (int j = 3 * q_; j < tri.size(); ++j) {
      const std::array<double, 3> r = tri.ref_node(j);
      out.push_back(p0 * (1 - r[0] - r[1]) + p1 * r[0] + p2 * r[1]);
    }
    return out;
  }

  TriSurface& s_;
  TriMesh& m_;
  int q_;
  std::vector<std::vector<Eigen::Vector3d>> edge_curved_, face_curved_;
  std::vector<double> edge_t_, face_t_;
};

JacobianBounds certify_face(const TriSurface& s, JacobianCertifier& certifier, FaceHandle f) {
  const std::vector<Eigen::Vector3d> nodes = s.triangle_nodes(f);
  return certify_surface_triangle(certifier, s.order, nodes.data());
}

}  // namespace

CurvingReport curve_surface(TriSurface& s, const ReferenceGeometry<3>& reference, int order,
                            const ValidityOptions& validity, double min_scaled_jacobian) {
  check_order(order);
  TriMesh& m = s.mesh;
  s.order = order;
  JacobianCertifier certifier(validity);
  CurvingReport report;
  std::vector<char> was_invalid(m.n_faces(), 0);

  if (order > 1) {
    Curving curving(s, reference, order);
    // Good: valid, its scaled Jacobian at least the floor asked for.
    const auto good = [&](FaceHandle f) {
      const JacobianBounds jb = certify_face(s, certifier, f);
      return jb.valid && jb.scaled_lower() >= min_scaled_jacobian;
    };
    std::deque<FaceHandle> work;
    for (const FaceHandle f : m.faces())
      if (!good(f)) {
        work.push_back(f);
        was_invalid[static_cast<std::size_t>(f.idx())] = 1;
      }
    // Straighten until no face is invalid or below the floor, or nothing more can move. Every
    // straightening lowers at least one factor among finitely many values, so the loop ends.
    while (!work.empty()) {
      const FaceHandle f = work.front();
      work.pop_front();
      if (good(f)) continue;  // a neighbour's straightening fixed it
      was_invalid[static_cast<std::size_t>(f.idx())] = 1;
      const auto hs = face_halfedges(m, f);
      std::array<bool, 3> moved{false, false, false};
      bool valid = false;
      for (int phase = 0; phase < 2 && !valid; ++phase)  // phase 1 also moves feature-curve edges
        for (double t : pullback_steps) {
          curving.pull_face(f, t);
          for (int i = 0; i < 3; ++i) {
            const EdgeHandle e = m.edge_handle(hs[static_cast<std::size_t>(i)]);
            if (phase == 1 || !curving.is_feature(e)) moved[static_cast<std::size_t>(i)] |= curving.pull_edge(e, t);
          }
          if (good(f)) {
            valid = true;
            break;
          }
        }
      // The neighbours across moved edges changed: certify them again.
      for (int i = 0; i < 3; ++i) {
        if (!moved[static_cast<std::size_t>(i)]) continue;
        const HalfedgeHandle opposite = m.opposite_halfedge_handle(hs[static_cast<std::size_t>(i)]);
        if (!m.is_boundary(opposite)) work.push_back(m.face_handle(opposite));
      }
    }
  } else {
    for (const EdgeHandle e : m.edges()) m.property(s.edge_nodes, e).clear();
    for (const FaceHandle f : m.faces()) m.property(s.face_nodes, f).clear();
  }

  report.min_scaled_jacobian = std::numeric_limits<double>::infinity();
  for (const FaceHandle f : m.faces()) {
    const JacobianBounds jb = certify_face(s, certifier, f);
    ++report.triangles;
    if (!jb.valid)
      ++report.invalid;
    else if (was_invalid[static_cast<std::size_t>(f.idx())])
      ++report.straightened;
    report.min_scaled_jacobian = std::min(report.min_scaled_jacobian, jb.scaled_lower());
  }
  if (report.triangles == 0) report.min_scaled_jacobian = 0;
  return report;
}

double surface_area(const TriSurface& s) {
  check_order(s.order);
  const LagrangeElement& tri = lagrange_element(CellType::Triangle, s.order);
  // Collapsed (Duffy) rule: (x, y) in [0,1]^2 -> (u, v) = (x, y (1 - x)), dA = (1 - x) dx dy.
  constexpr int n = 8;
  std::array<double, n> gx{}, gw{};
  gauss_legendre_01(n, gx.data(), gw.data());
  const auto size = static_cast<std::size_t>(tri.size());
  std::vector<double> grads(n * n * size * 2), weights;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double xi[2] = {gx[i], gx[j] * (1 - gx[i])};
      tri.eval_grad(xi, grads.data() + static_cast<std::size_t>(i * n + j) * size * 2);
      weights.push_back(gw[i] * gw[j] * (1 - gx[i]));
    }
  double area = 0;
  for (const FaceHandle f : s.mesh.faces()) {
    const std::vector<Eigen::Vector3d> nodes = s.triangle_nodes(f);
    for (std::size_t p = 0; p < weights.size(); ++p) {
      const double* g = grads.data() + p * size * 2;
      Eigen::Vector3d xu = Eigen::Vector3d::Zero(), xv = Eigen::Vector3d::Zero();
      for (std::size_t k = 1; k < size; ++k) {  // relative to node 0: the gradients sum to zero
        const Eigen::Vector3d d = nodes[k] - nodes[0];
        xu += g[2 * k] * d;
        xv += g[2 * k + 1] * d;
      }
      area += weights[p] * xu.cross(xv).norm();
    }
  }
  return area;
}

HybridMesh<3> surface_to_mesh(const TriSurface& s) {
  check_order(s.order);
  const int q = s.order;
  const TriMesh& m = s.mesh;
  const int num_tags = static_cast<int>(s.tags.size());
  HybridMesh<3> out;
  out.tags = s.tags;

  // 1. Nodes: vertices, the interior nodes of each edge, then (below) of each face.
  std::vector<NodeId> vertex_id(m.n_vertices(), -1), edge_base(m.n_edges(), -1);
  for (const auto v : m.vertices()) {
    vertex_id[static_cast<std::size_t>(v.idx())] = static_cast<NodeId>(out.nodes.size());
    out.nodes.push_back(m.point(v));
  }
  for (const EdgeHandle e : m.edges()) {
    edge_base[static_cast<std::size_t>(e.idx())] = static_cast<NodeId>(out.nodes.size());
    const std::vector<Eigen::Vector3d>& en = m.property(s.edge_nodes, e);
    const HalfedgeHandle h = m.halfedge_handle(e, 0);
    const Eigen::Vector3d a = m.point(m.from_vertex_handle(h)), b = m.point(m.to_vertex_handle(h));
    // Missing nodes are straight, as TriSurface::triangle_nodes reads them.
    for (int k = 1; k < q; ++k)
      out.nodes.push_back(static_cast<int>(en.size()) == q - 1 ? en[static_cast<std::size_t>(k - 1)]
                                                               : edge_point(a, b, k, q));
  }
  // The interior nodes of edge e in the direction of its half-edge h.
  auto edge_nodes_along = [&](HalfedgeHandle h, std::vector<NodeId>& into) {
    const EdgeHandle e = m.edge_handle(h);
    const bool forward = m.halfedge_handle(e, 0) == h;
    const NodeId base = edge_base[static_cast<std::size_t>(e.idx())];
    for (int k = 0; k < q - 1; ++k) into.push_back(base + (forward ? k : q - 2 - k));
  };

  // 2. Triangles, one block per face tag.
  const int n_face = num_nodes(CellType::Triangle, q) - 3 * q;
  std::vector<NodeId> cell;
  for (const FaceHandle f : m.faces()) {
    const int tag = m.property(s.face_tag, f);
    if (tag < 0 || tag >= num_tags)
      throw MesherError("surface_to_mesh: face " + std::to_string(f.idx()) + " has tag " + std::to_string(tag) +
                        " but the surface has " + std::to_string(num_tags) + " tags");
    cell.clear();
    for (const auto v : s.face_vertices(f)) cell.push_back(vertex_id[static_cast<std::size_t>(v.idx())]);
    for (const HalfedgeHandle h : face_halfedges(m, f)) edge_nodes_along(h, cell);
    if (n_face > 0) {
      const std::vector<Eigen::Vector3d> nodes = s.triangle_nodes(f);
      for (int k = 0; k < n_face; ++k) {
        cell.push_back(static_cast<NodeId>(out.nodes.size()));
        out.nodes.push_back(nodes[static_cast<std::size_t>(3 * q + k)]);
      }
    }
    CellBlock& b = out.boundary_block(CellType::Triangle, q, tag);
    b.connectivity.insert(b.connectivity.end(), cell.begin(), cell.end());
  }

  // 3. Curves: the tagged edges, along their face (for boundary edges) in Gmsh line order.
  for (const EdgeHandle e : m.edges()) {
    const int tag = m.property(s.edge_tag, e);
    if (tag < 0) continue;
    if (tag >= num_tags)
      throw MesherError("surface_to_mesh: edge " + std::to_string(e.idx()) + " has tag " + std::to_string(tag) +
                        " but the surface has " + std::to_string(num_tags) + " tags");
    HalfedgeHandle h = m.halfedge_handle(e, 0);
    if (m.is_boundary(h)) h = m.halfedge_handle(e, 1);
    cell.clear();
    cell.push_back(vertex_id[static_cast<std::size_t>(m.from_vertex_handle(h).idx())]);
    cell.push_back(vertex_id[static_cast<std::size_t>(m.to_vertex_handle(h).idx())]);
    edge_nodes_along(h, cell);
    CellBlock& b = out.curve_block(q, tag);
    b.connectivity.insert(b.connectivity.end(), cell.begin(), cell.end());
  }
  return out;
}

}  // namespace plaf
