// SPDX-License-Identifier: MIT
// The farfield surfaces of 3D runs (farfield3d.h).
#include "volume/farfield3d.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "modules/base/error.h"
#include "modules/base/format.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector3d;


// Node ids shared along edges: a point is identified by its rounded integer lattice coordinates.
class NodeSet {
 public:
  explicit NodeSet(FarfieldMesh3& m) : m_(m) {}
  // The node at integer lattice point `key`, made at x when first asked for.
  int at(const std::array<long, 3>& key, const Vec& x) {
    const auto [it, added] = ids_.emplace(key, static_cast<int>(m_.nodes.size()));
    if (added) m_.nodes.push_back(x);
    return it->second;
  }

 private:
  FarfieldMesh3& m_;
  std::map<std::array<long, 3>, int> ids_;
};

void sphere(FarfieldMesh3& m, const Vec& c, double r, double h) {
  // Icosahedron vertices and faces (outward), each face split into n^2 triangles.
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                        {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec& x : v) x.normalize();
  const int f[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                        {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                        {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  // The icosahedron's edge on the unit sphere is 1.0515; pushing the sub-triangles onto the
  // sphere stretches their edges, by less than the factor 1.25 allows for (farfield3d_test checks
  // every edge under h).
  const int n = std::max(1, static_cast<int>(std::ceil(1.0515 * 1.25 * r / h)));
  // Shared nodes: a point of a face at lattice (i, j) has integer weights (n - i - j, i, j) on
  // the face's icosahedron vertices; its key lists the (vertex, weight) pairs of positive weight,
  // sorted, so the faces sharing an edge or a vertex agree on it.
  std::map<std::array<std::pair<int, int>, 3>, int> ids;
  auto node = [&](const int* tri, int wa, int wb, int wc) {
    std::array<std::pair<int, int>, 3> key = {{{-1, 0}, {-1, 0}, {-1, 0}}};
    const int w[3] = {wa, wb, wc};
    for (int k = 0; k < 3; ++k)
      if (w[k] > 0) key[static_cast<std::size_t>(k)] = {tri[k], w[k]};
    std::sort(key.begin(), key.end());
    const auto [it, added] = ids.emplace(key, static_cast<int>(m.nodes.size()));
    if (added) {
      Vec x = Vec::Zero();
      for (int k = 0; k < 3; ++k) x += w[k] * v[static_cast<std::size_t>(tri[k])];
      m.nodes.push_back(c + r * x.normalized());
    }
    return it->second;
  };
  for (const auto& tri : f)
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j) {
        auto p = [&](int ii, int jj) { return node(tri, n - ii - jj, ii, jj); };
        // Outward (a, b, c) reversed: normals inward.
        m.triangles.push_back({p(i, j), p(i, j + 1), p(i + 1, j)});
        if (i + j + 1 < n) m.triangles.push_back({p(i + 1, j), p(i, j + 1), p(i + 1, j + 1)});
      }
}

void box(FarfieldMesh3& m, const Vec& lo, const Vec& hi, double h, const std::vector<FarfieldParams3::Cut>& cuts) {
  std::array<int, 3> n{};
  for (int d = 0; d < 3; ++d) n[static_cast<std::size_t>(d)] = std::max(1, static_cast<int>(std::ceil((hi[d] - lo[d]) / h)));
  NodeSet nodes(m);
  auto at = [&](const std::array<long, 3>& k) {
    Vec x;
    for (int d = 0; d < 3; ++d)
      x[d] = k[static_cast<std::size_t>(d)] == n[static_cast<std::size_t>(d)]
                 ? hi[d]
                 : lo[d] + (hi[d] - lo[d]) * static_cast<double>(k[static_cast<std::size_t>(d)]) / n[static_cast<std::size_t>(d)];
    return nodes.at(k, x);
  };
  // Face d = axis, side s: a grid over the two other axes (a, b) with a x b = +axis; inward
  // normals are -axis on the high side and +axis on the low side.
  m.cut_loops.assign(cuts.size(), {});
  for (int d = 0; d < 3; ++d)
    for (int s = 0; s < 2; ++s) {
      const int a = (d + 1) % 3, b = (d + 2) % 3;
      auto face_node = [&](int ii, int jj) {
        std::array<long, 3> k{};
        k[static_cast<std::size_t>(d)] = s == 0 ? 0 : n[static_cast<std::size_t>(d)];
        k[static_cast<std::size_t>(a)] = ii;
        k[static_cast<std::size_t>(b)] = jj;
        return at(k);
      };
      bool cut = false;
      for (std::size_t c = 0; c < cuts.size(); ++c) {
        // The face on the plane: the side of the box away from the bodies.
        if (cuts[c].axis != d || (cuts[c].side > 0) != (s == 0)) continue;
        cut = true;
        std::vector<int>& loop = m.cut_loops[c];
        const int na = n[static_cast<std::size_t>(a)], nb = n[static_cast<std::size_t>(b)];
        for (int i = 0; i < na; ++i) loop.push_back(face_node(i, 0));
        for (int j = 0; j < nb; ++j) loop.push_back(face_node(na, j));
        for (int i = na; i > 0; --i) loop.push_back(face_node(i, nb));
        for (int j = nb; j > 0; --j) loop.push_back(face_node(0, j));
      }
      if (cut) continue;
      for (int i = 0; i < n[static_cast<std::size_t>(a)]; ++i)
        for (int j = 0; j < n[static_cast<std::size_t>(b)]; ++j) {
          auto p = [&](int ii, int jj) { return face_node(ii, jj); };
          const int p00 = p(i, j), p10 = p(i + 1, j), p11 = p(i + 1, j + 1), p01 = p(i, j + 1);
          if (s == 0) {  // normal +axis: (a, b) counter-clockwise
            m.triangles.push_back({p00, p10, p11});
            m.triangles.push_back({p00, p11, p01});
          } else {
            m.triangles.push_back({p00, p11, p10});
            m.triangles.push_back({p00, p01, p11});
          }
        }
    }
}

}  // namespace

Eigen::Vector3d farfield_center(const FarfieldParams3& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return p.has_center ? p.center : Vec(0.5 * (lo + hi));
}

FarfieldMesh3 make_farfield(const FarfieldParams3& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  if (!(p.h > 0)) throw ConfigError("fill.farfield.h: must be positive, got " + num(p.h));
  // At most a few million farfield triangles (an h far too small for the farfield's extent
  // would overflow the grid counts or exhaust the memory).
  auto too_fine = [&](double triangles) {
    if (triangles > 4e6)
      throw ConfigError("fill.farfield.h: " + num(p.h) + " makes about " + num(triangles) +
                        " farfield triangles (at most 4e6); give a larger h");
  };
  const double diag = (hi - lo).norm();
  const Vec c = farfield_center(p, lo, hi);
  FarfieldMesh3 m;
  if (p.shape == "sphere" && !p.cuts.empty())
    throw ConfigError("fill.farfield.shape: a sphere is not cut by the symmetry planes; use box");
  if (p.shape == "sphere") {
    const double r = p.radius > 0 ? p.radius : 10 * diag;
    // Every body corner inside, with room for a farfield triangle's sag and the layers.
    double far = 0;
    for (int k = 0; k < 8; ++k) far = std::max(far, (Vec(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z()) - c).norm());
    too_fine(20 * std::pow(1.0515 * 1.25 * r / p.h + 1, 2));
    sphere(m, c, r, p.h);
    // The inscribed polyhedron's inradius (its faces' closest distance to the centre) must clear
    // every body corner by 5 %.
    double inner = r;
    for (const auto& t : m.triangles) {
      const Vec &a = m.nodes[static_cast<std::size_t>(t[0])], &b = m.nodes[static_cast<std::size_t>(t[1])],
                &cc = m.nodes[static_cast<std::size_t>(t[2])];
      inner = std::min(inner, std::abs((a - c).dot((b - a).cross(cc - a).normalized())));
    }
    if (!(far < 0.95 * inner))
      throw ConfigError("fill.farfield.radius: " + num(r) + " does not enclose the bodies (they reach " + num(far) +
                        " from the centre; the farfield's triangles of size h " + num(p.h) + " come within " +
                        num(inner) + " of it)");
  } else {
    Vec half;
    for (int d = 0; d < 3; ++d) half[d] = 0.5 * (p.size[static_cast<std::size_t>(d)] > 0 ? p.size[static_cast<std::size_t>(d)] : 20 * diag);
    Vec blo = c - half, bhi = c + half;
    for (const FarfieldParams3::Cut& cut : p.cuts) (cut.side > 0 ? blo : bhi)[cut.axis] = cut.offset;
    for (int d = 0; d < 3; ++d) {
      bool cut_lo = false, cut_hi = false;  // a symmetry plane bounds the box there
      for (const FarfieldParams3::Cut& cut : p.cuts)
        if (cut.axis == d) (cut.side > 0 ? cut_lo : cut_hi) = true;
      if (!((cut_lo || blo[d] + 0.05 * half[d] < lo[d]) && (cut_hi || hi[d] < bhi[d] - 0.05 * half[d])))
        throw ConfigError("fill.farfield.size: the box [" + num(blo[d]) + ", " + num(bhi[d]) + "] along axis " +
                          std::to_string(d) + " does not enclose the bodies' [" + num(lo[d]) + ", " + num(hi[d]) +
                          "] with a margin of 5 % of its half size");
    }
    const Vec e = (bhi - blo) / p.h + Vec::Ones();
    too_fine(4 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x()));
    box(m, blo, bhi, p.h, p.cuts);
  }
  return m;
}

}  // namespace plaf::volume
