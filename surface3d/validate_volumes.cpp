// SPDX-License-Identifier: MIT
// Step 6 of validate_surface (validate.h): each component's enclosed volume (open half models
// closed by caps on their symmetry planes), inward components turned out, and components nested
// inside another found by exact ray parity over the bounding-box tree.
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"
#include "surface3d/validate_steps.h"

namespace plaf::validate_detail {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

// A component whose |volume| is below this x (its bounding-box diagonal)^3 is flat (a sheet
// folded onto itself): far below any real body (a 1 % thick plate has about 1e-3) and far above
// the rounding of the volume sum (about 1e-16 per triangle).
constexpr double kZeroVolumeRel = 1e-9;
// A plane normal component below this counts as zero when choosing a ray parallel to the
// symmetry planes.
constexpr double kParallelTol = 1e-12;

// Ray parity along +axis from p against triangle abc: 1 crossed, 0 not, -1 degenerate (the ray
// grazes an edge or a vertex, or p lies on the triangle); exact.
int ray_crosses(const Vector3d& p, const Vector3d& far, int axis, const Vector3d& a, const Vector3d& b,
                const Vector3d& c) {
  const int s_p = sign_orient3d(a, b, c, p), s_far = sign_orient3d(a, b, c, far);
  if (s_p == s_far && s_p != 0) return 0;
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  const Vector2d q(p[i], p[j]), a2(a[i], a[j]), b2(b[i], b[j]), c2(c[i], c[j]);
  const int s0 = sign_orient2d(a2, b2, q), s1 = sign_orient2d(b2, c2, q), s2 = sign_orient2d(c2, a2, q);
  const bool pos = s0 > 0 || s1 > 0 || s2 > 0, neg = s0 < 0 || s1 < 0 || s2 < 0;
  if (pos && neg) return 0;
  if (s0 == 0 || s1 == 0 || s2 == 0 || s_p == 0) return -1;
  return 1;
}

// Per boundary loop, the apex its cap fan closes from: the point of the intersection of the
// planes it lies on nearest the loop's centre (least squares, minimal norm), so the caps lie in
// the planes and the half model's volume is the mirrored body's half with the right sign.
std::vector<Vector3d> loop_apexes(const Work& w, const BoundaryLoops& loops, const std::vector<SymmetryPlane>& planes) {
  std::vector<Vector3d> loop_apex(loops.planes.size(), Vector3d::Zero());
  std::vector<double> loop_size(loops.planes.size(), 0.0);
  for (std::size_t i = 0; i < loops.slots.size(); ++i) {
    loop_apex[idx(loops.loop_of_slot[i])] += w.p(w.slot_from(loops.slots[i]));
    ++loop_size[idx(loops.loop_of_slot[i])];
  }
  for (std::size_t l = 0; l < loops.planes.size(); ++l) {
    const Vector3d centre = loop_apex[l] / loop_size[l];
    std::vector<std::size_t> used;
    for (std::size_t p = 0; p < planes.size(); ++p)
      if (loops.planes[l][p]) used.push_back(p);
    if (used.empty()) {
      loop_apex[l] = centre;
      continue;
    }
    Eigen::MatrixXd n(static_cast<Eigen::Index>(used.size()), 3);
    Eigen::VectorXd r(static_cast<Eigen::Index>(used.size()));
    for (std::size_t i = 0; i < used.size(); ++i) {
      n.row(static_cast<Eigen::Index>(i)) = planes[used[i]].normal.transpose();
      r(static_cast<Eigen::Index>(i)) = planes[used[i]].offset - planes[used[i]].normal.dot(centre);
    }
    const Eigen::Vector3d shift = n.jacobiSvd(Eigen::ComputeFullU | Eigen::ComputeFullV).solve(r);
    loop_apex[l] = centre + shift;
  }
  return loop_apex;
}

// The axis of the nesting rays: parallel to all symmetry planes if an axis allows, so a ray never
// crosses the planes that close the open components (else x, and open components cannot contain
// others).
struct RayAxis {
  int axis = 0;
  bool open_can_contain = true;
};

RayAxis ray_axis(const std::vector<SymmetryPlane>& planes, const std::vector<char>& comp_open) {
  int axis = -1;
  for (int a = 0; a < 3 && axis < 0; ++a) {
    bool parallel = true;
    for (const auto& pl : planes) parallel = parallel && std::abs(pl.normal[a]) <= kParallelTol;
    if (parallel) axis = a;
  }
  const bool any_open = std::any_of(comp_open.begin(), comp_open.end(), [](char o) { return o != 0; });
  if (axis < 0) axis = 0;
  const bool open_can_contain = !any_open || std::all_of(planes.begin(), planes.end(), [&](const SymmetryPlane& pl) {
    return std::abs(pl.normal[axis]) <= kParallelTol;
  });
  return {axis, open_can_contain};
}

// Which component each component lies inside (-1: none), by ray parity from a point inside one
// of its triangles, and that point.
struct Containment {
  std::vector<int> inner_of;
  std::vector<Vector3d> inner_point;
};

Containment find_containers(const Work& w, const Components& comps, const std::vector<char>& comp_open,
                            const RayAxis& ray, double far_coord, const TriangleTree& tree) {
  const std::size_t n_comps = comps.size();
  const int axis = ray.axis;
  Containment out{std::vector<int>(n_comps, -1), std::vector<Vector3d>(n_comps)};
  std::vector<char> parity(n_comps, 0);
  std::vector<int> hits, touched;
  for (std::size_t c = 0; c < n_comps; ++c) {
    const std::vector<int>& ct = comps.tris[c];
    constexpr int kTries = 8;
    for (int attempt = 0; attempt < kTries; ++attempt) {
      // Generic barycentric weights keep the start point off the other surfaces' edges.
      const Tri& x = w.tris[idx(ct[ct.size() * idx(attempt) / kTries])];
      const Vector3d p = 0.2137 * w.p(x[0]) + 0.3461 * w.p(x[1]) + 0.4402 * w.p(x[2]);
      Vector3d far = p;
      far[axis] = far_coord;
      hits.clear();
      tree.query(Eigen::AlignedBox3d(p.cwiseMin(far), p.cwiseMax(far)), hits);
      bool degenerate = false;
      for (const int t : hits) {
        const int b = comps.of[idx(t)];
        if (idx(b) == c || (comp_open[idx(b)] && !ray.open_can_contain)) continue;
        const Tri& y = w.tris[idx(t)];
        const int r = ray_crosses(p, far, axis, w.p(y[0]), w.p(y[1]), w.p(y[2]));
        if (r < 0) {
          degenerate = true;
          break;
        }
        if (r == 1) {
          if (!parity[idx(b)]) touched.push_back(b);
          parity[idx(b)] ^= 1;
        }
      }
      bool inside = false;
      for (const int b : touched) {
        if (parity[idx(b)] && !degenerate && !inside) {
          inside = true;
          out.inner_of[c] = b;
          out.inner_point[c] = p;
        }
        parity[idx(b)] = 0;
      }
      touched.clear();
      if (!degenerate) break;
    }
  }
  return out;
}

}  // namespace

std::vector<double> component_volumes(const Work& w, const Components& comps, const BoundaryLoops& loops,
                                      const std::vector<SymmetryPlane>& planes) {
  const std::vector<Vector3d> loop_apex = loop_apexes(w, loops, planes);
  // Terms are taken about the component's first vertex so the sum does not lose digits far from
  // the origin.
  std::vector<double> comp_volume(comps.size(), 0.0);
  for (std::size_t c = 0; c < comps.size(); ++c) {
    const Vector3d o = w.p(w.tris[idx(comps.tris[c].front())][0]);
    double v6 = 0;
    for (const int t : comps.tris[c]) {
      const Tri& x = w.tris[idx(t)];
      v6 += (w.p(x[0]) - o).dot((w.p(x[1]) - o).cross(w.p(x[2]) - o));
    }
    comp_volume[c] = v6;
  }
  for (std::size_t i = 0; i < loops.slots.size(); ++i) {
    const int s = loops.slots[i];
    const int c = comps.of[idx(s / 3)];
    const Vector3d o = w.p(w.tris[idx(comps.tris[idx(c)].front())][0]);
    // The cap triangle (to, from, apex) runs the edge the other way, as a neighbour would.
    const Vector3d& q = loop_apex[idx(loops.loop_of_slot[i])];
    comp_volume[idx(c)] += (w.p(w.slot_to(s)) - o).dot((w.p(w.slot_from(s)) - o).cross(q - o));
  }
  for (double& v : comp_volume) v /= 6;
  return comp_volume;
}

void flip_inward_components(Work& w, const Components& comps, std::vector<double>& volume, SurfaceCheckReport& rep) {
  const std::size_t n_comps = comps.size();
  std::vector<Eigen::AlignedBox3d> comp_box(n_comps);
  for (std::size_t t = 0; t < w.tris.size(); ++t)
    for (const int v : w.tris[t]) comp_box[idx(comps.of[t])].extend(w.p(v));
  int first_inward = -1;
  std::size_t inward_comps = 0;
  for (std::size_t c = 0; c < n_comps; ++c) {
    const double d = comp_box[c].diagonal().norm();
    if (!(std::abs(volume[c]) > kZeroVolumeRel * d * d * d))
      throw InputError(w.source() + ": a component of " + plural(comps.tris[c].size(), "triangle") +
                       " encloses (near) zero volume (" + fmt_number(volume[c]) + "), e.g. triangle " +
                       std::to_string(w.input_index[idx(comps.tris[c].front())]) + " at " +
                       fmt_point(w.centroid(comps.tris[c].front())));
    if (volume[c] < 0) {
      for (const int t : comps.tris[c]) std::swap(w.tris[idx(t)][1], w.tris[idx(t)][2]);
      rep.flipped_inward += comps.tris[c].size();
      volume[c] = -volume[c];
      if (inward_comps++ == 0) first_inward = w.input_index[idx(comps.tris[c].front())];
    }
  }
  if (inward_comps > 0)
    rep.repairs.push_back(w.source() + ": flipped " + plural(inward_comps, "inward component") + " (" +
                          plural(rep.flipped_inward, "triangle") + "; first: the one with triangle " +
                          std::to_string(first_inward) + ")");
}

std::vector<char> drop_nested_components(const Work& w, const Components& comps, const BoundaryLoops& loops,
                                         const std::vector<SymmetryPlane>& planes, const Eigen::AlignedBox3d& bbox,
                                         const TriangleTree& tree, bool drop_inner_components,
                                         SurfaceCheckReport& rep) {
  const std::size_t n_comps = comps.size();
  std::vector<char> alive(w.tris.size(), 1);
  if (n_comps <= 1) {
    rep.components = n_comps;
    return alive;
  }
  std::vector<char> comp_open(n_comps, 0);
  for (const int c : loops.comp) comp_open[idx(c)] = 1;
  const RayAxis ray = ray_axis(planes, comp_open);
  const double far_coord = bbox.max()[ray.axis] + bbox.diagonal().norm() + 1;
  const Containment inside = find_containers(w, comps, comp_open, ray, far_coord, tree);
  std::size_t nested = 0;
  int first_nested = -1;
  for (std::size_t c = 0; c < n_comps; ++c)
    if (inside.inner_of[c] >= 0 && nested++ == 0) first_nested = static_cast<int>(c);
  if (nested > 0) {
    const std::size_t fc = idx(first_nested);
    const std::string what = plural(nested, "component") + " inside another; first: a component of " +
                             plural(comps.tris[fc].size(), "triangle") + " (with triangle " +
                             std::to_string(w.input_index[idx(comps.tris[fc].front())]) + ") at " +
                             fmt_point(inside.inner_point[fc]) + " inside the component with triangle " +
                             std::to_string(w.input_index[idx(comps.tris[idx(inside.inner_of[fc])].front())]);
    if (!drop_inner_components)
      throw InputError(w.source() + ": " + what + " (geometry.inner_components is error; drop drops them)");
    for (std::size_t c = 0; c < n_comps; ++c)
      if (inside.inner_of[c] >= 0) {
        for (const int t : comps.tris[c]) alive[idx(t)] = 0;
        rep.dropped_inner += comps.tris[c].size();
      }
    rep.repairs.push_back(w.source() + ": dropped " + what + " (" + plural(rep.dropped_inner, "triangle") + ")");
  }
  for (std::size_t c = 0; c < n_comps; ++c)
    if (inside.inner_of[c] < 0) ++rep.components;
  return alive;
}

}  // namespace plaf::validate_detail
