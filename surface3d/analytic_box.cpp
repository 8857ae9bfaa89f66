// SPDX-License-Identifier: MIT
// The analytic box (see analytic.h): closest point by clamping (outside) or the nearest face
// (inside), and an initial triangulation from a cube lattice with the box's 12 edges as convex
// ridge curves and its 8 vertices as convex corners.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "surface3d/analytic.h"
#include "surface3d/analytic_builder.h"

namespace plaf {

using analytic_detail::CubeLattice;
using analytic_detail::kInf;
using analytic_detail::MeshBuilder;
using analytic_detail::num;
using Eigen::Vector3d;

namespace {

class BoxReference final : public ReferenceGeometry<3> {
 public:
  BoxReference(const Vector3d& lo, const Vector3d& hi) : lo_(lo), hi_(hi) {}
  Vector3d project(const Vector3d& p) const override {
    const Vector3d c = p.cwiseMax(lo_).cwiseMin(hi_);
    if (c != p) return c;  // outside: the clamp is the closest point
    const auto [axis, side] = nearest_face(p);
    Vector3d out = p;
    out[axis] = side ? hi_[axis] : lo_[axis];
    return out;
  }
  Vector3d normal(const Vector3d& x) const override {
    const auto [axis, side] = nearest_face(x);
    Vector3d n = Vector3d::Zero();
    n[axis] = side ? 1 : -1;
    return n;
  }
  // Curve 4 a + 2 sb + sc: the edge along axis a at the lo (0) / hi (1) sides sb, sc of the two
  // following axes b = a + 1, c = a + 2 (mod 3).
  Vector3d project_to_curve(const Vector3d& p, int curve) const override {
    if (curve < 0 || curve >= 12) throw MesherError("box: no feature curve " + std::to_string(curve));
    const int a = curve / 4, b = (a + 1) % 3, c = (a + 2) % 3;
    Vector3d out;
    out[a] = std::clamp(p[a], lo_[a], hi_[a]);
    out[b] = (curve & 2) ? hi_[b] : lo_[b];
    out[c] = (curve & 1) ? hi_[c] : lo_[c];
    return out;
  }
  int num_curves() const override { return 12; }
  double scale() const override { return (hi_ - lo_).norm(); }

 private:
  // The face nearest to x (inside or on the box; outside, the face x is farthest beyond).
  std::pair<int, bool> nearest_face(const Vector3d& x) const {
    int axis = 0;
    bool side = false;
    double best = kInf;
    for (int a = 0; a < 3; ++a) {
      const double dl = x[a] - lo_[a], dh = hi_[a] - x[a];
      if (dl < best) best = dl, axis = a, side = false;
      if (dh < best) best = dh, axis = a, side = true;
    }
    return {axis, side};
  }
  Vector3d lo_, hi_;
};

// The 12 edges of the lattice's cube (curve 4 a + 2 sb + sc, as BoxReference) and its 8 corners.
void mark_box_features(MeshBuilder& mb, const CubeLattice& lat) {
  const std::array<int, 3>& n = lat.n;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int sb = 0; sb < 2; ++sb)
      for (int sc = 0; sc < 2; ++sc) {
        std::vector<int> vs;
        for (int m = 0; m <= n[a]; ++m) {
          std::array<int, 3> ijk{};
          ijk[a] = m;
          ijk[b] = sb ? n[b] : 0;
          ijk[c] = sc ? n[c] : 0;
          vs.push_back(lat.id(ijk[0], ijk[1], ijk[2]));
        }
        mb.mark_polyline(vs, 4 * a + 2 * sb + sc, EdgeFeature::ConvexRidge);
      }
  }
  for (int corner = 0; corner < 8; ++corner)
    mb.mark_corner(lat.id(corner & 1 ? n[0] : 0, corner & 2 ? n[1] : 0, corner & 4 ? n[2] : 0),
                   VertexFeature::ConvexCorner);
}

}  // namespace

AnalyticBody make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double h) {
  if (!lo.allFinite() || !hi.allFinite() || !((hi - lo).minCoeff() > 0))
    throw ConfigError("box: need lo < hi in every coordinate, got lo = (" + num(lo.x()) + ", " + num(lo.y()) + ", " +
                      num(lo.z()) + "), hi = (" + num(hi.x()) + ", " + num(hi.y()) + ", " + num(hi.z()) + ")");
  analytic_detail::check_h("box", h, (hi - lo).maxCoeff());
  AnalyticBody body;
  body.reference = std::make_unique<BoxReference>(lo, hi);
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = std::max(1, static_cast<int>(std::lround((hi[a] - lo[a]) / h)));
  MeshBuilder mb;
  const CubeLattice lat = analytic_detail::build_cube(mb, n, [&](int i, int j, int k) {
    const std::array<int, 3> ijk = {i, j, k};
    Vector3d p;
    // Exact end values (no rounding at hi), uniform in between.
    for (int a = 0; a < 3; ++a) p[a] = ijk[a] == n[a] ? hi[a] : lo[a] + (hi[a] - lo[a]) * ijk[a] / n[a];
    return p;
  });
  mb.end_patch(false);
  mark_box_features(mb, lat);
  body.initial = mb.build("box");
  return body;
}

}  // namespace plaf
