// SPDX-License-Identifier: MIT
// The first layer's fans (PartLayerBuilder::fans, layer3d_builder.h; grow_layers_3d.h, step 6):
// ridge chains, their arcs and kites, corner patches, fades.
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

void PartLayerBuilder::fans() {
  const Part& p = part_;
  const std::size_t nt = p.nt();
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
  const double corner_rad = p_.corner_angle_deg * M_PI / 180, fan_rad = p_.fan_angle_deg * M_PI / 180;
  auto tri = [&](std::size_t t) { return p.tri.data() + t * static_cast<std::size_t>(np_); };
  // Edges by vertex pair: the two triangles and their local edges.
  struct Edge {
    int t[2] = {-1, -1}, e[2] = {0, 0};
  };
  std::map<std::pair<int, int>, Edge> edges;
  for (std::size_t t = 0; t < nt; ++t)
    for (int e = 0; e < 3; ++e) {
      const int a = tri(t)[e], b = tri(t)[(e + 1) % 3];
      Edge& E = edges[{std::min(a, b), std::max(a, b)}];
      const int slot = E.t[0] < 0 ? 0 : 1;
      E.t[slot] = static_cast<int>(t);
      E.e[slot] = e;
    }
  std::set<std::pair<int, int>> fan;
  for (const auto& [ab, E] : edges) {
    if (E.t[1] < 0) continue;
    double dev = 0;
    for (int k : te.edge_nodes(E.e[0])) {
      const int l = tri(static_cast<std::size_t>(E.t[0]))[k];
      dev = std::max(dev, std::acos(std::clamp(side_normal(E.t[0], l).dot(side_normal(E.t[1], l)), -1.0, 1.0)));
    }
    const int o0 = tri(static_cast<std::size_t>(E.t[0]))[(E.e[0] + 2) % 3], o1 = tri(static_cast<std::size_t>(E.t[1]))[(E.e[1] + 2) % 3];
    const Vec& xa = x_[static_cast<std::size_t>(ab.first)];
    const bool convex = (x_[static_cast<std::size_t>(o1)] - xa).dot(side_normal(E.t[0], ab.first)) < 0 &&
                        (x_[static_cast<std::size_t>(o0)] - xa).dot(side_normal(E.t[1], ab.first)) < 0;
    if (convex && dev > corner_rad) fan.insert(ab);
  }
  auto on_rim = [&](int v) { return p.plane[static_cast<std::size_t>(v)][0] >= 0; };
  std::map<int, int> cnt;
  // A chain's end where its ridge fades (one fan edge at a node off the planes): the fan closes
  // there to the node's one direction (fade_cells).
  auto fades = [&](int v) {
    const auto it = cnt.find(v);
    return it != cnt.end() && it->second == 1 && !on_rim(v);
  };
  // Without fan_fades a fade is a bad end (below): the chain keeps the merged normal.
  const bool fading = p_.fan_fades;
  // Pruning, as a worklist: a node is bad with a fan edge on two planes or with other than one
  // on a plane (one elsewhere is a fade); its fan edges go, and their other ends are checked
  // again; then the chains of one edge that fade go, until nothing changes.
  std::map<int, std::vector<std::pair<int, int>>> at_node;
  const std::size_t n = p.size();
  std::unordered_map<std::uint64_t, int> side_dir;  // (fan node, triangle) -> its wedge's direction
  auto key = [&](int l, int t) { return static_cast<std::uint64_t>(l) * nt + static_cast<std::uint64_t>(t); };
  // Pruning and wedges, again without the fan edges about which their fan would not turn.
  for (;;) {
    cnt.clear();
    at_node.clear();
    side_dir.clear();
    dirs_.clear();
    for (const auto& ab : fan) {
      ++cnt[ab.first], ++cnt[ab.second];
      at_node[ab.first].push_back(ab);
      at_node[ab.second].push_back(ab);
    }
    auto bad = [&](int v) {
      const int c = cnt[v];
      return c > 0 && (p.plane[static_cast<std::size_t>(v)][1] >= 0 || (on_rim(v) ? c != 1 : !fading && c == 1));
    };
    // A chain of one edge that fades (its other end a corner, a plane or a fade too) is no
    // fan: a fan must open over a node before it closes. (On the published ONERA M6 the remeshed
    // rounded tip has three such creases off the trailing edge's last node, fading within one
    // edge of 0.02 to 0.03 c each; their sectors, collapsing over a corner patch 1e-5 wide, made
    // second-layer prisms of aspect 1e4 that no height could make valid. Without them the
    // trailing edge's own fan fades at that node.)
    auto short_fade = [&](const std::pair<int, int>& ab) {
      auto closed = [&](int v) { return fades(v) || cnt[v] >= 3 || on_rim(v); };
      return (fades(ab.first) && closed(ab.second)) || (fades(ab.second) && closed(ab.first));
    };
    for (bool changed = true; changed;) {
      changed = false;
      std::vector<int> work;
      for (const auto& [v, c] : cnt) work.push_back(v);
      while (!work.empty()) {
        const int v = work.back();
        work.pop_back();
        if (!bad(v)) continue;
        for (const auto& ab : at_node[v]) {
          if (!fan.erase(ab)) continue;
          for (int x : {ab.first, ab.second}) {
            --cnt[x];
            if (x != v) work.push_back(x);
          }
        }
      }
      std::vector<std::pair<int, int>> drop;
      for (const auto& ab : fan)
        if (short_fade(ab)) drop.push_back(ab);
      for (const auto& ab : drop) {
        fan.erase(ab);
        --cnt[ab.first], --cnt[ab.second];
        changed = true;
      }
    }
    for (auto it = cnt.begin(); it != cnt.end();) it = it->second == 0 ? cnt.erase(it) : std::next(it);
    if (fan.empty()) return;
    fan_node_.assign(n, 0);
    // Wedges at fan vertices: the triangles around v joined across edges that are not fan edges.
    std::vector<Vec> fv, to_nb;
    std::vector<double> w;
    for (const auto& [v, c] : cnt) {
      fan_node_[static_cast<std::size_t>(v)] = 1;
      std::vector<int> around, root;
      for (int k = p.node_face_start[static_cast<std::size_t>(v)]; k < p.node_face_start[static_cast<std::size_t>(v) + 1]; ++k)
        around.push_back(p.node_face[static_cast<std::size_t>(k)]);
      for (std::size_t i = 0; i < around.size(); ++i) root.push_back(static_cast<int>(i));
      std::function<int(int)> find = [&](int a) { return root[static_cast<std::size_t>(a)] == a ? a : root[static_cast<std::size_t>(a)] = find(root[static_cast<std::size_t>(a)]); };
      std::map<int, int> by_other;  // the other vertex of an edge at v -> first triangle index there
      for (std::size_t i = 0; i < around.size(); ++i)
        for (int k = 0; k < 3; ++k) {
          const int x = tri(static_cast<std::size_t>(around[i]))[k];
          if (x == v || fan.count({std::min(v, x), std::max(v, x)})) continue;
          const auto [it, added] = by_other.emplace(x, static_cast<int>(i));
          if (!added) root[static_cast<std::size_t>(find(static_cast<int>(i)))] = find(it->second);
        }
      std::map<int, int> wedge_dir;
      for (std::size_t i = 0; i < around.size(); ++i) {
        const int r = find(static_cast<int>(i));
        if (wedge_dir.count(r)) continue;
        fv.clear();
        w.clear();
        to_nb.clear();
        for (std::size_t j = 0; j < around.size(); ++j) {
          if (find(static_cast<int>(j)) != r) continue;
          for (std::size_t e = ent_begin(static_cast<std::size_t>(v)); e < ent_end(static_cast<std::size_t>(v)); ++e)
            if (ent_f_[e] == around[j]) fv.push_back(ent_n_[e]), w.push_back(ent_w_[e]);
          for (int k = 0; k < 3; ++k)
            if (tri(static_cast<std::size_t>(around[j]))[k] != v) to_nb.push_back(x_[static_cast<std::size_t>(tri(static_cast<std::size_t>(around[j]))[k])] - x_[static_cast<std::size_t>(v)]);
        }
        const NodeNormal nn = normal_at(static_cast<std::size_t>(v), fv, w, to_nb, corner_rad);
        wedge_dir[r] = add_dir(v, nn.n, nn.stretch, is_concave(nn.kind), true);
        dirs_.back().normal = true;
      }
      for (std::size_t i = 0; i < around.size(); ++i) side_dir[key(v, around[i])] = wedge_dir[find(static_cast<int>(i))];
    }
    // High-order nodes of fan edges: one direction per side, its face's normal there (also on
    // an edge whose ridge fades at an end: the fan keeps its opening up to the fade node, where
    // its sectors close as cones, fade_cells; an opening falling along the edge would start
    // every sector's diagonals tangent to one another at the fade node, det J = 0 there).
    for (const auto& ab : fan) {
      const Edge& E = edges.at(ab);
      const std::vector<int>& en = te.edge_nodes(E.e[0]);
      for (std::size_t k = 1; k + 1 < en.size(); ++k) {
        const int l = tri(static_cast<std::size_t>(E.t[0]))[en[k]];
        fan_node_[static_cast<std::size_t>(l)] = 1;
        for (int s = 0; s < 2; ++s) side_dir[key(l, E.t[s])] = add_dir(l, side_normal(E.t[s], l), 1, false, true);
      }
    }
    // A fan turns about its ridge: at both ends it opens by at least 5 degrees and the axis of
    // its arc (right x left wedge direction) lies within 60 degrees of the edge. Where wedge normals lean along the ridge
    // (a trailing edge meeting a wing tip's edges) the arc's plane nearly holds the edge and its
    // sector prisms invert whatever their height; such edges keep the merged normal.
    std::vector<std::pair<int, int>> twisted;
    for (const auto& ab : fan) {
      const Edge& E = edges.at(ab);
      const Vec u = (x_[static_cast<std::size_t>(ab.second)] - x_[static_cast<std::size_t>(ab.first)]).normalized();
      for (int v : {ab.first, ab.second}) {
        if (fades(v)) {
          // One direction there, where the fan closes (fade_cells); a fade node whose faces
          // make two wedges (a pinched, non-manifold node) has none to close to.
          if (side_dir.at(key(v, E.t[0])) != side_dir.at(key(v, E.t[1]))) {
            twisted.push_back(ab);
            break;
          }
          continue;
        }
        const Vec& d0 = dirs_[static_cast<std::size_t>(side_dir.at(key(v, E.t[0])))].d;
        const Vec& d1 = dirs_[static_cast<std::size_t>(side_dir.at(key(v, E.t[1])))].d;
        const Vec axis = d0.cross(d1);
        // Under 5 degrees of opening its cells are slivers. (The angle, not |axis|: a thin
        // trailing edge opens by 175 degrees, whose sine is that of 5.)
        const double opening = std::atan2(axis.norm(), d0.dot(d1));
        if (opening < 5 * M_PI / 180 || !(axis.norm() > 1e-9) || std::abs(axis.normalized().dot(u)) < 0.5) {
          twisted.push_back(ab);
          break;
        }
      }
    }
    if (twisted.empty()) break;
    for (const auto& ab : twisted) fan.erase(ab);
  }
  fanned_ = true;
  // Every other node keeps its one direction.
  std::vector<int> node_dir(n, -1);
  for (std::size_t l = 0; l < n; ++l)
    if (!fan_node_[l]) {
      dirs_.push_back({static_cast<int>(l), nn_[l].n, nn_[l].stretch, is_concave(nn_[l].kind), false});
      node_dir[l] = static_cast<int>(dirs_.size()) - 1;
    }
  auto dir_of = [&](int l, int t) {
    return fan_node_[static_cast<std::size_t>(l)] ? side_dir.at(key(l, t)) : node_dir[static_cast<std::size_t>(l)];
  };
  // Chains, oriented by walking; an end is a node with other than two fan edges, or on the rim.
  std::map<int, std::vector<std::pair<int, int>>> at_vertex;
  for (const auto& ab : fan) at_vertex[ab.first].push_back(ab), at_vertex[ab.second].push_back(ab);
  auto is_end = [&](int v) { return cnt[v] != 2 || on_rim(v); };
  std::set<std::pair<int, int>> done;
  std::vector<std::vector<std::pair<int, int>>> chains;  // directed edges (a, b)
  auto walk = [&](int v, std::pair<int, int> e) {
    std::vector<std::pair<int, int>> chain;
    while (!done.count(e)) {
      done.insert(e);
      const int b = e.first == v ? e.second : e.first;
      chain.push_back({v, b});
      if (is_end(b)) break;
      for (const auto& f : at_vertex[b])
        if (!done.count(f)) e = f;
      v = b;
    }
    chains.push_back(chain);
  };
  for (const auto& [v, list] : at_vertex)
    if (is_end(v))
      for (const auto& e : list)
        if (!done.count(e)) walk(v, e);
  for (const auto& e : fan)
    if (!done.count(e)) walk(e.first, e);
  // Fade zones. Where a chain ends in a fade, its fan closes there to one direction, and a
  // sector's cells on the last edge are cones (fade_cells) whose outer edges sag by about a
  // quarter of the angle they close over, in heights: a trailing edge's 160 degrees closed
  // over one edge left the published ONERA M6's tip with front faces that needed 260 heights
  // of attenuation and stayed curved to the last layer. So toward a fade the fan narrows, by at
  // most fan_angle_deg (one sector's angle) per edge: at i edges from the fade a chain node's
  // two wedge directions open by at most i fan_angle_deg, turned toward their bisector (each
  // still sees its wedge's faces: the set of directions that see a face is a hemisphere, and
  // both ends of the turn lie in it), so the wall's columns beside the ridge lean like the
  // merged normal there; a high-order node on the last edge keeps its far end's opening (its
  // sectors' diagonals from the fade node must start apart: an opening falling along the edge
  // starts them tangent, det J = 0 at the fade node), on the edges before it the opening is
  // interpolated. Corners and rim nodes keep theirs. The kites fall with the opening, one per
  // edge (kites_at, below): with the chain's k kept, the 16 arc directions of a 45-degree arc
  // at h0 8.06e-6 c lay 4e-7 apart by the M6's tip, which gmsh -check reports as duplicate
  // nodes. (Sec. II.E does not meet fades.)
  {
    std::map<int, double> allowed;            // node -> the opening it may keep
    std::map<int, std::array<int, 2>> sides;  // node -> its two wedge directions
    for (const auto& chain : chains) {
      std::vector<int> vs = {chain.front().first};
      for (const auto& e : chain) vs.push_back(e.second);
      const bool f0 = fades(vs.front()), f1 = fades(vs.back());
      if (!f0 && !f1) continue;
      const std::size_t m = vs.size() - 1;  // edges
      auto dist = [&](std::size_t i) {
        double d = std::numeric_limits<double>::infinity();
        if (f0) d = std::min(d, static_cast<double>(i));
        if (f1) d = std::min(d, static_cast<double>(m - i));
        return d;
      };
      for (std::size_t i = 0; i < m; ++i) {
        const auto [a, b] = chain[i];
        const Edge& E = edges.at({std::min(a, b), std::max(a, b)});
        const std::vector<int>& en = te.edge_nodes(E.e[0]);
        const bool from_a = tri(static_cast<std::size_t>(E.t[0]))[en.front()] == a;
        const bool last = fades(a) || fades(b);
        for (std::size_t k = 0; k < en.size(); ++k) {
          const int l = tri(static_cast<std::size_t>(E.t[0]))[en[k]];
          const auto c = cnt.find(l);
          if (fades(l) || (c != cnt.end() && c->second >= 3) || on_rim(l)) continue;
          const double t = static_cast<double>(from_a ? k : en.size() - 1 - k) / q_;  // from a
          const double d = last ? std::max(dist(i), dist(i + 1)) : dist(i) + t * (dist(i + 1) - dist(i));
          const auto it = allowed.emplace(l, d * fan_rad).first;
          it->second = std::min(it->second, d * fan_rad);
          sides[l] = {dir_of(l, E.t[0]), dir_of(l, E.t[1])};
          if (k == 0 || k + 1 == en.size()) {
            const auto lv = zone_level_.emplace(l, static_cast<int>(d)).first;
            lv->second = std::min(lv->second, static_cast<int>(d));
          }
        }
      }
    }
    for (const auto& [l, open] : allowed) {
      Dir& d0 = dirs_[static_cast<std::size_t>(sides[l][0])];
      Dir& d1 = dirs_[static_cast<std::size_t>(sides[l][1])];
      const double opening = std::acos(std::clamp(d0.d.dot(d1.d), -1.0, 1.0));
      if (!(opening > open)) continue;
      const Vec mid = slerp(d0.d, d1.d, 0.5);
      const double f = open / opening;
      d0.d = in_plane(static_cast<std::size_t>(l), slerp(mid, d0.d, f));
      d1.d = in_plane(static_cast<std::size_t>(l), slerp(mid, d1.d, f));
      ++narrowed_;
    }
    // The zone's columns keep their directions in later layers, as a corner's do: the faces'
    // average at a kite node between a narrowed arc and a wider one leans along the ridge,
    // and on the published ONERA M6 two kite nodes 2e-6 apart by the tip leaned toward each
    // other (a focus 7e-6 ahead, layer 6). The zone is every chain with a fade, whole
    // (columns_and_cells), not only its narrowed nodes: measured both ways, keeping only the
    // narrowed nodes and those whose kites change raised the published M6's coverage at its
    // metric's 60 layers from 95.9 % to 97.6 %, but stopped columns at its tip in layer 28 of
    // 28 (a closing layer of 43 rounds) and lost 5 columns of the test roof at Q4; the whole
    // chain kept grows the M6's 28 layers with no event.
    for (const auto& [l, open] : allowed) zone_.insert(l);
    for (const auto& [v, c] : cnt)
      if (fades(v)) zone_.insert(v), zone_level_[v] = 0;
  }
  // Arcs and fan edges.
  std::map<std::pair<int, int>, int> arc_of;  // (right direction, left direction) -> arc
  for (const auto& chain : chains) {
    std::vector<FanEdge> list;
    int k = 1;
    for (const auto& [a, b] : chain) {
      const Edge& E = edges.at({std::min(a, b), std::max(a, b)});
      FanEdge fe;
      const int s = tri(static_cast<std::size_t>(E.t[0]))[E.e[0]] == a ? 0 : 1;
      fe.left = E.t[s];
      fe.right = E.t[1 - s];
      for (int node : te.edge_nodes(E.e[s])) fe.nodes.push_back(tri(static_cast<std::size_t>(fe.left))[node]);
      for (int l : fe.nodes) {
        const double ang = std::acos(std::clamp(dirs_[static_cast<std::size_t>(dir_of(l, fe.right))].d.dot(dirs_[static_cast<std::size_t>(dir_of(l, fe.left))].d), -1.0, 1.0));
        k = std::max(k, static_cast<int>(std::ceil(ang / fan_rad - 1e-9)));
      }
      fe.plane[0] = on_rim(a) ? p.plane[static_cast<std::size_t>(a)][0] : -1;
      fe.plane[1] = on_rim(b) ? p.plane[static_cast<std::size_t>(b)][0] : -1;
      list.push_back(fe);
    }
    // Kites per node: k, but in a fade zone as many as its distance from the fade (none at the
    // fade itself), so the sectors' count falls by one kite per edge toward the fade. The arc
    // keeps 2 k sectors, the central ones open, the outer ones closed onto the wedge
    // directions (both their ends one direction); a sector closed at one end of an edge and
    // open at the other closes as a fade's does (fade_cells), one closed at both has no cells.
    auto kites_at = [&](int l) {
      const auto it = zone_level_.find(l);
      return it == zone_level_.end() ? k : std::min(k, it->second);
    };
    for (FanEdge& fe : list) {
      fe.k = k;
      const int k0 = kites_at(fe.nodes.front()), k1 = kites_at(fe.nodes.back());
      auto open = [k](int slot, int kites) { return k - kites <= slot && slot < k + kites; };
      for (std::size_t pos = 0; pos < fe.nodes.size(); ++pos) {
        const int l = fe.nodes[pos];
        const bool inner = pos > 0 && pos + 1 < fe.nodes.size();
        const int kn = pos == 0 ? k0 : (inner ? std::max(k0, k1) : k1);
        const int dr = dir_of(l, fe.right), dl = dir_of(l, fe.left);
        const auto [it, added] = arc_of.emplace(std::make_pair(dr, dl), static_cast<int>(arcs_.size()));
        if (added && (dr == dl || kn == 0)) {
          arcs_.push_back(std::vector<int>(static_cast<std::size_t>(2 * k * q_ + 1), dr));  // a fade: closed
        } else if (added) {
          // The kites of Fig. 4 (the 2D fan, grow_layers_2d.cpp), k per node: normals n_s
          // dividing the angle between the wedge directions equally, the kite of sector s
          // (node, P_s, X_s, P_s+1) with P_s = x + h n_s and X_s where the perpendiculars to
          // n_s at P_s and to n_s+1 at P_s+1 meet, h (n_s + n_s+1) / (1 + n_s . n_s+1). The
          // arc runs P_0 X_0 P_1 ... P_k straight between them: 2 k Q + 1 directions, each
          // with the stretch that puts its top on the kites' edges (heights per unit h).
          // (kn kites between the wedge directions, in the arc's central 2 kn sectors.)
          std::vector<int> arc(static_cast<std::size_t>(2 * k * q_ + 1));
          const int off = (k - kn) * q_;
          for (int m = 0; m <= off; ++m) arc[static_cast<std::size_t>(m)] = dr;
          for (int m = off + 2 * kn * q_; m <= 2 * k * q_; ++m) arc[static_cast<std::size_t>(m)] = dl;
          const Vec d0 = dirs_[static_cast<std::size_t>(dr)].d, d1 = dirs_[static_cast<std::size_t>(dl)].d;
          std::vector<Vec> pts;  // P_0 X_0 P_1 ... P_kn per unit height
          for (int s = 0; s <= kn; ++s) {
            const Vec ns = slerp(d0, d1, static_cast<double>(s) / kn);
            if (s > 0) {
              const Vec& np = pts.back();
              pts.push_back((np + ns) / (1 + np.dot(ns)));
            }
            pts.push_back(ns);
          }
          pts.front() = unit_h(dr);
          pts.back() = unit_h(dl);
          for (int m = 1; m < 2 * kn * q_; ++m) {
            const std::size_t j = static_cast<std::size_t>(m / q_);
            const double t = static_cast<double>(m % q_) / q_;
            const int at = off + m, slot = at / q_;
            // A sector closed at one end of the edge and open at the other has one triangle,
            // which at the edge's high-order nodes uses only the arc's sector ends (and
            // collapsed_dir's points): the directions between would be front nodes of no face.
            if (inner && m % q_ != 0 && open(slot, k0) != open(slot, k1)) {
              arc[static_cast<std::size_t>(at)] = arc[static_cast<std::size_t>(at - m % q_)];  // never asked for
              continue;
            }
            arc[static_cast<std::size_t>(at)] = add_unit_h(l, pts[j] + t * (pts[j + 1] - pts[j]));
            if (m % (2 * q_) == 0) dirs_.back().normal = true;  // n_s
          }
          arcs_.push_back(arc);
        }
        fe.arcs.push_back(it->second);
      }
      fan_edges_.push_back(fe);
    }
  }
  // The new front: the wall triangles over their directions, then the corner patches.
  auto nw = std::make_shared<Part>();
  nw->name = p.name;
  nw->np = p.np;
  for (std::size_t t = 0; t < nt; ++t) {
    for (int k = 0; k < np_; ++k) nw->tri.push_back(dir_of(tri(t)[k], static_cast<int>(t)));
    nw->tri_tag.push_back(p.tri_tag[t]);
    out_.face_origin.push_back(static_cast<int>(t));
  }
  for (const auto& vc : cnt) {  // (not a structured binding: the lambdas below capture v)
    const int v = vc.first;
    if (vc.second < 3) continue;
    ++corner_fans_;
    corner_node_.insert(v);
    const int around0 = p.node_face[static_cast<std::size_t>(p.node_face_start[static_cast<std::size_t>(v)])];
    const int centre = add_dir(v, nn_[static_cast<std::size_t>(v)].n, 1, false, true);
    dirs_.back().normal = true;
    std::map<int, std::vector<int>> centre_edge;  // boundary direction -> the Q - 1 directions toward it
    auto towards = [&](int d, int m) {
      auto [it, added] = centre_edge.emplace(d, std::vector<int>());
      if (added)
        for (int j = 1; j < q_; ++j)
          it->second.push_back(add_unit_h(v, ((q_ - j) * unit_h(centre) + j * unit_h(d)) / q_));
      return it->second[static_cast<std::size_t>(m - 1)];
    };
    for (const FanEdge& fe : fan_edges_) {
      int end = -1;
      if (fe.nodes.front() == v) end = 0;
      if (fe.nodes.back() == v) end = q_;
      if (end < 0) continue;
      const std::vector<int>& arc = arcs_[static_cast<std::size_t>(fe.arcs[static_cast<std::size_t>(end)])];
      for (int s = 0; s < 2 * fe.k; ++s) {
        const int a = arc[static_cast<std::size_t>(s * q_)], b = arc[static_cast<std::size_t>((s + 1) * q_)];
        const Vec dc = unit_h(centre), da = unit_h(a), db = unit_h(b);
        const bool ab = (da - dc).cross(db - dc).dot(dc) > 0;  // (centre, a, b) counter-clockwise from outside
        for (const Lattice& lat : te.lattice()) {
          const int w1 = lat[0], w2 = lat[1], w0 = q_ - w1 - w2;
          const int wb = ab ? w2 : w1, wa = ab ? w1 : w2;
          int d;
          if (w0 == q_) d = centre;
          else if (w0 == 0) d = arc[static_cast<std::size_t>(s * q_ + wb)];
          else if (wa == 0) d = towards(b, wb);
          else if (wb == 0) d = towards(a, wa);
          else d = add_unit_h(v, (w0 * dc + wa * da + wb * db) / q_);
          nw->tri.push_back(d);
        }
        nw->tri_tag.push_back(p.tri_tag[static_cast<std::size_t>(around0)]);
        out_.face_origin.push_back(around0);
        corner_tets_.push_back({v, static_cast<int>(nw->tri_tag.size()) - 1});
      }
    }
  }
  // The kites' outer faces: per kite edge and ridge edge a quadrilateral (lattice i along the
  // chain, j along the arc), cut into two triangles along the diagonal the first layer's
  // tetrahedra cut it (column_order), each grown as a prism in later layers.
  nw->rim = p.rim;
  for (const FanEdge& fe : fan_edges_)
    for (int s = 0; s < 2 * fe.k; ++s) {
      auto dir = [&](int i, int j) {
        return arcs_[static_cast<std::size_t>(fe.arcs[static_cast<std::size_t>(i)])][static_cast<std::size_t>(s * q_ + j)];
      };
      const bool c0 = closed_at(fe, s, 0), c1 = closed_at(fe, s, q_);
      if (c0 && c1) continue;  // no cells, no front
      std::vector<QuadCorners> cut;
      if (c0)
        cut.push_back({{{0, 0}, {q_, 0}, {q_, q_}}});
      else if (c1)
        cut.push_back({{{0, 0}, {q_, 0}, {0, q_}}});
      else
        for (const QuadCorners& h : quad_cut(q_, top_rank(dir(0, 0)), top_rank(dir(q_, 0)), top_rank(dir(q_, q_)), top_rank(dir(0, q_))))
          cut.push_back(h);
      for (const QuadCorners& h : cut) {
        for (const Lattice& lat : te.lattice()) {
          if (c0 || c1) {
            // The one triangle of a sector's quadrilateral whose end at the fade is a point:
            // the fade's corner t0 (i = 0) or t1 (i = Q); across the sector a point divides the
            // kite edge as it divides the triangle's edges from that corner (collapsed_dir).
            const int t0 = q_ - lat[0] - lat[1], t1 = lat[0], t2 = lat[1];
            const int i = c0 ? t1 + t2 : t1, rest = c0 ? t1 + t2 : t0 + t2;
            nw->tri.push_back(rest == 0 ? dir(i, 0) : collapsed_dir(fe, s, i, q_ * t2, rest));
            continue;
          }
          const auto [i, j] = quad_point(h, lat, q_);
          nw->tri.push_back(dir(i, j));
        }
        nw->tri_tag.push_back(p.tri_tag[static_cast<std::size_t>(fe.left)]);
        out_.face_origin.push_back(fe.left);
        // Its edge on a symmetry plane (the chain's end there): both ends at i = 0 or at i = Q.
        for (int end = 0; end < 2; ++end) {
          if (fe.plane[end] < 0) continue;
          for (int e = 0; e < 3; ++e) {
            const int i0 = h[static_cast<std::size_t>(e)][0], i1 = h[static_cast<std::size_t>((e + 1) % 3)][0];
            if (i0 == end * q_ && i1 == end * q_)
              nw->rim.push_back({static_cast<int>(nw->tri_tag.size()) - 1, e, fe.plane[end]});
          }
        }
      }
    }
  nw->ids.assign(dirs_.size(), -1);
  nw->keep.assign(dirs_.size(), Vec::Zero());
  nw->plane.resize(dirs_.size());
  for (std::size_t d = 0; d < dirs_.size(); ++d) nw->plane[d] = p.plane[static_cast<std::size_t>(dirs_[d].base)];
  for (const auto& [l, level] : zone_level_) fades_ += level == 0 ? 1 : 0;
  finish_part(*nw, q_);
  out_.next = nw;
}

auto PartLayerBuilder::closed_at(const FanEdge& fe, int s, int i) const -> bool {
  const std::vector<int>& a = arcs_[static_cast<std::size_t>(fe.arcs[static_cast<std::size_t>(i)])];
  return a[static_cast<std::size_t>(s * q_)] == a[static_cast<std::size_t>((s + 1) * q_)];
}

auto PartLayerBuilder::collapsed_dir(const FanEdge& fe, int s, int i, int num, int den) -> int {
  const int arc = fe.arcs[static_cast<std::size_t>(i)];
  const std::vector<int>& a = arcs_[static_cast<std::size_t>(arc)];
  // The arc's own directions: its sector ends, and at the edge's end nodes every one (shared
  // with the quadrilaterals of the next edge); between the ends of a sector closed at one end
  // of the edge a high-order node's arc holds none (fans(): "never asked for").
  if (num % den == 0 && ((num / den) % q_ == 0 || i == 0 || i == q_)) return a[static_cast<std::size_t>(s * q_ + num / den)];
  const int g = std::gcd(num, den);
  num /= g, den /= g;
  const auto key = std::make_tuple(arc, s, num, den);
  const auto it = collapsed_dirs_.find(key);
  if (it != collapsed_dirs_.end()) return it->second;
  // The kite edge is straight: its points per unit height are linear across the sector.
  const double t = static_cast<double>(num) / (static_cast<double>(den) * q_);
  const Vec lo = unit_h(a[static_cast<std::size_t>(s * q_)]), hi = unit_h(a[static_cast<std::size_t>((s + 1) * q_)]);
  const int d = add_unit_h(dirs_[static_cast<std::size_t>(a[static_cast<std::size_t>(s * q_)])].base, lo + t * (hi - lo));
  collapsed_dirs_.emplace(key, d);
  return d;
}

auto PartLayerBuilder::slerp(const Vec& a, const Vec& b, double t) -> Vec {
  const double ang = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
  if (ang < 1e-12) return a;
  return (std::sin((1 - t) * ang) * a + std::sin(t * ang) * b) / std::sin(ang);
}

}  // namespace plaf::layers::grow3d
