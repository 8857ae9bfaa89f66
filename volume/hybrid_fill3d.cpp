// SPDX-License-Identifier: MIT
// The 3D fill around prism layers (hybrid_fill3d.h).
#include "volume/hybrid_fill3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/elements/lagrange.h"
#include "modules/metric/metric_integrals.h"
#include "volume/advancing_front_2d.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector3d;

// The progress's share of the fill done when TetGen returns (the planes and TetGen), the rest for
// the optimisation's passes (HybridFillParams::progress).
constexpr double kTetGenShare = 0.3;


// One point inside the layers of every connected part of their outer front (TetGen's holes:
// the bodies and their layers are not filled): the centroid of the vertices of a last-layer cell
// under a triangle of the part, a prism's (by its top face) or a tetrahedron's (by a face; a
// first layer with fans is tetrahedra). MesherError when a part has none.
std::vector<Vec> layer_holes(const LayerResult<3>& lr, int outer_tag) {
  const LinearFront<3>& ff = lr.fill_front;
  std::vector<std::size_t> root(ff.nodes.size());
  std::iota(root.begin(), root.end(), std::size_t{0});
  auto find = [&](std::size_t a) {
    while (root[a] != a) a = root[a] = root[root[a]];
    return a;
  };
  std::vector<std::size_t> outer;
  for (std::size_t t = 0; t < ff.triangles.size(); ++t) {
    if (ff.triangle_tag[t] != outer_tag) continue;
    outer.push_back(t);
    const auto& tri = ff.triangles[t];
    root[find(static_cast<std::size_t>(tri[1]))] = find(static_cast<std::size_t>(tri[0]));
    root[find(static_cast<std::size_t>(tri[2]))] = find(static_cast<std::size_t>(tri[0]));
  }
  // One outer triangle per connected part, by its sorted vertices; then one pass over the cells
  // for a prism whose top (Gmsh nodes 3, 4, 5) or a tetrahedron one of whose faces is one of them.
  std::map<std::array<NodeId, 3>, std::size_t> wanted;  // sorted triangle -> its part's root
  std::map<std::size_t, bool> parts;
  for (std::size_t t : outer) {
    const std::size_t r = find(static_cast<std::size_t>(ff.triangles[t][0]));
    if (!parts.emplace(r, true).second) continue;
    std::array<NodeId, 3> key = ff.triangles[t];
    std::sort(key.begin(), key.end());
    wanted.emplace(key, r);
  }
  std::map<std::size_t, Vec> hole;
  for (const CellBlock& cb : lr.mesh.cells) {
    const bool prism = cb.type == CellType::Prism;
    const int nv = prism ? 6 : 4;
    static constexpr int kPrismTop[1][3] = {{3, 4, 5}};
    static constexpr int kTetFaces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    for (std::size_t c = 0; c < cb.size() && hole.size() < wanted.size(); ++c) {
      const NodeId* v = cb.cell(c);
      for (int f = 0; f < (prism ? 1 : 4); ++f) {
        const int* fv = prism ? kPrismTop[f] : kTetFaces[f];
        std::array<NodeId, 3> key = {v[fv[0]], v[fv[1]], v[fv[2]]};
        std::sort(key.begin(), key.end());
        const auto it = wanted.find(key);
        if (it == wanted.end() || hole.count(it->second)) continue;
        Vec x = Vec::Zero();
        for (int k = 0; k < nv; ++k) x += lr.mesh.nodes[static_cast<std::size_t>(v[k])] / nv;
        hole.emplace(it->second, x);
      }
    }
  }
  std::vector<Vec> out;
  for (std::size_t t : outer) {
    const std::size_t r = find(static_cast<std::size_t>(ff.triangles[t][0]));
    if (hole.count(r)) continue;
    const Vec& x = ff.nodes[static_cast<std::size_t>(ff.triangles[t][0])];
    throw MesherError("fill: no layer cell under the outer front at (" + num(x.x()) + ", " + num(x.y()) + ", " + num(x.z()) +
                      ") to put the hole point of its body in");
  }
  for (const auto& [r, x] : hole) out.push_back(x);
  return out;
}

// Distance from x to the plane of triangle abc.
double plane_distance(const Vec& a, const Vec& b, const Vec& c, const Vec& x) {
  const Vec n = (b - a).cross(c - a);
  const double nn = n.norm();
  return nn > 0 ? std::abs(n.dot(x - a)) / nn : 0.0;
}

// The size ratio across the layers' outer front (HybridFill::FrontRatio): over each outer
// triangle, the fill tetrahedron's height (its apex's distance to the triangle's plane) over the
// layer cell's below it (a prism's bottom centroid's, a tetrahedron's apex's).
using FrontHeights = std::map<std::array<NodeId, 3>, std::pair<double, double>>;  // sorted triangle -> (layer, fill)

// Over each outer triangle, the height of the layer cell below it (the fill's left 0): computed
// once, before and after the optimiser alike.
FrontHeights layer_heights(const LayerResult<3>& lr, int outer_tag) {
  const LinearFront<3>& ff = lr.fill_front;
  FrontHeights heights;
  for (std::size_t t = 0; t < ff.triangles.size(); ++t) {
    if (ff.triangle_tag[t] != outer_tag) continue;
    std::array<NodeId, 3> key = ff.triangles[t];
    std::sort(key.begin(), key.end());
    heights.emplace(key, std::pair{0.0, 0.0});
  }
  auto at = [&](NodeId v) -> const Vec& { return lr.mesh.nodes[static_cast<std::size_t>(v)]; };
  static constexpr int kTetFaces[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};  // face, apex
  for (const CellBlock& cb : lr.mesh.cells) {
    const bool prism = cb.type == CellType::Prism;
    for (std::size_t c = 0; c < cb.size(); ++c) {
      const NodeId* v = cb.cell(c);
      if (prism) {
        std::array<NodeId, 3> key = {v[3], v[4], v[5]};
        std::sort(key.begin(), key.end());
        const auto it = heights.find(key);
        if (it != heights.end())
          it->second.first = plane_distance(at(v[3]), at(v[4]), at(v[5]), (at(v[0]) + at(v[1]) + at(v[2])) / 3);
        continue;
      }
      for (const auto& f : kTetFaces) {
        std::array<NodeId, 3> key = {v[f[0]], v[f[1]], v[f[2]]};
        std::sort(key.begin(), key.end());
        const auto it = heights.find(key);
        if (it != heights.end()) it->second.first = plane_distance(at(v[f[0]]), at(v[f[1]]), at(v[f[2]]), at(v[f[3]]));
      }
    }
  }
  return heights;
}

// The ratio with the fill's tetrahedra on the outer triangles (heights: layer_heights).
FrontRatio front_ratio(FrontHeights heights, const FillResult<3>& fill) {
  static constexpr int kTetFaces[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};  // face, apex
  for (const auto& t : fill.simplices)
    for (const auto& f : kTetFaces) {
      std::array<NodeId, 3> key = {t[f[0]], t[f[1]], t[f[2]]};
      std::sort(key.begin(), key.end());
      const auto it = heights.find(key);
      if (it == heights.end()) continue;
      const auto& x = fill.nodes;
      it->second.second = plane_distance(x[static_cast<std::size_t>(t[f[0]])], x[static_cast<std::size_t>(t[f[1]])],
                                         x[static_cast<std::size_t>(t[f[2]])], x[static_cast<std::size_t>(t[f[3]])]);
    }
  std::vector<double> ratios;
  for (const auto& [key, h] : heights)
    if (h.first > 0 && h.second > 0) ratios.push_back(h.second / h.first);
  FrontRatio r;
  r.triangles = ratios.size();
  if (ratios.empty()) return r;
  std::sort(ratios.begin(), ratios.end());
  auto pct = [&](double q) { return ratios[std::min(ratios.size() - 1, static_cast<std::size_t>(q * static_cast<double>(ratios.size())))]; };
  r.p50 = pct(0.5);
  r.p95 = pct(0.95);
  r.max = ratios.back();
  return r;
}

// A symmetry plane x[axis] = offset of the layer mesh, with the tag its facets carry.
struct Plane {
  int axis = 0;
  double offset = 0;
  std::string tag;
};

std::vector<Plane> symmetry_planes(const HybridMesh<3>& mesh, double scale) {
  std::vector<Plane> planes;
  for (const CellBlock& b : mesh.boundary) {
    const BoundaryTag& tag = mesh.tags[static_cast<std::size_t>(b.tag)];
    if (tag.kind != BoundaryKind::Symmetry) continue;
    // Every facet: one tag may lie on several planes (a wing's root and tip).
    for (std::size_t c = 0; c < b.size(); ++c) {
      const NodeId* f = b.cell(c);
      const Vec &a = mesh.nodes[static_cast<std::size_t>(f[0])], &c1 = mesh.nodes[static_cast<std::size_t>(f[1])],
                &c2 = mesh.nodes[static_cast<std::size_t>(f[2])];
      const Vec n = (c1 - a).cross(c2 - a).normalized();
      int axis = 0;
      for (int d = 1; d < 3; ++d)
        if (std::abs(n[d]) > std::abs(n[axis])) axis = d;
      if (!(std::abs(n[axis]) > 1 - 1e-9))
        throw MesherError("fill: the symmetry plane of tag " + tag.name + " is not axis-aligned (normal " + num(n.x()) + ", " +
                          num(n.y()) + ", " + num(n.z()) + "); the farfield box is cut by axis-aligned planes only");
      const bool known = std::any_of(planes.begin(), planes.end(), [&](const Plane& p) {
        return p.axis == axis && std::abs(p.offset - a[axis]) <= 1e-9 * scale;
      });
      if (!known) planes.push_back({axis, a[axis], tag.name});
    }
  }
  return planes;
}

// Sizes growing from the nodes of a plane's loops: min(cap, min_i s_i + g |x - p_i|).
class GradedSizes final : public MetricField<2> {
 public:
  GradedSizes(std::vector<Eigen::Vector2d> p, std::vector<double> s, double g, double cap)
      : p_(std::move(p)), s_(std::move(s)), g_(g), cap_(cap) {}
  Metric<2> evaluate(const Eigen::Vector2d& x) const override { return Metric<2>::isotropic(size(x)); }
  double size(const Eigen::Vector2d& x) const {
    double h = cap_;
    for (std::size_t i = 0; i < p_.size(); ++i) h = std::min(h, s_[i] + g_ * (x - p_[i]).norm());
    return h;
  }

 private:
  std::vector<Eigen::Vector2d> p_;
  std::vector<double> s_;
  double g_, cap_;
};

// A symmetry plane's metric for its 2D fill: the run's metric restricted to the plane (the
// block of its tensor along the plane's two axes u, v: exact for every length in the plane),
// intersected with the sizes graded from the plane's loops (GradedSizes), so that the triangles
// start at the loops' edge lengths and follow the metric, anisotropic where it is, away from them.
class PlaneMetric final : public MetricField<2> {
 public:
  PlaneMetric(const MetricField<3>& metric, int axis, double offset, const GradedSizes& graded)
      : metric_(metric), axis_(axis), offset_(offset), graded_(graded) {}
  Metric<2> evaluate(const Eigen::Vector2d& p) const override {
    const int u = (axis_ + 1) % 3, v = (axis_ + 2) % 3;
    Vec x;
    x[axis_] = offset_;
    x[u] = p.x();
    x[v] = p.y();
    const Eigen::Matrix3d m = metric_.evaluate(x).matrix();
    Eigen::Matrix2d in_plane;
    in_plane << m(u, u), m(u, v), m(v, u), m(v, v);
    return intersect(Metric<2>::from_matrix(in_plane), graded_.evaluate(p));
  }

 private:
  const MetricField<3>& metric_;
  int axis_;
  double offset_;
  const GradedSizes& graded_;
};

double signed_area(const std::vector<Eigen::Vector2d>& pts) {
  double a = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector2d& p = pts[i];
    const Eigen::Vector2d& q = pts[(i + 1) % pts.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return a / 2;
}

}  // namespace

namespace {

// How many of the outer front's triangles are still curved (where columns stopped on faces no
// closing layer straightened, layers.events): the tetrahedra on them are curved (step 1).
std::size_t count_curved_outer_triangles(const LayerResult<3>& lr) {
  const CellBlock outer{CellType::Triangle, lr.outer.order, -1, lr.outer.triangles};
  std::size_t curved = 0;
  for (std::size_t t = 0; t < outer.size(); ++t)
    if (is_curved(lr.mesh, outer, t)) ++curved;
  return curved;
}

}  // namespace

HybridFill fill_around_layers(const LayerResult<3>& lr, const MetricField<3>& metric, const HybridFillParams& params) {
  if (lr.layers.empty()) throw MesherError("fill: tetgen fills around prism layers; the layer stage grew none");
  if (lr.outer.num_quads() > 0)
    throw MesherError("fill: the layers' outer front has " + std::to_string(lr.outer.num_quads()) +
                      " quadrilaterals; the TetGen fill meets triangles only");
  HybridFill r;
  r.curved_front_triangles = count_curved_outer_triangles(lr);  // step 1
  LinearFront<3> front = lr.fill_front;
  int outer_tag = -1;
  for (std::size_t k = 0; k < front.tags.size(); ++k)
    if (front.tags[k].name == "layers_outer") outer_tag = static_cast<int>(k);
  Vec lo = Vec::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& t : front.triangles)
    for (NodeId id : t) {
      lo = lo.cwiseMin(front.nodes[static_cast<std::size_t>(id)]);
      hi = hi.cwiseMax(front.nodes[static_cast<std::size_t>(id)]);
    }
  const double scale = (hi - lo).norm();

  // 2. Symmetry planes, the bodies' side of each, and the rim edges on each.
  const std::vector<Plane> planes = symmetry_planes(lr.mesh, scale);
  const Vec mid = 0.5 * (lo + hi);
  FarfieldParams3 fp = params.farfield;
  fp.cuts.clear();  // one per plane, in the planes' order
  for (const Plane& p : planes) fp.cuts.push_back({p.axis, p.offset, mid[p.axis] > p.offset ? 1 : -1});
  std::map<std::pair<NodeId, NodeId>, int> edge_count;
  for (std::size_t t = 0; t < front.triangles.size(); ++t) {
    if (front.triangle_tag[t] != outer_tag) continue;
    for (int k = 0; k < 3; ++k) {
      const NodeId a = front.triangles[t][static_cast<std::size_t>(k)], b = front.triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      ++edge_count[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::vector<std::map<NodeId, NodeId>> rim_next(planes.size());  // per plane: directed rim edges a -> b
  for (std::size_t t = 0; t < front.triangles.size(); ++t) {
    if (front.triangle_tag[t] != outer_tag) continue;
    for (int k = 0; k < 3; ++k) {
      const NodeId a = front.triangles[t][static_cast<std::size_t>(k)], b = front.triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      if (edge_count.at({std::min(a, b), std::max(a, b)}) != 1) continue;
      const Vec &xa = front.nodes[static_cast<std::size_t>(a)], &xb = front.nodes[static_cast<std::size_t>(b)];
      std::size_t on = planes.size();
      for (std::size_t p = 0; p < planes.size(); ++p)
        if (std::abs(xa[planes[p].axis] - planes[p].offset) <= 1e-9 * scale &&
            std::abs(xb[planes[p].axis] - planes[p].offset) <= 1e-9 * scale)
          on = p;
      if (on == planes.size())
        throw MesherError("fill: the layers' outer front is open at (" + num(xa.x()) + ", " + num(xa.y()) + ", " + num(xa.z()) +
                          ") off every symmetry plane");
      rim_next[on][a] = b;
    }
  }

  // The farfield, its h from the metric unless given.
  if (fp.h <= 0) {
    const Vec c = farfield_center(fp, lo, hi);
    // The sphere's radius, or the box's smallest half size across no symmetry plane.
    double extent = fp.radius > 0 ? fp.radius : 10 * scale;
    if (fp.shape == "box") {
      extent = std::numeric_limits<double>::infinity();
      for (int d = 0; d < 3; ++d) {
        const bool cut = std::any_of(fp.cuts.begin(), fp.cuts.end(), [d](const FarfieldParams3::Cut& k) { return k.axis == d; });
        if (!cut) extent = std::min(extent, 0.5 * (fp.size[static_cast<std::size_t>(d)] > 0 ? fp.size[static_cast<std::size_t>(d)] : 20 * scale));
      }
      if (!std::isfinite(extent)) extent = 10 * scale;
    }
    int free_axis = 0;  // a farfield point off the symmetry planes
    while (free_axis < 2 && std::any_of(fp.cuts.begin(), fp.cuts.end(), [free_axis](const FarfieldParams3::Cut& k) { return k.axis == free_axis; }))
      ++free_axis;
    fp.h = std::min(metric.evaluate(c + extent * Vec::Unit(free_axis)).max_size(), extent / 4);
    // Within fill.max_volume, with room for the farfield's triangles above h (TetGen keeps them):
    // at the full edge, the sphere hybrid's largest tetrahedron was 1.43 for a bound of 1.
    if (params.tet.max_volume > 0) fp.h = std::min(fp.h, 0.8 * largest_edge_within(params.tet.max_volume));
  }
  const FarfieldMesh3 far = make_farfield(fp, lo, hi);
  const NodeId base = static_cast<NodeId>(front.nodes.size());
  front.nodes.insert(front.nodes.end(), far.nodes.begin(), far.nodes.end());
  r.fill.tags.push_back({"farfield", BoundaryKind::Farfield});
  const int far_tag = static_cast<int>(front.tags.size());
  front.tags.push_back(r.fill.tags.back());
  for (const auto& t : far.triangles) {
    front.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    front.triangle_tag.push_back(far_tag);
    r.fill.boundary.push_back(front.triangles.back());
    r.fill.boundary_tag.push_back(0);
  }
  r.farfield_triangles = far.triangles.size();
  if (params.size_check) {
    // The tetrahedra the farfield will hold (HybridFillParams::size_check), before any is made.
    Vec flo = far.nodes.front(), fhi = far.nodes.front();
    for (const Vec& x : far.nodes) {
      flo = flo.cwiseMin(x);
      fhi = fhi.cwiseMax(x);
    }
    const Vec centre = 0.5 * (flo + fhi);
    const double radius = 0.5 * (fhi - flo).maxCoeff();
    const bool sphere = fp.shape == "sphere";
    // TetGen's sizes inside are interpolated from its boundary nodes' sizes (their edges' lengths,
    // step 4); far from the bodies, where most of the volume is, from the farfield's: so no
    // coarser there than the farfield's h, given or not. And no tetrahedron is larger than
    // fill.max_volume. Those bound the count from below where the metric's sizes are coarser
    // (issue 37, item 2: a farfield h of 0.6 on the sphere hybrid, 1.5M tetrahedra by TetGen,
    // about 1.3M by this, saw no budget; they are counted before the optimiser coarsens them).
    const double floor_density = std::max(kTetrahedraPerMetricVolume * std::pow(fp.h, -3.0),
                                          params.tet.max_volume > 0 ? 1 / params.tet.max_volume : 0.0);
    const double tets = region_integral<3>(
        flo, fhi, [&](const Vec& x) { return !sphere || (x - centre).norm() <= radius; },
        [&](const Vec& x) {
          return std::max(kTetrahedraPerMetricVolume * std::pow(metric.evaluate(x).max_size(), -3.0), floor_density);
        },
        20000);
    params.size_check(tets);
  }

  // 3. Each plane's region: the farfield's cut loop and the rim loops, by the 2D advancing front.
  std::vector<std::pair<NodeId, int>> in_plane;  // the planes' own nodes and their axes
  for (std::size_t p = 0; p < planes.size(); ++p) {
    const int a = planes[p].axis, u = (a + 1) % 3, v = (a + 2) % 3;
    auto flat = [&](NodeId id) { return Eigen::Vector2d(front.nodes[static_cast<std::size_t>(id)][u], front.nodes[static_cast<std::size_t>(id)][v]); };
    std::vector<std::vector<NodeId>> loops;
    std::vector<NodeId> cut;
    for (int id : far.cut_loops[p]) cut.push_back(base + id);
    loops.push_back(cut);
    std::map<NodeId, NodeId> next = rim_next[p];
    while (!next.empty()) {
      std::vector<NodeId> loop;
      NodeId at = next.begin()->first;
      while (next.count(at)) {
        loop.push_back(at);
        const NodeId b = next.at(at);
        next.erase(at);
        at = b;
      }
      if (at != loop.front()) throw MesherError("fill: the layers' rim on symmetry plane " + planes[p].tag + " is not closed");
      loops.push_back(loop);
    }
    LinearFront<2> plane;
    std::vector<NodeId> id3;  // plane node -> front node
    std::vector<double> sizes;
    for (std::size_t l = 0; l < loops.size(); ++l) {
      std::vector<Eigen::Vector2d> pts;
      for (NodeId id : loops[l]) pts.push_back(flat(id));
      // The region on the left: the farfield's loop counter-clockwise, the rims clockwise.
      if ((signed_area(pts) > 0) != (l == 0)) std::reverse(loops[l].begin(), loops[l].end());
      LinearLoop loop;
      loop.tag = planes[p].tag;
      loop.kind = l == 0 ? BoundaryKind::Farfield : BoundaryKind::Wall;
      const std::size_t n = loops[l].size();
      for (std::size_t k = 0; k < n; ++k) {
        const NodeId id = loops[l][k];
        loop.nodes.push_back(static_cast<NodeId>(plane.nodes.size()));
        plane.nodes.push_back(flat(id));
        id3.push_back(id);
        sizes.push_back(0.5 * ((flat(loops[l][(k + 1) % n]) - flat(id)).norm() + (flat(loops[l][(k + n - 1) % n]) - flat(id)).norm()));
      }
      plane.loops.push_back(loop);
    }
    const GradedSizes graded(plane.nodes, sizes, params.grading, fp.h);
    const PlaneMetric field(metric, a, planes[p].offset, graded);
    const AdvancingFrontResult af = advancing_front_fill(plane, field);
    for (std::size_t k = plane.nodes.size(); k < af.nodes.size(); ++k) {
      in_plane.emplace_back(static_cast<NodeId>(front.nodes.size()), a);  // the optimiser may slide it
      Vec x;
      x[a] = planes[p].offset;
      x[u] = af.nodes[k].x();
      x[v] = af.nodes[k].y();
      id3.push_back(static_cast<NodeId>(front.nodes.size()));
      front.nodes.push_back(x);
    }
    // Counter-clockwise in (u, v) faces +axis; the fill lies on the bodies' side.
    const bool flip = fp.cuts[p].side < 0;
    const int tag = static_cast<int>(front.tags.size());
    front.tags.push_back({planes[p].tag, BoundaryKind::Symmetry});
    r.fill.tags.push_back(front.tags.back());
    for (const auto& t : af.simplices) {
      std::array<NodeId, 3> tri = {id3[static_cast<std::size_t>(t[0])], id3[static_cast<std::size_t>(t[1])], id3[static_cast<std::size_t>(t[2])]};
      if (flip) std::swap(tri[1], tri[2]);
      front.triangles.push_back(tri);
      front.triangle_tag.push_back(tag);
      r.fill.boundary.push_back(tri);
      r.fill.boundary_tag.push_back(static_cast<int>(r.fill.tags.size()) - 1);
    }
    r.plane_triangles += af.simplices.size();
  }

  // 4. Holes and sizes, then TetGen.
  front.holes = layer_holes(lr, outer_tag);
  r.holes = front.holes.size();
  TetFillParams tp = params.tet;
  tp.node_sizes.assign(front.nodes.size(), 0.0);
  std::vector<int> edges(front.nodes.size(), 0);
  for (const auto& t : front.triangles)
    for (int k = 0; k < 3; ++k) {
      const NodeId ea = t[static_cast<std::size_t>(k)], eb = t[static_cast<std::size_t>((k + 1) % 3)];
      const double len = (front.nodes[static_cast<std::size_t>(ea)] - front.nodes[static_cast<std::size_t>(eb)]).norm();
      for (NodeId x : {ea, eb}) tp.node_sizes[static_cast<std::size_t>(x)] += len, ++edges[static_cast<std::size_t>(x)];
    }
  for (std::size_t x = 0; x < front.nodes.size(); ++x)
    if (edges[x] > 0) tp.node_sizes[x] /= edges[x];
  TetFillResult tets = tetgen_fill(front, tp);
  r.stats = tets.stats;
  r.fill.nodes = std::move(tets.nodes);
  r.fill.simplices = std::move(tets.simplices);
  if (params.progress)
    params.progress(kTetGenShare, "TetGen: " + std::to_string(r.fill.simplices.size()) + " tetrahedra");

  // 5. The metric optimisation, every front node fixed but the planes' own (sliding in them).
  const FrontHeights below = layer_heights(lr, outer_tag);
  r.front_ratio_before = front_ratio(below, r.fill);
  Optimize3Params op = params.optimize;
  op.in_plane = std::move(in_plane);
  op.max_volume = params.tet.max_volume;
  if (params.progress)
    op.on_pass = [&params](int pass, int passes) {
      params.progress(kTetGenShare + (1 - kTetGenShare) * pass / passes,
                      "optimisation pass " + std::to_string(pass) + " of " + std::to_string(passes));
    };
  r.optimize = optimize_fill_3d(r.fill, front.nodes.size(), metric, op);
  r.front_ratio_after = front_ratio(below, r.fill);
  r.farfield = fp;
  return r;
}

}  // namespace plaf::volume
