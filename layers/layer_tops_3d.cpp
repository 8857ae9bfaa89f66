// SPDX-License-Identifier: MIT
// The tops of one layer (PartLayerBuilder::tops, layer3d_builder.h): the metric's heights, the
// shrinks' scales, the slopes beside stops, the attenuation toward the chords.
#include "layers/layer3d_builder.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>

#include <Eigen/Eigenvalues>

#include "layers/front_collisions_3d.h"
#include "modules/base/error.h"
#include "modules/elements/validity.h"
#include "modules/geometry/aabb_tree.h"
#include "modules/geometry/predicates.h"

namespace plaf::layers::grow3d {

auto PartLayerBuilder::chord_sag_need(const Part& nw) const -> double {
  double need = 0;
  for (std::size_t f = 0; f < nw.num_faces(); ++f) {
    const int* fl = nw.face(f);
    const int nv = nw.face_vertices(f);
    for (int k = 0; k < nv; ++k) {
      const Dir& u = dirs_[static_cast<std::size_t>(fl[k])];
      const Dir& v = dirs_[static_cast<std::size_t>(fl[(k + 1) % nv])];
      if ((u.fan && !u.normal) || (v.fan && !v.normal) || u.concave || v.concave) continue;  // 2D's rule
      const Vec axis = u.d.cross(v.d);
      const double sin_t = axis.norm(), theta = std::atan2(sin_t, u.d.dot(v.d));
      if (!(sin_t > 1e-12)) continue;
      Vec c = top_[static_cast<std::size_t>(fl[(k + 1) % nv])] - top_[static_cast<std::size_t>(fl[k])];
      c -= c.dot(axis / sin_t) * (axis / sin_t);
      const double sag = 0.5 * c.norm() * std::tan(0.25 * theta);
      const double h = std::min(dh_[static_cast<std::size_t>(fl[k])], dh_[static_cast<std::size_t>(fl[(k + 1) % nv])]);
      if (h > 0 && sag > f_atten_ * h) need = std::max(need, sag / h);
    }
  }
  return need;
}

void PartLayerBuilder::slope_from_stops(const std::vector<std::uint8_t>& before) {
  const std::size_t n = part_.size();
  if (part_.stack.size() != n) return;
  constexpr double kStopSlope = 0.5, kStopCreep = 0.25;
  std::vector<double> cap(n, std::numeric_limits<double>::infinity());
  for (std::size_t l = 0; l < n; ++l)
    if (before[l]) cap[l] = part_.stack[l];
  spread_min(cap, before, [&](double c, std::size_t l, std::size_t m) { return c + kStopSlope * (x_[m] - x_[l]).norm(); });
  for (std::size_t l = 0; l < n; ++l) {
    if (!part_.is_vertex[l] || stop_[l] || !std::isfinite(cap[l])) continue;
    const double rise = h_[l] * nn_[l].stretch;
    const double room = cap[l] - part_.stack[l];
    if (rise > room) h_[l] *= std::max(room / rise, kStopCreep);
  }
}

void PartLayerBuilder::limit_height_jumps() {
  constexpr double kHeightJump = 2;
  std::vector<std::uint8_t> growing(part_.size(), 0);
  for (std::size_t l = 0; l < part_.size(); ++l) growing[l] = part_.is_vertex[l] && !stop_[l] && std::isfinite(h_[l]);
  spread_min(h_, growing, [&](double h, std::size_t, std::size_t m) {
    return stop_[m] ? std::numeric_limits<double>::infinity() : kHeightJump * h;
  });
}

void PartLayerBuilder::tops() {
  const std::size_t n = part_.size();
  const Part& nw = next();
  h_.resize(n);
  // The metric's height at the vertices (at a fan node the smallest over its normals -- wedge
  // directions, kite normals n_s, a corner's centre -- not over the kites' X_s: the wall's
  // normal size, whichever direction the metric takes for the normal on the ridge itself, one
  // face's or the bisector as a wing's trailing edge reports; over the sides alone a bisector
  // gives h0 / cos 87 degrees = 20 h0); a high-order node takes the
  // interpolation of its face's vertex heights (the attenuation's recipe; high_order_heights:
  // own gives it its own, as 2D does by default, except on fan edges). Its own metric height
  // would feed back: a node the attenuation pulled toward the chord lies nearer the wall, gets a
  // smaller height from a wall law, and falls further behind every layer (measured on a sphere:
  // the front's sag grew from 0.005 to 0.012 in 30 layers instead of vanishing).
  for (std::size_t l = 0; l < n; ++l)
    if (part_.is_vertex[l]) h_[l] = fanned_ && fan_node_[l] ? std::numeric_limits<double>::infinity()
                                                          : heights_(metric_, x_[l], nn_[l].n, p_.integrate_height);
  if (fanned_)
    for (const Dir& r : dirs_) {
      const std::size_t l = static_cast<std::size_t>(r.base);
      if (part_.is_vertex[l] && fan_node_[l] && r.normal)
        h_[l] = std::min(h_[l], heights_(metric_, x_[l], r.d, p_.integrate_height));
    }
  // The shrinks' scales (layer_core.h, step 3) apply to the vertices before a high-order node
  // interpolates them: scaling the nodes one by one raised a bump on the faces just outside a
  // shrunk ring (an edge node at the full height between a halved vertex and a whole one),
  // which the cut cells of a layer with stops cannot follow (their heights are affine over a
  // cell; on the published bullet, h0 1e-5 L at Q3, the bump stood 1.2 layer heights above
  // them and the cut cells inverted there).
  for (std::size_t l = 0; l < n; ++l)
    if (part_.is_vertex[l]) h_[l] *= scale_[l];
  // Beside a column stopped in an earlier layer (a stop on a failure, the proximity rule's, or
  // isotropic_stop's) a layer with stops grows half the height: the front slopes down into the
  // stop instead of standing as a wall that rises a full layer each time. Without it the
  // columns around a stop sank into a pit whose walls their cut cells could not follow: on the
  // published 717 wing (h0 1e-5 L, Q2) 36 of the 78 tetrahedra that failed at the height floor
  // in layers 21-40 touched a column stopped earlier, and each such failure stopped more
  // columns. (Not beside the stops of this layer's own rounds: no pit stands there yet, and on
  // the published BWB at Q3 halving there, over its curved wall in layer 1, failed the
  // neighbours in turn, round after round: 92.0 % coverage instead of 97.0 %.) Sec. II.B grows
  // every column by the metric's height and does not meet stops; halving is the shrink
  // step's own factor (layer_core.h, step 3).
  if (any_stop_ && !fanned_ && !held_.empty()) {
    std::vector<std::uint8_t> before(n, 0), beside(n, 0);
    for (std::size_t k = 0; k < held_.size() && k < part_.vertices.size(); ++k)
      if (held_[k]) before[static_cast<std::size_t>(part_.vertices[k])] = 1;
    for (std::size_t f = 0; f < part_.num_faces(); ++f) {
      const int* fl = part_.face(f);
      bool stopped = false;
      for (int v = 0; v < 3; ++v) stopped = stopped || before[static_cast<std::size_t>(fl[v])];
      if (stopped)
        for (int v = 0; v < 3; ++v) beside[static_cast<std::size_t>(fl[v])] = 1;
    }
    constexpr double kBesideStop = 0.5;
    for (std::size_t l = 0; l < n; ++l)
      if (part_.is_vertex[l] && beside[l] && !stop_[l]) h_[l] *= kBesideStop;
    slope_from_stops(before);
  }
  if (!fanned_) limit_height_jumps();
  const bool own = p_.high_order_heights == HighOrderHeights::Own;
  for (std::size_t l = 0; l < n; ++l)
    if (!part_.is_vertex[l] && own && !(fanned_ && fan_node_[l])) {
      h_[l] = heights_(metric_, x_[l], nn_[l].n, p_.integrate_height) * scale_[l];
    } else if (!part_.is_vertex[l]) {
      double h = 0;
      for (int k = 0; k < 4; ++k) h += part_.tw[l][static_cast<std::size_t>(k)] * h_[static_cast<std::size_t>(part_.tv[l][static_cast<std::size_t>(k)])];
      h_[l] = h;
    }
  const std::size_t nd = dirs_.size();
  top_.resize(nd);
  dh_.resize(nd);
  for (std::size_t d = 0; d < nd; ++d) {
    const Dir& r = dirs_[d];
    const std::size_t l = static_cast<std::size_t>(r.base);
    dh_[d] = stopped_dir(d) ? 0.0 : h_[l] * r.stretch;
    top_[d] = stopped_dir(d) ? x_[l] : onto_planes(x_[l] + dh_[d] * r.d, part_.plane[l], planes_);
  }
  // Straight tops: on a straight base (the node at its linear position), on every face
  // touching a concave node, and on every face of a layer with stopped columns. That layer is
  // cut into tetrahedra (columns_and_cells), and the attenuation's pull cannot follow into them:
  // a pull that grows with the level in the layer is of degree Q + 1 in a tetrahedron cut from
  // the prism, and its order-Q interpolant tilts the cell's rise by several times the pull
  // (on the published spot, h0 1e-5 L, Q3, an edge attenuated by -0.2 and +0.2 of the height at
  // its two inner nodes made the cut tetrahedron's rise at its base vertex -0.2 of the height:
  // 262 invalid cells in the layer after the first stop, 1,289 after four shrinks). With the
  // base's own offset carried up (layer_node) every cut cell is its base carried up by heights
  // affine over the cell (4 invalid cells there). A stop is for good, so the part's front
  // would keep its curvature to the last layer, where the offsets of a concave front's
  // shrinking cells invert them (the spot at Q3: 3 columns stopped in layer 6 and all 52,015
  // cells of layers 6 to 40 stayed curved, needing up to 1,468 heights of attenuation; the
  // columns lost came from layers 25 to 40). So such a layer attenuates gently: each top moves
  // toward its chord by at most kStopAtten of its height (a quarter of the paper's f_atten), a
  // pull whose degree-(Q + 1) share in a cut cell stays a small part of the cell's rise, and
  // the front becomes linear once the heights outgrow the sag.
  // A closing layer (f_atten infinite) straightens the faces away from the stops.
  const bool keep_curvature = any_stop_ && std::isfinite(f_atten_);
  constexpr double kStopAtten = 0.05;
  std::vector<std::uint8_t> straight(nd, keep_curvature ? 1 : 0);
  for (std::size_t f = 0; f < nw.num_faces() && !keep_curvature; ++f) {
    const int* fl = nw.face(f);
    bool c = false;
    for (int v = 0; v < nw.face_vertices(f); ++v)
      c = c || dirs_[static_cast<std::size_t>(fl[v])].concave || stopped_dir(static_cast<std::size_t>(fl[v]));
    if (c)
      for (int k = nw.face_vertices(f); k < nw.face_size(f); ++k) straight[static_cast<std::size_t>(fl[k])] = 1;
  }
  // The narrowest face each high-order node lies on: the smallest altitude of the linear
  // triangles of the base under its faces (lean_cap below).
  std::vector<double> narrow(nd, std::numeric_limits<double>::infinity());
  for (std::size_t f = 0; f < nw.num_faces(); ++f) {
    const int* fl = nw.face(f);
    if (nw.face_vertices(f) != 3) continue;
    const Vec& a = x_[static_cast<std::size_t>(dirs_[static_cast<std::size_t>(fl[0])].base)];
    const Vec& b = x_[static_cast<std::size_t>(dirs_[static_cast<std::size_t>(fl[1])].base)];
    const Vec& c = x_[static_cast<std::size_t>(dirs_[static_cast<std::size_t>(fl[2])].base)];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const double altitude = longest > 0 ? (b - a).cross(c - a).norm() / longest : 0.0;
    for (int k = 3; k < nw.face_size(f); ++k) {
      double& w = narrow[static_cast<std::size_t>(fl[k])];
      w = std::min(w, altitude);
    }
  }
  double clipped_max = 0;
  off_lift_.assign(nd, Vec::Zero());
  for (std::size_t d = 0; d < nd; ++d) {
    if (nw.is_vertex[d] || dirs_[d].fan || stopped_dir(d)) continue;
    const std::size_t l = static_cast<std::size_t>(dirs_[d].base);
    Vec target = Vec::Zero(), linear = Vec::Zero();
    double size = 0;
    for (int k = 0; k < 4; ++k) {
      const double w = nw.tw[d][static_cast<std::size_t>(k)];
      target += w * top_[static_cast<std::size_t>(nw.tv[d][static_cast<std::size_t>(k)])];
      const std::size_t v = static_cast<std::size_t>(part_.tv[l][static_cast<std::size_t>(k)]);
      linear += part_.tw[l][static_cast<std::size_t>(k)] * x_[v];
      size = std::max(size, (x_[v] - x_[l]).norm());
    }
    if ((x_[l] - linear).norm() <= straight_tolerance(size, std::max(x_[l].cwiseAbs().maxCoeff(), linear.cwiseAbs().maxCoeff()))) {
      top_[d] = target;
      continue;
    }
    if (straight[d]) {
      // A face touching a concave node, and every face of a layer with stops (then attenuated
      // below), grows a top as straight as its base:
      // the vertex tops' chord plus the base's own offset from its chord. A straight top over a
      // curved base lies under the base's bump wherever the bump is taller than the layer
      // (measured on the published spot, whose coarse facets make 275 spurious concave ridge
      // nodes: 589 of 21050 first-layer prisms inverted at h0 and 627 at h0/16 with straight
      // tops, none with the base's offset); on a straight base the two are one.
      top_[d] = target + (x_[l] - linear);
      // A layer with stops attenuates gently: a pull of at most kStopAtten of the height, whose
      // degree-(Q + 1) share inside a cut tetrahedron stays a small part of the cell's rise
      // (layer_node adds the point's level times it).
      if (keep_curvature) {
        const Vec kept = top_[d];
        clipped_max = std::max(clipped_max, attenuate<3>(&top_[d], &target, &dh_[d], 1, kStopAtten));
        off_lift_[d] = top_[d] - kept;
      }
      continue;
    }
    // Lean cap. A node grown along its own direction stands off the straight top (its face's
    // vertex tops' chord plus the base's own offset) by up to kMaxBend of its height (blend()).
    // On a sliver face of the front that offset turns the curved edges' tangents at the
    // sliver's sharp corner: an edge's end tangent turns by 4 x its middle node's offset over
    // its length (Q2), and the corner's angle is the face's width over that length, so two edges
    // leaning differently by a quarter of the width invert the cell there. Fans along a curved
    // ridge make such slivers (a fan's sector strip, split into two triangles, is 1e-4 as wide
    // as it is long in the first layers: a cylinder's flat end at h0 1e-5, 93 invalid cells in
    // layer 3, 5 % of the wall stopped). So the offset is capped at the narrowest face's
    // altitude over 2 Q^2 (an eighth at Q2; at Q3 an edge's end tangent moves by 9 x its nearer
    // inner node's offset over its length, so an eighteenth: a CAD cylinder's STL at Q3, 97.1 %
    // with an eighth, 99.9 %): no cap on a well-shaped face of a thin layer, the straight top
    // on a sliver.
    const Vec straight_top = target + (x_[l] - linear);
    const Vec lean = top_[d] - straight_top;
    const double cap = narrow[d] / (2.0 * q_ * q_);
    if (lean.norm() > cap) top_[d] = straight_top + lean * (cap / lean.norm());
    clipped_max = std::max(clipped_max, attenuate<3>(&top_[d], &target, &dh_[d], 1, f_atten_));
    off_lift_[d] = top_[d] - straight_top;
  }
  if (q_ == 1 && std::isfinite(f_atten_)) clipped_max = std::max(clipped_max, chord_sag_need(nw));
  out_.built.max_clipped_rel = clipped_max;
  out_.built.fixed_f_atten = keep_curvature ? kStopAtten : 0.0;
  out_.built.linear = clipped_max == 0;
  // The layer's heights along the vertex columns grown along a normal (a fan's wedge and kite
  // normals, not its arc directions), as 2D records them.
  for (std::size_t d = 0; d < nd; ++d) {
    if (!nw.is_vertex[d] || (dirs_[d].fan && !dirs_[d].normal) || stopped_dir(d)) continue;
    const Vec& b = x_[static_cast<std::size_t>(dirs_[d].base)];
    out_.built.columns.push_back({b[0], b[1], b[2], (top_[d] - b).norm(), scale_[static_cast<std::size_t>(dirs_[d].base)]});
  }
}

}  // namespace plaf::layers::grow3d
