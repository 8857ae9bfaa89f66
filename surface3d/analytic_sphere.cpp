// SPDX-License-Identifier: MIT
// The analytic sphere (see analytic.h): radial closest-point projection, and an initial
// triangulation from the icosahedron, each face cut into n^2 triangles (frequency n from h)
// whose vertices are projected onto the sphere.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "surface3d/analytic.h"
#include "surface3d/analytic_builder.h"

namespace plaf {

using analytic_detail::kInf;
using analytic_detail::MeshBuilder;
using analytic_detail::num;
using Eigen::Vector3d;

namespace {

class SphereReference final : public ReferenceGeometry<3> {
 public:
  SphereReference(const Vector3d& c, double r) : c_(c), r_(r) {}
  Vector3d project(const Vector3d& p) const override { return c_ + r_ * direction(p); }
  Vector3d normal(const Vector3d& x) const override { return direction(x); }
  Vector3d project_to_curve(const Vector3d& p, int curve) const override {
    throw MesherError("sphere: no feature curve " + std::to_string(curve) + " (a sphere has none); point " +
                      num(p.x()) + " " + num(p.y()) + " " + num(p.z()));
  }
  int num_curves() const override { return 0; }
  double scale() const override { return 2 * std::sqrt(3.0) * r_; }

 private:
  Vector3d direction(const Vector3d& p) const {
    const Vector3d d = p - c_;
    const double len = d.norm();
    return len > 0 ? Vector3d(d / len) : Vector3d::UnitZ();  // the centre: any point is closest
  }
  Vector3d c_;
  double r_;
};

struct Icosahedron {
  std::vector<Vector3d> vertices;         // on the unit sphere
  std::vector<std::array<int, 3>> faces;  // outward
};

Icosahedron unit_icosahedron() {
  Icosahedron ico;
  std::vector<Vector3d>& v = ico.vertices;
  // Vertices: the cyclic permutations of (0, +-1, +-phi).
  const double phi = 0.5 * (1 + std::sqrt(5.0));
  for (int perm = 0; perm < 3; ++perm)
    for (double a : {-1.0, 1.0})
      for (double b : {-phi, phi}) {
        Vector3d x;
        x[perm] = 0;
        x[(perm + 1) % 3] = a;
        x[(perm + 2) % 3] = b;
        v.push_back(x.normalized());
      }
  // Faces: triples of mutually adjacent vertices (edge length 2 before normalisation), outward.
  double min_edge = kInf;
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t j = i + 1; j < v.size(); ++j) min_edge = std::min(min_edge, (v[i] - v[j]).norm());
  const auto adjacent = [&](std::size_t i, std::size_t j) { return (v[i] - v[j]).norm() < 1.01 * min_edge; };
  for (std::size_t i = 0; i < 12; ++i)
    for (std::size_t j = i + 1; j < 12; ++j)
      for (std::size_t k = j + 1; k < 12; ++k)
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k)) {
          std::array<int, 3> f = {static_cast<int>(i), static_cast<int>(j), static_cast<int>(k)};
          if ((v[j] - v[i]).cross(v[k] - v[i]).dot(v[i]) < 0) std::swap(f[1], f[2]);
          ico.faces.push_back(f);
        }
  return ico;
}

// Each face of ico cut into n^2 triangles, their vertices projected onto the sphere; points on
// the icosahedron's edges and vertices are shared between its faces.
void add_subdivided(MeshBuilder& mb, const Icosahedron& ico, int n, const Vector3d& center, double radius) {
  std::map<std::array<int, 4>, int> ids;  // canonical barycentric key -> vertex
  const auto vertex = [&](int fi, int i, int j) {
    const std::array<int, 3>& f = ico.faces[fi];
    // Weights of (f0, f1, f2) = (n - i - j, i, j); the key lists the nonzero ones by vertex id.
    std::array<std::pair<int, int>, 3> w = {{{f[0], n - i - j}, {f[1], i}, {f[2], j}}};
    std::sort(w.begin(), w.end());
    std::array<int, 4> key = {-1, -1, -1, -1};
    int used = 0, nonzero = 0;
    for (const auto& [v, wt] : w)
      if (wt > 0) ++nonzero;
    if (nonzero == 3) {
      key = {1000 + fi, i, j, 0};
    } else {
      for (const auto& [v, wt] : w)
        if (wt > 0 && used < 2) key[2 * used] = v, key[2 * used + 1] = wt, ++used;
    }
    const auto it = ids.find(key);
    if (it != ids.end()) return it->second;
    const Vector3d p = (n - i - j) * ico.vertices[f[0]] + i * ico.vertices[f[1]] + j * ico.vertices[f[2]];
    const int id = mb.add_point(center + radius * p.normalized());
    ids[key] = id;
    return id;
  };
  for (int fi = 0; fi < static_cast<int>(ico.faces.size()); ++fi)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        mb.add_triangle(vertex(fi, i, j), vertex(fi, i + 1, j), vertex(fi, i, j + 1));
        if (i + j + 1 < n) mb.add_triangle(vertex(fi, i + 1, j), vertex(fi, i + 1, j + 1), vertex(fi, i, j + 1));
      }
}

}  // namespace

AnalyticBody make_sphere(const Eigen::Vector3d& center, double radius, double h) {
  if (!center.allFinite()) throw ConfigError("sphere: the centre must be finite");
  if (!(radius > 0) || !std::isfinite(radius)) throw ConfigError("sphere: radius must be positive, got " + num(radius));
  analytic_detail::check_h("sphere", h, 2 * radius);
  AnalyticBody body;
  body.reference = std::make_unique<SphereReference>(center, radius);
  // Frequency n: the projected icosahedron edge (angle atan(2) ~ 63.4 degrees) cut into ~h pieces.
  const int n = std::max(1, static_cast<int>(std::lround(std::atan(2.0) * radius / h)));
  MeshBuilder mb;
  add_subdivided(mb, unit_icosahedron(), n, center, radius);
  mb.end_patch(false);  // sub-triangles keep the outward order of their icosahedron face
  body.initial = mb.build("sphere");
  return body;
}

}  // namespace plaf
