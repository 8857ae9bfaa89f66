// SPDX-License-Identifier: MIT
// The 3D front specifics of the layers (see grow_layers_3d.h for the steps and the paper's
// sections; the generic core is layer_core.cpp).
#include "layers/grow_layers_3d.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include <Eigen/Eigenvalues>

#include "layers/front_collisions_3d.h"
#include "layers/normals_3d.h"
#include "modules/base/error.h"
#include "modules/elements/lagrange.h"

namespace plaf::layers {

namespace {

using Vec = Eigen::Vector3d;

struct Plane {
  Vec point = Vec::Zero(), normal = Vec::UnitZ();
  int tag = -1;
};

// Direction d kept in the planes ids (one or two; -1 entries skipped): its component along their
// intersection (zero when it has none).
Vec in_planes(const Vec& d, const std::array<int, 2>& ids, const std::vector<Plane>& planes) {
  if (ids[0] < 0) return d;
  const Vec& a = planes[static_cast<std::size_t>(ids[0])].normal;
  const Vec cross = a.cross(planes[static_cast<std::size_t>(ids[1])].normal);
  // Two (nearly) parallel planes through one node are one plane (two tags on it).
  if (ids[1] < 0 || cross.norm() < 1e-9) return d - d.dot(a) * a;
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

// One connected set of wall triangles with a fixed local numbering of its nodes (step 1).
struct Part {
  std::string name;
  std::vector<int> tri;                 // np local node ids per triangle, Gmsh order
  std::vector<int> tri_tag;             // per triangle: index into the front's tags
  std::vector<NodeId> ids;              // current mesh node id of each local node
  std::vector<std::uint8_t> is_vertex;  // a vertex of some triangle (else high-order)
  // The attenuation target of node l: sum_k w[l][k] * top of local vertex v[l][k].
  std::vector<std::array<int, 3>> tv;
  std::vector<std::array<double, 3>> tw;
  std::vector<std::array<int, 2>> plane;             // per node: the planes it lies on (-1: none)
  std::vector<int> node_tri_start, node_tri;         // CSR: the triangles around each node
  std::vector<std::array<int, 3>> rim;               // per rim edge: triangle, local edge, plane
  std::vector<int> vertices;                          // local ids of vertex nodes
  std::size_t size() const { return ids.size(); }
};

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
    const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
    std::unordered_map<NodeId, int> local;
    p.name = f_.tags[static_cast<std::size_t>(f_.triangle_tag[static_cast<std::size_t>(tris[0])])].name;
    for (int t : tris) {
      const NodeId* n = f_.triangle(static_cast<std::size_t>(t));
      for (int k = 0; k < np_; ++k) p.tri.push_back(local.emplace(n[k], static_cast<int>(local.size())).first->second);
      p.tri_tag.push_back(f_.triangle_tag[static_cast<std::size_t>(t)]);
    }
    p.ids.assign(local.size(), -1);
    p.is_vertex.assign(local.size(), 0);
    p.tv.assign(local.size(), {0, 0, 0});
    p.tw.assign(local.size(), {0, 0, 0});
    for (const auto& [id, l] : local) p.ids[static_cast<std::size_t>(l)] = id;
    const std::size_t nt = tris.size();
    for (std::size_t t = 0; t < nt; ++t) {
      const int* tl = p.tri.data() + t * static_cast<std::size_t>(np_);
      for (int k = 0; k < np_; ++k) {
        const Lattice& lat = te.lattice()[static_cast<std::size_t>(k)];
        const double u = static_cast<double>(lat[0]) / q_, v = static_cast<double>(lat[1]) / q_;
        const std::size_t l = static_cast<std::size_t>(tl[k]);
        p.tv[l] = {tl[0], tl[1], tl[2]};
        p.tw[l] = {1 - u - v, u, v};
        if (k < 3) p.is_vertex[l] = 1;
      }
    }
    for (std::size_t l = 0; l < p.size(); ++l)
      if (p.is_vertex[l]) p.vertices.push_back(static_cast<int>(l));
    // Triangles around each node (CSR).
    p.node_tri_start.assign(p.size() + 1, 0);
    for (int l : p.tri) ++p.node_tri_start[static_cast<std::size_t>(l) + 1];
    for (std::size_t l = 0; l < p.size(); ++l) p.node_tri_start[l + 1] += p.node_tri_start[l];
    p.node_tri.resize(p.tri.size());
    std::vector<int> fill(p.node_tri_start.begin(), p.node_tri_start.end() - 1);
    for (std::size_t t = 0; t < nt; ++t)
      for (int k = 0; k < np_; ++k) {
        const std::size_t l = static_cast<std::size_t>(p.tri[t * static_cast<std::size_t>(np_) + static_cast<std::size_t>(k)]);
        p.node_tri[static_cast<std::size_t>(fill[l]++)] = static_cast<int>(t);
      }
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
      double off = 0;
      for (int l : nodes) off = std::max(off, std::abs((at(l) - c).dot(pl.normal)));
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

// The pending build of one part: its new top ids, the columns, and the rim quadrilaterals.
struct PartLayer {
  BuiltLayer built;
  std::vector<NodeId> top;         // per local node: its new node
  std::vector<NodeId> rim_quads;   // (Q+1)^2 ids per quadrilateral, Gmsh order
  std::vector<int> rim_quad_tag;
};

// Builds one layer on one part (steps 2-4).
class PartLayerBuilder {
 public:
  PartLayerBuilder(HybridMesh<3>& mesh, const MetricField<3>& metric, const LayerParams& p, int q,
                   const CurvedFront<3>& front0, const Part& part, const std::vector<Plane>& planes, bool first_layer,
                   const std::vector<double>& scale, double f_atten, std::vector<std::pair<std::string, std::size_t>>* counts)
      : mesh_(mesh), metric_(metric), p_(p), q_(q), np_(num_nodes(CellType::Triangle, q)), front0_(front0),
        part_(part), planes_(planes), first_(first_layer), scale_(scale), f_atten_(f_atten), counts_(counts) {}

  PartLayer build() {
    const std::size_t n = part_.size();
    x_.resize(n);
    for (std::size_t l = 0; l < n; ++l) x_[l] = mesh_.nodes[static_cast<std::size_t>(part_.ids[l])];
    normals();
    tops();
    columns_and_cells();
    return std::move(out_);
  }

 private:
  const int* tri(std::size_t t) const { return part_.tri.data() + t * static_cast<std::size_t>(np_); }
  std::size_t num_tris() const { return part_.tri_tag.size(); }

  // 2. Normals: per node, the sub-triangle normals around it with their angles there.
  void normals() {
    const std::size_t n = part_.size();
    const std::vector<std::array<int, 3>> subs = sub_triangles(q_);
    std::vector<int> start(n + 1, 0);
    for (std::size_t t = 0; t < num_tris(); ++t)
      for (const auto& s : subs)
        for (int k : s) ++start[static_cast<std::size_t>(tri(t)[k]) + 1];
    for (std::size_t l = 0; l < n; ++l) start[l + 1] += start[l];
    std::vector<Vec> face(static_cast<std::size_t>(start[n]));
    std::vector<double> weight(face.size());
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (std::size_t t = 0; t < num_tris(); ++t)
      for (const auto& s : subs) {
        const int* tl = tri(t);
        const Vec a = x_[static_cast<std::size_t>(tl[s[0]])], b = x_[static_cast<std::size_t>(tl[s[1]])],
                  c = x_[static_cast<std::size_t>(tl[s[2]])];
        const Vec nn = (b - a).cross(c - a);
        if (!(nn.norm() > 0)) {
          throw MesherError("layers: a degenerate front triangle in surface " + part_.name + " at " +
                            std::to_string(a.x()) + ", " + std::to_string(a.y()) + ", " + std::to_string(a.z()));
        }
        const Vec un = nn.normalized();
        const Vec pts[3] = {a, b, c};
        for (int k = 0; k < 3; ++k) {
          const Vec e1 = pts[(k + 1) % 3] - pts[k], e2 = pts[(k + 2) % 3] - pts[k];
          const std::size_t l = static_cast<std::size_t>(tl[s[static_cast<std::size_t>(k)]]);
          face[static_cast<std::size_t>(fill[l])] = un;
          weight[static_cast<std::size_t>(fill[l]++)] = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
        }
      }
    nn_.assign(n, NodeNormal{});
    concave_.assign(n, 0);
    const double corner_rad = p_.corner_angle_deg * M_PI / 180;
    std::vector<Vec> f, to_nb;
    std::vector<double> w;
    std::size_t classes[6] = {0, 0, 0, 0, 0, 0}, sym = 0;
    for (std::size_t l = 0; l < n; ++l) {
      f.assign(face.begin() + start[l], face.begin() + start[l + 1]);
      w.assign(weight.begin() + start[l], weight.begin() + start[l + 1]);
      to_nb.clear();
      for (int k = part_.node_tri_start[l]; k < part_.node_tri_start[l + 1]; ++k) {
        const int* tl = tri(static_cast<std::size_t>(part_.node_tri[static_cast<std::size_t>(k)]));
        for (int v = 0; v < 3; ++v)
          if (static_cast<std::size_t>(tl[v]) != l) to_nb.push_back(x_[static_cast<std::size_t>(tl[v])] - x_[l]);
      }
      NodeNormal r;
      try {
        r = node_normal(f, w, to_nb, corner_rad);
      } catch (const MesherError& e) {
        // Name the node: a cusp is a defect of the surface there (a fold, a notch).
        throw MesherError(std::string(e.what()) + " at " + std::to_string(x_[l].x()) + ", " +
                          std::to_string(x_[l].y()) + ", " + std::to_string(x_[l].z()) + " on surface " + part_.name +
                          "; check the surface mesh there (surface.* in the report)");
      }
      // The first layer starts from the reference normal where the surface is smooth (Sec. II.B).
      const std::size_t id = static_cast<std::size_t>(part_.ids[l]);
      if (first_ && r.kind == NodeClass::Smooth && id < front0_.normals.size()) r.n = front0_.normals[id];
      if (part_.plane[l][0] >= 0) {
        const Vec inplane = in_planes(r.n, part_.plane[l], planes_);
        if (!(inplane.norm() > 1e-3))
          throw MesherError("layers: surface " + part_.name + " meets its symmetry plane tangentially at " +
                            std::to_string(x_[l].x()) + ", " + std::to_string(x_[l].y()) + ", " + std::to_string(x_[l].z()));
        r.n = inplane.normalized();
        ++sym;
      }
      if (part_.is_vertex[l]) ++classes[static_cast<int>(r.kind)];
      concave_[l] = is_concave(r.kind) ? 1 : 0;
      nn_[l] = r;
    }
    // Next to a convex ridge or corner (merged normals, no fan yet) the high-order nodes move along
    // the blend of their triangle's vertex normals: the faces' own normals there differ from the
    // merged vertex normal by up to half the dihedral angle, and the attenuation (f_atten h per
    // layer) could never catch up with the bend that would grow each layer.
    std::vector<std::uint8_t> blend(n, 0);
    for (std::size_t t = 0; t < num_tris(); ++t) {
      const int* tl = tri(t);
      bool convex = false;
      for (int v = 0; v < 3; ++v) {
        const NodeClass k = nn_[static_cast<std::size_t>(tl[v])].kind;
        convex = convex || (k != NodeClass::Smooth && !is_concave(k));
      }
      if (convex)
        for (int k = 3; k < np_; ++k) blend[static_cast<std::size_t>(tl[k])] = 1;
    }
    for (std::size_t l = 0; l < n; ++l) {
      if (!blend[l] || nn_[l].kind != NodeClass::Smooth) continue;
      Vec m = Vec::Zero();
      for (int k = 0; k < 3; ++k)
        m += part_.tw[l][static_cast<std::size_t>(k)] * nn_[static_cast<std::size_t>(part_.tv[l][static_cast<std::size_t>(k)])].n;
      m = in_planes(m, part_.plane[l], planes_);
      if (m.norm() > 1e-6) nn_[l].n = m.normalized();
    }
    if (counts_ != nullptr) {
      counts_->clear();
      for (int k = 0; k < 6; ++k)
        counts_->push_back({std::string("nodes.") + node_class_name(static_cast<NodeClass>(k)), classes[k]});
      counts_->push_back({"nodes.symmetry", sym});
      counts_->push_back({"merges", classes[static_cast<int>(NodeClass::ConcaveRidge)] +
                                        classes[static_cast<int>(NodeClass::ConcaveCorner)]});
    }
  }

  // 3-4. Heights, tops (on the symmetry planes), attenuation of the high-order tops.
  void tops() {
    const std::size_t n = part_.size();
    top_.resize(n);
    h_.resize(n);
    // The metric's height at the vertices; a high-order node takes the interpolation of its
    // triangle's vertex heights (the attenuation's recipe). Its own metric height would feed back:
    // a node the attenuation pulled toward the chord lies nearer the wall, gets a smaller height
    // from a wall law, and falls further behind every layer (measured on a sphere: the front's
    // sag grew from 0.005 to 0.012 in 30 layers instead of vanishing).
    for (std::size_t l = 0; l < n; ++l)
      if (part_.is_vertex[l]) h_[l] = layer_height<3>(metric_, x_[l], nn_[l].n, p_.integrate_height) * scale_[l];
    for (std::size_t l = 0; l < n; ++l)
      if (!part_.is_vertex[l]) {
        double h = 0;
        for (int k = 0; k < 3; ++k)
          h += part_.tw[l][static_cast<std::size_t>(k)] * h_[static_cast<std::size_t>(part_.tv[l][static_cast<std::size_t>(k)])];
        h_[l] = h;
      }
    for (std::size_t l = 0; l < n; ++l) {
      const NodeNormal& r = nn_[l];
      h_[l] *= r.stretch;
      top_[l] = x_[l] + h_[l] * r.n;
      top_[l] = onto_planes(top_[l], part_.plane[l], planes_);
    }
    // Straight tops: on a straight base (the node at its linear position) and on every triangle
    // touching a concave node.
    std::vector<std::uint8_t> straight(n, 0);
    for (std::size_t t = 0; t < num_tris(); ++t) {
      const int* tl = tri(t);
      if (concave_[static_cast<std::size_t>(tl[0])] || concave_[static_cast<std::size_t>(tl[1])] ||
          concave_[static_cast<std::size_t>(tl[2])])
        for (int k = 3; k < np_; ++k) straight[static_cast<std::size_t>(tl[k])] = 1;
    }
    double clipped_max = 0;
    for (std::size_t l = 0; l < n; ++l) {
      if (part_.is_vertex[l]) continue;
      const auto& v = part_.tv[l];
      const auto& w = part_.tw[l];
      Vec target = Vec::Zero(), linear = Vec::Zero();
      double size = 0;
      for (int k = 0; k < 3; ++k) {
        target += w[static_cast<std::size_t>(k)] * top_[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])];
        linear += w[static_cast<std::size_t>(k)] * x_[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])];
        size = std::max(size, (x_[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])] - x_[l]).norm());
      }
      if (straight[l] || (x_[l] - linear).norm() <= 1e-12 * size) {
        top_[l] = target;
        continue;
      }
      clipped_max = std::max(clipped_max, attenuate<3>(&top_[l], &target, &h_[l], 1, f_atten_));
    }
    out_.built.max_clipped_rel = clipped_max;
    out_.built.linear = clipped_max == 0;
  }

  // Columns of Q nodes per front node, one prism per triangle, the rim quadrilaterals.
  void columns_and_cells() {
    const std::size_t n = part_.size();
    const std::size_t q = static_cast<std::size_t>(q_);
    col_.resize(n * q);
    out_.top.resize(n);
    for (std::size_t l = 0; l < n; ++l) {
      for (std::size_t k = 1; k <= q; ++k) {
        mesh_.nodes.push_back(x_[l] + (static_cast<double>(k) / q_) * (top_[l] - x_[l]));
        col_[l * q + k - 1] = static_cast<NodeId>(mesh_.nodes.size() - 1);
      }
      out_.top[l] = col_[l * q + q - 1];
    }
    auto at = [&](int l, int level) {
      return level == 0 ? part_.ids[static_cast<std::size_t>(l)] : col_[static_cast<std::size_t>(l) * q + static_cast<std::size_t>(level) - 1];
    };
    const LagrangeElement& te = lagrange_element(CellType::Triangle, q_);
    const LagrangeElement& pe = lagrange_element(CellType::Prism, q_);
    std::vector<int> tri_of_prism_node;
    for (const Lattice& lat : pe.lattice()) tri_of_prism_node.push_back(te.find({lat[0], lat[1], 0}));
    std::vector<NodeId>& cells = out_.built.cells[0];
    cells.reserve(num_tris() * static_cast<std::size_t>(pe.size()));
    for (std::size_t t = 0; t < num_tris(); ++t) {
      const int* tl = tri(t);
      for (int k = 0; k < pe.size(); ++k)
        cells.push_back(at(tl[tri_of_prism_node[static_cast<std::size_t>(k)]], pe.lattice()[static_cast<std::size_t>(k)][2]));
    }
    // Rim quadrilaterals: u runs from the edge's second vertex to its first, v up the layer, so
    // their normal points into the prisms (into the domain, as the wall's).
    const LagrangeElement& qe = lagrange_element(CellType::Quadrilateral, q_);
    for (const auto& re : part_.rim) {
      const int* tl = tri(static_cast<std::size_t>(re[0]));
      const std::vector<int>& en = te.edge_nodes(re[1]);
      for (const Lattice& lat : qe.lattice())
        out_.rim_quads.push_back(at(tl[en[static_cast<std::size_t>(q_ - lat[0])]], lat[1]));
      out_.rim_quad_tag.push_back(planes_[static_cast<std::size_t>(re[2])].tag);
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
  const double f_atten_;
  std::vector<std::pair<std::string, std::size_t>>* counts_;
  std::vector<Vec> x_, top_;
  std::vector<double> h_;
  std::vector<NodeNormal> nn_;
  std::vector<std::uint8_t> concave_;
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
  BuiltLayer build(std::size_t part, int layer, const std::vector<double>& scale, const std::vector<std::uint8_t>&,
                   double f_atten) override {
    pending_part_ = part;
    pending_ = PartLayerBuilder(mesh_, metric_, p_, q_, front0_, parts_[part], planes_, layer == 1, scale, f_atten,
                                layer == 1 && part == 0 ? &counts_ : nullptr)
                   .build();
    return std::move(pending_.built);
  }
  std::vector<std::size_t> collisions(std::size_t part) const override {
    std::vector<FrontSurface> fronts;
    fronts.push_back({&parts_[part].tri, &pending_.top});
    for (std::size_t other = 0; other < parts_.size(); ++other)
      if (other != part) fronts.push_back({&parts_[other].tri, &parts_[other].ids});
    return front_collisions(fronts, mesh_.nodes, q_);
  }
  Vec front_point(std::size_t e) const override {
    const Part& p = parts_[pending_part_];
    return mesh_.nodes[static_cast<std::size_t>(pending_.top[static_cast<std::size_t>(p.tri[e * static_cast<std::size_t>(num_nodes(CellType::Triangle, q_))])])];
  }
  // Heights halve on the nodes of the failing triangles and of every triangle around them.
  void shrink(std::size_t part, const std::vector<LayerFailure>& failures, std::vector<double>& scale) const override {
    const Part& p = parts_[part];
    const std::size_t np = static_cast<std::size_t>(num_nodes(CellType::Triangle, q_));
    std::vector<std::uint8_t> halve(p.size(), 0);
    for (const LayerFailure& f : failures) {
      const int* tl = p.tri.data() + f.index * np;
      for (int v = 0; v < 3; ++v)
        for (int k = p.node_tri_start[static_cast<std::size_t>(tl[v])]; k < p.node_tri_start[static_cast<std::size_t>(tl[v]) + 1]; ++k)
          for (std::size_t j = 0; j < np; ++j)
            halve[static_cast<std::size_t>(p.tri[static_cast<std::size_t>(p.node_tri[static_cast<std::size_t>(k)]) * np + j])] = 1;
    }
    for (std::size_t l = 0; l < p.size(); ++l)
      if (halve[l]) scale[l] *= 0.5;
  }
  void accept(std::size_t part) override {
    parts_[part].ids = std::move(pending_.top);
    rim_quads_.insert(rim_quads_.end(), pending_.rim_quads.begin(), pending_.rim_quads.end());
    rim_quad_tag_.insert(rim_quad_tag_.end(), pending_.rim_quad_tag.begin(), pending_.rim_quad_tag.end());
  }

  const std::vector<Part>& parts() const { return parts_; }
  const std::vector<NodeId>& rim_quads() const { return rim_quads_; }
  const std::vector<int>& rim_quad_tag() const { return rim_quad_tag_; }

 private:
  HybridMesh<3>& mesh_;
  const CurvedFront<3>& front0_;
  const MetricField<3>& metric_;
  const LayerParams& p_;
  const int q_;
  std::vector<std::pair<std::string, std::size_t>>& counts_;
  std::vector<Plane> planes_;
  std::vector<Part> parts_;
  std::size_t pending_part_ = 0;
  PartLayer pending_;
  std::vector<NodeId> rim_quads_;
  std::vector<int> rim_quad_tag_;
};

}  // namespace

LayerResult<3> grow_layers(const CurvedFront<3>& front, const MetricField<3>& metric, const LayerParams& p) {
  check_order(front.order);
  if (p.isotropic_stop == IsotropicStop::Node)
    throw ConfigError("layers.isotropic_stop: node is not available in 3D (use any, all or off)");
  const int q = front.order;
  const std::size_t np = static_cast<std::size_t>(num_nodes(CellType::Triangle, q));
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
  // Symmetry quadrilaterals of every accepted layer.
  const std::size_t nq = static_cast<std::size_t>(num_nodes(CellType::Quadrilateral, q));
  for (std::size_t k = 0; k < fronts.rim_quad_tag().size(); ++k) {
    CellBlock& b = r.mesh.boundary_block(CellType::Quadrilateral, q, fronts.rim_quad_tag()[k]);
    b.connectivity.insert(b.connectivity.end(), fronts.rim_quads().begin() + static_cast<std::ptrdiff_t>(k * nq),
                          fronts.rim_quads().begin() + static_cast<std::ptrdiff_t>((k + 1) * nq));
  }
  // The outer front (the wall's tags) and the fill's boundary.
  r.outer.order = q;
  r.outer.nodes = r.mesh.nodes;
  r.outer.tags = front.tags;
  r.fill_front.nodes = r.mesh.nodes;
  const int outer_tag = static_cast<int>(r.fill_front.tags.size());
  r.fill_front.tags.push_back({"layers_outer", BoundaryKind::Named});
  for (const Part& part : fronts.parts()) {
    for (std::size_t t = 0; t < part.tri_tag.size(); ++t) {
      for (std::size_t k = 0; k < np; ++k)
        r.outer.triangles.push_back(part.ids[static_cast<std::size_t>(part.tri[t * np + k])]);
      r.outer.triangle_tag.push_back(part.tri_tag[t]);
      const int* tl = part.tri.data() + t * np;
      r.fill_front.triangles.push_back({part.ids[static_cast<std::size_t>(tl[0])], part.ids[static_cast<std::size_t>(tl[1])],
                                        part.ids[static_cast<std::size_t>(tl[2])]});
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
