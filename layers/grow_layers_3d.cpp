// SPDX-License-Identifier: MIT
// The 3D front specifics of the layers (see grow_layers_3d.h for the steps and the paper's
// sections; the generic core is layer_core.cpp).
#include "layers/grow_layers_3d.h"

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

namespace {

using Vec = Eigen::Vector3d;

// A symmetry plane the wall's rim lies on; its normal points into the meshed half-space (the
// side of the part whose rim fitted it: PartBuilder::rim).
struct Plane {
  Vec point = Vec::Zero(), normal = Vec::UnitZ();
  int tag = -1;
};

// Direction d kept in the planes ids (one or two; -1 entries skipped): its component along their
// intersection (zero when it has none).
Vec in_planes(const Vec& d, const std::array<int, 2>& ids, const std::vector<Plane>& planes) {
  if (ids[0] < 0) return d;
  const Vec& a = planes[static_cast<std::size_t>(ids[0])].normal;
  if (ids[1] < 0) return d - d.dot(a) * a;
  const Vec cross = a.cross(planes[static_cast<std::size_t>(ids[1])].normal);
  // Two (nearly) parallel planes through one node are one plane (two tags on it).
  if (cross.norm() < 1e-9) return d - d.dot(a) * a;
  const Vec line = cross.normalized();
  return d.dot(line) * line;
}

// The closest point to x on the planes ids (one, or the line where two meet).
Vec onto_planes(const Vec& x, const std::array<int, 2>& ids, const std::vector<Plane>& planes) {
  if (ids[0] < 0) return x;
  const Plane& a = planes[static_cast<std::size_t>(ids[0])];
  const Plane& b = planes[static_cast<std::size_t>(std::max(ids[1], 0))];
  if (ids[1] < 0 || a.normal.cross(b.normal).norm() < 1e-9) return x - (x - a.point).dot(a.normal) * a.normal;
  Eigen::Matrix<double, 2, 3> m;
  m.row(0) = a.normal.transpose();
  m.row(1) = b.normal.transpose();
  const Eigen::Vector2d r(a.normal.dot(x - a.point), b.normal.dot(x - b.point));
  return x - m.transpose() * (m * m.transpose()).ldlt().solve(r);
}

// The two triangles a quadrilateral of order q (corners (0, 0), (q, 0), (q, q), (0, q), counter-
// clockwise in its lattice, with ranks r00 .. r0q) is cut into: along the diagonal through its
// corner of smallest rank (the rule of column_order), counter-clockwise like it. Each triangle is
// its three corners in the quadrilateral's lattice.
using QuadCorners = std::array<std::array<int, 2>, 3>;
std::array<QuadCorners, 2> quad_cut(int q, long r00, long rq0, long rqq, long r0q) {
  const long lo = std::min(std::min(r00, rq0), std::min(rqq, r0q));
  if (lo == r00 || lo == rqq) return {{{{{0, 0}, {q, 0}, {q, q}}}, {{{0, 0}, {q, q}, {0, q}}}}};
  return {{{{{0, 0}, {q, 0}, {0, q}}}, {{{q, 0}, {q, q}, {0, q}}}}};
}
// The quadrilateral lattice point of node `lat` of such a triangle.
std::array<int, 2> quad_point(const QuadCorners& h, const Lattice& lat, int q) {
  const int w[3] = {q - lat[0] - lat[1], lat[0], lat[1]};
  int i = 0, j = 0;
  for (int k = 0; k < 3; ++k) i += w[k] * h[static_cast<std::size_t>(k)][0], j += w[k] * h[static_cast<std::size_t>(k)][1];
  return {i / q, j / q};
}

// A front of one part with a fixed local numbering of its nodes (step 1): the wall triangles at
// first; after a first layer with fans also the corner patches' triangles and the two triangles
// of every kite edge's quadrilateral (step 6). Every face is a triangle, grown as a prism (or, in
// a first layer with fans, three tetrahedra).
struct Part {
  std::string name;
  int np = 3;                           // nodes per triangle
  std::vector<int> tri;                 // np local node ids per triangle, Gmsh order
  std::vector<int> tri_tag;             // per triangle: index into the front's tags
  std::vector<NodeId> ids;              // current mesh node id of each local node
  std::vector<std::uint8_t> is_vertex;  // a vertex of some face (else high-order)
  // The attenuation target of node l: sum_k w[l][k] * top of local vertex v[l][k] (k < 4).
  std::vector<std::array<int, 4>> tv;
  std::vector<std::array<double, 4>> tw;
  std::vector<std::array<int, 2>> plane;             // per node: the planes it lies on (-1: none)
  std::vector<int> node_face_start, node_face;       // CSR: the faces around each node
  // Per rim edge: face, edge (0-2, Gmsh's triangle edges), plane.
  std::vector<std::array<int, 3>> rim;
  std::vector<int> vertices;                          // local ids of vertex nodes
  // Per node: the direction its column grew along when it descends from a fan direction (zero
  // for the others; step 6), kept while it sees every face around the node.
  std::vector<Vec> keep;
  // Per node: the thickness of its column's layers so far (empty before the first layer).
  std::vector<double> stack;
  std::size_t size() const { return ids.size(); }
  std::size_t nt() const { return tri_tag.size(); }
  std::size_t num_faces() const { return nt(); }
  const int* face(std::size_t f) const { return tri.data() + f * static_cast<std::size_t>(np); }
  int face_size(std::size_t) const { return np; }
  int face_vertices(std::size_t) const { return 3; }
  int face_tag(std::size_t f) const { return tri_tag[f]; }
};

// The derived arrays of a part from its faces: vertex flags, attenuation recipes (barycentric on
// the triangles), the faces around each node.
void finish_part(Part& p, int q) {
  const std::size_t n = p.size();
  p.is_vertex.assign(n, 0);
  p.tv.assign(n, {0, 0, 0, 0});
  p.tw.assign(n, {0, 0, 0, 0});
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q);
  for (std::size_t f = 0; f < p.num_faces(); ++f) {
    const int* fl = p.face(f);
    for (int k = 0; k < p.face_size(f); ++k) {
      const Lattice& lat = te.lattice()[static_cast<std::size_t>(k)];
      // From the lattice's integers: an edge node's weight on the opposite vertex is exactly 0
      // (1 - 1/3 - 2/3 is 1.1e-16 in doubles, which tied a Q3 edge node to that vertex, so the
      // edge between two stopped columns grew a top of its own).
      const double u = static_cast<double>(lat[0]) / q, v = static_cast<double>(lat[1]) / q;
      const std::size_t l = static_cast<std::size_t>(fl[k]);
      p.tv[l] = {fl[0], fl[1], fl[2], fl[0]};
      p.tw[l] = {static_cast<double>(q - lat[0] - lat[1]) / q, u, v, 0};
      if (k < p.face_vertices(f)) p.is_vertex[l] = 1;
    }
  }
  p.vertices.clear();
  for (std::size_t l = 0; l < n; ++l)
    if (p.is_vertex[l]) p.vertices.push_back(static_cast<int>(l));
  p.node_face_start.assign(n + 1, 0);
  for (std::size_t f = 0; f < p.num_faces(); ++f)
    for (int k = 0; k < p.face_size(f); ++k) ++p.node_face_start[static_cast<std::size_t>(p.face(f)[k]) + 1];
  for (std::size_t l = 0; l < n; ++l) p.node_face_start[l + 1] += p.node_face_start[l];
  p.node_face.resize(static_cast<std::size_t>(p.node_face_start[n]));
  std::vector<int> fill(p.node_face_start.begin(), p.node_face_start.end() - 1);
  for (std::size_t f = 0; f < p.num_faces(); ++f)
    for (int k = 0; k < p.face_size(f); ++k)
      p.node_face[static_cast<std::size_t>(fill[static_cast<std::size_t>(p.face(f)[k])]++)] = static_cast<int>(f);
}

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

// A growth direction of the new layer at an old front node. Without fans every node has one; the
// first layer's fans give a fan node one per wedge of faces around it, the directions along each
// fan's arc and, at a corner, the directions of the corner's patch (step 6).
struct Dir {
  int base = 0;          // the old front node it grows from
  Vec d = Vec::UnitZ();  // unit direction
  double stretch = 1;    // height factor (concave merges)
  bool concave = false;
  bool fan = false;      // a direction of a fan node: its top stays on the fan (no attenuation)
  bool normal = false;   // a fan node's wedge direction or kite normal n_s (the fan's height is theirs)
};

// The pending build of one part.
struct PartLayer {
  BuiltLayer built;
  std::array<std::vector<int>, 2> cell_face;  // per new cell: the old face whose neighbourhood shrinks if it fails
  std::vector<int> face_origin;               // per face of the new front: the same
  std::vector<NodeId> top;                    // per node of the new front
  std::vector<Vec> keep;                      // per node of the new front: Part::keep
  std::vector<double> stack;                  // per node of the new front: Part::stack
  std::shared_ptr<Part> next;                 // the new front's faces when fans changed them (else the old ones)
  std::vector<NodeId> sym_quads, sym_tris;    // symmetry facets, Gmsh order, facing the cells
  std::vector<int> sym_quad_tag, sym_tri_tag;
};

// The metric's layer heights (layer_height) asked for since the part's front last moved, keyed by
// point and direction bit for bit: the shrink, attenuation and stop rounds of a layer rebuild it
// from the same front, up to dozens of times (the published Orion capsule at h0 1e-5 L, Q2: about
// 900 builds in 40 layers), and the wall law's distance to the wall, a closest-point search, was
// a quarter of each build. A key not met before is evaluated; the result is the same either way.
class HeightMemo {
 public:
  double operator()(const MetricField<3>& metric, const Vec& x, const Vec& d, bool integrate) {
    const Key k{x.x(), x.y(), x.z(), d.x(), d.y(), d.z(), integrate ? 1.0 : 0.0};
    const auto it = map_.find(k);
    if (it != map_.end()) return it->second;
    const double h = layer_height<3>(metric, x, d, integrate);
    map_.emplace(k, h);
    return h;
  }
  void clear() { map_.clear(); }

 private:
  using Key = std::array<double, 7>;
  struct Hash {
    std::size_t operator()(const Key& k) const {
      std::size_t h = 0;
      for (double v : k) h = h * 1000003u ^ std::hash<double>()(v);
      return h;
    }
  };
  std::unordered_map<Key, double, Hash> map_;
};

// Builds one layer on one part (steps 2-6).
class PartLayerBuilder {
 public:
  PartLayerBuilder(HybridMesh<3>& mesh, const MetricField<3>& metric, const LayerParams& p, int q,
                   const CurvedFront<3>& front0, const Part& part, const std::vector<Plane>& planes, bool first_layer,
                   const std::vector<double>& scale, const std::vector<std::uint8_t>& stopped,
                   const std::vector<std::uint8_t>& held, double f_atten,
                   std::vector<std::pair<std::string, std::size_t>>* counts, HeightMemo& heights)
      : mesh_(mesh), metric_(metric), p_(p), q_(q), np_(num_nodes(CellType::Triangle, q)),
        front0_(front0), part_(part), planes_(planes), first_(first_layer),
        scale_(scale), stopped_(stopped), held_(held), f_atten_(f_atten), counts_(counts), heights_(heights) {}

  PartLayer build() {
    const std::size_t n = part_.size();
    x_.resize(n);
    for (std::size_t l = 0; l < n; ++l) x_[l] = mesh_.nodes[static_cast<std::size_t>(part_.ids[l])];
    stops();
    normals();
    relax_normals();
    if (first_ && std::isfinite(f_atten_) && !any_stop_) fans();
    check_cusps();
    if (!fanned_) {
      dirs_.resize(n);
      for (std::size_t l = 0; l < n; ++l)
        dirs_[l] = {static_cast<int>(l), nn_[l].n, nn_[l].stretch, is_concave(nn_[l].kind), false};
      out_.face_origin.resize(part_.num_faces());
      for (std::size_t f = 0; f < part_.num_faces(); ++f) out_.face_origin[f] = static_cast<int>(f);
    }
    blend();
    if (counts_ != nullptr) count();
    tops();
    columns_and_cells();
    return std::move(out_);
  }

 private:
  // A ridge edge of the first layer's fans: its Q + 1 old nodes along the chain, its sides (the
  // chain's left and right triangles), the arc at each node, the sector count, and the plane its
  // first and last node lie on (-1: none).
  struct FanEdge {
    std::vector<int> nodes, arcs;
    int left = 0, right = 0, k = 1;
    std::array<int, 2> plane = {-1, -1};
  };

  const Part& next() const { return out_.next ? *out_.next : part_; }
  std::size_t ent_begin(std::size_t l) const { return static_cast<std::size_t>(ent_start_[l]); }
  std::size_t ent_end(std::size_t l) const { return static_cast<std::size_t>(ent_start_[l + 1]); }

  // Local stops (layer_core.h, step 3): the stopped vertices, and the high-order nodes whose
  // element's vertices all stopped, keep their place (no column); every cell of a layer with a
  // stop is cut into tetrahedra (columns_and_cells), those of a collapsed column dropped.
  void stops() {
    const std::size_t n = part_.size();
    stop_.assign(n, 0);
    for (std::size_t k = 0; k < stopped_.size() && k < part_.vertices.size(); ++k)
      if (stopped_[k]) stop_[static_cast<std::size_t>(part_.vertices[k])] = 1;
    for (std::size_t l = 0; l < n; ++l) {
      if (part_.is_vertex[l]) continue;
      bool all = true;
      for (int k = 0; k < 4; ++k)
        if (part_.tw[l][static_cast<std::size_t>(k)] > 0) all = all && stop_[static_cast<std::size_t>(part_.tv[l][static_cast<std::size_t>(k)])];
      stop_[l] = all ? 1 : 0;
    }
    any_stop_ = std::any_of(stop_.begin(), stop_.end(), [](std::uint8_t b) { return b != 0; });
    // About Q^2 lifted nodes per face (its cut's edges and faces through the layer): no rehash.
    if (any_stop_) lifted_.reserve(part_.nt() * static_cast<std::size_t>(q_ * q_));
  }
  bool stopped_dir(std::size_t d) const { return any_stop_ && !fanned_ && stop_[static_cast<std::size_t>(dirs_[d].base)]; }

  // 2. Normals: per node, the sub-triangle normals around it with their angles there and faces.
  void normals() {
    const std::size_t n = part_.size();
    const std::vector<std::array<int, 3>> subs = sub_triangles(q_);
    ent_start_.assign(n + 1, 0);
    for (std::size_t f = 0; f < part_.num_faces(); ++f)
      for (const auto& s : subs)
        for (int k : s) ++ent_start_[static_cast<std::size_t>(part_.face(f)[k]) + 1];
    for (std::size_t l = 0; l < n; ++l) ent_start_[l + 1] += ent_start_[l];
    ent_n_.resize(static_cast<std::size_t>(ent_start_[n]));
    ent_w_.resize(ent_n_.size());
    ent_f_.resize(ent_n_.size());
    std::vector<int> fill(ent_start_.begin(), ent_start_.end() - 1);
    for (std::size_t f = 0; f < part_.num_faces(); ++f)
      for (const auto& s : subs) {
        const int* fl = part_.face(f);
        const Vec a = x_[static_cast<std::size_t>(fl[s[0]])], b = x_[static_cast<std::size_t>(fl[s[1]])],
                  c = x_[static_cast<std::size_t>(fl[s[2]])];
        const Vec nn = (b - a).cross(c - a);
        if (!(nn.norm() > 0)) {
          throw MesherError("layers: a degenerate front triangle in surface " + part_.name + " at " +
                            std::to_string(a.x()) + ", " + std::to_string(a.y()) + ", " + std::to_string(a.z()));
        }
        const Vec un = nn.normalized();
        const Vec pts[3] = {a, b, c};
        for (int k = 0; k < 3; ++k) {
          const Vec e1 = pts[(k + 1) % 3] - pts[k], e2 = pts[(k + 2) % 3] - pts[k];
          const std::size_t l = static_cast<std::size_t>(fl[s[static_cast<std::size_t>(k)]]);
          const std::size_t e = static_cast<std::size_t>(fill[l]++);
          ent_n_[e] = un;
          ent_w_[e] = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
          ent_f_[e] = static_cast<int>(f);
        }
      }
    nn_.assign(n, NodeNormal{});
    const double corner_rad = p_.corner_angle_deg * M_PI / 180;
    std::vector<Vec> fv, to_nb;
    std::vector<double> w;
    for (std::size_t l = 0; l < n; ++l) {
      fv.assign(ent_n_.begin() + static_cast<std::ptrdiff_t>(ent_begin(l)), ent_n_.begin() + static_cast<std::ptrdiff_t>(ent_end(l)));
      w.assign(ent_w_.begin() + static_cast<std::ptrdiff_t>(ent_begin(l)), ent_w_.begin() + static_cast<std::ptrdiff_t>(ent_end(l)));
      to_nb.clear();
      for (int k = part_.node_face_start[l]; k < part_.node_face_start[l + 1]; ++k) {
        const std::size_t f = static_cast<std::size_t>(part_.node_face[static_cast<std::size_t>(k)]);
        for (int v = 0; v < part_.face_vertices(f); ++v)
          if (static_cast<std::size_t>(part_.face(f)[v]) != l) to_nb.push_back(x_[static_cast<std::size_t>(part_.face(f)[v])] - x_[l]);
      }
      // A corner's columns keep their direction (radial from the corner) while every face around
      // sees it at less than 80 degrees: the faces' average would lean the corner patch's nodes
      // toward its centre, a little every layer, until the patch's triangles collapse (measured
      // on a box with 20-degree fans: slivers at the corners by layer 5). A ridge's kites take
      // the faces' average, as the 2D kites do.
      const Vec& kept = part_.keep[l];
      if (!first_ && kept.squaredNorm() > 0) {
        double worst = 1;
        for (const Vec& f : fv) worst = std::min(worst, kept.dot(f));
        if (worst > std::cos(80 * M_PI / 180)) {
          nn_[l] = NodeNormal{kept, 1, worst, NodeClass::Smooth};
          continue;
        }
      }
      NodeNormal r;
      try {
        r = normal_at(l, fv, w, to_nb, corner_rad);
      } catch (const MesherError& e) {
        // A cusp (no direction sees every face): the direction that sees them best (the largest
        // smallest cosine, negative here: Aubry and Loehner's "most normal" direction), counted;
        // the cells it folds fail certification, shrink, and where even the floor fails the
        // column stops (layer_core.h, step 3) -- a cusp is no error for the whole run.
        cusp_.emplace_back(l, e.what());
        r.n = most_normal(fv);
        if (r.n.isZero()) r.n = fv.front();
        r.kind = NodeClass::ConvexRidge;
      }
      // The first layer starts from the reference normal where the surface is smooth (Sec. II.B).
      const std::size_t id = static_cast<std::size_t>(part_.ids[l]);
      if (first_ && r.kind == NodeClass::Smooth && id < front0_.normals.size()) r.n = front0_.normals[id];
      r.n = in_plane(l, r.n);
      nn_[l] = r;
    }
  }

  // Normal relaxation (layers.smooth_normals; Aubry and Loehner's smoothing of the marching
  // directions, issue 30's "relax the normals over the next layers"): after the first layer, two
  // Jacobi passes move each smooth node's normal halfway toward the mean of the normals of the
  // nodes of its faces, kept in its symmetry planes, and taken only where every face around the
  // node still sees it at least as well as cos 75 degrees or as before. Columns over a concave
  // bend or beside a fan turn with their neighbours instead of converging on them. Fan, ridge,
  // corner, cusp and stopped nodes keep their normals.
  void relax_normals() {
    if (!p_.smooth_normals || first_) return;
    const std::size_t n = part_.size();
    const double floor = std::cos(75 * M_PI / 180);
    std::vector<Vec> next(n);
    std::vector<double> next_cosine(n);
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t l = 0; l < n; ++l) {
        next[l] = nn_[l].n;
        next_cosine[l] = nn_[l].min_cosine;
        if (nn_[l].kind != NodeClass::Smooth || part_.keep[l].squaredNorm() > 0 || stop_[l]) continue;
        Vec sum = Vec::Zero();
        int count = 0;
        for (int k = part_.node_face_start[l]; k < part_.node_face_start[l + 1]; ++k) {
          const std::size_t f = static_cast<std::size_t>(part_.node_face[static_cast<std::size_t>(k)]);
          for (int v = 0; v < part_.face_size(f); ++v) {
            const std::size_t m = static_cast<std::size_t>(part_.face(f)[v]);
            if (m == l) continue;
            sum += nn_[m].n;
            ++count;
          }
        }
        if (count == 0) continue;
        const Vec mid = nn_[l].n + sum / count;
        if (!(mid.norm() > 1e-12)) continue;
        // In its symmetry planes (skipped where the projection is too short to trust: in_plane
        // would end the run there, and the relaxation is optional).
        const Vec planar = in_planes(mid.normalized(), part_.plane[l], planes_);
        if (!(planar.norm() > 1e-3)) continue;
        const Vec c = planar.normalized();
        double worst = 1;
        for (std::size_t e = ent_begin(l); e < ent_end(l); ++e) worst = std::min(worst, c.dot(ent_n_[e]));
        if (worst >= std::min(nn_[l].min_cosine, floor)) {
          next[l] = c;
          next_cosine[l] = worst;
        }
      }
      for (std::size_t l = 0; l < n; ++l) {
        nn_[l].n = next[l];
        nn_[l].min_cosine = next_cosine[l];
      }
    }
  }

  // The cusp nodes a fan does not take (a fan vertex other than a corner, a fan edge's high-order
  // node), for the first layer's counts: they grow along their most normal direction.
  void check_cusps() {
    for (const auto& [l, what] : cusp_) {
      const bool fan = fanned_ && fan_node_[l] && !corner_node_.count(static_cast<int>(l));
      if (!fan) ++cusps_;
    }
  }

  NodeNormal normal_at(std::size_t l, const std::vector<Vec>& f, const std::vector<double>& w,
                       const std::vector<Vec>& to_nb, double corner_rad) const {
    try {
      return node_normal(f, w, to_nb, corner_rad);
    } catch (const MesherError& e) {
      // Name the node: a cusp is a defect of the surface there (a fold, a notch).
      throw MesherError(std::string(e.what()) + " at " + std::to_string(x_[l].x()) + ", " + std::to_string(x_[l].y()) +
                        ", " + std::to_string(x_[l].z()) + " on surface " + part_.name +
                        "; check the surface mesh there (surface.* in the report)");
    }
  }

  // A direction at node l kept in its symmetry planes.
  Vec in_plane(std::size_t l, const Vec& d) const {
    if (part_.plane[l][0] < 0) return d;
    const Vec inplane = in_planes(d, part_.plane[l], planes_);
    if (!(inplane.norm() > 1e-3))
      throw MesherError("layers: surface " + part_.name + " meets its symmetry plane tangentially at " +
                        std::to_string(x_[l].x()) + ", " + std::to_string(x_[l].y()) + ", " + std::to_string(x_[l].z()));
    return inplane.normalized();
  }

  // The angle-weighted normal of the old face f at its node l (one side of a ridge).
  Vec side_normal(int f, int l) const {
    Vec s = Vec::Zero();
    for (std::size_t e = ent_begin(static_cast<std::size_t>(l)); e < ent_end(static_cast<std::size_t>(l)); ++e)
      if (ent_f_[e] == f) s += ent_w_[e] * ent_n_[e];
    return s.normalized();
  }

  int add_dir(int base, const Vec& d, double stretch, bool concave, bool fan) {
    dirs_.push_back({base, in_plane(static_cast<std::size_t>(base), d.normalized()), stretch, concave, fan});
    return static_cast<int>(dirs_.size()) - 1;
  }
  // A fan direction by its top per unit height (its direction and stretch), and back.
  int add_unit_h(int base, const Vec& v) { return add_dir(base, v, v.norm(), false, true); }
  Vec unit_h(int d) const { return dirs_[static_cast<std::size_t>(d)].stretch * dirs_[static_cast<std::size_t>(d)].d; }

  // 6. Fans at convex ridges and corners, on the first layer (Aubry & Loehner's ridge and corner
  // fans; the issue's prism/tetrahedron variant). A wall edge is a fan edge when its two faces
  // meet convexly at more than corner_angle_deg (at any of its nodes). Fan edges form chains
  // between corners (3 or more fan edges at a node), symmetry planes (the chain's end node on
  // the rim), closed loops or, with fan_fades, fades (without it a chain ending elsewhere keeps
  // the merged normal). A fade is a chain's end anywhere else (one fan edge at a node off the
  // planes: its ridge fades out, as a trailing edge into a rounded tip): the node keeps its one
  // merged direction, the fan narrows toward it by at most fan_angle_deg and one kite per edge
  // (the fade zone, whose columns keep their directions in later layers) and closes there, a
  // sector closed at one end of an edge being two tetrahedra (fade_cells). A chain of one edge
  // that fades is no fan; nor is a node on two planes or with two chains on a plane: the fan
  // would have nowhere to close (the robust choice; Sec. II.E leaves ridges open).
  // At a fan node the faces around it form wedges (separated by fan edges), each growing along
  // its own normal; between the two wedges of a fan edge an arc of 2 k Q + 1 directions (k
  // kites of at most fan_angle_deg, the same k along the chain; two straight kite edges each)
  // gives in this layer two prisms per kite and ridge edge (cross sections: the node, P_s, X_s
  // and the node, X_s, P_s+1; extruded along the ridge), each cut into three tetrahedra like
  // every prism of this layer (column_order), and two quadrilaterals whose cut triangles join the
  // new front (lattice i along the chain, j across the arc from the right wedge to the left one,
  // so i x j faces the domain); at a corner, a flat patch of triangles from the corner's merged
  // normal to every kite edge gives tetrahedra (node + patch triangle) and front triangles. Every
  // face of the new front grows as a prism in later layers.
  void fans() {
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

  // True when sector s of fan edge fe is closed at its node i (0 or Q): both its ends there are
  // one direction (a fade, or a fade zone's outer sector).
  bool closed_at(const FanEdge& fe, int s, int i) const {
    const std::vector<int>& a = arcs_[static_cast<std::size_t>(fe.arcs[static_cast<std::size_t>(i)])];
    return a[static_cast<std::size_t>(s * q_)] == a[static_cast<std::size_t>((s + 1) * q_)];
  }

  // The direction at node i (0..Q) of fan edge fe whose top divides sector s's kite edge at
  // j = num / den of Q (from the arc's right end): the arc's own direction where j is a lattice
  // point, else a new one on the straight kite edge between its two neighbours (a fade's
  // sector at Q >= 3), one per point.
  int collapsed_dir(const FanEdge& fe, int s, int i, int num, int den) {
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

  static Vec slerp(const Vec& a, const Vec& b, double t) {
    const double ang = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
    if (ang < 1e-12) return a;
    return (std::sin((1 - t) * ang) * a + std::sin(t * ang) * b) / std::sin(ang);
  }

  // Next to a convex ridge or corner with a merged normal (no fan) the smooth high-order nodes
  // move along the blend of their face's vertex normals: the faces' own normals there differ from
  // the merged vertex normal by up to half the dihedral angle, and the attenuation (f_atten h per
  // layer) could never catch up with the bend that would grow each layer. Every other high-order
  // node (but a fan's or a concave merge's) leans at most kMaxBend from that blend.
  void blend() {
    const Part& nw = next();
    auto convex = [&](int d) {
      const Dir& r = dirs_[static_cast<std::size_t>(d)];
      const NodeClass k = nn_[static_cast<std::size_t>(r.base)].kind;
      return !r.fan && k != NodeClass::Smooth && !is_concave(k);
    };
    std::vector<std::uint8_t> blend(dirs_.size(), 0);
    for (std::size_t f = 0; f < nw.num_faces(); ++f) {
      const int* fl = nw.face(f);
      bool c = false;
      for (int v = 0; v < nw.face_vertices(f); ++v) c = c || convex(fl[v]);
      if (c)
        for (int k = nw.face_vertices(f); k < nw.face_size(f); ++k) blend[static_cast<std::size_t>(fl[k])] = 1;
    }
    for (std::size_t d = 0; d < dirs_.size(); ++d) {
      Dir& r = dirs_[d];
      const NodeClass kind = nn_[static_cast<std::size_t>(r.base)].kind;
      if (nw.is_vertex[d] || r.fan || r.concave) continue;
      Vec m = Vec::Zero();
      for (int k = 0; k < 4; ++k) m += nw.tw[d][static_cast<std::size_t>(k)] * dirs_[static_cast<std::size_t>(nw.tv[d][static_cast<std::size_t>(k)])].d;
      m = in_planes(m, part_.plane[static_cast<std::size_t>(r.base)], planes_);
      if (!(m.norm() > 1e-6)) continue;
      m.normalize();
      if (blend[d] && kind == NodeClass::Smooth) {
        r.d = m;
        continue;
      }
      // Everywhere else (ridge nodes too) a high-order node keeps its own normal within
      // kMaxBend of the blend. The paper grows each node along its normal and pulls its top
      // toward the chord by at most f_atten h (Sec. II.B); a node whose normal leans further from
      // its face's vertex directions than that bends its face more with every layer, so the sag
      // grows with the heights instead of fading. Measured on the published ONERA M6 (h0 8.06e-6
      // c): where the trailing edge's ridge fades into the rounded tip, a ridge edge's middle
      // node grew along its own bisector 40 degrees from the blend of the tip corner's merged
      // normal and its other end's; the edge's sag went from 0.2 % of its length at the wall to
      // 21 % at layer 35, 195 cells stayed curved to the last layer and, grown to its metric's
      // 46 layers, three of the fill's tetrahedra on that front inverted. Half the paper's
      // f_atten (0.2) keeps the net pull at least 0.1 h (the front linear after layer 41); a
      // layer rebuilt with f_atten halved (layer_core.h) or a user's smaller f_atten pulls less
      // than this lean, and its sag fades only where the node's own normal leans less.
      constexpr double kMaxBend = 0.1;
      const double bend = std::atan2(m.cross(r.d).norm(), m.dot(r.d));
      if (bend > kMaxBend) {
        // Turned from m toward the node's own normal by kMaxBend (straight to m where the two are
        // opposite, as on the line two symmetry planes share).
        const Vec u = r.d - r.d.dot(m) * m;
        r.d = u.norm() > 1e-9 ? Vec(std::cos(kMaxBend) * m + std::sin(kMaxBend) * u.normalized()) : m;
      }
    }
  }

  void count() {
    std::size_t classes[6] = {0, 0, 0, 0, 0, 0}, sym = 0;
    for (std::size_t l = 0; l < part_.size(); ++l) {
      if (part_.is_vertex[l]) ++classes[static_cast<int>(nn_[l].kind)];
      if (part_.plane[l][0] >= 0) ++sym;
    }
    counts_->clear();
    for (int k = 0; k < 6; ++k)
      counts_->push_back({std::string("nodes.") + node_class_name(static_cast<NodeClass>(k)), classes[k]});
    counts_->push_back({"nodes.symmetry", sym});
    counts_->push_back({"merges", classes[static_cast<int>(NodeClass::ConcaveRidge)] +
                                      classes[static_cast<int>(NodeClass::ConcaveCorner)]});
    counts_->push_back({"ridge_fans.edges", fan_edges_.size()});
    std::size_t sectors = 0;
    for (const FanEdge& fe : fan_edges_) sectors += static_cast<std::size_t>(fe.k);
    counts_->push_back({"ridge_fans.sectors", sectors});
    counts_->push_back({"ridge_fans.fades", fades_});
    counts_->push_back({"ridge_fans.narrowed", narrowed_});
    counts_->push_back({"corner_fans", corner_fans_});
    counts_->push_back({"nodes.cusp", cusps_});
  }

  // 3-4. Heights, tops (on the symmetry planes), attenuation of the high-order tops.
  // Order 1: the new front's edges as chords of the surface the metric is measured from, as 2D
  // does (grow_layers_2d.cpp, chord_sag_need): an edge between directions theta apart sags about
  // |c| tan(theta / 4) / 2 off it, c the chord's part across the axis d_u x d_v (so a cylinder's
  // diagonal edge sags as its section's chord); an element counts as curved until every edge's
  // sag is at most f_atten times the smaller height at its ends. Edges to a fan's arc directions
  // are straight-sided fan cells' and are skipped, as are edges to a concave merge (its normal
  // turns by half the corner on flat faces). Returns the largest sag / h (0 when met).
  double chord_sag_need(const Part& nw) const {
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

  // The front around an earlier stop keeps a bounded slope: a vertex's stack may rise at most
  // kStopSlope times its distance along the front (over the faces' edges) above the stack of a
  // column stopped before this layer, and where it already stands that high it grows kStopCreep
  // of its height. The half height beside a stop (above) slopes the first ring only; the stop
  // itself is for good, so the rings beyond rose a full layer every time until the front stood as
  // a wall around the stop again, whose cells failed in the last layers, where a layer is as tall
  // as the faces are wide (the published spot, h0 1e-5 L, Q2: tetrahedra of layer 37 grown
  // sideways from a front face turned on its side). Sec. II.B does not meet stops; 0.5 is the
  // grading of the proximity rule's allowances over the front (grow_layers_3d.h, step 8).
  // Against 1.0 and 0.25 on the published 717, spot and BWB (h0 1e-5 L, Q2): 1.0 lost coverage
  // on all three; 0.25 gained up to 0.4 points but compresses a wider ring to a quarter height.
  void slope_from_stops(const std::vector<std::uint8_t>& before) {
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

  // Neighbouring columns' heights differ by at most kHeightJump: a vertex grows at most that
  // many times the height of any growing vertex it shares a face with. The shrinks halve the
  // heights on rings around failures, the rules around stops cut them again, and the metric's own
  // heights are smooth, so only those make jumps; unlimited, a ring shrunk to the floor (1/16)
  // stood beside full columns, and the cells across its edge, a hundred times taller on one
  // side, failed and stopped the ring's columns (the published spot, h0 1e-5 L, Q2: in layer 37
  // every tetrahedron that failed at the floor had columns of 2.9e-4 and 2.5e-2 or such). The
  // jump is the shrink's own factor.
  void limit_height_jumps() {
    constexpr double kHeightJump = 2;
    std::vector<std::uint8_t> growing(part_.size(), 0);
    for (std::size_t l = 0; l < part_.size(); ++l) growing[l] = part_.is_vertex[l] && !stop_[l] && std::isfinite(h_[l]);
    spread_min(h_, growing, [&](double h, std::size_t, std::size_t m) {
      return stop_[m] ? std::numeric_limits<double>::infinity() : kHeightJump * h;
    });
  }

  // Spreads the smallest values over the front's vertices from the seeds, smallest first
  // (Dijkstra's order): vertex m beside l (on a face with it) takes relax(value[l], l, m) where
  // that is smaller than its own, relax being nondecreasing in the value.
  template <class Relax>
  void spread_min(std::vector<double>& value, const std::vector<std::uint8_t>& seed, const Relax& relax) const {
    using Item = std::pair<double, std::size_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    for (std::size_t l = 0; l < seed.size(); ++l)
      if (seed[l]) queue.emplace(value[l], l);
    while (!queue.empty()) {
      const auto [x, l] = queue.top();
      queue.pop();
      if (x > value[l]) continue;
      for (int k = part_.node_face_start[l]; k < part_.node_face_start[l + 1]; ++k) {
        const int* fl = part_.face(static_cast<std::size_t>(part_.node_face[static_cast<std::size_t>(k)]));
        for (int v = 0; v < 3; ++v) {
          const std::size_t m = static_cast<std::size_t>(fl[v]);
          const double via = relax(x, l, m);
          if (via < value[m]) {
            value[m] = via;
            queue.emplace(via, m);
          }
        }
      }
    }
  }

  void tops() {
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

  // Node `level` (0..Q) of direction d's column; the inner ones are made when a cell first asks
  // (an arc direction inside a sector of the first layer's fans has only its top).
  NodeId at(int d, int level) {
    const std::size_t b = static_cast<std::size_t>(dirs_[static_cast<std::size_t>(d)].base);
    if (level == 0 || stopped_dir(static_cast<std::size_t>(d))) return part_.ids[b];
    NodeId& id = col_[static_cast<std::size_t>(d) * static_cast<std::size_t>(q_) + static_cast<std::size_t>(level) - 1];
    if (id < 0) {
      mesh_.nodes.push_back(x_[b] + (static_cast<double>(level) / q_) * (top_[static_cast<std::size_t>(d)] - x_[b]));
      id = static_cast<NodeId>(mesh_.nodes.size() - 1);
    }
    return id;
  }

  // A node of the first layer's fan cells off the columns: x + sum_k (w_k / Q) (top_k - x) (k
  // over directions of one base node x, sum w = level < Q), the fans' cells being straight-sided
  // (kites and flat corner patches); one node per weight set, shared by every cell that has it.
  NodeId fan_point(std::vector<std::pair<int, int>> weights) {
    std::sort(weights.begin(), weights.end());
    // One direction given twice (a fade's collapsed section): that column's node.
    for (std::size_t k = 1; k < weights.size();)
      if (weights[k].first == weights[k - 1].first) {
        weights[k - 1].second += weights[k].second;
        weights.erase(weights.begin() + static_cast<std::ptrdiff_t>(k));
      } else {
        ++k;
      }
    if (weights.size() == 1) return at(weights[0].first, weights[0].second);
    const auto it = fan_points_.find(weights);
    if (it != fan_points_.end()) return it->second;
    const std::size_t base = static_cast<std::size_t>(dirs_[static_cast<std::size_t>(weights[0].first)].base);
    Vec x = x_[base];
    for (const auto& [dir, w] : weights) x += (static_cast<double>(w) / q_) * (top_[static_cast<std::size_t>(dir)] - x_[base]);
    mesh_.nodes.push_back(x);
    const NodeId id = static_cast<NodeId>(mesh_.nodes.size() - 1);
    fan_points_.emplace(weights, id);
    return id;
  }

  // 5-6. Columns of Q nodes per direction; per face of the new front grown from an old face a
  // prism, or three tetrahedra in a first layer with fans; the first layer's fan cells; the
  // symmetry facets.
  void columns_and_cells() {
    const std::size_t nd = dirs_.size();
    const std::size_t q = static_cast<std::size_t>(q_);
    col_.assign(nd * q, -1);
    out_.keep.assign(nd, Vec::Zero());
    for (std::size_t d = 0; d < nd; ++d)
      if (fanned_ ? dirs_[d].fan && (corner_node_.count(dirs_[d].base) || zone_.count(dirs_[d].base))
                  : part_.keep[d].squaredNorm() > 0)
        out_.keep[d] = dirs_[d].d;
    out_.top.resize(nd);
    for (std::size_t d = 0; d < nd; ++d) out_.top[d] = at(static_cast<int>(d), q_);
    out_.stack.resize(nd);
    for (std::size_t d = 0; d < nd; ++d) {
      const std::size_t b = static_cast<std::size_t>(dirs_[d].base);
      out_.stack[d] = (part_.stack.size() == part_.size() ? part_.stack[b] : 0.0) +
                      (mesh_.nodes[static_cast<std::size_t>(out_.top[d])] - x_[b]).norm();
    }
    const Part& nw = next();
    const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
    const LagrangeElement& qe = lagrange_element(CellType::Quadrilateral, q_);
    const LagrangeElement& pe = lagrange_element(CellType::Prism, q_);
    std::vector<int> tri_of_prism_node;
    for (const Lattice& lat : pe.lattice()) tri_of_prism_node.push_back(te.find({lat[0], lat[1], 0}));
    std::vector<NodeId>& prisms = out_.built.cells[0];
    std::vector<NodeId>& tets = out_.built.cells[1];
    const std::size_t grown = fanned_ ? part_.nt() : nw.num_faces();  // faces grown from an old face
    const bool tetra = fanned_ || any_stop_;
    const std::size_t npt = static_cast<std::size_t>(num_nodes(CellType::Tetrahedron, q_));
    for (std::size_t f = 0; f < grown; ++f) {
      const int* fl = nw.face(f);
      if (tetra) {
        // The first layer of a part with fans is all tetrahedra (grow_layers_3d.h, step 6), and
        // so is a layer with stopped columns: a prism over a face with a stopped vertex is a
        // pyramid (two stopped, a tetrahedron), which only tetrahedra meet conformingly, and a
        // quadrilateral shared with a whole prism must be cut alike. The cut's tetrahedron
        // holding both ends of a collapsed column has no volume and is dropped; in a layer with
        // stops every cut cell's nodes follow layer_node (heights affine over the cell).
        std::array<long, 6> rank{};
        for (int k = 0; k < 3; ++k) {
          rank[static_cast<std::size_t>(k)] = base_rank(dirs_[static_cast<std::size_t>(fl[k])].base);
          rank[static_cast<std::size_t>(k + 3)] = top_rank(fl[k]);
        }
        const std::size_t before = tets.size();
        if (any_stop_ && !fanned_)
          transition_tets(fl, column_order(rank), tets);
        else
          split_tets(fl, column_order(rank), tets);
        for (std::size_t k = before; k < tets.size(); k += npt) out_.cell_face[1].push_back(static_cast<int>(f));
      } else {
        for (int k = 0; k < pe.size(); ++k)
          prisms.push_back(at(fl[tri_of_prism_node[static_cast<std::size_t>(k)]], pe.lattice()[static_cast<std::size_t>(k)][2]));
        out_.cell_face[0].push_back(static_cast<int>(f));
      }
    }
    if (fanned_) fan_cells();
    // Symmetry facets of the grown faces: a triangle's rim edge gives a quadrilateral (u from the
    // edge's second vertex to its first, v up the layer: facing the cells, as the wall does), or
    // its two triangles where the layer is tetrahedra.
    for (const auto& re : nw.rim) {
      const std::size_t f = static_cast<std::size_t>(re[0]);
      if (f >= grown) continue;
      const int* fl = nw.face(f);
      const int tag = planes_[static_cast<std::size_t>(re[2])].tag;
      if (tetra) {
        // The side of a first-layer prism cut into tetrahedra: the two triangles of its cut
        // (column_order's rule on the quadrilateral (u from the edge's second vertex to its first,
        // v up the layer)).
        const std::vector<int>& en = te.edge_nodes(re[1]);
        auto node = [&](int u, int v) { return at(fl[en[static_cast<std::size_t>(q_ - u)]], v); };
        const int d0 = fl[en[static_cast<std::size_t>(q_)]], d1 = fl[en[0]];  // u = 0 and u = Q
        const long r00 = base_rank(dirs_[static_cast<std::size_t>(d0)].base), rq0 = base_rank(dirs_[static_cast<std::size_t>(d1)].base);
        const long rqq = top_rank(d1), r0q = top_rank(d0);
        for (const QuadCorners& h : quad_cut(q_, r00, rq0, rqq, r0q)) {
          Corner corner[3];
          for (int k = 0; k < 3; ++k)
            corner[k] = {h[static_cast<std::size_t>(k)][0] == 0 ? d0 : d1, h[static_cast<std::size_t>(k)][1] == 0 ? 0 : 1};
          if (collapsed(corner, 3)) continue;  // a stopped column's side of no area
          for (const Lattice& lat : te.lattice()) {
            const auto [u, v] = quad_point(h, lat, q_);
            const int w[3] = {q_ - lat[0] - lat[1], lat[0], lat[1]};
            const int d = fl[en[static_cast<std::size_t>(q_ - u)]];
            out_.sym_tris.push_back(any_stop_ ? layer_node(corner, w, 3, d) : node(u, v));
          }
          out_.sym_tri_tag.push_back(tag);
        }
      } else {
        const std::vector<int>& en = te.edge_nodes(re[1]);
        for (const Lattice& lat : qe.lattice()) out_.sym_quads.push_back(at(fl[en[static_cast<std::size_t>(q_ - lat[0])]], lat[1]));
        out_.sym_quad_tag.push_back(tag);
      }
    }
  }

  // A corner of a cell or facet of a tetrahedral layer: direction d's column at level 0 or 1 (its
  // base or its top).
  struct Corner {
    int d = 0;
    int level = 0;
  };
  NodeId corner_node(const Corner& c) { return at(c.d, c.level * q_); }
  // True when two corners are one node (a stopped column's base and top): no volume or area.
  bool collapsed(const Corner* c, int n) {
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b)
        if (corner_node(c[a]) == corner_node(c[b])) return true;
    return false;
  }

  // The node of a tetrahedral layer with stopped columns (layer_core.h, step 3) at the point of
  // lattice weights w (summing to Q) over the n corners of a cell or facet, the point being over
  // the base node of direction d (in the prism's lattice). On the old front (every
  // corner with weight a base, or a stopped column's top, which is its base): that column's base;
  // on the new front (every such corner a top, or a stopped column's base): the new front's node
  // d; elsewhere the base's node under the point raised by the corners' weighted column heights,
  // x_base(d) + sum_k (w_k / Q) (corner_k - its base), one node per corner set and weights, so
  // every cell and facet sharing a point agrees, plus the point's level times the pull at d
  // (off_lift_: a closing layer's straightening, or the gentle attenuation of a layer with
  // stops, at most kStopAtten of the height). Without the pull the tops of such a layer are
  // the vertex tops' lift plus the base's own offset, so the new front's node d is that same
  // point, and a cell is the base's curved triangle carried up by heights affine
  // over the cell, x = B(xi) + G(lambda) (G affine and 0 on the base), exactly of order Q:
  // det J is about det[B_xi1, B_xi2, G_zeta], G_zeta one corner's column, wherever the heights
  // are small against the cell's width, positive over a regular base with outward heights, a
  // stopped column's zero height included (its corner keeps the other two directions). The prism's own
  // lattice fails both ways: it collapses at a stopped column (a zero Jacobian at its base), and
  // a tetrahedron cut from it carries the column heights' variation over the face (shrinks,
  // attenuation) at one degree above Q, which the order-Q cell cannot hold: at Q3, cut cells of
  // valid prisms had det J = 0 on their thin edge (two spheres 0.05 apart), and on the published
  // bullet (h0 1e-5 L) one stop at layer 7 turned into invalid cells over the whole layer, 0.8 %
  // coverage. (An earlier rule put the points touching a stop on the corners' straight simplex,
  // which lays a Q3 facet's centre on the chord of a base that bows by more than the layer.)
  NodeId layer_node(const Corner* corners, const int* w, int n, int d) {
    bool bottom = true, top = true;
    for (int k = 0; k < n; ++k) {
      if (w[k] == 0) continue;
      const bool st = stopped_dir(static_cast<std::size_t>(corners[k].d));
      bottom = bottom && (corners[k].level == 0 || st);
      top = top && (corners[k].level == 1 || st);
    }
    if (bottom) return at(d, 0);
    if (top) return at(d, q_);
    LiftedKey key;
    key.fill(-1);
    for (int k = 0, m = 0; k < n; ++k)
      if (w[k] > 0) key[static_cast<std::size_t>(m++)] = static_cast<std::int64_t>(corner_node(corners[k])) * 64 + w[k];
    std::sort(key.begin(), key.end());
    const auto it = lifted_.find(key);
    if (it != lifted_.end()) return it->second;
    Vec x = x_[static_cast<std::size_t>(dirs_[static_cast<std::size_t>(d)].base)];
    double up = 0;  // the point's level in the layer, 0 to 1
    for (int k = 0; k < n; ++k) {
      const std::size_t dk = static_cast<std::size_t>(corners[k].d);
      x += (static_cast<double>(w[k]) / q_) *
           (mesh_.nodes[static_cast<std::size_t>(corner_node(corners[k]))] - x_[static_cast<std::size_t>(dirs_[dk].base)]);
      if (corners[k].level == 1 && !stopped_dir(dk)) up += static_cast<double>(w[k]) / q_;
    }
    x += up * off_lift_[static_cast<std::size_t>(d)];  // the pull: a closing layer's, or a layer with stops' gentle one
    mesh_.nodes.push_back(x);
    const NodeId id = static_cast<NodeId>(mesh_.nodes.size() - 1);
    lifted_.emplace(std::move(key), id);
    return id;
  }

  // The tetrahedra of the prism over triangle fl with column order r (prism_tets' cut) in a layer
  // with stopped columns: the cut's tetrahedra holding both ends of a collapsed column have no
  // volume and are left out, and the others' nodes follow layer_node.
  void transition_tets(const int* fl, const std::array<int, 3>& r, std::vector<NodeId>& tets) {
    const LagrangeElement& tet = lagrange_element(CellType::Tetrahedron, q_);
    const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
    for (const auto& c : prism_cut(r)) {
      Corner corner[4];
      for (int k = 0; k < 4; ++k) corner[k] = {fl[c[static_cast<std::size_t>(k)][0]], c[static_cast<std::size_t>(k)][1]};
      if (collapsed(corner, 4)) continue;
      for (const Lattice& lat : tet.lattice()) {
        const int w[4] = {q_ - lat[0] - lat[1] - lat[2], lat[0], lat[1], lat[2]};
        Eigen::Vector3i pt = Eigen::Vector3i::Zero();
        for (int k = 0; k < 4; ++k) pt += w[k] * lat_of(c[static_cast<std::size_t>(k)]);
        pt /= q_;
        tets.push_back(layer_node(corner, w, 4, fl[te.find({pt[0], pt[1], 0})]));
      }
    }
  }

  // The column order (s, m, t) of a prism from its vertices' ranks (0-2 the bottom, 3-5 the top):
  // every quadrilateral face is cut along the diagonal through its vertex of smallest rank, the
  // rule of Dompierre et al. ("How to subdivide pyramids, prisms and hexahedra into tetrahedra",
  // 1999), which never closes a cycle on a prism; a cut from the bottom of column x to the top of
  // column y puts x before y. Cells sharing a quadrilateral cut it alike, whatever their kind.
  static std::array<int, 3> column_order(const std::array<long, 6>& rank) {
    int wins[3] = {0, 0, 0};
    for (int x = 0; x < 3; ++x)
      for (int y = x + 1; y < 3; ++y) {
        const long lo = std::min(std::min(rank[static_cast<std::size_t>(x)], rank[static_cast<std::size_t>(y)]),
                                 std::min(rank[static_cast<std::size_t>(x + 3)], rank[static_cast<std::size_t>(y + 3)]));
        const bool x_first = lo == rank[static_cast<std::size_t>(x)] || lo == rank[static_cast<std::size_t>(y + 3)];
        ++wins[x_first ? x : y];
      }
    std::array<int, 3> r{};
    for (int k = 0; k < 3; ++k) r[static_cast<std::size_t>(2 - wins[k])] = k;
    if (wins[r[0]] != 2 || wins[r[2]] != 0)  // only with ranks that are not distinct
      throw MesherError("layers: a prism's diagonals close a cycle (its vertices' ranks are not distinct)");
    return r;
  }

  // A corner of a prism's cut: (vertex 0-2 of its triangle, level 0 or 1), and its point of the
  // prism's lattice.
  using PrismCorner = std::array<int, 2>;
  Eigen::Vector3i lat_of(const PrismCorner& vl) const {
    return Eigen::Vector3i(vl[0] == 1 ? q_ : 0, vl[0] == 2 ? q_ : 0, vl[1] * q_);
  }
  // The three tetrahedra of a prism with column order r, each positively oriented in the reference
  // prism (its Jacobian has the prism's sign): the diagonals run from the bottom of the earlier
  // column to the top of the later (acyclic, so they fill the prism).
  std::array<std::array<PrismCorner, 4>, 3> prism_cut(const std::array<int, 3>& r) const {
    const int s = r[0], m = r[1], t = r[2];
    std::array<std::array<PrismCorner, 4>, 3> cells = {{{{{s, 0}, {m, 0}, {t, 0}, {t, 1}}},
                                                        {{{s, 0}, {m, 0}, {m, 1}, {t, 1}}},
                                                        {{{s, 0}, {s, 1}, {m, 1}, {t, 1}}}}};
    for (auto& c : cells) {
      const Eigen::Vector3i a = lat_of(c[0]), b = lat_of(c[1]), cc = lat_of(c[2]), dd = lat_of(c[3]);
      const Eigen::Matrix3d m3 = (Eigen::Matrix3d() << (b - a).cast<double>(), (cc - a).cast<double>(), (dd - a).cast<double>()).finished();
      if (m3.determinant() < 0) std::swap(c[2], c[3]);
    }
    return cells;
  }

  // The three tetrahedra of a prism with column order r (prism_cut): node(a, b, c) is its lattice
  // node (a, b on the triangle as in the prism's Gmsh lattice, c the level).
  template <class NodeAt>
  void prism_tets(const NodeAt& node, const std::array<int, 3>& r, std::vector<NodeId>& tets) const {
    const LagrangeElement& tet = lagrange_element(CellType::Tetrahedron, q_);
    for (const auto& c : prism_cut(r)) {
      for (const Lattice& lat : tet.lattice()) {
        const int w[4] = {q_ - lat[0] - lat[1] - lat[2], lat[0], lat[1], lat[2]};
        Eigen::Vector3i pt = Eigen::Vector3i::Zero();
        for (int k = 0; k < 4; ++k) pt += w[k] * lat_of(c[static_cast<std::size_t>(k)]);
        pt /= q_;
        tets.push_back(node(pt[0], pt[1], pt[2]));
      }
    }
  }

  // The three tetrahedra of the prism over triangle fl (its directions) with column order r.
  void split_tets(const int* fl, const std::array<int, 3>& r, std::vector<NodeId>& tets) {
    const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
    prism_tets([&](int a, int b, int c) { return at(fl[te.find({a, b, 0})], c); }, r, tets);
  }

  // Ranks of the first layer's prism vertices (column_order): an old node by its local id (after
  // base_rank's levels), the top of direction d after every old node.
  // Nodes nearer a fade rank first (the fade, then a fade zone's nodes by their distance, then
  // every other), so that every quadrilateral beside a sector closed at one end is cut along the
  // diagonal from its closed end (fade_cells' two tetrahedra).
  static_assert(sizeof(long) >= 8, "base_rank and top_rank need 64-bit ranks");
  long base_rank(int l) const {
    const auto it = zone_level_.find(l);
    const long level = it == zone_level_.end() ? (1L << 20) : it->second;
    return level * static_cast<long>(part_.size()) + l;
  }
  long top_rank(int d) const { return ((1L << 20) + 1) * static_cast<long>(part_.size()) + d; }

  // The cells of sector s of fan edge fe closed at its end cf (at a fade, or a fade zone's outer
  // sector where the kites fall by one), where its prism (lattice node(a, b, c): c along the
  // edge, a toward the sector's left arc direction d1, b toward its right one d0) has its
  // section collapsed to one column (V's): two tetrahedra, (closed node, other node, A, B) and
  // (closed node, its top V, A, B), A and B the sector's tops at the other node. The closed end
  // ranks first (base_rank), so both quadrilaterals the sector shares with its neighbours are
  // cut along the diagonal from the closed node to A or B, which these two
  // tetrahedra meet; Dompierre's cut of the prism would put the third tetrahedron, of no volume
  // when straight, on the collapsed column as a curved lens. In the second a point of weights
  // (u_v, u_V, u_A, u_B) lies at c from its weights, and divides the sector across as the
  // tetrahedron's faces from V do: a = u_A + u_V u_A / (u_A + u_B), b likewise, so its faces on
  // the sector's sides are theirs and its face on the outer front is the new front's triangle
  // (fans(), collapsed_dir). The first is ordered by the exact orientation of its corners, the
  // second opposite to it (below).
  template <class Node>
  void fade_cells(const FanEdge& fe, int s, int cf, const Node& node) {
    const LagrangeElement& tet = lagrange_element(CellType::Tetrahedron, q_);
    const int cn = q_ - cf;  // the closed end and the other, in c
    const int d_fade = arcs_[static_cast<std::size_t>(fe.arcs[static_cast<std::size_t>(cf)])][static_cast<std::size_t>(s * q_)];
    // Corners: 0 the fade node, 1 the other node (first cell) or V (second), 2 A (a = Q), 3 B (b = Q).
    auto x = [&](int a, int b, int c) -> const Vec& { return mesh_.nodes[static_cast<std::size_t>(node(a, b, c))]; };
    const bool first_positive = positive_tet(x(0, 0, cf), x(0, 0, cn), x(q_, 0, cn), x(0, q_, cn));
    for (int cell = 0; cell < 2; ++cell) {
      auto point = [&](const std::array<int, 4>& u) -> NodeId {
        if (cell == 0) return node(u[2], u[3], (u[0] * cf + (q_ - u[0]) * cn) / q_);
        const int c = ((u[0] + u[1]) * cf + (u[2] + u[3]) * cn) / q_;
        const int ab = u[2] + u[3];
        if (ab == 0) return at(d_fade, u[1]);
        const int an = u[2] * (ab + u[1]), bn = u[3] * (ab + u[1]);  // a = an / ab, b = bn / ab
        if (u[0] == 0) return at(collapsed_dir(fe, s, c, an, ab), q_);  // on the new front
        if (an % ab == 0) return node(an / ab, bn / ab, c);
        return sector_point(fe, s, c, an, bn, ab);
      };
      // In the prism's reference the two have opposite orientations for one order of A and B:
      // the first is ordered by the exact orientation of its corners and the second the other
      // way, so that a fold (the fade node's top leaning past the other node) shows as an
      // inverted cell, not as two positive ones overlapping.
      std::array<int, 4> perm = {0, 1, 2, 3};
      if (first_positive == (cell == 1)) std::swap(perm[2], perm[3]);
      for (const Lattice& lat : tet.lattice()) {
        const int w[4] = {q_ - lat[0] - lat[1] - lat[2], lat[0], lat[1], lat[2]};
        std::array<int, 4> u{};
        for (int k = 0; k < 4; ++k) u[static_cast<std::size_t>(perm[static_cast<std::size_t>(k)])] = w[k];
        out_.built.cells[1].push_back(point(u));
      }
      out_.cell_face[1].push_back(fe.left);
    }
  }

  // A point inside sector s of a fade's fan edge fe, at node c along the edge, off the lattice
  // (a = an / den, b = bn / den; Q >= 4): the straight section's point x + (a / Q)(top_d1 - x) +
  // (b / Q)(top_d0 - x), as fan_point's, one per point.
  NodeId sector_point(const FanEdge& fe, int s, int c, int an, int bn, int den) {
    const int g = std::gcd(std::gcd(an, bn), den);
    an /= g, bn /= g, den /= g;
    const int arc = fe.arcs[static_cast<std::size_t>(c)];
    const auto key = std::make_tuple(arc, s, an, bn, den);
    const auto it = sector_points_.find(key);
    if (it != sector_points_.end()) return it->second;
    const std::vector<int>& a = arcs_[static_cast<std::size_t>(arc)];
    const std::size_t d0 = static_cast<std::size_t>(a[static_cast<std::size_t>(s * q_)]);
    const std::size_t d1 = static_cast<std::size_t>(a[static_cast<std::size_t>((s + 1) * q_)]);
    const Vec& x = x_[static_cast<std::size_t>(dirs_[d0].base)];
    const double sa = static_cast<double>(an) / (static_cast<double>(den) * q_), sb = static_cast<double>(bn) / (static_cast<double>(den) * q_);
    mesh_.nodes.push_back(x + sa * (top_[d1] - x) + sb * (top_[d0] - x));
    const NodeId id = static_cast<NodeId>(mesh_.nodes.size() - 1);
    sector_points_.emplace(key, id);
    return id;
  }

  // The first layer's ridge fan cells (prisms of cross section the edge node and the ends of kite
  // edge s of the arc, s + 1's first, extruded along the chain, each cut into three tetrahedra)
  // and corner tetrahedra (corner node + patch triangle), and their symmetry triangles at chain
  // ends on a plane.
  void fan_cells() {
    const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
    const LagrangeElement& tet = lagrange_element(CellType::Tetrahedron, q_);
    for (const FanEdge& fe : fan_edges_)
      for (int s = 0; s < 2 * fe.k; ++s) {
        auto node = [&](int a, int b, int c) {
          const std::vector<int>& arc = arcs_[static_cast<std::size_t>(fe.arcs[static_cast<std::size_t>(c)])];
          const int d0 = arc[static_cast<std::size_t>(s * q_)], d1 = arc[static_cast<std::size_t>((s + 1) * q_)];
          if (a + b == q_) return at(arc[static_cast<std::size_t>(s * q_ + a)], q_);
          if (a == 0 && b == 0) return part_.ids[static_cast<std::size_t>(fe.nodes[static_cast<std::size_t>(c)])];
          if (b == 0) return at(d1, a);
          if (a == 0) return at(d0, b);
          return fan_point({{d0, b}, {d1, a}});
        };
        const bool c0 = closed_at(fe, s, 0), c1 = closed_at(fe, s, q_);
        if (c0 && c1) continue;
        if (c0 || c1) {
          fade_cells(fe, s, c0 ? 0 : q_, node);
        } else {
          const std::vector<int>& arc0 = arcs_[static_cast<std::size_t>(fe.arcs.front())];
          const std::vector<int>& arc1 = arcs_[static_cast<std::size_t>(fe.arcs.back())];
          const std::size_t a_at = static_cast<std::size_t>((s + 1) * q_), b_at = static_cast<std::size_t>(s * q_);
          const std::array<long, 6> rank = {base_rank(fe.nodes.front()), top_rank(arc0[a_at]), top_rank(arc0[b_at]),
                                            base_rank(fe.nodes.back()),  top_rank(arc1[a_at]), top_rank(arc1[b_at])};
          prism_tets(node, column_order(rank), out_.built.cells[1]);
          for (int k = 0; k < 3; ++k) out_.cell_face[1].push_back(fe.left);
        }
        // The section on a symmetry plane at an open end (a closed end is a fade zone's node,
        // never on a plane): a sector closed at its other end has the same face there.
        for (int end = 0; end < 2; ++end) {
          if (fe.plane[end] < 0 || (end == 0 ? c0 : c1)) continue;
          for (const Lattice& lat : te.lattice())
            out_.sym_tris.push_back(end == 0 ? node(lat[0], lat[1], 0) : node(lat[1], lat[0], q_));
          out_.sym_tri_tag.push_back(planes_[static_cast<std::size_t>(fe.plane[end])].tag);
        }
      }
    const Part& nw = next();
    for (const auto& [v, f] : corner_tets_) {
      const int* fl = nw.face(static_cast<std::size_t>(f));
      for (const Lattice& lat : tet.lattice()) {
        const int w[4] = {q_ - lat[0] - lat[1] - lat[2], lat[0], lat[1], lat[2]};
        if (w[0] == q_) {
          out_.built.cells[1].push_back(part_.ids[static_cast<std::size_t>(v)]);
        } else if (w[0] == 0) {
          out_.built.cells[1].push_back(at(fl[te.find({w[2], w[3], 0})], q_));
        } else {
          std::vector<std::pair<int, int>> weights;
          for (int k = 1; k < 4; ++k)
            if (w[k] > 0) weights.push_back({fl[k - 1], w[k]});
          out_.built.cells[1].push_back(weights.size() == 1 ? at(weights[0].first, weights[0].second) : fan_point(weights));
        }
      }
      out_.cell_face[1].push_back(out_.face_origin[static_cast<std::size_t>(f)]);
    }
  }


  HybridMesh<3>& mesh_;
  const MetricField<3>& metric_;
  const LayerParams& p_;
  const int q_, np_;
  const CurvedFront<3>& front0_;
  const Part& part_;
  const std::vector<Plane>& planes_;
  const bool first_;
  const std::vector<double>& scale_;
  const std::vector<std::uint8_t>& stopped_;  // per stop point (Part::vertices): stopped locally
  const std::vector<std::uint8_t>& held_;     // per stop point: stopped before this layer (empty: none)
  const double f_atten_;
  std::vector<std::pair<std::string, std::size_t>>* counts_;
  HeightMemo& heights_;
  std::vector<Vec> x_, top_;
  std::vector<double> h_, dh_;
  std::vector<NodeNormal> nn_;
  std::vector<std::pair<std::size_t, std::string>> cusp_;  // nodes with no merged normal, and why
  std::size_t cusps_ = 0;               // of them, those no fan takes
  std::vector<std::uint8_t> stop_;      // per node: stopped (stops())
  bool any_stop_ = false;
  std::set<int> corner_node_;
  std::set<int> zone_;  // the fade zones' nodes (fans()): their columns keep their directions
  std::map<int, int> zone_level_;  // the fade zones' chain vertices: edges to the fade (0 at it)
  std::vector<int> ent_start_, ent_f_;  // per node: its sub-triangle normals, angles and faces
  std::vector<Vec> ent_n_;
  std::vector<double> ent_w_;
  std::vector<Dir> dirs_;
  bool fanned_ = false;
  std::vector<std::uint8_t> fan_node_;
  std::vector<std::vector<int>> arcs_;
  std::vector<FanEdge> fan_edges_;
  std::size_t fades_ = 0;
  std::size_t narrowed_ = 0;  // fan nodes whose opening a fade zone narrowed (fans())
  std::map<std::tuple<int, int, int, int>, int> collapsed_dirs_;  // (arc, sector, num, den) -> direction
  std::map<std::tuple<int, int, int, int, int>, NodeId> sector_points_;  // (arc, sector, a, b, den) -> node
  std::vector<std::pair<int, int>> corner_tets_;  // (corner node, new front triangle)
  std::size_t corner_fans_ = 0;
  std::map<std::vector<std::pair<int, int>>, NodeId> fan_points_;
  // layer_node's nodes inside the layer, by their corners' node ids and weights (id * 64 + w, w <=
  // Q < 64, sorted, -1 for no corner): every node of every cell of a layer with stops asks.
  using LiftedKey = std::array<std::int64_t, 4>;
  static_assert(max_order < 64, "LiftedKey packs a weight in 6 bits");
  struct LiftedHash {
    std::size_t operator()(const LiftedKey& k) const {
      std::size_t h = 0;
      for (std::int64_t v : k) h = h * 1000003u ^ std::hash<std::int64_t>()(v);
      return h;
    }
  };
  std::unordered_map<LiftedKey, NodeId, LiftedHash> lifted_;
  // Per direction: its top's offset from the lift of its face's vertex tops (the straightening's
  // pull toward the chord), which layer_node carries up a closing layer in proportion to the
  // point's level; 0 in every other layer with stops (straight tops).
  std::vector<Vec> off_lift_;
  std::vector<NodeId> col_;
  PartLayer out_;
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
    std::vector<std::size_t> hit = front_collisions(fronts, mesh_.nodes, q_, &unmoved);
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
