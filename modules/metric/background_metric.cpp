// SPDX-License-Identifier: MIT
// Implements the background-mesh metric of K. J. Fidkowski, *Anisotropic Metric-Based Curved
// Meshing Using Prismatic Layers*, Sec. II.D: the mesh is snapped to linear, the containing
// element is found through a quadtree, and the vertex metrics are averaged with the linear
// (barycentric) weights of the point. File formats: Gmsh reference manual, "MSH file format"
// (version 4.1, $NodeData); libMeshb / Medit ASCII .mesh and .sol (as read by MMG and BAMG).
#include "modules/metric/background_metric.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "modules/base/error.h"
#include "modules/io/msh_io.h"
#include "modules/io/text_cursor.h"

namespace plaf {
inline namespace metric {
namespace {

// A 2x2 block read from a file as an SPD metric; the reason names the node and the line.
Metric<2> metric_from_file(TextCursor& in, int line, const Eigen::Matrix2d& m, const std::string& where) {
  try {
    return Metric<2>::from_matrix(m);
  } catch (const InputError& e) {
    in.fail_at(line, "the tensor at " + where + " (xx " + std::to_string(m(0, 0)) + ", xy " + std::to_string(m(0, 1)) +
                         ", yx " + std::to_string(m(1, 0)) + ", yy " + std::to_string(m(1, 1)) + "): " + e.what());
  }
}

// Keeps only the nodes some triangle uses (high-order and free nodes go), in their order.
// has_value[i] tells whether node i carries a metric; a used node without one is reported.
template <class Missing>
BackgroundMesh compact(std::vector<Eigen::Vector2d> nodes, std::vector<std::array<NodeId, 3>> triangles,
                       std::vector<Metric<2>> metrics, const std::vector<bool>& has_value, const Missing& missing) {
  std::vector<NodeId> new_id(nodes.size(), -1);
  for (const auto& t : triangles)
    for (NodeId v : t) new_id[static_cast<std::size_t>(v)] = 0;
  BackgroundMesh out;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (new_id[i] < 0) continue;
    if (!has_value[i]) missing(i);
    new_id[i] = static_cast<NodeId>(out.nodes.size());
    out.nodes.push_back(nodes[i]);
    out.metrics.push_back(metrics[i]);
  }
  out.triangles = std::move(triangles);
  for (auto& t : out.triangles)
    for (NodeId& v : t) v = new_id[static_cast<std::size_t>(v)];
  return out;
}

// ---- Gmsh MSH 4.1: node tags in file order and the $NodeData view --------------------------

struct NodeDataEntry {
  std::int64_t tag;
  int line;
  Metric<2> metric;
};

struct MshScan {
  std::vector<std::int64_t> node_tags;  // in file order, as read_msh41 numbers the nodes
  int elements_line = 1;
  int view_line = 0;  // 0: no $NodeData
  std::string view_name;
  std::vector<NodeDataEntry> entries;
};

// Skips a section the scan does not use, up to the token $End<name> (read_msh41 has already
// checked the file's structure).
void skip_section(TextCursor& in, const std::string& name, int line) {
  const std::string end_keyword = "$End" + name;
  while (!in.at_end())
    if (in.token(end_keyword.c_str()) == end_keyword) return;
  in.fail_at(line, "section $" + name + " has no " + end_keyword);
}

// The mesh itself has been validated by read_msh41; this reads what it does not keep.
void scan_nodes(TextCursor& in, MshScan& scan) {
  const std::int64_t num_blocks = in.count("number of node blocks", 8);
  const std::int64_t num_nodes = in.count("number of nodes", 8);
  in.integer("minimum node tag");
  in.integer("maximum node tag");
  scan.node_tags.reserve(static_cast<std::size_t>(num_nodes));
  for (std::int64_t b = 0; b < num_blocks; ++b) {
    const std::int64_t entity_dim = in.integer("entity dimension", 0, 3);
    in.integer("entity tag");
    const bool parametric = in.integer("parametric flag", 0, 1) == 1;
    const std::int64_t n = in.count("number of nodes in block", 4);
    for (std::int64_t i = 0; i < n; ++i) scan.node_tags.push_back(in.integer("node tag"));
    const std::int64_t values = n * (3 + (parametric ? entity_dim : 0));
    for (std::int64_t i = 0; i < values; ++i) in.token("node coordinate");
  }
  in.expect("$EndNodes");
}

// Layout (MSH 4.1): string tags (the first is the view name), real tags (the first is the
// time), integer tags (time step, number of components, number of entries, [partition]), then
// one line per entry: node tag and the components. Gmsh stores a tensor row-major (9 values:
// xx xy xz yx yy yz zx zy zz); a 2D metric uses the xx xy yx yy block.
void read_node_data(TextCursor& in, MshScan& scan, int section_line) {
  if (scan.view_line > 0)
    in.fail_at(section_line, "a second $NodeData view (the first is at line " + std::to_string(scan.view_line) +
                                 "); a background metric file holds one");
  scan.view_line = section_line;
  const std::int64_t num_strings = in.count("number of string tags", 2);
  for (std::int64_t i = 0; i < num_strings; ++i) {
    std::string s = in.quoted("string tag");
    if (i == 0) scan.view_name = std::move(s);
  }
  const std::int64_t num_reals = in.count("number of real tags", 2);
  for (std::int64_t i = 0; i < num_reals; ++i) in.real("real tag");
  const int integers_line = in.next_line();
  const std::int64_t num_integers = in.count("number of integer tags", 2);
  if (num_integers < 3)
    in.fail_at(integers_line, "$NodeData has " + std::to_string(num_integers) +
                                  " integer tags; it needs 3 (time step, number of components, number of entries)");
  in.integer("time step");
  const int components_line = in.next_line();
  const std::int64_t components = in.integer("number of components");
  if (components != 9 && components != 4)
    in.fail_at(components_line, "view '" + scan.view_name + "' has " + std::to_string(components) +
                                    " components per node; a metric view has 9 (3x3 tensor) or 4 (2x2 tensor)");
  const int per = static_cast<int>(components);
  const std::int64_t num_entries = in.count("number of entries", 2 * static_cast<std::size_t>(per) + 2);
  for (std::int64_t i = 3; i < num_integers; ++i) in.integer("integer tag");
  scan.entries.reserve(static_cast<std::size_t>(num_entries));
  std::array<double, 9> v{};
  for (std::int64_t e = 0; e < num_entries; ++e) {
    const int line = in.next_line();
    const std::int64_t tag = in.integer("node tag");
    for (int k = 0; k < per; ++k) v[static_cast<std::size_t>(k)] = in.real("tensor component");
    const int row = per == 9 ? 3 : 2;  // row-major: (i, j) at i * row + j
    Eigen::Matrix2d m;
    m << v[0], v[1], v[static_cast<std::size_t>(row)], v[static_cast<std::size_t>(row) + 1];
    scan.entries.push_back({tag, line, metric_from_file(in, line, m, "node tag " + std::to_string(tag))});
  }
  in.expect("$EndNodeData");
}

MshScan scan_msh(const std::filesystem::path& path, const std::string& text) {
  TextCursor in(path, text);
  MshScan scan;
  while (!in.at_end()) {
    const int line = in.next_line();
    const std::string_view t = in.token("a section");
    if (t.size() < 2 || t[0] != '$') in.fail_at(line, "expected a section, found " + TextCursor::quote(t));
    const std::string name(t.substr(1));
    if (name == "Nodes") {
      scan_nodes(in, scan);
    } else if (name == "NodeData") {
      read_node_data(in, scan, line);
    } else {
      if (name == "Elements") scan.elements_line = line;
      skip_section(in, name, line);
    }
  }
  if (scan.view_line == 0)
    in.fail("no $NodeData view: a background metric needs one with a 3x3 or 2x2 tensor per node");
  return scan;
}

// ---- libMeshb ASCII ----------------------------------------------------------------------

bool is_keyword(std::string_view t) {
  return !t.empty() && std::isalpha(static_cast<unsigned char>(t[0]));
}

// Skips the data of a keyword plaf does not use: every token up to the next keyword.
void skip_keyword_data(TextCursor& in) {
  while (!in.at_end() && !is_keyword(in.peek())) in.token("data");
}

struct MeshbEnd {
  int line;        // of the End keyword
  bool dimension;  // whether a Dimension keyword came before it
};

// Reads a .mesh or .sol up to End: the header, Dimension (which must be 2), and every other
// keyword through read_section(keyword, line, dimension seen so far), which returns false for a
// keyword it does not use; the data of those is skipped.
template <class ReadSection>
MeshbEnd read_meshb_keywords(TextCursor& in, const ReadSection& read_section) {
  in.expect("MeshVersionFormatted");
  in.integer("mesh version", 1, 4);
  bool dimension = false;
  while (true) {
    const int line = in.next_line();
    const std::string_view kw = in.token("a keyword (the file ends with End)");
    if (kw == "End") return {line, dimension};
    if (kw == "Dimension") {
      const int dim_line = in.next_line();
      const std::int64_t dim = in.integer("dimension");
      if (dim != 2)
        in.fail_at(dim_line, "Dimension " + std::to_string(dim) + ": plaf reads 2D background meshes (Dimension 2)");
      dimension = true;
    } else if (!read_section(kw, line, dimension)) {
      if (!is_keyword(kw)) in.fail_at(line, "expected a keyword, found " + TextCursor::quote(kw));
      skip_keyword_data(in);
    }
  }
}

}  // namespace

// ---- readers -----------------------------------------------------------------------------

BackgroundMesh read_background_msh(const std::filesystem::path& path) {
  // 1. The mesh part, validated by the MSH reader; its nodes are in file order.
  const MshMesh msh = read_msh41(path);
  // 2. Node tags and the metric view.
  const std::string text = read_whole_file(path);
  const MshScan scan = scan_msh(path, text);
  TextCursor in(path, text);
  if (msh.dim != 2)
    in.fail_at(scan.elements_line, "the background mesh has 3D elements; plaf reads 2D background meshes");
  const HybridMesh<2>& mesh = msh.mesh2;
  if (scan.node_tags.size() != mesh.nodes.size())
    in.fail_at(scan.elements_line, "node count mismatch between $Nodes and the mesh read");
  // 3. Node tag -> index, then one metric per node.
  std::unordered_map<std::int64_t, std::size_t> index;
  index.reserve(scan.node_tags.size());
  for (std::size_t i = 0; i < scan.node_tags.size(); ++i) index.emplace(scan.node_tags[i], i);
  std::vector<Metric<2>> metrics(mesh.nodes.size());
  std::vector<bool> has_value(mesh.nodes.size(), false);
  for (const NodeDataEntry& e : scan.entries) {
    const auto it = index.find(e.tag);
    if (it == index.end()) in.fail_at(e.line, "$NodeData refers to unknown node tag " + std::to_string(e.tag));
    if (has_value[it->second]) in.fail_at(e.line, "$NodeData gives node tag " + std::to_string(e.tag) + " twice");
    has_value[it->second] = true;
    metrics[it->second] = e.metric;
  }
  // 4. Linear triangles: the vertices of every 2D cell, quadrilaterals split along 0-2.
  std::vector<std::array<NodeId, 3>> triangles;
  for (const CellBlock& b : mesh.cells) {
    for (std::size_t c = 0; c < b.size(); ++c) {
      const NodeId* v = b.cell(c);
      triangles.push_back({v[0], v[1], v[2]});
      if (b.type == CellType::Quadrilateral) triangles.push_back({v[0], v[2], v[3]});
    }
  }
  std::vector<Eigen::Vector2d> nodes(mesh.nodes.begin(), mesh.nodes.end());
  return compact(std::move(nodes), std::move(triangles), std::move(metrics), has_value, [&](std::size_t i) {
    in.fail_at(scan.view_line, "view '" + scan.view_name + "' has no value at node tag " +
                                   std::to_string(scan.node_tags[i]) + ", a vertex of the mesh");
  });
}

BackgroundMesh read_background_meshb(const std::filesystem::path& mesh_path, const std::filesystem::path& sol_path) {
  // 1. The .mesh: Dimension 2, Vertices (x y ref), Triangles and Quadrilaterals (1-based vertex
  //    indices and a ref); other keywords are skipped up to the next keyword.
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<NodeId, 3>> triangles;
  {
    const std::string text = read_whole_file(mesh_path);
    TextCursor in(mesh_path, text, true);
    bool vertices = false;
    const MeshbEnd end = read_meshb_keywords(in, [&](std::string_view kw, int line, bool dimension) {
      if (kw == "Vertices") {
        if (!dimension) in.fail_at(line, "Vertices before Dimension");
        if (vertices) in.fail_at(line, "a second Vertices section");
        vertices = true;
        const std::int64_t n = in.count("number of vertices", 6);
        if (n > std::numeric_limits<NodeId>::max()) in.fail_at(line, "too many vertices: " + std::to_string(n));
        nodes.reserve(static_cast<std::size_t>(n));
        for (std::int64_t i = 0; i < n; ++i) {
          const double x = in.real("vertex coordinate");
          const double y = in.real("vertex coordinate");
          in.integer("vertex reference");
          nodes.emplace_back(x, y);
        }
        return true;
      }
      if (kw == "Triangles" || kw == "Quadrilaterals") {
        if (!vertices) in.fail_at(line, std::string(kw) + " before Vertices");
        const int per = kw == "Triangles" ? 3 : 4;
        const std::int64_t n = in.count("number of elements", 2 * static_cast<std::size_t>(per) + 2);
        std::array<NodeId, 4> v{};
        for (std::int64_t e = 0; e < n; ++e) {
          for (int k = 0; k < per; ++k)
            v[static_cast<std::size_t>(k)] =
                static_cast<NodeId>(in.integer("vertex index", 1, static_cast<std::int64_t>(nodes.size())) - 1);
          in.integer("element reference");
          triangles.push_back({v[0], v[1], v[2]});
          if (per == 4) triangles.push_back({v[0], v[2], v[3]});
        }
        return true;
      }
      return false;
    });
    if (!end.dimension) in.fail_at(end.line, "no Dimension keyword");
    if (!vertices) in.fail_at(end.line, "no Vertices section");
    if (triangles.empty()) in.fail_at(end.line, "no Triangles or Quadrilaterals: the background mesh has no elements");
  }
  // 2. The .sol: SolAtVertices with one symmetric-matrix field (type 3), stored xx xy yy.
  std::vector<Metric<2>> metrics;
  const std::string text = read_whole_file(sol_path);
  TextCursor in(sol_path, text, true);
  bool solution = false;
  const MeshbEnd end = read_meshb_keywords(in, [&](std::string_view kw, int line, bool dimension) {
    if (kw != "SolAtVertices") return false;
    if (!dimension) in.fail_at(line, "SolAtVertices before Dimension");
    if (solution) in.fail_at(line, "a second SolAtVertices section");
    solution = true;
    const int count_line = in.next_line();
    const std::int64_t n = in.count("number of values", 6);
    if (static_cast<std::size_t>(n) != nodes.size())
      in.fail_at(count_line, "SolAtVertices has " + std::to_string(n) + " values but " + mesh_path.string() + " has " +
                                 std::to_string(nodes.size()) + " vertices");
    const int types_line = in.next_line();
    const std::int64_t num_fields = in.integer("number of fields", 1, 64);
    std::string types;
    bool symmetric_matrix = num_fields == 1;
    for (std::int64_t f = 0; f < num_fields; ++f) {
      const std::int64_t type = in.integer("field type");
      if (f > 0) types += ' ';
      types += std::to_string(type);
      symmetric_matrix = symmetric_matrix && type == 3;
    }
    if (!symmetric_matrix)
      in.fail_at(types_line, "SolAtVertices has field types '" + types +
                                 "'; a background metric is one field of type 3 (symmetric matrix)");
    metrics.reserve(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) {
      const int value_line = in.next_line();
      const double xx = in.real("metric component");
      const double xy = in.real("metric component");
      const double yy = in.real("metric component");
      Eigen::Matrix2d m;
      m << xx, xy, xy, yy;
      metrics.push_back(metric_from_file(in, value_line, m, "vertex " + std::to_string(i + 1)));
    }
    return true;
  });
  if (!solution) in.fail_at(end.line, "no SolAtVertices section");
  const std::vector<bool> has_value(nodes.size(), true);
  return compact(std::move(nodes), std::move(triangles), std::move(metrics), has_value, [](std::size_t) {});
}

// ---- the field ---------------------------------------------------------------------------

namespace {

// A point may lie this far outside a triangle, in units of the triangle's altitude (the
// barycentric coordinate is the signed distance to an edge over the altitude), and be in it.
constexpr double bary_tol_rel = 1e-10;
// Triangles with |det| <= degenerate_rel * (longest edge)^2 cover no area and are never located.
constexpr double degenerate_rel = 1e-13;
// A quadtree cell is split while it holds more than leaf_capacity triangles, is shallower than
// max_depth, and its side is larger than split_stop_rel times the smallest altitude of its
// triangles (below that, splitting cannot separate triangles that meet at one vertex).
constexpr std::size_t leaf_capacity = 8;
constexpr int max_depth = 40;
constexpr double split_stop_rel = 1.0;

// The affine-invariant mean stops when its Riemannian gradient (dimensionless) is this small.
constexpr double karcher_gradient_tol = 1e-12;
constexpr int karcher_max_iterations = 100;

// A symmetric 2x2 matrix in closed form: S = l1 u u^T + l2 v v^T with u = (c, s), v = (-s, c).
// With m = tr(S)/2 and d = sqrt(((a-c)/2)^2 + b^2), l1,2 = m +- d, and u is at the angle theta
// with cos 2 theta = (a-c)/(2d), sin 2 theta = b/d; the half-angle branch keeps the larger of
// cos theta, sin theta exact. Functions of S are f(l1) u u^T + f(l2) v v^T, which keeps the
// small eigenvalue's share exact for axis-aligned S.
struct SymEig2 {
  double l1, l2, c, s;
};

SymEig2 sym_eig2(const Eigen::Matrix2d& m) {
  const double a = m(0, 0), b = 0.5 * (m(0, 1) + m(1, 0)), c = m(1, 1);
  const double mean = 0.5 * (a + c), r = 0.5 * (a - c), d = std::hypot(r, b);
  if (!(d > 0)) return {mean, mean, 1, 0};
  const double cos2 = r / d, sin2 = b / d;
  double ct, st;
  if (cos2 >= 0) {
    ct = std::sqrt(0.5 * (1 + cos2));
    st = sin2 / (2 * ct);
  } else {
    st = std::sqrt(0.5 * (1 - cos2));
    ct = sin2 / (2 * st);
  }
  return {mean + d, mean - d, ct, st};
}

Eigen::Matrix2d sym_compose(double f1, double f2, const SymEig2& e) {
  const double cc = e.c * e.c, ss = e.s * e.s, cs = e.c * e.s;
  Eigen::Matrix2d r;
  r << f1 * cc + f2 * ss, (f1 - f2) * cs, (f1 - f2) * cs, f1 * ss + f2 * cc;
  return r;
}

Eigen::Matrix2d spd_log2(const Eigen::Matrix2d& m) {
  const SymEig2 e = sym_eig2(m);
  return sym_compose(std::log(e.l1), std::log(e.l2), e);
}

// The metric exp(S): sizes exp(-l/2) along the eigenvectors (a size h means eigenvalue 1/h^2).
Metric<2> metric_exp2(const Eigen::Matrix2d& s) {
  const SymEig2 e = sym_eig2(s);
  Eigen::Matrix2d dirs;
  dirs << e.c, -e.s, e.s, e.c;
  return Metric<2>::from_directions(dirs, Eigen::Vector2d(std::exp(-0.5 * e.l1), std::exp(-0.5 * e.l2)));
}

// The SPD matrix x as a metric, without a second validation.
Metric<2> metric_from_spd(const Eigen::Matrix2d& x) {
  const SymEig2 e = sym_eig2(x);
  Eigen::Matrix2d dirs;
  dirs << e.c, -e.s, e.s, e.c;
  return Metric<2>::from_directions(dirs, Eigen::Vector2d(1 / std::sqrt(e.l1), 1 / std::sqrt(e.l2)));
}

// Weighted Karcher mean of three metrics in the affine-invariant distance (Pennec et al., the
// paper's ref. [15]): the minimiser of sum w_i d(X, M_i)^2, d(X, M) = |log(X^-1/2 M X^-1/2)|_F.
// Steepest descent in a whitened frame X = E E^T, from the log-Euclidean mean: with
// W_i = E^-1 M_i E^-T, the descent direction is T = sum w_i log W_i, and the geodesic
// X(tau) = E exp(tau T) E^T updates E <- E exp(tau T / 2), W_i <- R W_i R with R = exp(-tau T / 2).
// The step is the secant root of the directional derivative phi'(tau) = -<T(tau), T> between
// tau = 0 (-|T|^2) and tau = 1; the objective is geodesically convex, so phi'(1) >= 0 unless
// tau = 1 is itself short, and the secant step stays in (0, 1]. Near the mean (neighbouring
// background nodes) tau ~ 1 and one or two iterations suffice.
Metric<2> karcher_mean3(const std::array<const Eigen::Matrix2d*, 3>& m,
                        const std::array<const Eigen::Matrix2d*, 3>& logs, const Eigen::Vector3d& w) {
  const Eigen::Matrix2d l0 = w[0] * *logs[0] + w[1] * *logs[1] + w[2] * *logs[2];
  const SymEig2 e0 = sym_eig2(l0);
  const double h1 = std::exp(0.5 * e0.l1), h2 = std::exp(0.5 * e0.l2);
  Eigen::Matrix2d e = sym_compose(h1, h2, e0);
  const Eigen::Matrix2d e_inv = sym_compose(1 / h1, 1 / h2, e0);
  std::array<Eigen::Matrix2d, 3> wm, wl, wm1, wl1;
  for (std::size_t i = 0; i < 3; ++i) {
    wm[i] = e_inv * *m[i] * e_inv;
    wl[i] = spd_log2(wm[i]);
  }
  for (int it = 0; it < karcher_max_iterations; ++it) {
    const Eigen::Matrix2d t = w[0] * wl[0] + w[1] * wl[1] + w[2] * wl[2];
    const double g2 = t.squaredNorm();
    if (g2 <= karcher_gradient_tol * karcher_gradient_tol) break;
    // Trial step tau = 1.
    const SymEig2 et = sym_eig2(t);
    double r1 = std::exp(-0.5 * et.l1), r2 = std::exp(-0.5 * et.l2);
    Eigen::Matrix2d r = sym_compose(r1, r2, et);
    for (std::size_t i = 0; i < 3; ++i) {
      wm1[i] = r * wm[i] * r;
      wl1[i] = spd_log2(wm1[i]);
    }
    const Eigen::Matrix2d t1 = w[0] * wl1[0] + w[1] * wl1[1] + w[2] * wl1[2];
    const double slope1 = -t1.cwiseProduct(t).sum();  // phi'(1)
    const double tau = slope1 > 0 ? g2 / (g2 + slope1) : 1.0;
    constexpr double accept_unit_step = 0.999;
    if (tau >= accept_unit_step) {
      wm = wm1;
      wl = wl1;
      e = e * sym_compose(1 / r1, 1 / r2, et);
      continue;
    }
    r1 = std::exp(-0.5 * tau * et.l1);
    r2 = std::exp(-0.5 * tau * et.l2);
    r = sym_compose(r1, r2, et);
    for (std::size_t i = 0; i < 3; ++i) {
      wm[i] = r * wm[i] * r;
      wl[i] = spd_log2(wm[i]);
    }
    e = e * sym_compose(1 / r1, 1 / r2, et);
  }
  const Eigen::Matrix2d x = e * e.transpose();
  return metric_from_spd(0.5 * (x + x.transpose()));
}

}  // namespace

struct BackgroundMetricField::Quadtree {
  // A node is a square cell; the root's centre and half side are stored, children are found by
  // halving. Leaves list the triangles that meet their cell (closed, widened by the locate
  // tolerance), so the triangle containing a point is among those of the point's leaf.
  struct Node {
    std::int32_t first_child = -1;  // four consecutive nodes, or -1; child k: bit 0 right, bit 1 above
    std::int32_t begin = 0, count = 0;
  };
  std::vector<Node> nodes;
  std::vector<std::int32_t> items;
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double half = 0;

  // Per triangle: vertex 0 and the inverse of [v1 - v0, v2 - v0] (NaN if degenerate), side by
  // side for one cache line per barycentric test; the smallest altitude and the longest edge.
  struct Affine {
    Eigen::Vector2d origin;
    Eigen::Matrix2d inverse;
  };
  std::vector<Affine> affine;
  std::vector<double> min_altitude, diameter;
  std::vector<bool> valid;

  static int quadrant(const Eigen::Vector2d& x, const Eigen::Vector2d& c) {
    return (x[0] >= c[0]) + 2 * (x[1] >= c[1]);
  }
  static Eigen::Vector2d child_center(const Eigen::Vector2d& c, double half, int q) {
    return {c[0] + ((q & 1) ? 0.5 : -0.5) * half, c[1] + ((q & 2) ? 0.5 : -0.5) * half};
  }
};

namespace {

// Squared distance from x to the axis-aligned square (c, half); 0 inside.
double box_distance2(const Eigen::Vector2d& x, const Eigen::Vector2d& c, double half) {
  const double dx = std::max(0.0, std::abs(x[0] - c[0]) - half);
  const double dy = std::max(0.0, std::abs(x[1] - c[1]) - half);
  return dx * dx + dy * dy;
}

// Closest point to x on the segment p q.
Eigen::Vector2d closest_on_segment(const Eigen::Vector2d& x, const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
  const Eigen::Vector2d e = q - p;
  const double len2 = e.squaredNorm();
  const double t = len2 > 0 ? std::clamp((x - p).dot(e) / len2, 0.0, 1.0) : 0.0;
  return p + t * e;
}

// Does the triangle (p0, p1, p2) meet the square (c, half) widened by margin? Separating axes:
// the square's two axes and the three edge normals.
bool triangle_meets_square(const std::array<Eigen::Vector2d, 3>& p, const Eigen::Vector2d& c, double half) {
  for (int d = 0; d < 2; ++d) {
    const double lo = std::min({p[0][d], p[1][d], p[2][d]}), hi = std::max({p[0][d], p[1][d], p[2][d]});
    if (lo > c[d] + half || hi < c[d] - half) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector2d& a = p[static_cast<std::size_t>(i)];
    const Eigen::Vector2d& b = p[static_cast<std::size_t>((i + 1) % 3)];
    const Eigen::Vector2d& o = p[static_cast<std::size_t>((i + 2) % 3)];
    Eigen::Vector2d n(b[1] - a[1], a[0] - b[0]);
    if (n.dot(o - a) > 0) n = -n;  // outward
    // The square's corner deepest inside the edge's half plane.
    if (n.dot(c - a) - half * (std::abs(n[0]) + std::abs(n[1])) > 0) return false;
  }
  return true;
}

}  // namespace

BackgroundMetricField::BackgroundMetricField(BackgroundMesh mesh, MetricMean mean)
    : mesh_(std::move(mesh)), mean_(mean), tree_(std::make_unique<Quadtree>()) {
  // 1. Validate the mesh.
  const std::size_t num_nodes = mesh_.nodes.size(), num_tris = mesh_.triangles.size();
  if (mesh_.metrics.size() != num_nodes)
    throw InputError("background mesh: " + std::to_string(mesh_.metrics.size()) + " metrics for " +
                     std::to_string(num_nodes) + " nodes");
  if (num_tris > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InputError("background mesh: too many triangles");
  for (std::size_t i = 0; i < num_nodes; ++i)
    if (!mesh_.nodes[i].allFinite()) throw InputError("background mesh: node " + std::to_string(i) + " is not finite");
  for (std::size_t t = 0; t < num_tris; ++t)
    for (NodeId v : mesh_.triangles[t])
      if (v < 0 || static_cast<std::size_t>(v) >= num_nodes)
        throw InputError("background mesh: triangle " + std::to_string(t) + " refers to node " + std::to_string(v) +
                         " of " + std::to_string(num_nodes));

  // 2. Node logarithms: the log-Euclidean mean is then one exp, and it starts the
  //    affine-invariant iteration.
  logs_.reserve(num_nodes);
  for (const Metric<2>& m : mesh_.metrics) logs_.push_back(m.log());

  // 3. Per-triangle affine data.
  Quadtree& q = *tree_;
  q.affine.resize(num_tris);
  q.min_altitude.resize(num_tris);
  q.diameter.resize(num_tris);
  q.valid.resize(num_tris);
  std::vector<std::int32_t> all;
  all.reserve(num_tris);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  double max_margin = 0;
  for (std::size_t t = 0; t < num_tris; ++t) {
    const auto& tri = mesh_.triangles[t];
    const Eigen::Vector2d &a = mesh_.nodes[tri[0]], &b = mesh_.nodes[tri[1]], &c = mesh_.nodes[tri[2]];
    Eigen::Matrix2d e;
    e << b - a, c - a;
    const double det = e.determinant();
    const double longest = std::sqrt(std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()}));
    q.affine[t].origin = a;
    q.diameter[t] = longest;
    q.valid[t] = std::abs(det) > degenerate_rel * longest * longest && std::isfinite(det);
    if (!q.valid[t]) {
      q.affine[t].inverse.setConstant(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    q.affine[t].inverse = e.inverse();
    q.min_altitude[t] = std::abs(det) / longest;
    all.push_back(static_cast<std::int32_t>(t));
    for (const Eigen::Vector2d* p : {&a, &b, &c}) {
      lo = lo.cwiseMin(*p);
      hi = hi.cwiseMax(*p);
    }
    max_margin = std::max(max_margin, 2 * bary_tol_rel * longest);
  }
  if (all.empty()) throw InputError("background mesh has no triangle of positive area");

  // 4. The quadtree: a square root cell around every triangle (widened by the largest locate
  //    margin), split recursively; O(N log N) for meshes of bounded vertex degree.
  q.center = 0.5 * (lo + hi);
  q.half = 0.5 * (hi - lo).maxCoeff() + max_margin;
  q.half *= 1 + 1e-12;
  q.nodes.push_back({});
  q.items.reserve(2 * all.size());
  struct Builder {
    const BackgroundMetricField& field;
    Quadtree& q;
    void build(std::size_t node, const Eigen::Vector2d& c, double half, int depth, std::vector<std::int32_t> tris) {
      double smallest = std::numeric_limits<double>::infinity();
      for (std::int32_t t : tris) smallest = std::min(smallest, q.min_altitude[static_cast<std::size_t>(t)]);
      if (tris.size() <= leaf_capacity || depth >= max_depth || 2 * half < split_stop_rel * smallest) {
        q.nodes[node].begin = static_cast<std::int32_t>(q.items.size());
        q.nodes[node].count = static_cast<std::int32_t>(tris.size());
        q.items.insert(q.items.end(), tris.begin(), tris.end());
        return;
      }
      const std::size_t first = q.nodes.size();
      q.nodes[node].first_child = static_cast<std::int32_t>(first);
      q.nodes.resize(first + 4);
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d cc = Quadtree::child_center(c, half, k);
        std::vector<std::int32_t> sub;
        for (std::int32_t t : tris) {
          const auto& tri = field.mesh_.triangles[static_cast<std::size_t>(t)];
          const double margin = 2 * bary_tol_rel * q.diameter[static_cast<std::size_t>(t)];
          if (triangle_meets_square({field.mesh_.nodes[tri[0]], field.mesh_.nodes[tri[1]], field.mesh_.nodes[tri[2]]},
                                    cc, 0.5 * half + margin))
            sub.push_back(t);
        }
        build(first + static_cast<std::size_t>(k), cc, 0.5 * half, depth + 1, std::move(sub));
      }
    }
  };
  Builder{*this, q}.build(0, q.center, q.half, 0, std::move(all));
}

BackgroundMetricField::~BackgroundMetricField() = default;

Eigen::Vector3d BackgroundMetricField::barycentric(int t, const Eigen::Vector2d& x) const {
  const auto i = static_cast<std::size_t>(t);
  const Quadtree::Affine& a = tree_->affine[i];
  const Eigen::Vector2d l = a.inverse * (x - a.origin);
  return {1 - l[0] - l[1], l[0], l[1]};
}

int BackgroundMetricField::locate(const Eigen::Vector2d& x) const {
  const Quadtree& q = *tree_;
  if (box_distance2(x, q.center, q.half) > 0) return -1;
  // Descend to the leaf holding x.
  std::size_t node = 0;
  Eigen::Vector2d c = q.center;
  double half = q.half;
  while (q.nodes[node].first_child >= 0) {
    const int k = Quadtree::quadrant(x, c);
    c = Quadtree::child_center(c, half, k);
    half *= 0.5;
    node = static_cast<std::size_t>(q.nodes[node].first_child + k);
  }
  // Of its triangles, the first with x inside, else the one x is least outside (within tolerance).
  int best = -1;
  double best_min = -bary_tol_rel;
  const Quadtree::Node& leaf = q.nodes[node];
  for (std::int32_t k = 0; k < leaf.count; ++k) {
    const int t = q.items[static_cast<std::size_t>(leaf.begin + k)];
    const double m = barycentric(t, x).minCoeff();
    if (m >= 0) return t;
    if (m >= best_min) {
      best_min = m;
      best = t;
    }
  }
  return best;
}

Metric<2> BackgroundMetricField::evaluate(const Eigen::Vector2d& x) const {
  if (!x.allFinite()) throw MesherError("background metric: evaluated at a non-finite point");
  int t = locate(x);
  Eigen::Vector3d w;
  if (t >= 0) {
    w = barycentric(t, x);
  } else {
    // Outside: the nearest triangle by branch and bound over the tree (children visited nearest
    // first, cells pruned by their distance), then the metric at its closest point. The closest
    // point of a triangle lies in a leaf that lists it, so pruning by cell distance is exact.
    const Quadtree& q = *tree_;
    struct Entry {
      std::int32_t node;
      double half, dist2;
      Eigen::Vector2d c;
    };
    std::array<Entry, 4 * max_depth + 8> stack;  // depth-first: at most 3 pending siblings a level
    std::size_t top = 0;
    stack[top++] = {0, q.half, box_distance2(x, q.center, q.half), q.center};
    double best2 = std::numeric_limits<double>::infinity();
    Eigen::Vector2d best_point = x;
    while (top > 0) {
      const Entry e = stack[--top];
      if (e.dist2 >= best2) continue;
      const Quadtree::Node& n = q.nodes[static_cast<std::size_t>(e.node)];
      if (n.first_child < 0) {
        for (std::int32_t k = 0; k < n.count; ++k) {
          const int tri = q.items[static_cast<std::size_t>(n.begin + k)];
          const auto& v = mesh_.triangles[static_cast<std::size_t>(tri)];
          for (int i = 0; i < 3; ++i) {
            const Eigen::Vector2d p =
                closest_on_segment(x, mesh_.nodes[v[static_cast<std::size_t>(i)]], mesh_.nodes[v[(i + 1) % 3]]);
            const double d2 = (p - x).squaredNorm();
            if (d2 < best2) {
              best2 = d2;
              best_point = p;
              t = tri;
            }
          }
        }
        continue;
      }
      std::array<Entry, 4> children;
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d cc = Quadtree::child_center(e.c, e.half, k);
        children[static_cast<std::size_t>(k)] = {n.first_child + k, 0.5 * e.half, box_distance2(x, cc, 0.5 * e.half),
                                                 cc};
      }
      std::sort(children.begin(), children.end(), [](const Entry& a, const Entry& b) { return a.dist2 > b.dist2; });
      for (const Entry& child : children)
        if (child.dist2 < best2) stack[top++] = child;
    }
    if (t < 0) throw MesherError("background metric: no nearest triangle (the point is too far away)");
    w = barycentric(t, best_point);
  }
  // Barycentric weights, clipped to the triangle (a point within the tolerance outside, or a
  // closest point on an edge, may give -1e-16).
  w = w.cwiseMax(0.0);
  w /= w.sum();
  const auto& v = mesh_.triangles[static_cast<std::size_t>(t)];
  const auto i0 = static_cast<std::size_t>(v[0]), i1 = static_cast<std::size_t>(v[1]),
             i2 = static_cast<std::size_t>(v[2]);
  // Weighted log-Euclidean mean exp(sum w_i log M_i), or the affine-invariant (Karcher) mean.
  if (mean_ == MetricMean::LogEuclidean) return metric_exp2(w[0] * logs_[i0] + w[1] * logs_[i1] + w[2] * logs_[i2]);
  return karcher_mean3({&mesh_.metrics[i0].matrix(), &mesh_.metrics[i1].matrix(), &mesh_.metrics[i2].matrix()},
                       {&logs_[i0], &logs_[i1], &logs_[i2]}, w);
}

}  // namespace metric
}  // namespace plaf
