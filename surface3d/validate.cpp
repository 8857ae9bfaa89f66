// SPDX-License-Identifier: MIT
// Validation of a triangle soup (the seven steps of validate.h). Everything up to the
// orientation fix works on the soup's index triples, because OpenMesh refuses non-manifold and
// inconsistently oriented faces; the half-edge surface is built only once the soup is known to be
// an oriented manifold. All steps are O(n log n): edges are found by sorting, fans and boundary
// loops by union-find, components by breadth-first search, and the nesting and self-intersection
// tests use the bounding-box tree.
//
// This file holds validate_surface, the combinatorial steps 0-5 and the assembly of the result;
// the geometric steps are in validate_volumes.cpp (6) and self_intersections.cpp (7).
#include "surface3d/validate.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/geometry/aabb_tree.h"
#include "modules/geometry/predicates.h"
#include "surface3d/slivers.h"
#include "surface3d/validate_steps.h"

namespace plaf {

using Eigen::Vector3d;
using namespace validate_detail;

namespace {

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int x) {
    while (parent_[idx(x)] != x) {
      parent_[idx(x)] = parent_[idx(parent_[idx(x)])];  // path halving
      x = parent_[idx(x)];
    }
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[idx(std::max(a, b))] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

// Edge-to-edge adjacency: neighbor[3 t + k] is 3 u + m when edge k of triangle t (from corner k
// to corner k + 1) is edge m of triangle u, -1 on a boundary. Returns the edges used more than
// twice (as the first use of each, 3 t + k).
std::vector<int> build_adjacency(const std::vector<Tri>& tris, std::vector<int>& neighbor) {
  struct Use {
    int a, b, slot;
  };
  std::vector<Use> uses;
  uses.reserve(3 * tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tris[t][idx(k)], b = tris[t][idx((k + 1) % 3)];
      uses.push_back({std::min(a, b), std::max(a, b), static_cast<int>(3 * t) + k});
    }
  std::sort(uses.begin(), uses.end(),
            [](const Use& x, const Use& y) { return std::tie(x.a, x.b, x.slot) < std::tie(y.a, y.b, y.slot); });
  neighbor.assign(uses.size(), -1);
  std::vector<int> non_manifold;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].a == uses[i].a && uses[j].b == uses[i].b) ++j;
    if (j - i == 2) {
      neighbor[idx(uses[i].slot)] = uses[i + 1].slot;
      neighbor[idx(uses[i + 1].slot)] = uses[i].slot;
    } else if (j - i > 2) {
      non_manifold.push_back(uses[i].slot);
    }
    i = j;
  }
  return non_manifold;
}

// Three distinct points are collinear iff all three coordinate projections are (exactly).
bool collinear(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (sign_orient2d({a[i], a[j]}, {b[i], b[j]}, {c[i], c[j]}) != 0) return false;
  }
  return true;
}

// Step 0: indices in range and finite points; returns the bounding box of the used points.
Eigen::AlignedBox3d check_readable(const TriangleSoup& soup) {
  const std::string& src = soup.source;
  const std::vector<Vector3d>& pts = soup.points;
  for (std::size_t t = 0; t < soup.triangles.size(); ++t)
    for (const int v : soup.triangles[t])
      if (v < 0 || idx(v) >= pts.size())
        throw InputError(src + ": triangle " + std::to_string(t) + " refers to point " + std::to_string(v) +
                         " but there are " + plural(pts.size(), "point"));
  Eigen::AlignedBox3d bbox;
  for (const auto& tri : soup.triangles)
    for (const int v : tri) {
      const Vector3d& x = pts[idx(v)];
      if (!x.allFinite())
        throw InputError(src + ": point " + std::to_string(v) + " has a non-finite coordinate " + fmt_point(x));
      bbox.extend(x);
    }
  if (soup.triangles.empty()) throw InputError(src + ": the surface has no triangles");
  return bbox;
}

// Step 1: triangles with a repeated vertex are dropped; zero area with three distinct vertices is
// an error. Returns the working soup of the rest.
Work drop_degenerate(const TriangleSoup& soup, SurfaceCheckReport& rep) {
  const std::string& src = soup.source;
  rep.repairs.insert(rep.repairs.end(), soup.repairs.begin(), soup.repairs.end());  // the reader's first
  const std::vector<Vector3d>& pts = soup.points;
  Work w;
  w.soup = &soup;
  std::size_t zero_area = 0;
  std::size_t first_zero = 0, first_repeated = 0;
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    const Tri& x = soup.triangles[t];
    if (x[0] == x[1] || x[1] == x[2] || x[2] == x[0]) {
      if (rep.dropped_degenerate++ == 0) first_repeated = t;
      continue;
    }
    if (collinear(pts[idx(x[0])], pts[idx(x[1])], pts[idx(x[2])])) {
      if (zero_area++ == 0) first_zero = t;
      continue;
    }
    w.tris.push_back(x);
    w.input_index.push_back(static_cast<int>(t));
  }
  if (zero_area > 0) {
    const Tri& x = soup.triangles[first_zero];
    throw InputError(src + ": " + plural(zero_area, "triangle") +
                     " with zero area (three distinct collinear points); first: triangle " +
                     std::to_string(first_zero) + " at " +
                     fmt_point((pts[idx(x[0])] + pts[idx(x[1])] + pts[idx(x[2])]) / 3));
  }
  if (rep.dropped_degenerate > 0)
    rep.repairs.push_back(src + ": dropped " + plural(rep.dropped_degenerate, "triangle") +
                          " with a repeated vertex (first: triangle " + std::to_string(first_repeated) + ")");
  return w;
}

// Step 2: duplicate triangles (the same three vertices, either orientation): sort by the sorted
// vertex triple, keep the first of each run.
void drop_duplicates(Work& w, SurfaceCheckReport& rep) {
  std::vector<std::pair<Tri, int>> keyed;
  keyed.reserve(w.tris.size());
  for (std::size_t i = 0; i < w.tris.size(); ++i) {
    Tri k = w.tris[i];
    std::sort(k.begin(), k.end());
    keyed.emplace_back(k, static_cast<int>(i));
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<char> keep(w.tris.size(), 1);
  int first_dup = -1, first_original = -1;
  std::size_t run = 0;  // the first (kept) entry of the current run of equal keys
  for (std::size_t i = 1; i < keyed.size(); ++i) {
    if (keyed[i].first != keyed[run].first) {
      run = i;
      continue;
    }
    keep[idx(keyed[i].second)] = 0;
    ++rep.dropped_duplicate;
    const int dup = w.input_index[idx(keyed[i].second)];
    if (first_dup < 0 || dup < first_dup) {
      first_dup = dup;
      first_original = w.input_index[idx(keyed[run].second)];
    }
  }
  if (rep.dropped_duplicate > 0) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < w.tris.size(); ++i)
      if (keep[i]) {
        w.tris[n] = w.tris[i];
        w.input_index[n++] = w.input_index[i];
      }
    w.tris.resize(n);
    w.input_index.resize(n);
    rep.repairs.push_back(w.source() + ": dropped " + plural(rep.dropped_duplicate, "duplicate triangle") +
                          " (first: triangle " + std::to_string(first_dup) + ", a copy of triangle " +
                          std::to_string(first_original) + ")");
  }
  if (w.tris.empty()) throw InputError(w.source() + ": no triangles left after dropping the degenerate ones");
}

// Step 3: non-manifold edges, then non-manifold vertices (more than one fan of triangles), are
// errors. Returns the edge adjacency (build_adjacency).
std::vector<int> check_manifold(const Work& w) {
  const std::size_t n_tris = w.tris.size();
  std::vector<int> neighbor;
  const std::vector<int> bad_edges = build_adjacency(w.tris, neighbor);
  if (!bad_edges.empty()) {
    const int slot = bad_edges.front();
    throw InputError(w.source() + ": " + plural(bad_edges.size(), "non-manifold edge") +
                     " (used by more than two triangles); first: edge " + fmt_point(w.p(w.slot_from(slot))) + " - " +
                     fmt_point(w.p(w.slot_to(slot))) + " of triangle " + std::to_string(w.input_index[idx(slot / 3)]));
  }
  // Corners 3 t + k; two triangles across an edge put their corners at both ends in one fan.
  UnionFind fans(3 * n_tris);
  for (std::size_t s = 0; s < neighbor.size(); ++s) {
    const int o = neighbor[s];
    if (o < static_cast<int>(s)) continue;  // boundary, or done from the other side
    const int t = static_cast<int>(s / 3), u = o / 3;
    const Tri& x = w.tris[idx(t)];
    const Tri& y = w.tris[idx(u)];
    for (const int v : {x[s % 3], x[(s + 1) % 3]}) {
      int kx = 0, ky = 0;
      while (x[idx(kx)] != v) ++kx;
      while (y[idx(ky)] != v) ++ky;
      fans.unite(3 * t + kx, 3 * u + ky);
    }
  }
  std::vector<int> fan_of(w.points().size(), -1);
  std::vector<char> counted(w.points().size(), 0);
  std::size_t bad_vertices = 0;
  int first_bad = -1;
  for (std::size_t c = 0; c < 3 * n_tris; ++c) {
    const int v = w.tris[c / 3][c % 3];
    const int root = fans.find(static_cast<int>(c));
    if (fan_of[idx(v)] < 0) {
      fan_of[idx(v)] = root;
    } else if (fan_of[idx(v)] != root && !counted[idx(v)]) {
      counted[idx(v)] = 1;
      if (bad_vertices++ == 0) first_bad = v;
    }
  }
  if (bad_vertices > 0)
    throw InputError(w.source() + ": " + plural(bad_vertices, "non-manifold vertex", "non-manifold vertices") +
                     " (triangles around it form more than one fan); first: point " + std::to_string(first_bad) +
                     " at " + fmt_point(w.p(first_bad)));
  return neighbor;
}

// Step 4: orientation, by breadth-first search over each component from its first triangle; a
// neighbour that runs the shared edge the same way must be flipped relative to its parent. A
// non-orientable component is an error. Flipped triangles get a fresh adjacency.
Components orient_components(Work& w, std::vector<int>& neighbor, SurfaceCheckReport& rep) {
  const std::size_t n_tris = w.tris.size();
  Components comps;
  comps.of.assign(n_tris, -1);
  std::vector<char> flip(n_tris, 0);
  std::vector<int> queue;
  for (std::size_t start = 0; start < n_tris; ++start) {
    if (comps.of[start] >= 0) continue;
    const int c = static_cast<int>(comps.tris.size());
    comps.tris.emplace_back();
    comps.of[start] = c;
    queue.assign(1, static_cast<int>(start));
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int t = queue[q];
      comps.tris.back().push_back(t);
      for (int k = 0; k < 3; ++k) {
        const int o = neighbor[idx(3 * t + k)];
        if (o < 0) continue;
        const int u = o / 3;
        const bool same_way = w.tris[idx(t)][idx(k)] == w.tris[idx(u)][idx(o % 3)];
        const char want = static_cast<char>(flip[idx(t)] ^ (same_way ? 1 : 0));
        if (comps.of[idx(u)] < 0) {
          comps.of[idx(u)] = c;
          flip[idx(u)] = want;
          queue.push_back(u);
        } else if (flip[idx(u)] != want) {
          throw InputError(w.source() + ": a component (with triangle " + std::to_string(w.input_index[start]) +
                           ") is non-orientable; the orientation conflict closes at edge " +
                           fmt_point(w.p(w.slot_from(3 * t + k))) + " - " + fmt_point(w.p(w.slot_to(3 * t + k))));
        }
      }
    }
  }
  int first_flipped = -1;
  for (std::size_t t = 0; t < n_tris; ++t)
    if (flip[t]) {
      std::swap(w.tris[t][1], w.tris[t][2]);
      if (rep.flipped_inconsistent++ == 0) first_flipped = w.input_index[t];
    }
  if (rep.flipped_inconsistent > 0) {
    rep.repairs.push_back(w.source() + ": flipped " + plural(rep.flipped_inconsistent, "triangle") +
                          " to agree with the orientation of their component (first: triangle " +
                          std::to_string(first_flipped) + ")");
    build_adjacency(w.tris, neighbor);
  }
  return comps;
}

// The declared symmetry planes with unit normals (a zero or non-finite one is an error).
std::vector<SymmetryPlane> unit_planes(const std::vector<SymmetryPlane>& declared, const std::string& src) {
  std::vector<SymmetryPlane> planes = declared;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const double len = planes[i].normal.norm();
    if (!(len > 0) || !std::isfinite(len) || !std::isfinite(planes[i].offset))
      throw InputError(src + ": symmetry plane " + std::to_string(i) + " has a zero or non-finite normal");
    planes[i].normal /= len;
    planes[i].offset /= len;
  }
  return planes;
}

// Step 5: open boundaries. Boundary edges are grouped into loops (each boundary vertex of a
// manifold surface has one boundary edge in and one out); every edge must lie on a symmetry
// plane (within plane_tol, absolute), else its loop is an error.
BoundaryLoops check_open_boundaries(const Work& w, const std::vector<int>& neighbor, const Components& comps,
                                    const std::vector<SymmetryPlane>& planes, double plane_tol,
                                    SurfaceCheckReport& rep) {
  auto on_plane = [&](std::size_t i, const Vector3d& x) {
    return std::abs(planes[i].normal.dot(x) - planes[i].offset) <= plane_tol;
  };
  BoundaryLoops loops;
  for (std::size_t s = 0; s < neighbor.size(); ++s)
    if (neighbor[s] < 0) loops.slots.push_back(static_cast<int>(s));
  loops.loop_of_slot.resize(loops.slots.size());
  // Loops are numbered by their first edge; per loop, its edge count and first edge off every
  // plane.
  UnionFind vertex_loops(w.points().size());
  for (const int s : loops.slots) vertex_loops.unite(w.slot_from(s), w.slot_to(s));
  std::vector<int> loop_id(w.points().size(), -1);
  std::vector<std::size_t> loop_edges;
  std::vector<int> loop_bad_slot;
  for (std::size_t i = 0; i < loops.slots.size(); ++i) {
    const int s = loops.slots[i];
    const int root = vertex_loops.find(w.slot_from(s));
    if (loop_id[idx(root)] < 0) {
      loop_id[idx(root)] = static_cast<int>(loop_edges.size());
      loop_edges.push_back(0);
      loop_bad_slot.push_back(-1);
      loops.planes.emplace_back(planes.size(), 0);
      loops.comp.push_back(comps.of[idx(s / 3)]);
    }
    const int l = loop_id[idx(root)];
    loops.loop_of_slot[i] = l;
    ++loop_edges[idx(l)];
    bool on_any = false;
    for (std::size_t p = 0; p < planes.size(); ++p)
      if (on_plane(p, w.p(w.slot_from(s))) && on_plane(p, w.p(w.slot_to(s)))) {
        loops.planes[idx(l)][p] = 1;
        on_any = true;
      }
    if (!on_any && loop_bad_slot[idx(l)] < 0) loop_bad_slot[idx(l)] = s;
  }
  std::size_t open = 0;
  int first_open = -1;
  for (std::size_t l = 0; l < loop_edges.size(); ++l)
    if (loop_bad_slot[l] >= 0 && open++ == 0) first_open = static_cast<int>(l);
  if (open > 0)
    throw InputError(w.source() + ": " + plural(open, "open boundary loop") +
                     " not on a symmetry plane; first: a loop of " + plural(loop_edges[idx(first_open)], "edge") +
                     " through " + fmt_point(w.p(w.slot_from(loop_bad_slot[idx(first_open)]))));
  rep.boundary_loops = loop_edges.size();
  rep.symmetry_edges = loops.slots.size();
  return loops;
}

// Step 5 too: each declared plane holds a half model's cut -- an open loop on it -- and the surface
// lies on one side of it. A plane that crosses a closed body, or misses it, was accepted without
// a word (issue 37, item 8), and mirrored a body that is no half.
void check_planes_hold_the_cut(const Work& w, const BoundaryLoops& loops, const std::vector<SymmetryPlane>& planes,
                               double plane_tol) {
  for (std::size_t p = 0; p < planes.size(); ++p) {
    const SymmetryPlane& pl = planes[p];
    const std::string which = "symmetry plane " + std::to_string(p) + " (geometry.symmetry_planes[" + std::to_string(p) +
                              "]: normal " + fmt_point(pl.normal) + ", offset " + num(pl.offset) + ")";
    const bool holds = std::any_of(loops.planes.begin(), loops.planes.end(), [p](const std::vector<char>& on) { return on[p] != 0; });
    if (!holds)
      throw InputError(w.source() + ": " + which + " holds none of the surface's open edges" +
                       (loops.planes.empty() ? " (the surface is closed)" : "") +
                       "; a symmetry plane is where a half model is cut open: leave it out for a whole body");
    double below = 0, above = 0;
    for (const Vector3d& x : w.points()) {
      const double d = pl.normal.dot(x) - pl.offset;
      below = std::min(below, d);
      above = std::max(above, d);
    }
    if (below < -plane_tol && above > plane_tol)
      throw InputError(w.source() + ": the surface lies on both sides of " + which + " (from " + num(below) +
                       " to " + num(above) + " off it); a half model lies on one side of its plane");
  }
}

// The surface: the kept triangles on their used points only (no isolated vertices), the wall
// tag renamed, open edges tagged "symmetry"; the report's symmetry edges, loops (of what is
// left) and Euler characteristic.
TriSurface assemble_surface(const Work& w, const std::vector<char>& alive, const Components& comps,
                            const BoundaryLoops& loops, const std::string& wall_tag, SurfaceCheckReport& rep) {
  TriangleSoup clean;
  clean.source = w.source();
  std::vector<int> new_index(w.points().size(), -1);
  for (std::size_t t = 0; t < w.tris.size(); ++t) {
    if (!alive[t]) continue;
    Tri y{};
    for (std::size_t k = 0; k < 3; ++k) {
      const int v = w.tris[t][k];
      if (new_index[idx(v)] < 0) {
        new_index[idx(v)] = static_cast<int>(clean.points.size());
        clean.points.push_back(w.p(v));
      }
      y[k] = new_index[idx(v)];
    }
    clean.triangles.push_back(y);
  }
  TriSurface s = surface_from_soup(clean);
  s.tags[0].name = wall_tag;
  rep.symmetry_edges = 0;
  int sym = -1;
  for (const auto e : s.mesh.edges()) {
    if (!s.mesh.is_boundary(e)) continue;
    if (sym < 0) sym = s.add_tag("symmetry", BoundaryKind::Symmetry);
    s.mesh.property(s.edge_tag, e) = sym;
    s.mesh.property(s.edge_feature, e) = EdgeFeature::Boundary;
    ++rep.symmetry_edges;
  }
  if (rep.dropped_inner > 0) {
    // Recount the loops of what is left.
    std::size_t n_loops = 0;
    for (std::size_t l = 0; l < loops.comp.size(); ++l)
      if (alive[idx(comps.tris[idx(loops.comp[l])].front())]) ++n_loops;
    rep.boundary_loops = n_loops;
  }
  rep.euler_characteristic = s.euler_characteristic();
  return s;
}

// Step 8 (slivers.h): repaired on a copy, kept unless it makes the surface cross itself (when
// that is checked: step 7 left none).
void repair_cad_slivers(TriSurface& s, const std::string& src, bool check_crossings, SurfaceCheckReport& rep) {
  TriSurface repaired = s;
  const SliverRepairReport r = repair_slivers(repaired);
  rep.slivers_found = rep.slivers_left = r.found;
  if (r.found == 0) return;
  std::ostringstream o;
  o << src << ": " << plural(r.found, "sliver triangle") << " (thinner than " << kSliverRatio
    << " of their longest edge, a CAD tessellation's needles and caps): ";
  if (r.collapsed + r.flipped == 0) {
    rep.repairs.push_back(o.str() + "none could be repaired");
    return;
  }
  if (check_crossings && count_self_intersections(repaired) > 0) {
    rep.repairs.push_back(o.str() + "not repaired, the repair would make the surface cross itself");
    return;
  }
  o << plural(r.collapsed, "short edge") << " collapsed, " << plural(r.flipped, "long edge")
    << " flipped, each moving the surface by at most " << r.max_moved << ", " << r.left << " left";
  rep.repairs.push_back(o.str());
  rep.slivers_left = r.left;
  s = std::move(repaired);
}

}  // namespace

TriSurface validate_surface(const TriangleSoup& soup, const SurfaceCheckOptions& options, SurfaceCheckReport* report) {
  SurfaceCheckReport local;
  SurfaceCheckReport& rep = report ? *report : local;
  rep = SurfaceCheckReport{};
  rep.input_triangles = soup.triangles.size();

  // 0. The soup must at least be readable: indices in range, finite points.
  const Eigen::AlignedBox3d bbox = check_readable(soup);
  // 1. Degenerate triangles.
  Work w = drop_degenerate(soup, rep);
  // 2. Duplicate triangles.
  drop_duplicates(w, rep);
  // 3. Non-manifold edges and vertices.
  std::vector<int> neighbor = check_manifold(w);
  // 4. Consistent orientation per connected component.
  const Components comps = orient_components(w, neighbor, rep);
  // 5. Open boundaries, on the symmetry planes only.
  const std::vector<SymmetryPlane> planes = unit_planes(options.symmetry_planes, soup.source);
  const BoundaryLoops loops =
      check_open_boundaries(w, neighbor, comps, planes, options.plane_tol_rel * bbox.diagonal().norm(), rep);
  check_planes_hold_the_cut(w, loops, planes, options.plane_tol_rel * bbox.diagonal().norm());
  // 6. Outward components by their enclosed volume; nested components.
  std::vector<double> volume = component_volumes(w, comps, loops, planes);
  flip_inward_components(w, comps, volume, rep);
  const TriangleTree tree(soup.points, w.tris);
  const std::vector<char> alive =
      drop_nested_components(w, comps, loops, planes, bbox, tree, options.drop_inner_components, rep);
  for (std::size_t c = 0; c < comps.size(); ++c)
    if (alive[idx(comps.tris[c].front())]) rep.volume += volume[c];
  // 7. Self-intersections.
  if (options.check_self_intersections) check_self_intersections(w, tree, alive, options.repair_folded_caps, rep);

  TriSurface s = assemble_surface(w, alive, comps, loops, options.wall_tag, rep);
  // 8. CAD slivers.
  if (options.repair_slivers)
    repair_cad_slivers(s, soup.source, options.check_self_intersections, rep);
  else
    rep.slivers_found = rep.slivers_left = count_slivers(s);
  return s;
}

}  // namespace plaf
