// SPDX-License-Identifier: MIT
// PNG pictures of 3D meshes (picture3d.h).
#include "modules/io/picture3d.h"

#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>

#include <Eigen/Geometry>

#include "modules/base/error.h"
#include "modules/elements/lagrange.h"
#include "modules/geometry/aabb_tree.h"
#include "modules/io/atomic_file.h"
#include "modules/io/picture_canvas.h"

namespace plaf {
inline namespace io {

namespace {

using Vec = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

// A curved facet of order q: its type and nodes (Gmsh order).
struct Facet {
  CellType type = CellType::Triangle;
  int order = 1;
  std::vector<Vec> x;
};

// Points of a facet on its n-sub-lattice, with the sub-triangles (indices into the points) and the
// outline (indices, around the reference boundary).
struct Sampled {
  std::vector<Vec> p;
  std::vector<std::array<int, 3>> tris;
  std::vector<int> outline;
};

Sampled sample(const Facet& f, int n) {
  const LagrangeElement& e = lagrange_element(f.type, f.order);
  std::vector<double> phi(static_cast<std::size_t>(e.size()));
  Sampled s;
  const bool quad = f.type == CellType::Quadrilateral;
  std::map<std::pair<int, int>, int> at;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= (quad ? n : n - j); ++i) {
      const double xi[2] = {static_cast<double>(i) / n, static_cast<double>(j) / n};
      e.eval(xi, phi.data());
      Vec x = Vec::Zero();
      for (int k = 0; k < e.size(); ++k) x += phi[static_cast<std::size_t>(k)] * f.x[static_cast<std::size_t>(k)];
      at[{i, j}] = static_cast<int>(s.p.size());
      s.p.push_back(x);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < (quad ? n : n - j); ++i) {
      s.tris.push_back({at[{i, j}], at[{i + 1, j}], at[{i, j + 1}]});
      if (quad || i + j + 1 < n) s.tris.push_back({at[{i + 1, j}], quad ? at[{i + 1, j + 1}] : at[{i + 1, j + 1}], at[{i, j + 1}]});
    }
  for (int i = 0; i < n; ++i) s.outline.push_back(at[{i, 0}]);
  if (quad) {
    for (int j = 0; j < n; ++j) s.outline.push_back(at[{n, j}]);
    for (int i = n; i > 0; --i) s.outline.push_back(at[{i, n}]);
    for (int j = n; j > 0; --j) s.outline.push_back(at[{0, j}]);
  } else {
    for (int i = 0; i < n; ++i) s.outline.push_back(at[{n - i, i}]);
    for (int j = n; j > 0; --j) s.outline.push_back(at[{0, j}]);
  }
  return s;
}

bool is_curved(const Facet& f) {
  if (f.order == 1) return false;
  const LagrangeElement& e = lagrange_element(f.type, f.order);
  double size = 0;
  for (const Vec& x : f.x) size = std::max(size, (x - f.x[0]).norm());
  const int nv = f.type == CellType::Quadrilateral ? 4 : 3;
  for (int k = nv; k < e.size(); ++k) {
    const auto r = e.ref_node(k);
    Vec lin;
    if (nv == 3)
      lin = (1 - r[0] - r[1]) * f.x[0] + r[0] * f.x[1] + r[1] * f.x[2];
    else
      lin = (1 - r[0]) * (1 - r[1]) * f.x[0] + r[0] * (1 - r[1]) * f.x[1] + r[0] * r[1] * f.x[2] + (1 - r[0]) * r[1] * f.x[3];
    if ((lin - f.x[static_cast<std::size_t>(k)]).norm() > 1e-9 * size) return true;
  }
  return false;
}

// The plane's frame (picture3d.h): u, v in the plane, n its unit normal.
struct Frame {
  Vec p, n, u, v;
  Frame(const Vec& point, const Vec& normal) : p(point) {
    // u, v: the two coordinate axes least aligned with the normal, in x, y, z order, made
    // orthonormal in the plane (the plane z = 0 gets u = x, v = y); n = u x v.
    const Vec m = normal.normalized();
    int skip = 0;
    m.cwiseAbs().maxCoeff(&skip);
    const int a = skip == 0 ? 1 : 0, b = skip == 2 ? 1 : 2;
    u = (Vec::Unit(a) - Vec::Unit(a).dot(m) * m).normalized();
    v = (Vec::Unit(b) - Vec::Unit(b).dot(m) * m - Vec::Unit(b).dot(u) * u).normalized();
    n = u.cross(v);
  }
  Vec2 to2(const Vec& x) const { return Vec2(x.dot(u), x.dot(v)); }  // model coordinates in the plane
  double dist(const Vec& x) const { return (x - p).dot(n); }
};

// What the cut panel draws, in plane coordinates.
struct Cut {
  struct Polygon {
    std::vector<Vec2> p;
    int colour;  // 0 straight, 1 curved, 2 invalid
  };
  struct Segment {
    Vec2 a, b;
    bool wall, invalid;
  };
  std::vector<Polygon> polygons;
  std::vector<Segment> segments;
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  void grow(const Vec2& x) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
};

std::vector<NodeId> sorted_vertices(const NodeId* c, int nv) {
  std::vector<NodeId> k(c, c + nv);
  std::sort(k.begin(), k.end());
  return k;
}

Cut cut_mesh(const HybridMesh<3>& mesh, const std::vector<std::uint8_t>& valid, const Frame& fr, double diag) {
  // Wall facets (drawn thicker where cut).
  std::map<std::vector<NodeId>, bool> wall;
  for (const CellBlock& b : mesh.boundary)
    if (b.tag >= 0 && mesh.tags[static_cast<std::size_t>(b.tag)].kind == BoundaryKind::Wall)
      for (std::size_t i = 0; i < b.size(); ++i) wall[sorted_vertices(b.cell(i), num_vertices(b.type))] = true;
  // Every cell facet near the plane once (its nodes within a quarter of its size of it: a curved
  // facet bulges less than that past its nodes); a facet of an invalid cell is drawn invalid.
  // Only ids are kept, so memory follows the cut, not the mesh.
  const double tol = 1e-6 * diag;  // in the plane: as the layers' symmetry planes are fitted
  std::map<std::vector<NodeId>, std::pair<Facet, bool>> facets;
  auto near = [&](const std::vector<NodeId>& ids, int order) {
    double dmin = std::numeric_limits<double>::infinity(), dmax = -dmin, size = 0;
    const Vec& x0 = mesh.nodes[static_cast<std::size_t>(ids[0])];
    for (NodeId id : ids) {
      const Vec& x = mesh.nodes[static_cast<std::size_t>(id)];
      dmin = std::min(dmin, fr.dist(x));
      dmax = std::max(dmax, fr.dist(x));
      size = std::max(size, (x - x0).norm());
    }
    const double margin = order == 1 ? tol : 0.25 * size + tol;
    return !(dmin > margin || dmax < -margin);
  };
  std::size_t index = 0;
  std::vector<NodeId> ids;
  for (const CellBlock& b : mesh.cells) {
    const LagrangeElement& e = lagrange_element(b.type, b.order);
    for (std::size_t i = 0; i < b.size(); ++i, ++index) {
      const bool ok = valid.empty() || valid[index];
      const NodeId* c = b.cell(i);
      for (int f = 0; f < e.num_facets(); ++f) {
        ids.clear();
        for (int k : e.facet_nodes(f)) ids.push_back(c[k]);
        if (!near(ids, b.order)) continue;
        const bool quad = topology(b.type).faces[static_cast<std::size_t>(f)].size() == 4;
        const std::vector<NodeId> key = sorted_vertices(ids.data(), quad ? 4 : 3);
        auto [it, added] = facets.emplace(key, std::make_pair(Facet{}, ok));
        if (added) {
          it->second.first.type = quad ? CellType::Quadrilateral : CellType::Triangle;
          it->second.first.order = b.order;
          for (NodeId id : ids) it->second.first.x.push_back(mesh.nodes[static_cast<std::size_t>(id)]);
        } else {
          it->second.second = it->second.second && ok;
        }
      }
    }
  }
  // A surface alone (no cells): its facets are cut instead.
  if (mesh.cells.empty())
    for (const CellBlock& b : mesh.boundary) {
      if (b.type != CellType::Triangle && b.type != CellType::Quadrilateral) continue;
      for (std::size_t i = 0; i < b.size(); ++i) {
        ids.assign(b.cell(i), b.cell(i) + b.nodes_per_cell());
        if (!near(ids, b.order)) continue;
        Facet f{b.type, b.order, {}};
        for (NodeId id : ids) f.x.push_back(mesh.nodes[static_cast<std::size_t>(id)]);
        facets.emplace(sorted_vertices(b.cell(i), num_vertices(b.type)), std::make_pair(f, true));
      }
    }
  Cut cut;
  for (const auto& [key, fv] : facets) {
    const Facet& f = fv.first;
    double dmin = std::numeric_limits<double>::infinity(), dmax = -dmin;
    for (const Vec& x : f.x) {
      dmin = std::min(dmin, fr.dist(x));
      dmax = std::max(dmax, fr.dist(x));
    }
    const int n = f.order == 1 ? 1 : 4 * f.order;
    const Sampled s = sample(f, n);
    if (std::max(std::abs(dmin), std::abs(dmax)) <= tol) {  // in the plane: drawn as a cell
      Cut::Polygon poly;
      for (int k : s.outline) poly.p.push_back(fr.to2(s.p[static_cast<std::size_t>(k)]));
      for (const Vec2& x : poly.p) cut.grow(x);
      poly.colour = !fv.second ? 2 : is_curved(f) ? 1 : 0;
      cut.polygons.push_back(poly);
      continue;
    }
    const bool on_wall = wall.count(key) > 0;
    for (const auto& t : s.tris) {
      Vec2 pts[3];
      int np = 0;
      for (int k = 0; k < 3 && np < 2; ++k) {
        const Vec& a = s.p[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])];
        const Vec& b = s.p[static_cast<std::size_t>(t[static_cast<std::size_t>((k + 1) % 3)])];
        const double da = fr.dist(a), db = fr.dist(b);
        if ((da < 0) != (db < 0) && da != db) pts[np++] = fr.to2(a + (da / (da - db)) * (b - a));
      }
      if (np == 2) {
        cut.segments.push_back({pts[0], pts[1], on_wall, !fv.second});
        cut.grow(pts[0]);
        cut.grow(pts[1]);
      }
    }
  }
  return cut;
}

// The main panel's frame in (u, v): where the cut crosses the wall (or, on a symmetry plane,
// holds curved facets: the layers'; and invalid cells) and reaches more than three times their
// extent (a fill out to a farfield), that crossing widened by a quarter of its extent on each
// side, so that the body and its layers fill the panel; else the whole cut.
std::array<Vec2, 2> cut_frame(const Cut& cut) {
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Cut::Segment& s : cut.segments)
    if (s.wall) {
      lo = lo.cwiseMin(s.a).cwiseMin(s.b);
      hi = hi.cwiseMax(s.a).cwiseMax(s.b);
    }
  for (const Cut::Polygon& poly : cut.polygons)
    if (poly.colour >= 1)  // curved, or invalid (a failed run's red cells stay in view)
      for (const Vec2& x : poly.p) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
      }
  for (const Cut::Segment& s : cut.segments)
    if (s.invalid) {
      lo = lo.cwiseMin(s.a).cwiseMin(s.b);
      hi = hi.cwiseMax(s.a).cwiseMax(s.b);
    }
  const double all = (cut.hi - cut.lo).maxCoeff();
  double wall = (hi - lo).maxCoeff();
  if (!(wall >= 0) || !(all > 3 * wall)) return {cut.lo, cut.hi};  // nothing to frame on, or no farfield
  // A plane that grazes the wall (a tip's station) crosses it over a sliver: the frame is at least
  // a twentieth of the whole cut across.
  const Vec2 mid = 0.5 * (lo + hi);
  wall = std::max(wall, all / 20);
  const Vec2 half = Vec2::Constant(0.75 * wall);
  return {(mid - half).cwiseMax(cut.lo), (mid + half).cwiseMin(cut.hi)};
}

void draw_cut(cairo_t* cr, const View& v, const Cut& cut, double lw) {
  for (const Cut::Polygon& poly : cut.polygons) {
    for (std::size_t k = 0; k < poly.p.size(); ++k)
      (k == 0 ? cairo_move_to : cairo_line_to)(cr, v.px(poly.p[k].x()), v.py(poly.p[k].y()));
    cairo_close_path(cr);
    fill_cell(cr, poly.colour != 2, poly.colour == 1, lw);
  }
  for (int pass = 0; pass < 3; ++pass)  // cut facets, then wall facets, then invalid cells' on top
    for (const Cut::Segment& s : cut.segments) {
      const int kind = s.invalid ? 2 : s.wall ? 1 : 0;
      if (kind != pass) continue;
      if (kind == 2)
        cairo_set_source_rgb(cr, 0.95, 0.1, 0.1);
      else if (kind == 1)
        cairo_set_source_rgb(cr, 0, 0, 0);
      else
        cairo_set_source_rgb(cr, 0.15, 0.15, 0.2);
      cairo_set_line_width(cr, kind == 0 ? lw : 2.5 * lw);
      cairo_move_to(cr, v.px(s.a.x()), v.py(s.a.y()));
      cairo_line_to(cr, v.px(s.b.x()), v.py(s.b.y()));
      cairo_stroke(cr);
    }
}

bool is_wall(const HybridMesh<3>& mesh, const CellBlock& b) {
  return b.tag >= 0 && (b.type == CellType::Triangle || b.type == CellType::Quadrilateral) &&
         mesh.tags[static_cast<std::size_t>(b.tag)].kind == BoundaryKind::Wall;
}

// Per wall corner node, the fewest layers its column grew (Picture3Options::short_columns): each
// short column goes to the corner nearest its point (the largest barycentric weight of its
// closest point on the wall's corner triangles). Corners absent grew o.layers.
std::unordered_map<NodeId, int> corner_layers(const HybridMesh<3>& mesh, const Picture3Options& o) {
  std::unordered_map<NodeId, int> out;
  if (o.short_columns.empty()) return out;
  std::vector<std::array<int, 3>> tris;
  for (const CellBlock& b : mesh.boundary) {
    if (!is_wall(mesh, b)) continue;
    for (std::size_t i = 0; i < b.size(); ++i) {
      const NodeId* c = b.cell(i);
      tris.push_back({static_cast<int>(c[0]), static_cast<int>(c[1]), static_cast<int>(c[2])});
      if (b.type == CellType::Quadrilateral) tris.push_back({static_cast<int>(c[0]), static_cast<int>(c[2]), static_cast<int>(c[3])});
    }
  }
  if (tris.empty()) return out;
  const TriangleTree tree(mesh.nodes, tris);
  for (const Picture3Options::ShortColumn& s : o.short_columns) {
    const TriangleTree::Closest c = tree.closest(s.point);
    if (c.triangle < 0) continue;
    int k = 0;
    c.barycentric.maxCoeff(&k);
    const NodeId id = static_cast<NodeId>(tris[static_cast<std::size_t>(c.triangle)][static_cast<std::size_t>(k)]);
    const int grown = std::max(0, s.layer - 1);
    const auto [it, added] = out.emplace(id, grown);
    if (!added) it->second = std::min(it->second, grown);
  }
  return out;
}

// The colour of a wall facet whose columns grew `fraction` of the stack (1: the outer front's
// blue; below it yellow at 0.9 through orange to red at none).
std::array<double, 3> coverage_colour(double fraction) {
  if (fraction >= 1) return {0.55, 0.7, 0.9};
  const double t = std::clamp(fraction / 0.9, 0.0, 1.0);
  return {0.95, 0.15 + 0.75 * t, 0.1 + 0.1 * t};
}

// The shaded outer front (or wall, then coloured by the layers grown when `grown` holds any
// corner) in the panel (ox, oy, w, h).
void draw_shaded(cairo_t* cr, const HybridMesh<3>& mesh, const Vec& view, double ox, double oy, double w, double h,
                 double lw, const std::optional<Vec>& focus, const std::unordered_map<NodeId, int>& grown, int layers) {
  int outer = -1;
  if (grown.empty())
    for (std::size_t t = 0; t < mesh.tags.size(); ++t)
      if (mesh.tags[t].name == "layers_outer") outer = static_cast<int>(t);
  const Vec d = view.normalized();
  Vec up = Vec::UnitZ();
  if (std::abs(up.dot(d)) > 0.95) up = Vec::UnitY();
  const Vec right = d.cross(up).normalized();
  const Vec up2 = right.cross(d);
  const Vec light = (-d + 0.6 * up2 + 0.3 * right).normalized();
  struct Tri {
    std::array<Vec2, 3> p;
    double depth, shade;
    std::array<double, 3> colour;
  };
  std::vector<Tri> tris;
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  auto to2 = [&](const Vec& x) { return Vec2(x.dot(right), x.dot(up2)); };
  // Sub-triangles per facet: Q^2 (the node lattice), or 1 past two million in all.
  std::size_t total = 0;
  for (const CellBlock& b : mesh.boundary) total += b.size() * static_cast<std::size_t>(b.order * b.order);
  const bool coarse = total > 2000000;
  for (const CellBlock& b : mesh.boundary) {
    if (b.tag < 0 || (b.type != CellType::Triangle && b.type != CellType::Quadrilateral)) continue;
    const bool take = outer >= 0 ? b.tag == outer : mesh.tags[static_cast<std::size_t>(b.tag)].kind == BoundaryKind::Wall;
    if (!take) continue;
    const int corners = b.type == CellType::Triangle ? 3 : 4;
    for (std::size_t i = 0; i < b.size(); ++i) {
      int fewest = layers;
      for (int k = 0; k < corners && !grown.empty(); ++k) {
        const auto it = grown.find(b.cell(i)[k]);
        if (it != grown.end()) fewest = std::min(fewest, it->second);
      }
      const std::array<double, 3> colour =
          grown.empty() ? coverage_colour(1) : coverage_colour(layers > 0 ? static_cast<double>(fewest) / layers : 0.0);
      Facet f{b.type, b.order, {}};
      for (int k = 0; k < b.nodes_per_cell(); ++k) f.x.push_back(mesh.nodes[static_cast<std::size_t>(b.cell(i)[k])]);
      const Sampled s = sample(f, coarse ? 1 : b.order);
      for (const auto& t : s.tris) {
        const Vec& a = s.p[static_cast<std::size_t>(t[0])];
        const Vec& bb = s.p[static_cast<std::size_t>(t[1])];
        const Vec& c = s.p[static_cast<std::size_t>(t[2])];
        const Vec nrm = (bb - a).cross(c - a);
        const double len = nrm.norm();
        const double shade = len > 0 ? 0.3 + 0.7 * std::abs(nrm.dot(light)) / len : 0.3;
        tris.push_back({{to2(a), to2(bb), to2(c)}, (a + bb + c).dot(d) / 3, shade, colour});
      }
      for (int k : s.outline) {
        lo = lo.cwiseMin(to2(s.p[static_cast<std::size_t>(k)]));
        hi = hi.cwiseMax(to2(s.p[static_cast<std::size_t>(k)]));
      }
    }
  }
  if (tris.empty()) return;
  // Painter's order: the farthest first (depth grows along the view direction).
  std::sort(tris.begin(), tris.end(), [](const Tri& a, const Tri& b) { return a.depth > b.depth; });
  const View v = fit(lo.x(), hi.x(), lo.y(), hi.y(), ox, oy, w, h);
  for (const Tri& t : tris) {
    cairo_move_to(cr, v.px(t.p[0].x()), v.py(t.p[0].y()));
    cairo_line_to(cr, v.px(t.p[1].x()), v.py(t.p[1].y()));
    cairo_line_to(cr, v.px(t.p[2].x()), v.py(t.p[2].y()));
    cairo_close_path(cr);
    cairo_set_source_rgb(cr, t.colour[0] * t.shade, t.colour[1] * t.shade, t.colour[2] * t.shade);
    cairo_fill_preserve(cr);
    cairo_set_line_width(cr, 0.3 * lw);
    cairo_stroke(cr);  // hides the seams between sub-triangles
  }
  if (focus) {  // drawn over everything: it may lie behind the body in this view
    const Vec2 f = to2(*focus);
    cairo_new_path(cr);
    cairo_arc(cr, v.px(f.x()), v.py(f.y()), 14 * lw, 0, 2 * M_PI);
    cairo_set_source_rgb(cr, 0.9, 0, 0);
    cairo_set_line_width(cr, 3 * lw);
    cairo_stroke(cr);
  }
}

}  // namespace

Eigen::Vector2d cut_plane_uv(const Eigen::Vector3d& normal, const Eigen::Vector3d& x) {
  return Frame(Vec::Zero(), normal).to2(x);
}

void default_cut(const HybridMesh<3>& mesh, Vec& point, Vec& normal) {
  // The plane of the first symmetry facet (its first three vertices; a tag may span two planes).
  for (const CellBlock& b : mesh.boundary) {
    if (b.tag < 0 || mesh.tags[static_cast<std::size_t>(b.tag)].kind != BoundaryKind::Symmetry || b.size() == 0) continue;
    const NodeId* c = b.cell(0);
    const Vec& x0 = mesh.nodes[static_cast<std::size_t>(c[0])];
    const Vec nrm = (mesh.nodes[static_cast<std::size_t>(c[1])] - x0).cross(mesh.nodes[static_cast<std::size_t>(c[2])] - x0);
    if (!(nrm.norm() > 0)) continue;
    point = x0;
    normal = nrm.normalized();
    return;
  }
  Vec lo = Vec::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  if (mesh.nodes.empty()) lo = hi = Vec::Zero();
  point = 0.5 * (lo + hi);
  int axis = 0;
  (hi - lo).minCoeff(&axis);
  normal = Vec::Unit(axis);
}

void write_png(const HybridMesh<3>& mesh, const std::vector<std::uint8_t>& valid, const std::filesystem::path& path,
               const Picture3Options& options) {
  if (!valid.empty() && valid.size() != mesh.num_cells())
    throw InputError(path.string() + ": " + std::to_string(valid.size()) + " validity flags for " +
                     std::to_string(mesh.num_cells()) + " cells");
  Vec lo = Vec::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double diag = mesh.nodes.empty() ? 1.0 : (hi - lo).norm();
  const Frame fr(options.cut_point, options.cut_normal);
  const Cut cut = cut_mesh(mesh, valid, fr, diag);
  const int w = options.width, h = options.height;
  std::vector<ZoomBox> zooms = options.zooms;
  if (options.focus) {
    const Vec2 c = fr.to2(*options.focus);
    const double r = options.focus_radius;
    zooms.insert(zooms.begin(), ZoomBox{options.focus_label, c.x() - r, c.x() + r, c.y() - r, c.y() + r});
  }
  const int panels = static_cast<int>(zooms.size());
  const int main_h = panels ? h * 2 / 3 : h;
  const int cut_w = w * 11 / 20;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  const double lw = std::max(0.4, w / 2400.0);
  if (!cut.polygons.empty() || !cut.segments.empty()) {
    cairo_save(cr);
    cairo_rectangle(cr, 0, 0, cut_w, main_h);
    cairo_clip(cr);
    const std::array<Vec2, 2> frame = cut_frame(cut);
    draw_cut(cr, fit(frame[0].x(), frame[1].x(), frame[0].y(), frame[1].y(), 0, 0, cut_w, main_h), cut, lw);
    cairo_restore(cr);
  }
  cairo_save(cr);
  cairo_rectangle(cr, cut_w, 0, w - cut_w, main_h);
  cairo_clip(cr);
  const std::unordered_map<NodeId, int> grown = corner_layers(mesh, options);
  draw_shaded(cr, mesh, options.view, cut_w, 0, w - cut_w, main_h, lw, options.focus, grown, options.layers);
  cairo_restore(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_font_size(cr, 16);
  cairo_move_to(cr, cut_w + 8, 48);
  // With a fill the layers' outer front is interior (no layers_outer facets): the wall is shaded.
  const bool outer = std::any_of(mesh.tags.begin(), mesh.tags.end(), [](const BoundaryTag& t) { return t.name == "layers_outer"; });
  if (!grown.empty()) {
    const std::string legend = "wall by layers grown: blue all " + std::to_string(options.layers) + ", yellow to red fewer";
    cairo_show_text(cr, legend.c_str());
  } else {
    cairo_show_text(cr, outer ? "outer front, shaded" : "wall, shaded");
  }
  const std::string plane = "cut: plane through (" + std::to_string(fr.p.x()) + ", " + std::to_string(fr.p.y()) + ", " +
                            std::to_string(fr.p.z()) + "), normal (" + std::to_string(fr.n.x()) + ", " +
                            std::to_string(fr.n.y()) + ", " + std::to_string(fr.n.z()) + ")";
  cairo_move_to(cr, 10, 48);
  cairo_show_text(cr, plane.c_str());
  zoom_panels(cr, zooms, w, h, main_h, [&](const View& v) { draw_cut(cr, v, cut, lw); });
  draw_title(cr, options.title);
  finish_png(cr, surface, path);
}

}  // namespace io
}  // namespace plaf
