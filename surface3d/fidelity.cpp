// SPDX-License-Identifier: MIT
// The surface's distance to its body (fidelity.h).
#include "surface3d/fidelity.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/base/parallel.h"
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

std::vector<Eigen::Vector3d> reference_samples(const TriSurface& input, const ReferenceGeometry<3>& reference,
                                               bool input_is_reference) {
  std::vector<Eigen::Vector3d> out;
  const TriMesh& m = input.mesh;
  if (input_is_reference) {
    // The input is the body: its vertices, edge midpoints and face centroids, each once.
    for (const auto v : m.vertices()) out.push_back(m.point(v));
    for (const auto e : m.edges()) {
      const auto h = m.halfedge_handle(e, 0);
      out.push_back(0.5 * (m.point(m.from_vertex_handle(h)) + m.point(m.to_vertex_handle(h))));
    }
    for (const auto f : m.faces()) {
      const auto fv = input.face_vertices(f);
      out.push_back((m.point(fv[0]) + m.point(fv[1]) + m.point(fv[2])) / 3);
    }
    return out;
  }
  // An analytic body's initial triangulation is coarse (1.5 x the largest size): its faces'
  // 8-sub-lattice, projected onto the body.
  const SubLattice lat(8);
  for (const auto f : m.faces()) {
    const auto fv = input.face_vertices(f);
    const Eigen::Vector3d a = m.point(fv[0]), b = m.point(fv[1]), c = m.point(fv[2]);
    for (const auto& x : lat.xi) out.push_back(reference.project(a + x[0] * (b - a) + x[1] * (c - a)));
  }
  return out;
}

namespace {

// The closest point to p on the curved triangle `nodes` (order q), from reference point xi by
// Gauss-Newton steps kept inside the triangle: its distance.
double curved_distance(const LagrangeElement& e, const std::vector<Eigen::Vector3d>& nodes, const Eigen::Vector3d& p,
                       std::array<double, 2> xi, std::vector<double>& phi, std::vector<double>& dphi) {
  double best = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 8; ++it) {
    e.eval(xi.data(), phi.data());
    e.eval_grad(xi.data(), dphi.data());
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), xu = Eigen::Vector3d::Zero(), xv = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      x += phi[k] * nodes[k];
      xu += dphi[2 * k] * nodes[k];
      xv += dphi[2 * k + 1] * nodes[k];
    }
    const Eigen::Vector3d r = p - x;
    best = std::min(best, r.norm());
    Eigen::Matrix2d jtj;
    jtj << xu.dot(xu), xu.dot(xv), xu.dot(xv), xv.dot(xv);
    const Eigen::Vector2d step = jtj.ldlt().solve(Eigen::Vector2d(xu.dot(r), xv.dot(r)));
    if (!step.allFinite()) break;
    xi[0] = std::max(0.0, xi[0] + step[0]);
    xi[1] = std::max(0.0, xi[1] + step[1]);
    if (xi[0] + xi[1] > 1) {
      const double sum = xi[0] + xi[1];
      xi[0] /= sum;
      xi[1] /= sum;
    }
    if (step.norm() < 1e-12) break;
  }
  return best;
}

}  // namespace

double samples_diagonal(const std::vector<Eigen::Vector3d>& samples) {
  if (samples.empty()) return 0;
  Eigen::Vector3d lo = samples.front(), hi = samples.front();
  for (const Eigen::Vector3d& p : samples) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

FidelityReport measure_fidelity(const TriSurface& surface, const ReferenceGeometry<3>& reference,
                                const std::vector<Eigen::Vector3d>& samples, double far_over) {
  FidelityReport r;
  const int q = std::max(1, surface.order);
  const SubLattice fine(2 * q), coarse(q);
  const LagrangeElement& e = lagrange_element(CellType::Triangle, q);
  std::vector<double> phi(static_cast<std::size_t>(e.size())), dphi(static_cast<std::size_t>(2 * e.size()));
  auto basis = [&](const SubLattice& lat) {
    std::vector<std::vector<double>> out;
    for (const auto& x : lat.xi) {
      e.eval(x.data(), phi.data());
      out.push_back(phi);
    }
    return out;
  };
  const std::vector<std::vector<double>> fine_basis = basis(fine), coarse_basis = basis(coarse);
  auto at = [](const std::vector<double>& w, const std::vector<Eigen::Vector3d>& nodes) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < nodes.size(); ++k) x += w[k] * nodes[k];
    return x;
  };
  // Mesh -> body on the fine lattice, computed as it goes; the tree over the coarse lattice's
  // sub-triangles (Q^2 per face), each knowing its face and its points' reference coordinates.
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> tris;
  std::vector<int> tri_face;
  std::vector<Eigen::Vector3d> face_nodes;  // e.size() per face, for the refinement
  std::size_t nfaces = 0;
  // The projections onto the reference on the worker threads (modules/base/parallel.h; a
  // reference keeps no mutable state), a block of faces at a time; what they give is taken in the
  // faces' order, so the report is the same as one thread's, bit for bit.
  const std::size_t nfine = fine_basis.size();
  std::vector<std::vector<Eigen::Vector3d>> block_nodes;
  std::vector<Eigen::Vector3d> block_x;
  std::vector<double> block_d;
  auto take_block = [&]() {
    block_x.resize(block_nodes.size() * nfine);
    block_d.resize(block_x.size());
    parallel_chunks(block_nodes.size(), 16, [&](unsigned, std::size_t begin, std::size_t end) {
      for (std::size_t b = begin; b < end; ++b)
        for (std::size_t k = 0; k < nfine; ++k) {
          const Eigen::Vector3d x = at(fine_basis[k], block_nodes[b]);
          block_x[b * nfine + k] = x;
          block_d[b * nfine + k] = (x - reference.project(x)).norm();
        }
    });
    for (std::size_t b = 0; b < block_nodes.size(); ++b) {
      for (std::size_t k = 0; k < nfine; ++k) {
        const Eigen::Vector3d& x = block_x[b * nfine + k];
        const double d = block_d[b * nfine + k];
        ++r.mesh_samples;
        if (d > far_over) r.far.emplace_back(x, d);
        if (d > r.to_reference || !(d == d)) {
          r.to_reference = d;
          r.worst_on_mesh = x;
        }
      }
      const std::vector<Eigen::Vector3d>& nodes = block_nodes[b];
      const int first = static_cast<int>(points.size());
      for (const auto& w : coarse_basis) points.push_back(at(w, nodes));
      for (const auto& t : coarse.tris) {
        tris.push_back({first + t[0], first + t[1], first + t[2]});
        tri_face.push_back(static_cast<int>(nfaces));
      }
      face_nodes.insert(face_nodes.end(), nodes.begin(), nodes.end());
      ++nfaces;
    }
    block_nodes.clear();
  };
  constexpr std::size_t kBlock = 4096;
  for (const auto f : surface.mesh.faces()) {
    std::vector<Eigen::Vector3d> nodes = surface.triangle_nodes(f);
    if (static_cast<int>(nodes.size()) != e.size()) continue;  // (triangle_nodes gives order-Q nodes)
    block_nodes.push_back(std::move(nodes));
    if (block_nodes.size() == kBlock) take_block();
  }
  take_block();
  r.reference_samples = samples.size();
  r.diagonal = samples_diagonal(samples);
  if (!samples.empty() && tris.empty()) {  // a body and no mesh: as far as it gets
    r.to_mesh = std::numeric_limits<double>::infinity();
    r.worst_on_reference = samples.front();
  } else if (!tris.empty()) {
    const TriangleTree tree(points, tris);
    // Each sample's distance on the worker threads (their own scratch), taken in the samples'
    // order as above.
    std::vector<double> dist(samples.size());
    parallel_chunks(samples.size(), 256, [&](unsigned, std::size_t begin, std::size_t end) {
      std::vector<Eigen::Vector3d> nodes(static_cast<std::size_t>(e.size()));
      std::vector<double> phi_w(phi.size()), dphi_w(dphi.size());
      for (std::size_t i = begin; i < end; ++i) {
        const Eigen::Vector3d& p = samples[i];
        const TriangleTree::Closest cl = tree.closest(p);
        const std::size_t t = static_cast<std::size_t>(cl.triangle);
        // The flat sub-triangle's closest point, refined on its curved face.
        const auto& st = coarse.tris[t % coarse.tris.size()];
        std::array<double, 2> xi{0, 0};
        for (int k = 0; k < 3; ++k)
          for (int d = 0; d < 2; ++d)
            xi[static_cast<std::size_t>(d)] += cl.barycentric[k] * coarse.xi[static_cast<std::size_t>(st[static_cast<std::size_t>(k)])][static_cast<std::size_t>(d)];
        const auto first = face_nodes.begin() + static_cast<std::ptrdiff_t>(tri_face[t]) * e.size();
        std::copy(first, first + e.size(), nodes.begin());
        dist[i] = std::min(std::sqrt(cl.distance2), curved_distance(e, nodes, p, xi, phi_w, dphi_w));
      }
    });
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (dist[i] > far_over) r.far.emplace_back(samples[i], dist[i]);
      if (dist[i] > r.to_mesh) {
        r.to_mesh = dist[i];
        r.worst_on_reference = samples[i];
      }
    }
  }
  r.hausdorff = std::max(r.to_reference, r.to_mesh);
  r.worst = r.to_mesh >= r.to_reference ? r.worst_on_reference : r.worst_on_mesh;
  r.relative = r.diagonal > 0 ? r.hausdorff / r.diagonal : (r.hausdorff > 0 ? std::numeric_limits<double>::infinity() : 0);
  return r;
}

FidelityRefinedField::FidelityRefinedField(std::unique_ptr<MetricField<3>>&& inner, std::vector<Spot> spots)
    : FidelityRefinedField(*inner, std::move(spots)) {
  owned_ = std::move(inner);
}

FidelityRefinedField::FidelityRefinedField(const MetricField<3>& inner, std::vector<Spot> spots)
    : inner_(&inner), spots_(std::move(spots)) {
  double largest = 0;
  for (const Spot& sp : spots_) largest = std::max(largest, sp.radius);
  cell_ = largest > 0 ? largest : 1;
  for (std::size_t s = 0; s < spots_.size(); ++s) {
    const Eigen::Vector3d lo = (spots_[s].point.array() - spots_[s].radius) / cell_;
    const Eigen::Vector3d hi = (spots_[s].point.array() + spots_[s].radius) / cell_;
    for (auto i = static_cast<std::int64_t>(std::floor(lo.x())); i <= static_cast<std::int64_t>(std::floor(hi.x())); ++i)
      for (auto j = static_cast<std::int64_t>(std::floor(lo.y())); j <= static_cast<std::int64_t>(std::floor(hi.y())); ++j)
        for (auto k = static_cast<std::int64_t>(std::floor(lo.z())); k <= static_cast<std::int64_t>(std::floor(hi.z())); ++k)
          grid_[key(i, j, k)].push_back(s);
  }
}

std::int64_t FidelityRefinedField::key(std::int64_t i, std::int64_t j, std::int64_t k) const {
  // 21 bits per axis: the cells of a body's bounding box at its spots' radius are far fewer.
  constexpr std::int64_t kMask = (std::int64_t{1} << 21) - 1;
  return ((i & kMask) << 42) | ((j & kMask) << 21) | (k & kMask);
}

double FidelityRefinedField::factor(const Eigen::Vector3d& x) const {
  const auto it = grid_.find(key(static_cast<std::int64_t>(std::floor(x.x() / cell_)),
                                 static_cast<std::int64_t>(std::floor(x.y() / cell_)),
                                 static_cast<std::int64_t>(std::floor(x.z() / cell_))));
  double f = 1;
  if (it == grid_.end()) return f;
  for (std::size_t s : it->second) {
    const Spot& sp = spots_[s];
    const double d = (x - sp.point).norm();
    if (d >= sp.radius) continue;
    const double ramp = std::clamp((d - sp.radius / 3) / (2 * sp.radius / 3), 0.0, 1.0);
    f = std::min(f, sp.factor + (1 - sp.factor) * ramp);
  }
  return f;
}

Metric<3> FidelityRefinedField::evaluate(const Point& x) const {
  const Metric<3> m = inner_->evaluate(x);
  const double f = factor(x);
  return f < 1 ? Metric<3>::from_matrix(m.matrix() / (f * f)) : m;
}

}  // namespace plaf
