// SPDX-License-Identifier: MIT
// The 3D front specifics of the layers (see grow_layers_3d.h for the steps and the paper's
// sections; the generic core is layer_core.cpp).
#include "layers/grow_layers_3d.h"
#include "layers/layer3d_builder.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <tuple>
#include <memory>
#include <queue>
#include <set>
#include <unordered_map>

#include <Eigen/Eigenvalues>

#include "layers/front_collisions_3d.h"
#include "layers/normals_3d.h"
#include "modules/base/error.h"
#include "modules/elements/lagrange.h"
#include "modules/elements/validity.h"
#include "modules/geometry/aabb_tree.h"
#include "modules/geometry/predicates.h"

namespace plaf::layers {

using namespace grow3d;

namespace {

// The parts of the front's wall triangles and their symmetry planes.
class PartBuilder {
 public:
  PartBuilder(const CurvedFront<3>& front) : f_(front), q_(front.order), np_(num_nodes(CellType::Triangle, q_)) {}

  std::vector<Part> parts(std::vector<Plane>& planes) {
    std::vector<int> walls;
    for (std::size_t t = 0; t < f_.num_triangles(); ++t)
      if (f_.tags[static_cast<std::size_t>(f_.triangle_tag[t])].kind == BoundaryKind::Wall)
        walls.push_back(static_cast<int>(t));
    // Connected components over shared nodes (union-find on node ids).
    std::vector<int> root(f_.nodes.size());
    for (std::size_t i = 0; i < root.size(); ++i) root[i] = static_cast<int>(i);
    auto find = [&](int a) {
      while (root[static_cast<std::size_t>(a)] != a) a = root[static_cast<std::size_t>(a)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(a)])];
      return a;
    };
    for (int t : walls) {
      const NodeId* n = f_.triangle(static_cast<std::size_t>(t));
      for (int k = 1; k < np_; ++k) root[static_cast<std::size_t>(find(n[k]))] = find(n[0]);
    }
    std::map<int, std::vector<int>> by_root;
    for (int t : walls) by_root[find(f_.triangle(static_cast<std::size_t>(t))[0])].push_back(t);
    std::vector<Part> out;
    for (auto& [r, tris] : by_root) out.push_back(part(tris, planes));
    return out;
  }

 private:
  Part part(const std::vector<int>& tris, std::vector<Plane>& planes) {
    Part p;
    p.np = np_;
    std::unordered_map<NodeId, int> local;
    p.name = f_.tags[static_cast<std::size_t>(f_.triangle_tag[static_cast<std::size_t>(tris[0])])].name;
    for (int t : tris) {
      const NodeId* n = f_.triangle(static_cast<std::size_t>(t));
      for (int k = 0; k < np_; ++k) p.tri.push_back(local.emplace(n[k], static_cast<int>(local.size())).first->second);
      p.tri_tag.push_back(f_.triangle_tag[static_cast<std::size_t>(t)]);
    }
    p.ids.assign(local.size(), -1);
    for (const auto& [id, l] : local) p.ids[static_cast<std::size_t>(l)] = id;
    p.keep.assign(local.size(), Vec::Zero());
    finish_part(p, q_);
    rim(p, planes);
    return p;
  }

  // The rim: edges used by one triangle; each connected rim must lie on a plane (step 3).
  void rim(Part& p, std::vector<Plane>& planes) {
    const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
    std::map<std::pair<int, int>, std::array<int, 3>> edges;  // (min, max vertex) -> uses, triangle, edge
    for (std::size_t t = 0; t * static_cast<std::size_t>(np_) < p.tri.size(); ++t)
      for (int e = 0; e < 3; ++e) {
        const std::vector<int>& en = te.edge_nodes(e);
        const int a = p.tri[t * static_cast<std::size_t>(np_) + static_cast<std::size_t>(en.front())];
        const int b = p.tri[t * static_cast<std::size_t>(np_) + static_cast<std::size_t>(en.back())];
        auto& use = edges[{std::min(a, b), std::max(a, b)}];
        ++use[0];
        use[1] = static_cast<int>(t);
        use[2] = e;
      }
    // Rim tags from the front's rim edges, by their vertex pair.
    std::map<std::pair<NodeId, NodeId>, int> rim_tag;
    const std::size_t ne = static_cast<std::size_t>(q_ + 1);
    for (std::size_t k = 0; k < f_.rim_tag.size(); ++k) {
      const NodeId a = f_.rim_edges[k * ne], b = f_.rim_edges[k * ne + 1];
      rim_tag[{std::min(a, b), std::max(a, b)}] = f_.rim_tag[k];
    }
    struct RimEdge {
      int tri, edge, tag;
    };
    std::vector<RimEdge> rim_edges;
    for (const auto& [ab, use] : edges) {
      if (use[0] > 2)
        throw MesherError("layers: an edge of surface " + p.name + " is shared by " + std::to_string(use[0]) +
                          " triangles");
      if (use[0] != 1) continue;
      const NodeId ga = p.ids[static_cast<std::size_t>(ab.first)], gb = p.ids[static_cast<std::size_t>(ab.second)];
      const auto it = rim_tag.find({std::min(ga, gb), std::max(ga, gb)});
      if (it == rim_tag.end()) {
        const Vec x = f_.nodes[static_cast<std::size_t>(ga)];
        throw MesherError("layers: surface " + p.name + " is open along an edge that is not on a symmetry plane (at " +
                          std::to_string(x.x()) + ", " + std::to_string(x.y()) + ", " + std::to_string(x.z()) +
                          "); the layers grow from closed surfaces or surfaces that end on symmetry planes");
      }
      rim_edges.push_back({use[1], use[2], it->second});
    }
    // One plane per connected run of rim edges of one tag (a corner node where two runs meet lies
    // on both planes), fitted to its nodes.
    std::vector<int> root(rim_edges.size());
    for (std::size_t i = 0; i < root.size(); ++i) root[i] = static_cast<int>(i);
    auto find = [&](int a) {
      while (root[static_cast<std::size_t>(a)] != a) a = root[static_cast<std::size_t>(a)];
      return a;
    };
    auto edge_nodes = [&](const RimEdge& e) {
      std::vector<int> nodes;
      for (int k : te.edge_nodes(e.edge)) nodes.push_back(p.tri[static_cast<std::size_t>(e.tri) * static_cast<std::size_t>(np_) + static_cast<std::size_t>(k)]);
      return nodes;
    };
    std::map<std::pair<int, int>, int> first_at;  // (vertex, tag) -> a rim edge there
    for (std::size_t i = 0; i < rim_edges.size(); ++i) {
      const std::vector<int> en = edge_nodes(rim_edges[i]);
      for (int v : {en.front(), en.back()}) {
        const auto [it, added] = first_at.emplace(std::make_pair(v, rim_edges[i].tag), static_cast<int>(i));
        if (!added) root[static_cast<std::size_t>(find(static_cast<int>(i)))] = find(it->second);
      }
    }
    std::map<int, std::vector<int>> groups;  // root edge -> nodes
    for (std::size_t i = 0; i < rim_edges.size(); ++i) {
      const std::vector<int> en = edge_nodes(rim_edges[i]);
      std::vector<int>& g = groups[find(static_cast<int>(i))];
      g.insert(g.end(), en.begin(), en.end());
    }
    p.plane.assign(p.size(), {-1, -1});
    std::map<int, int> plane_of_root;
    for (auto& [r, nodes] : groups) {
      std::sort(nodes.begin(), nodes.end());
      nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
      auto at = [&](int l) { return f_.nodes[static_cast<std::size_t>(p.ids[static_cast<std::size_t>(l)])]; };
      Vec c = Vec::Zero();
      for (int l : nodes) c += at(l);
      c /= static_cast<double>(nodes.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      double diameter = 0;
      for (int l : nodes) {
        const Vec d = at(l) - c;
        cov += d * d.transpose();
        diameter = std::max(diameter, 2 * d.norm());
      }
      Plane pl;
      pl.point = c;
      pl.normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0).normalized();
      pl.tag = rim_edges[static_cast<std::size_t>(r)].tag;
      double off = 0, side = 0;
      for (int l : nodes) off = std::max(off, std::abs((at(l) - c).dot(pl.normal)));
      for (std::size_t l = 0; l < p.size(); ++l) side += (at(static_cast<int>(l)) - c).dot(pl.normal);
      if (side < 0) pl.normal = -pl.normal;  // into the part's half-space
      if (off > 1e-6 * diameter)
        throw MesherError("layers: the open rim of surface " + p.name + " tagged " +
                          f_.tags[static_cast<std::size_t>(pl.tag)].name + " is not planar (a node lies " +
                          std::to_string(off) + " off its best plane); a surface may end only on symmetry planes");
      const int index = static_cast<int>(planes.size());
      plane_of_root[r] = index;
      for (int l : nodes) {
        std::array<int, 2>& np = p.plane[static_cast<std::size_t>(l)];
        if (np[0] < 0)
          np[0] = index;
        else if (np[1] < 0)
          np[1] = index;
        else
          throw MesherError("layers: a node of surface " + p.name + " lies on three symmetry planes");
      }
      planes.push_back(pl);
    }
    for (std::size_t i = 0; i < rim_edges.size(); ++i)
      p.rim.push_back({rim_edges[i].tri, rim_edges[i].edge, plane_of_root[find(static_cast<int>(i))]});
  }

  const CurvedFront<3>& f_;
  const int q_, np_;
};


// The wall parts of a 3D front as the parts of the generic layer core.
class SurfaceFronts final : public FrontGrower<3> {
 public:
  SurfaceFronts(HybridMesh<3>& mesh, const CurvedFront<3>& front0, const MetricField<3>& metric, const LayerParams& p,
                std::vector<std::pair<std::string, std::size_t>>& counts)
      : mesh_(mesh), front0_(front0), metric_(metric), p_(p), q_(front0.order), counts_(counts) {
    parts_ = PartBuilder(front0).parts(planes_);
    grown_.assign(parts_.size(), 0);
    held_.assign(parts_.size(), {});
    heights_.resize(parts_.size());
    // The wall's linear triangles, for the proximity rule's rays.
    std::vector<std::array<int, 3>> tris;
    Eigen::AlignedBox3d box;
    for (std::size_t t = 0; t < front0.num_triangles(); ++t) {
      if (front0.tags[static_cast<std::size_t>(front0.triangle_tag[t])].kind != BoundaryKind::Wall) continue;
      const NodeId* n = front0.triangle(t);
      tris.push_back({static_cast<int>(n[0]), static_cast<int>(n[1]), static_cast<int>(n[2])});
      const Vec& a = front0.nodes[static_cast<std::size_t>(n[0])];
      const Vec& b = front0.nodes[static_cast<std::size_t>(n[1])];
      const Vec& c = front0.nodes[static_cast<std::size_t>(n[2])];
      wall_normal_.push_back((b - a).cross(c - a).normalized());
      box.extend(a);
    }
    wall_ = TriangleTree(front0.nodes, tris);
    wall_tris_ = std::move(tris);
    wall_diagonal_ = box.isEmpty() ? 0.0 : box.diagonal().norm();
  }

  std::array<CellType, 2> cell_types() const override { return {CellType::Prism, CellType::Tetrahedron}; }
  std::size_t num_parts() const override { return parts_.size(); }
  std::string part_name(std::size_t part) const override { return "surface " + parts_[part].name; }
  std::size_t num_sites(std::size_t part) const override { return parts_[part].size(); }
  std::size_t num_stop_points(std::size_t part) const override { return parts_[part].vertices.size(); }
  std::vector<Vec> stop_points(std::size_t part) const override {
    std::vector<Vec> v;
    for (int l : parts_[part].vertices) v.push_back(mesh_.nodes[static_cast<std::size_t>(parts_[part].ids[static_cast<std::size_t>(l)])]);
    return v;
  }
  BuiltLayer build(std::size_t part, int /*layer*/, const std::vector<double>& scale,
                   const std::vector<std::uint8_t>& stopped, double f_atten) override {
    pending_part_ = part;
    pending_nodes_before_ = mesh_.nodes.size();
    // A part's first layer is its first accepted one (layer 1, or a closing layer after a failed
    // layer 1); a closing layer (straight tops, f_atten infinite) grows no fans: they are curved.
    const bool first = !grown_[part];
    std::vector<std::pair<std::string, std::size_t>> counts;
    pending_stopped_ = stopped;
    pending_ = PartLayerBuilder(mesh_, metric_, p_, q_, front0_, parts_[part], planes_, first, scale, stopped,
                                held_[part], f_atten, first ? &counts : nullptr, heights_[part])
                   .build();
    pending_counts_ = first ? counts : std::vector<std::pair<std::string, std::size_t>>{};
    return std::move(pending_.built);
  }
  const Part& pending_front() const { return pending_.next ? *pending_.next : parts_[pending_part_]; }
  std::vector<std::size_t> collisions(std::size_t part) const override {
    std::vector<FrontSurface> fronts;
    const Part& nw = pending_front();
    fronts.push_back({&nw.tri, &pending_.top});
    for (std::size_t other = 0; other < parts_.size(); ++other)
      if (other != part) fronts.push_back({&parts_[other].tri, &parts_[other].ids});
    // The faces the layer left in place (every column under them stopped: their nodes are the
    // old front's, made before this build, where every moved node is new): a crossing between
    // two of them is the wall's own (a fold of the curved surface the surface stage reports) or
    // none, and no stop can mend it. Counted as this layer's, it failed the published Orion
    // capsule's whole part at Q2 (h0 1e-5 L), layer 1, at a bead the remesher left folded (3
    // faces), where Q1 grew 40 layers.
    const std::size_t np = static_cast<std::size_t>(num_nodes(CellType::Triangle, q_));
    std::vector<std::uint8_t> unmoved(nw.tri.size() / np, 1);
    for (std::size_t t = 0; t < unmoved.size(); ++t)
      for (std::size_t k = 0; k < np && unmoved[t]; ++k) {
        const NodeId id = pending_.top[static_cast<std::size_t>(nw.tri[t * np + k])];
        unmoved[t] = id >= 0 && static_cast<std::size_t>(id) < pending_nodes_before_;
      }
    // The same faces as the base's (no fans changed them): a fold counts where the layer
    // sharpened it (front_collisions_3d.h).
    const std::vector<NodeId>* base = pending_.next ? nullptr : &parts_[part].ids;
    std::vector<std::size_t> hit = front_collisions(fronts, mesh_.nodes, q_, &unmoved, base);
    // A face with a node behind a symmetry plane crosses the mirrored half's front (the proximity
    // rule holds most columns short of the plane; this catches the rest).
    const double tol = 1e-9 * wall_diagonal_;
    for (std::size_t t = 0; t < unmoved.size() && !planes_.empty(); ++t) {
      bool behind = false;
      for (std::size_t k = 0; k < np && !behind; ++k) {
        const Vec& y = mesh_.nodes[static_cast<std::size_t>(pending_.top[static_cast<std::size_t>(nw.tri[t * np + k])])];
        for (const Plane& sp : planes_) behind = behind || (y - sp.point).dot(sp.normal) < -tol;
      }
      if (behind) hit.push_back(t);
    }
    std::sort(hit.begin(), hit.end());
    hit.erase(std::unique(hit.begin(), hit.end()), hit.end());
    return hit;
  }
  std::string collision_kind() const override { return "front crossings or folds"; }
  Vec front_point(std::size_t e) const override {
    return mesh_.nodes[static_cast<std::size_t>(pending_.top[static_cast<std::size_t>(pending_front().face(e)[0])])];
  }
  bool stops_locally() const override { return true; }
  // The vertices of the old faces behind the failures.
  std::vector<std::size_t> failure_stop_points(std::size_t part, const std::vector<LayerFailure>& failures) const override {
    const Part& p = parts_[part];
    std::vector<int> index(p.size(), -1);
    for (std::size_t k = 0; k < p.vertices.size(); ++k) index[static_cast<std::size_t>(p.vertices[k])] = static_cast<int>(k);
    std::vector<std::size_t> out;
    for (const LayerFailure& fl : failures) {
      const std::size_t f = static_cast<std::size_t>(
          fl.block == LayerFailure::kFrontElement ? pending_.face_origin[fl.index]
                                                  : pending_.cell_face[static_cast<std::size_t>(fl.block)][fl.index]);
      if (f >= p.num_faces()) continue;  // a fan cell of a first layer (its faces are the new front's)
      for (int v = 0; v < p.face_vertices(f); ++v) out.push_back(static_cast<std::size_t>(index[static_cast<std::size_t>(p.face(f)[v])]));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
  // A third of the area of each (linear) face to each of its vertices.
  std::vector<double> stop_point_measure(std::size_t part) const override {
    const Part& p = parts_[part];
    std::vector<int> index(p.size(), -1);
    for (std::size_t k = 0; k < p.vertices.size(); ++k) index[static_cast<std::size_t>(p.vertices[k])] = static_cast<int>(k);
    std::vector<double> m(p.vertices.size(), 0.0);
    for (std::size_t f = 0; f < p.num_faces(); ++f) {
      const int* fl = p.face(f);
      const Vec a = mesh_.nodes[static_cast<std::size_t>(p.ids[static_cast<std::size_t>(fl[0])])],
                b = mesh_.nodes[static_cast<std::size_t>(p.ids[static_cast<std::size_t>(fl[1])])],
                c = mesh_.nodes[static_cast<std::size_t>(p.ids[static_cast<std::size_t>(fl[2])])];
      const double third = (b - a).cross(c - a).norm() / 6;
      for (int v = 0; v < 3; ++v) m[static_cast<std::size_t>(index[static_cast<std::size_t>(fl[v])])] += third;
    }
    return m;
  }
  // The proximity rule (layer_core.h, step 1). From each stop point x along its front's normal d
  // (the faces' area-weighted normal), a ray finds the first wall it meets that faces it, at
  // distance t and with cos(theta) = -n_wall . d, and a ray back finds the column's own wall, s
  // below x. A facing wall's stack (grown along its own normal) crosses the ray 1/cos(theta) times
  // as tall, so two equal stacks meet at G cos/(1 + cos) along the ray from this wall (G = s + t:
  // half the gap when they face squarely); the stack may fill `share` of that. A wall met from
  // behind, or none, sets no limit here (a ray along the bisector of a concave crease meets
  // neither side): where the front is concave, the focal limit of graded_room (layer_core.h)
  // holds the columns short of where they meet, and the allowed stacks are graded over the
  // front's edges, so a proximity stop ramps down over the surface instead of ending in a cliff
  // beside columns that grow on. The room is A - s.
  std::vector<double> stop_point_room(std::size_t part, double share) const override {
    const Part& p = parts_[part];
    const std::size_t nv = p.vertices.size();
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<int> index(p.size(), -1);
    for (std::size_t k = 0; k < nv; ++k) index[static_cast<std::size_t>(p.vertices[k])] = static_cast<int>(k);
    auto at = [&](int l) -> const Vec& { return mesh_.nodes[static_cast<std::size_t>(p.ids[static_cast<std::size_t>(l)])]; };
    std::vector<Vec> normal(nv, Vec::Zero()), angled(nv, Vec::Zero());
    std::vector<std::vector<std::pair<std::size_t, double>>> edges(nv);
    for (std::size_t f = 0; f < p.num_faces(); ++f) {
      const int* fl = p.face(f);
      const Vec nn = (at(fl[1]) - at(fl[0])).cross(at(fl[2]) - at(fl[0]));
      const Vec un = nn.norm() > 0 ? Vec(nn.normalized()) : Vec::Zero();
      for (int v = 0; v < 3; ++v) {
        const std::size_t i = static_cast<std::size_t>(index[static_cast<std::size_t>(fl[v])]);
        const std::size_t j = static_cast<std::size_t>(index[static_cast<std::size_t>(fl[(v + 1) % 3])]);
        normal[i] += nn;
        const Vec e1 = at(fl[(v + 1) % 3]) - at(fl[v]), e2 = at(fl[(v + 2) % 3]) - at(fl[v]);
        angled[i] += std::atan2(e1.cross(e2).norm(), e1.dot(e2)) * un;
        const double len = (at(fl[v]) - at(fl[(v + 1) % 3])).norm();
        edges[i].emplace_back(j, len);
        edges[j].emplace_back(i, len);
      }
    }
    const double eps = 1e-9 * wall_diagonal_;
    std::vector<double> allowed(nv, inf), below(nv, 0.0);
    for (std::size_t k = 0; k < nv; ++k) {
      if (!(normal[k].norm() > 0)) continue;
      const Vec d = normal[k].normalized();
      Vec x = at(p.vertices[k]);
      // A rim vertex's rays run in its symmetry plane, along the edges of the wall's rim
      // triangles, where the triangle test misses or hits at random (the extruded E387 wing's rim
      // columns met no wall below them, so their stacks counted from the front, not the wall):
      // the rays start a hair off the plane, on the side of the column's faces.
      const std::size_t l = static_cast<std::size_t>(p.vertices[k]);
      for (int pl : p.plane[l]) {
        if (pl < 0) continue;
        const Vec& n = planes_[static_cast<std::size_t>(pl)].normal;
        double side = 0;
        for (const auto& [j, len] : edges[k]) side += (at(p.vertices[j]) - x).dot(n);
        if (side != 0) x += (side > 0 ? 1e-7 : -1e-7) * wall_diagonal_ * n;
      }
      // From a wall vertex the ray back meets its own faces at t = 0 (s = 0); from a front above
      // the wall, the wall below it, from its front side.
      const TriangleTree::Hit back = wall_.first_hit(x, -d, -eps, inf);
      const bool under = back.triangle >= 0 && wall_normal_[static_cast<std::size_t>(back.triangle)].dot(d) > 0;
      if (under) below[k] = std::max(0.0, back.t);
      // The column's own wall is at most its stack's thickness back along the column (the
      // stack's layers, summed along their zigzag), and along the front's normal, which leans
      // from the column, not much more. A ray back that misses it (grazing a convex ridge,
      // between the faces around the ridge node) meets the body's far side instead: on a flange
      // 0.4 thick, a rim column's ray back met the hub 1.2 away, which made its stack 1.2 thick,
      // its room negative and 74 columns along a convex rim stop for proximity in layer 2. So the
      // distance back is at most twice the stack (a ray leaning 60 degrees from the wall's normal).
      if (under && l < p.stack.size()) below[k] = std::min(below[k], 2 * p.stack[l]);
      // A wall face sharing a node with the face below is the column's own neighbourhood (a ray
      // along a vertex normal can graze its ring where the faces around bend), not a facing wall.
      // (On the wall the column's node is a wall node: its own faces are skipped by id.)
      const int self = static_cast<int>(p.ids[static_cast<std::size_t>(p.vertices[k])]);
      auto beside = [&](int t) {
        const auto& b = wall_tris_[static_cast<std::size_t>(t)];
        if (b[0] == self || b[1] == self || b[2] == self) return true;
        if (!under) return false;
        const auto& a = wall_tris_[static_cast<std::size_t>(back.triangle)];
        for (int u : b)
          if (u == a[0] || u == a[1] || u == a[2]) return true;
        return false;
      };
      const TriangleTree::Hit ahead = wall_.first_hit(x, d, eps, inf, beside);
      const double cosine = ahead.triangle < 0 ? 0.0 : -wall_normal_[static_cast<std::size_t>(ahead.triangle)].dot(d);
      if (cosine > 0) allowed[k] = share * (below[k] + ahead.t) * cosine / (1 + cosine);
      // A symmetry plane is the mirror of the body: a column heading for it meets its own mirror
      // image there (the mirrored half's stack grows toward it at the same angle), so the stack
      // may fill `share` of its column's length to the plane. (The ONERA M6 at h0 1e-5 c and
      // h_wall_max 0.03 c: the swept trailing edge's normals point toward the root plane, and
      // its 47-layer stacks crossed the plane by up to 0.09 c, where TetGen found the layers'
      // outer front crossing the plane's triangles, 24 pairs, and crashed.) The columns on the
      // plane grow in it (in_planes) and are not limited by it.
      for (std::size_t pl = 0; pl < planes_.size(); ++pl) {
        if (p.plane[l][0] == static_cast<int>(pl) || p.plane[l][1] == static_cast<int>(pl)) continue;
        const Plane& sp = planes_[pl];
        const double toward = -d.dot(sp.normal), dist = (x - sp.point).dot(sp.normal);
        if (toward > 1e-12 && dist > 0) allowed[k] = std::min(allowed[k], share * (below[k] + dist / toward));
      }
    }
    // The focal limit and the grading (layer_core.h, graded_room). The columns' directions are
    // those the next layer grows along where known (a corner fan's columns keep theirs,
    // Part::keep: their front's area-weighted normals mix a kite with the large faces beside it
    // and saw foci over a cube's convex ridges), else the front's angle-weighted normals: the
    // area-weighted ones zigzag wherever the triangles are split quadrilaterals (a rim vertex
    // has one triangle of a quadrilateral on one side and two on the other), and the differences
    // of neighbouring normals are what the foci are made of (spurious foci on an extruded
    // airfoil's symmetry planes, 2D having none).
    std::vector<Vec> x(nv), unit(nv, Vec::Zero());
    for (std::size_t k = 0; k < nv; ++k) {
      x[k] = at(p.vertices[k]);
      const std::size_t l = static_cast<std::size_t>(p.vertices[k]);
      if (l < p.keep.size() && p.keep[l].norm() > 0)
        unit[k] = p.keep[l].normalized();
      else if (angled[k].norm() > 0)
        unit[k] = angled[k].normalized();
    }
    return graded_room<3>(x, unit, edges, below, std::move(allowed));
  }
  // Heights are scaled on the nodes of the old faces behind the failures and of every face around
  // them.
  void rescale(std::size_t part, const std::vector<LayerFailure>& failures, double factor,
               std::vector<double>& scale) const override {
    const Part& p = parts_[part];
    std::vector<std::uint8_t> halve(p.size(), 0);
    for (const LayerFailure& fl : failures) {
      const std::size_t f = static_cast<std::size_t>(
          fl.block == LayerFailure::kFrontElement ? pending_.face_origin[fl.index]
                                                  : pending_.cell_face[static_cast<std::size_t>(fl.block)][fl.index]);
      for (int v = 0; v < p.face_vertices(f); ++v) {
        const std::size_t l = static_cast<std::size_t>(p.face(f)[v]);
        for (int k = p.node_face_start[l]; k < p.node_face_start[l + 1]; ++k) {
          const std::size_t g = static_cast<std::size_t>(p.node_face[static_cast<std::size_t>(k)]);
          for (int j = 0; j < p.face_size(g); ++j) halve[static_cast<std::size_t>(p.face(g)[j])] = 1;
        }
      }
    }
    for (std::size_t l = 0; l < p.size(); ++l)
      if (halve[l]) scale[l] *= factor;
  }
  void accept(std::size_t part) override {
    grown_[part] = 1;
    heights_[part].clear();  // the front moved
    // The stop points stopped from now on (a front that fans changed has new stop points).
    held_[part] = pending_.next ? std::vector<std::uint8_t>{} : pending_stopped_;
    if (pending_.next) parts_[part] = std::move(*pending_.next);
    parts_[part].ids = std::move(pending_.top);
    parts_[part].keep = std::move(pending_.keep);
    parts_[part].stack = std::move(pending_.stack);
    sym_quads_.insert(sym_quads_.end(), pending_.sym_quads.begin(), pending_.sym_quads.end());
    sym_quad_tag_.insert(sym_quad_tag_.end(), pending_.sym_quad_tag.begin(), pending_.sym_quad_tag.end());
    sym_tris_.insert(sym_tris_.end(), pending_.sym_tris.begin(), pending_.sym_tris.end());
    sym_tri_tag_.insert(sym_tri_tag_.end(), pending_.sym_tri_tag.begin(), pending_.sym_tri_tag.end());
    // The first layer's counts, summed over the parts.
    for (const auto& count : pending_counts_) {  // (captured by the lambda: no structured binding)
      auto it = std::find_if(counts_.begin(), counts_.end(), [&](const auto& c) { return c.first == count.first; });
      if (it == counts_.end())
        counts_.push_back(count);
      else
        it->second += count.second;
    }
    pending_counts_.clear();
  }

  const std::vector<Part>& parts() const { return parts_; }
  const std::vector<NodeId>& sym_quads() const { return sym_quads_; }
  const std::vector<int>& sym_quad_tag() const { return sym_quad_tag_; }
  const std::vector<NodeId>& sym_tris() const { return sym_tris_; }
  const std::vector<int>& sym_tri_tag() const { return sym_tri_tag_; }

 private:
  HybridMesh<3>& mesh_;
  const CurvedFront<3>& front0_;
  const MetricField<3>& metric_;
  const LayerParams& p_;
  const int q_;
  std::vector<std::pair<std::string, std::size_t>>& counts_;
  std::vector<Plane> planes_;
  std::vector<Part> parts_;
  std::vector<std::uint8_t> grown_;  // per part: a layer was accepted
  std::vector<HeightMemo> heights_;  // per part: the metric's heights on its current front
  std::vector<std::vector<std::uint8_t>> held_;  // per part: its stop points stopped in an accepted layer
  std::vector<std::uint8_t> pending_stopped_;    // the stopped stop points of the pending build
  TriangleTree wall_;                // the wall's linear triangles (every part's)
  std::vector<Vec> wall_normal_;     // their unit normals, toward the layers
  std::vector<std::array<int, 3>> wall_tris_;  // their node ids
  double wall_diagonal_ = 0;
  std::size_t pending_part_ = 0;
  std::size_t pending_nodes_before_ = 0;  // the mesh's nodes before the pending build (older ones did not move)
  PartLayer pending_;
  std::vector<std::pair<std::string, std::size_t>> pending_counts_;
  std::vector<NodeId> sym_quads_, sym_tris_;
  std::vector<int> sym_quad_tag_, sym_tri_tag_;
};

}  // namespace

// The outer front's triangles still curved (where columns stopped curved and no closing layer
// was valid: layer_core.h) made straight in place where the cells under them stay valid: each
// such triangle's high-order nodes move to their linear positions (an edge's nodes onto its
// chord, so a neighbour sharing the edge agrees), the cells holding a moved node are certified
// (det J > 0, validity.h), and the triangles behind a cell that fails go back to their curve,
// round by round until every touched cell is valid. A zero-height closing layer: the paper's
// fill starts from a linear front (Sec. II.C), and a curved front triangle under the fill's
// tetrahedron, which TetGen placed against the chord, inverts it wherever the apex sits closer
// than the sag (the ONERA M6 hybrid grown to its metric's 47 layers, before the high-order nodes'
// lean was bounded (blend): 9 such triangles at the tip's trailing edge, 3 of the fill's curved
// tetrahedra inverted; straightened in place, 5 of the 9 went straight, and the 4 left sat on
// cells too thin for any share of their sag; with the bound none is left there). Nodes of the
// input surface (a column stopped at the wall) never move: a triangle with a high-order node
// there is left as it was.
struct OuterStraightening {
  std::size_t straight = 0, flatter = 0, curved = 0;  // made straight; moved part of the way; left as they were
};
OuterStraightening straighten_outer_front(LayerResult<3>& r, std::size_t wall_nodes) {
  const int q = r.outer.order;
  if (q < 2) return {};
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q);
  const std::size_t np = static_cast<std::size_t>(te.size());
  std::vector<Vec>& x = r.mesh.nodes;
  // The curved triangles, by the rule the fill counts them with (hybrid_mesh.h, is_curved).
  const CellBlock outer{CellType::Triangle, q, -1, r.outer.triangles};
  std::vector<std::size_t> curved;
  for (std::size_t t = 0; t < outer.size(); ++t)
    if (is_curved(r.mesh, outer, t)) curved.push_back(t);
  if (curved.empty()) return {};
  auto lin_of = [&](std::size_t t, std::size_t k) {
    const NodeId* n = r.outer.triangle(t);
    const Lattice& l = te.lattice()[k];
    const Vec &a = x[static_cast<std::size_t>(n[0])], &b = x[static_cast<std::size_t>(n[1])], &c = x[static_cast<std::size_t>(n[2])];
    return Vec(a + (static_cast<double>(l[0]) / q) * (b - a) + (static_cast<double>(l[1]) / q) * (c - a));
  };
  // The cells holding each node a curved triangle would move.
  std::unordered_map<NodeId, std::vector<std::pair<std::size_t, std::size_t>>> cells_of;  // node -> (block, cell)
  for (std::size_t t : curved)
    for (std::size_t k = 3; k < np; ++k) cells_of[r.outer.triangle(t)[k]];
  for (std::size_t b = 0; b < r.mesh.cells.size(); ++b) {
    const CellBlock& blk = r.mesh.cells[b];
    const std::size_t nn = static_cast<std::size_t>(blk.nodes_per_cell());
    for (std::size_t c = 0; c < blk.size(); ++c)
      for (std::size_t k = 0; k < nn; ++k) {
        const auto it = cells_of.find(blk.cell(c)[k]);
        if (it != cells_of.end()) it->second.push_back({b, c});
      }
  }
  // Each triangle moves its nodes a share of the way to their linear positions: all of it, then,
  // while a cell around it fails, half as far, down to 1/8, then none. A node two triangles
  // share moves the smaller share of the two.
  constexpr int kLevels = 4;  // shares 1, 1/2, 1/4, 1/8; level kLevels: none
  // A triangle with a high-order node of the input surface (a column stopped before the first
  // layer) stays as it is, and so do the nodes it shares.
  std::vector<int> level(curved.size(), 0);
  for (std::size_t i = 0; i < curved.size(); ++i)
    for (std::size_t k = 3; k < np; ++k)
      if (static_cast<std::size_t>(r.outer.triangle(curved[i])[k]) < wall_nodes) level[i] = kLevels;
  std::unordered_map<NodeId, std::pair<Vec, Vec>> path;  // node -> (original, linear)
  for (std::size_t i = 0; i < curved.size(); ++i)
    for (std::size_t k = 3; k < np; ++k) {
      const NodeId id = r.outer.triangle(curved[i])[k];
      if (static_cast<std::size_t>(id) < wall_nodes) continue;
      path.emplace(id, std::make_pair(x[static_cast<std::size_t>(id)], lin_of(curved[i], k)));
    }
  JacobianCertifier certifier(ValidityOptions{std::numeric_limits<double>::infinity(), ValidityOptions{}.max_depth});
  std::vector<double> coords;
  for (;;) {
    std::unordered_map<NodeId, double> share;
    for (std::size_t i = 0; i < curved.size(); ++i)
      for (std::size_t k = 3; k < np; ++k) {
        const NodeId id = r.outer.triangle(curved[i])[k];
        const double a = level[i] >= kLevels ? 0.0 : std::ldexp(1.0, -level[i]);
        const auto [it, added] = share.emplace(id, a);
        if (!added) it->second = std::min(it->second, a);
      }
    for (const auto& [id, ends] : path) x[static_cast<std::size_t>(id)] = ends.first + share[id] * (ends.second - ends.first);
    // Certify the cells around moved nodes; the triangles with a node in a failing cell step down.
    std::set<std::pair<std::size_t, std::size_t>> failing, seen;
    for (std::size_t i = 0; i < curved.size(); ++i) {
      if (level[i] >= kLevels) continue;
      for (std::size_t k = 3; k < np; ++k)
        for (const auto& bc : cells_of[r.outer.triangle(curved[i])[k]]) {
          if (!seen.insert(bc).second) continue;
          const CellBlock& blk = r.mesh.cells[bc.first];
          const std::size_t nn = static_cast<std::size_t>(blk.nodes_per_cell());
          coords.resize(3 * nn);
          for (std::size_t j = 0; j < nn; ++j)
            for (int d = 0; d < 3; ++d) coords[3 * j + static_cast<std::size_t>(d)] = x[static_cast<std::size_t>(blk.cell(bc.second)[j])][d];
          if (!cell_valid<3>(certifier, blk.type, blk.order, coords.data())) failing.insert(bc);
        }
    }
    if (failing.empty()) break;
    for (std::size_t i = 0; i < curved.size(); ++i) {
      if (level[i] >= kLevels) continue;
      bool fails = false;
      for (std::size_t k = 3; k < np && !fails; ++k)
        for (const auto& bc : cells_of[r.outer.triangle(curved[i])[k]]) fails = fails || failing.count(bc) > 0;
      if (fails) ++level[i];
    }
  }
  // Counted by where they ended: a triangle whose own level allowed all of the way can still keep
  // part of its curve through a node shared with a triangle that stepped down.
  OuterStraightening out;
  for (std::size_t i = 0; i < curved.size(); ++i) {
    bool moved = false;
    for (std::size_t k = 3; k < np; ++k) {
      const auto it = path.find(r.outer.triangle(curved[i])[k]);
      moved = moved || (it != path.end() && x[static_cast<std::size_t>(it->first)] != it->second.first);
    }
    ++(!is_curved(r.mesh, outer, curved[i]) ? out.straight : moved ? out.flatter : out.curved);
  }
  return out;
}

LayerResult<3> grow_layers(const CurvedFront<3>& front, const MetricField<3>& metric, const LayerParams& p) {
  check_order(front.order);
  const int q = front.order;
  const std::size_t np = static_cast<std::size_t>(num_nodes(CellType::Triangle, q));
  const std::size_t nqn = static_cast<std::size_t>(num_nodes(CellType::Quadrilateral, q));
  LayerResult<3> r;
  r.mesh.nodes = front.nodes;
  r.mesh.tags = front.tags;
  for (std::size_t t = 0; t < front.num_triangles(); ++t) {
    const int tag = front.triangle_tag[t];
    if (front.tags[static_cast<std::size_t>(tag)].kind != BoundaryKind::Wall) continue;
    CellBlock& b = r.mesh.boundary_block(CellType::Triangle, q, tag);
    b.connectivity.insert(b.connectivity.end(), front.triangle(t), front.triangle(t) + np);
  }
  SurfaceFronts fronts(r.mesh, front, metric, p, r.counts);
  grow_fronts<3>(fronts, metric, p, q, r);
  // Symmetry facets of every accepted layer.
  for (std::size_t k = 0; k < fronts.sym_quad_tag().size(); ++k) {
    CellBlock& b = r.mesh.boundary_block(CellType::Quadrilateral, q, fronts.sym_quad_tag()[k]);
    b.connectivity.insert(b.connectivity.end(), fronts.sym_quads().begin() + static_cast<std::ptrdiff_t>(k * nqn),
                          fronts.sym_quads().begin() + static_cast<std::ptrdiff_t>((k + 1) * nqn));
  }
  for (std::size_t k = 0; k < fronts.sym_tri_tag().size(); ++k) {
    CellBlock& b = r.mesh.boundary_block(CellType::Triangle, q, fronts.sym_tri_tag()[k]);
    b.connectivity.insert(b.connectivity.end(), fronts.sym_tris().begin() + static_cast<std::ptrdiff_t>(k * np),
                          fronts.sym_tris().begin() + static_cast<std::ptrdiff_t>((k + 1) * np));
  }
  // The outer front (the wall's tags) and the fill's boundary.
  r.outer.order = q;
  r.outer.tags = front.tags;
  for (const Part& part : fronts.parts())
    for (std::size_t t = 0; t < part.nt(); ++t) {
      for (std::size_t k = 0; k < np; ++k) r.outer.triangles.push_back(part.ids[static_cast<std::size_t>(part.face(t)[k])]);
      r.outer.triangle_tag.push_back(part.tri_tag[t]);
    }
  // With a fill to come (close_linear), the curved triangles left are made straight in place
  // where they can be.
  const OuterStraightening st = p.close_linear ? straighten_outer_front(r, front.nodes.size()) : OuterStraightening{};
  if (st.straight + st.flatter + st.curved > 0)
    r.events.push_back("the layers' outer front: " + std::to_string(st.straight) + " of " +
                       std::to_string(st.straight + st.flatter + st.curved) +
                       " curved triangles made straight in place (the cells under them stay valid)" +
                       (st.flatter > 0 ? ", " + std::to_string(st.flatter) + " flattened part of the way" : std::string()) +
                       (st.curved > 0 ? ", " + std::to_string(st.curved) + " left as they were" : std::string()));
  r.outer.nodes = r.mesh.nodes;
  r.fill_front.nodes = r.mesh.nodes;
  const int outer_tag = static_cast<int>(r.fill_front.tags.size());
  r.fill_front.tags.push_back({"layers_outer", BoundaryKind::Named});
  for (const Part& part : fronts.parts()) {
    auto id = [&](int l) { return part.ids[static_cast<std::size_t>(l)]; };
    for (std::size_t t = 0; t < part.nt(); ++t) {
      const int* tl = part.face(t);
      r.fill_front.triangles.push_back({id(tl[0]), id(tl[1]), id(tl[2])});
      r.fill_front.triangle_tag.push_back(outer_tag);
    }
  }
  std::map<int, int> fill_tag;  // front tag -> fill_front tag, for the triangles that did not grow
  for (std::size_t t = 0; t < front.num_triangles(); ++t) {
    const int tag = front.triangle_tag[t];
    if (front.tags[static_cast<std::size_t>(tag)].kind == BoundaryKind::Wall) continue;
    const auto [it, added] = fill_tag.emplace(tag, static_cast<int>(r.fill_front.tags.size()));
    if (added) r.fill_front.tags.push_back(front.tags[static_cast<std::size_t>(tag)]);
    const NodeId* n = front.triangle(t);
    r.fill_front.triangles.push_back({n[0], n[1], n[2]});
    r.fill_front.triangle_tag.push_back(it->second);
  }
  return r;
}

}  // namespace plaf::layers
