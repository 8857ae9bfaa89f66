// SPDX-License-Identifier: MIT
// Internal to the 3D layers (grow_layers_3d.cpp and the files of PartLayerBuilder: layer3d_builder.cpp,
// ridge_fans_3d.cpp, layer_tops_3d.cpp, layer_cells_3d.cpp): the parts of the wall, the growth
// directions, and the build of one layer on one part (grow_layers_3d.h, steps 2-6). Not an interface
// (installed with the other headers; grow_layers_3d.h is the one to use).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <functional>
#include <memory>
#include <queue>
#include <set>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "layers/grow_layers_3d.h"
#include "layers/layer_core.h"
#include "layers/normals_3d.h"
#include "modules/elements/lagrange.h"
#include "modules/geometry/predicates.h"

namespace plaf::layers::grow3d {

using Vec = Eigen::Vector3d;

// A symmetry plane the wall's rim lies on; its normal points into the meshed half-space (the
// side of the part whose rim fitted it: PartBuilder::rim).
struct Plane {
  Vec point = Vec::Zero(), normal = Vec::UnitZ();
  int tag = -1;
};

// Direction d kept in the planes ids (one or two; -1 entries skipped): its component along their
// intersection (zero when it has none).
inline Vec in_planes(const Vec& d, const std::array<int, 2>& ids, const std::vector<Plane>& planes) {
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
inline Vec onto_planes(const Vec& x, const std::array<int, 2>& ids, const std::vector<Plane>& planes) {
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
inline std::array<QuadCorners, 2> quad_cut(int q, long r00, long rq0, long rqq, long r0q) {
  const long lo = std::min(std::min(r00, rq0), std::min(rqq, r0q));
  if (lo == r00 || lo == rqq) return {{{{{0, 0}, {q, 0}, {q, q}}}, {{{0, 0}, {q, q}, {0, q}}}}};
  return {{{{{0, 0}, {q, 0}, {0, q}}}, {{{q, 0}, {q, q}, {0, q}}}}};
}
// The quadrilateral lattice point of node `lat` of such a triangle.
inline std::array<int, 2> quad_point(const QuadCorners& h, const Lattice& lat, int q) {
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
void finish_part(Part& p, int q);

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

  PartLayer build();

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
  void stops();
  bool stopped_dir(std::size_t d) const { return any_stop_ && !fanned_ && stop_[static_cast<std::size_t>(dirs_[d].base)]; }

  // 2. Normals: per node, the sub-triangle normals around it with their angles there and faces.
  void normals();

  // Normal relaxation (layers.smooth_normals; Aubry and Loehner's smoothing of the marching
  // directions, issue 30's "relax the normals over the next layers"): after the first layer, two
  // Jacobi passes move each smooth node's normal halfway toward the mean of the normals of the
  // nodes of its faces, kept in its symmetry planes, and taken only where every face around the
  // node still sees it at least as well as cos 75 degrees or as before. Columns over a concave
  // bend or beside a fan turn with their neighbours instead of converging on them. Fan, ridge,
  // corner, cusp and stopped nodes keep their normals.
  void relax_normals();

  // The cusp nodes a fan does not take (a fan vertex other than a corner, a fan edge's high-order
  // node), for the first layer's counts: they grow along their most normal direction.
  void check_cusps();

  NodeNormal normal_at(std::size_t l, const std::vector<Vec>& f, const std::vector<double>& w,
                       const std::vector<Vec>& to_nb, double corner_rad) const;

  // A direction at node l kept in its symmetry planes.
  Vec in_plane(std::size_t l, const Vec& d) const;

  // The angle-weighted normal of the old face f at its node l (one side of a ridge).
  Vec side_normal(int f, int l) const;

  int add_dir(int base, const Vec& d, double stretch, bool concave, bool fan);
  // A fan direction by its top per unit height (its direction and stretch), and back.
  int add_unit_h(int base, const Vec& v) { return add_dir(base, v, v.norm(), false, true); }
  Vec unit_h(int d) const { return dirs_[static_cast<std::size_t>(d)].stretch * dirs_[static_cast<std::size_t>(d)].d; }

  // 6. Fans at convex ridges and corners, on the first layer (Aubry & Loehner's ridge and corner
  // fans; the prism/tetrahedron variant). A wall edge is a fan edge when its two faces
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
  void fans();

  // True when sector s of fan edge fe is closed at its node i (0 or Q): both its ends there are
  // one direction (a fade, or a fade zone's outer sector).
  bool closed_at(const FanEdge& fe, int s, int i) const;

  // The direction at node i (0..Q) of fan edge fe whose top divides sector s's kite edge at
  // j = num / den of Q (from the arc's right end): the arc's own direction where j is a lattice
  // point, else a new one on the straight kite edge between its two neighbours (a fade's
  // sector at Q >= 3), one per point.
  int collapsed_dir(const FanEdge& fe, int s, int i, int num, int den);

  static Vec slerp(const Vec& a, const Vec& b, double t);

  // Next to a convex ridge or corner with a merged normal (no fan) the smooth high-order nodes
  // move along the blend of their face's vertex normals: the faces' own normals there differ from
  // the merged vertex normal by up to half the dihedral angle, and the attenuation (f_atten h per
  // layer) could never catch up with the bend that would grow each layer. Every other high-order
  // node (but a fan's or a concave merge's) leans at most kMaxBend from that blend.
  void blend();

  void count();

  // 3-4. Heights, tops (on the symmetry planes), attenuation of the high-order tops.
  // Order 1: the new front's edges as chords of the surface the metric is measured from, as 2D
  // does (grow_layers_2d.cpp, chord_sag_need): an edge between directions theta apart sags about
  // |c| tan(theta / 4) / 2 off it, c the chord's part across the axis d_u x d_v (so a cylinder's
  // diagonal edge sags as its section's chord); an element counts as curved until every edge's
  // sag is at most f_atten times the smaller height at its ends. Edges to a fan's arc directions
  // are straight-sided fan cells' and are skipped, as are edges to a concave merge (its normal
  // turns by half the corner on flat faces). Returns the largest sag / h (0 when met).
  double chord_sag_need(const Part& nw) const;

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
  void slope_from_stops(const std::vector<std::uint8_t>& before);

  // Neighbouring columns' heights differ by at most kHeightJump: a vertex grows at most that
  // many times the height of any growing vertex it shares a face with. The shrinks halve the
  // heights on rings around failures, the rules around stops cut them again, and the metric's own
  // heights are smooth, so only those make jumps; unlimited, a ring shrunk to the floor (1/16)
  // stood beside full columns, and the cells across its edge, a hundred times taller on one
  // side, failed and stopped the ring's columns (the published spot, h0 1e-5 L, Q2: in layer 37
  // every tetrahedron that failed at the floor had columns of 2.9e-4 and 2.5e-2 or such). The
  // jump is the shrink's own factor.
  void limit_height_jumps();

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

  void tops();

  // Node `level` (0..Q) of direction d's column; the inner ones are made when a cell first asks
  // (an arc direction inside a sector of the first layer's fans has only its top).
  NodeId at(int d, int level);

  // A node of the first layer's fan cells off the columns: x + sum_k (w_k / Q) (top_k - x) (k
  // over directions of one base node x, sum w = level < Q), the fans' cells being straight-sided
  // (kites and flat corner patches); one node per weight set, shared by every cell that has it.
  NodeId fan_point(std::vector<std::pair<int, int>> weights);

  // 5-6. Columns of Q nodes per direction; per face of the new front grown from an old face a
  // prism, or three tetrahedra in a first layer with fans; the first layer's fan cells; the
  // symmetry facets.
  void columns_and_cells();

  // A corner of a cell or facet of a tetrahedral layer: direction d's column at level 0 or 1 (its
  // base or its top).
  struct Corner {
    int d = 0;
    int level = 0;
  };
  NodeId corner_node(const Corner& c) { return at(c.d, c.level * q_); }
  // True when two corners are one node (a stopped column's base and top): no volume or area.
  bool collapsed(const Corner* c, int n);

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
  NodeId layer_node(const Corner* corners, const int* w, int n, int d);

  // The tetrahedra of the prism over triangle fl with column order r (prism_tets' cut) in a layer
  // with stopped columns: the cut's tetrahedra holding both ends of a collapsed column have no
  // volume and are left out, and the others' nodes follow layer_node.
  void transition_tets(const int* fl, const std::array<int, 3>& r, std::vector<NodeId>& tets);

  // The column order (s, m, t) of a prism from its vertices' ranks (0-2 the bottom, 3-5 the top):
  // every quadrilateral face is cut along the diagonal through its vertex of smallest rank, the
  // rule of Dompierre et al. ("How to subdivide pyramids, prisms and hexahedra into tetrahedra",
  // 1999), which never closes a cycle on a prism; a cut from the bottom of column x to the top of
  // column y puts x before y. Cells sharing a quadrilateral cut it alike, whatever their kind.
  static std::array<int, 3> column_order(const std::array<long, 6>& rank);

  // A corner of a prism's cut: (vertex 0-2 of its triangle, level 0 or 1), and its point of the
  // prism's lattice.
  using PrismCorner = std::array<int, 2>;
  Eigen::Vector3i lat_of(const PrismCorner& vl) const;
  // The three tetrahedra of a prism with column order r, each positively oriented in the reference
  // prism (its Jacobian has the prism's sign): the diagonals run from the bottom of the earlier
  // column to the top of the later (acyclic, so they fill the prism).
  std::array<std::array<PrismCorner, 4>, 3> prism_cut(const std::array<int, 3>& r) const;

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
  void split_tets(const int* fl, const std::array<int, 3>& r, std::vector<NodeId>& tets);

  // Ranks of the first layer's prism vertices (column_order): an old node by its local id (after
  // base_rank's levels), the top of direction d after every old node.
  // Nodes nearer a fade rank first (the fade, then a fade zone's nodes by their distance, then
  // every other), so that every quadrilateral beside a sector closed at one end is cut along the
  // diagonal from its closed end (fade_cells' two tetrahedra).
  static_assert(sizeof(long) >= 8, "base_rank and top_rank need 64-bit ranks");
  long base_rank(int l) const;
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
  NodeId sector_point(const FanEdge& fe, int s, int c, int an, int bn, int den);

  // The first layer's ridge fan cells (prisms of cross section the edge node and the ends of kite
  // edge s of the arc, s + 1's first, extruded along the chain, each cut into three tetrahedra)
  // and corner tetrahedra (corner node + patch triangle), and their symmetry triangles at chain
  // ends on a plane.
  void fan_cells();


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

}  // namespace plaf::layers::grow3d
