// SPDX-License-Identifier: MIT
// The normal of a 3D front node (normals_3d.h).
#include "layers/normals_3d.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/base/error.h"

namespace plaf::layers {

const char* node_class_name(NodeClass c) {
  switch (c) {
    case NodeClass::Smooth: return "smooth";
    case NodeClass::ConvexRidge: return "convex_ridge";
    case NodeClass::ConcaveRidge: return "concave_ridge";
    case NodeClass::ConvexCorner: return "convex_corner";
    case NodeClass::ConcaveCorner: return "concave_corner";
    case NodeClass::SaddleCorner: return "saddle_corner";
  }
  return "?";
}

namespace {

using Vec = Eigen::Vector3d;

double min_cos(const Vec& n, const std::vector<Vec>& f) {
  double m = std::numeric_limits<double>::infinity();
  for (const Vec& v : f) m = std::min(m, n.dot(v));
  return m;
}

// Distinct directions (within 1e-9 rad): the candidates below are built from these.
std::vector<Vec> distinct(const std::vector<Vec>& f) {
  std::vector<Vec> d;
  for (const Vec& v : f)
    if (std::none_of(d.begin(), d.end(), [&](const Vec& w) { return (v - w).norm() < 1e-9; })) d.push_back(v);
  return d;
}

}  // namespace

Vec visibility_normal(const std::vector<Vec>& faces) {
  const Vec n = most_normal(faces);
  return min_cos(n, faces) > 0 ? n : Vec::Zero();
}

Vec most_normal(const std::vector<Vec>& faces) {
  // The centre of the smallest spherical cap holding the f_k is the max-min direction; it is
  // determined by one, two (their bisector) or three (equal angles) of them.
  const std::vector<Vec> f = distinct(faces);
  Vec best = Vec::Zero();
  double best_val = -std::numeric_limits<double>::infinity();
  auto consider = [&](Vec n) {
    const double len = n.norm();
    if (!(len > 1e-12)) return;
    n /= len;
    const double m = min_cos(n, f);
    if (m > best_val) {
      best_val = m;
      best = n;
    }
  };
  const std::size_t k = f.size();
  for (std::size_t a = 0; a < k; ++a) {
    consider(f[a]);
    for (std::size_t b = a + 1; b < k; ++b) {
      consider(f[a] + f[b]);
      for (std::size_t c = b + 1; c < k; ++c) {
        // n . f_a = n . f_b = n . f_c: n is along the normal of the plane through the three tips.
        // Both orientations: beyond a hemisphere (a cusp) the best can be the one facing away.
        const Vec n = (f[b] - f[a]).cross(f[c] - f[a]);
        consider(n);
        consider(-n);
      }
    }
  }
  return best;
}

NodeNormal node_normal(const std::vector<Vec>& faces, const std::vector<double>& weights,
                       const std::vector<Vec>& to_neighbours, double corner_rad) {
  NodeNormal r;
  Vec sum = Vec::Zero();
  for (std::size_t k = 0; k < faces.size(); ++k) sum += weights[k] * faces[k];
  // Sides: greedy clusters of face normals within the corner angle of a cluster's first normal.
  const double cos_corner = std::cos(corner_rad);
  std::vector<Vec> sides;
  for (const Vec& f : faces)
    if (std::none_of(sides.begin(), sides.end(), [&](const Vec& s) { return s.dot(f) >= cos_corner; }))
      sides.push_back(f);
  if (sides.size() <= 1) {
    if (!(sum.norm() > 0)) throw MesherError("layers: the faces around a front node cancel (a cusp)");
    r.n = sum.normalized();
    r.min_cosine = min_cos(r.n, faces);
    return r;
  }
  r.n = visibility_normal(faces);
  if (r.n.isZero()) throw MesherError("layers: no direction sees every face around a front node (a cusp)");
  r.min_cosine = min_cos(r.n, faces);
  // Convex or concave: where the neighbours lie against the tangent plane of n.
  int above = 0, below = 0;
  for (const Vec& d : to_neighbours) {
    const double s = r.n.dot(d) / std::max(d.norm(), std::numeric_limits<double>::min());
    if (s > 1e-6) ++above;
    if (s < -1e-6) ++below;
  }
  const bool corner = sides.size() >= 3;
  if (above > 0 && below > 0 && corner)
    r.kind = NodeClass::SaddleCorner;
  else if (above > below)
    r.kind = corner ? NodeClass::ConcaveCorner : NodeClass::ConcaveRidge;
  else
    r.kind = corner ? NodeClass::ConvexCorner : NodeClass::ConvexRidge;
  if (is_concave(r.kind)) r.stretch = 1 / std::max(r.min_cosine, 0.1);
  return r;
}

}  // namespace plaf::layers
