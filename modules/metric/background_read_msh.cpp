// SPDX-License-Identifier: MIT
// Implements read_background_msh (background_metric.h): a background metric from a Gmsh MSH 4.1
// file, format from the Gmsh reference manual, "MSH file format" (version 4.1, $NodeData). The
// mesh is read by read_msh41; a second pass reads the node tags and the metric view, which
// read_msh41 does not keep.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "modules/io/msh_io.h"
#include "modules/io/text_cursor.h"
#include "modules/metric/background_metric.h"
#include "modules/metric/background_read.h"

namespace plaf {
inline namespace metric {
namespace {

template <int Dim>
struct NodeDataEntry {
  std::int64_t tag;
  int line;
  Metric<Dim> metric;
};

template <int Dim>
struct MshScan {
  std::vector<std::int64_t> node_tags;  // in file order, as read_msh41 numbers the nodes
  int elements_line = 1;
  int view_line = 0;  // 0: no $NodeData
  std::string view_name;
  std::vector<NodeDataEntry<Dim>> entries;
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
void scan_nodes(TextCursor& in, std::vector<std::int64_t>& node_tags) {
  const std::int64_t num_blocks = in.count("number of node blocks", 8);
  const std::int64_t num_nodes = in.count("number of nodes", 8);
  in.integer("minimum node tag");
  in.integer("maximum node tag");
  node_tags.reserve(static_cast<std::size_t>(num_nodes));
  for (std::int64_t b = 0; b < num_blocks; ++b) {
    const std::int64_t entity_dim = in.integer("entity dimension", 0, 3);
    in.integer("entity tag");
    const bool parametric = in.integer("parametric flag", 0, 1) == 1;
    const std::int64_t n = in.count("number of nodes in block", 4);
    for (std::int64_t i = 0; i < n; ++i) node_tags.push_back(in.integer("node tag"));
    const std::int64_t values = n * (3 + (parametric ? entity_dim : 0));
    for (std::int64_t i = 0; i < values; ++i) in.token("node coordinate");
  }
  in.expect("$EndNodes");
}

// The components a metric view of a Dim-dimensional run may have per node: 9 (a 3x3 tensor,
// row-major, as Gmsh stores tensors: xx xy xz yx yy yz zx zy zz; a 2D run uses its xx xy / yx yy
// block), and 4 (2x2, row-major) in 2D or 6 (xx xy yy xz yz zz, libMeshb's order) in 3D.
constexpr int full_components = 9;
template <int Dim>
constexpr int short_components = Dim == 2 ? 4 : 6;

template <int Dim>
Eigen::Matrix<double, Dim, Dim> tensor_from_components(const std::array<double, full_components>& v, int per) {
  if constexpr (Dim == 3) {
    if (per == short_components<3>) {
      std::array<double, Dim*(Dim + 1) / 2> packed{};
      std::copy_n(v.begin(), packed.size(), packed.begin());
      return symmetric_from_packed<Dim>(packed);
    }
  }
  Eigen::Matrix<double, Dim, Dim> m;
  const int row = per == full_components ? 3 : Dim;  // row-major: (i, j) at i * row + j
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) m(i, j) = v[static_cast<std::size_t>(i * row + j)];
  return m;
}

// Layout (MSH 4.1): string tags (the first is the view name), real tags (the first is the
// time), integer tags (time step, number of components, number of entries, [partition]), then
// one line per entry: node tag and the components.
template <int Dim>
void read_node_data(TextCursor& in, MshScan<Dim>& scan, int section_line) {
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
  if (components != full_components && components != short_components<Dim>)
    in.fail_at(components_line, "view '" + scan.view_name + "' has " + std::to_string(components) +
                                    " components per node; a metric view of a " + std::to_string(Dim) +
                                    "D run has 9 (3x3 tensor) or " +
                                    (Dim == 2 ? "4 (2x2 tensor)" : "6 (xx xy yy xz yz zz)"));
  const int per = static_cast<int>(components);
  const std::int64_t num_entries = in.count("number of entries", 2 * static_cast<std::size_t>(per) + 2);
  for (std::int64_t i = 3; i < num_integers; ++i) in.integer("integer tag");
  scan.entries.reserve(static_cast<std::size_t>(num_entries));
  std::array<double, full_components> v{};
  for (std::int64_t e = 0; e < num_entries; ++e) {
    const int line = in.next_line();
    const std::int64_t tag = in.integer("node tag");
    for (int k = 0; k < per; ++k) v[static_cast<std::size_t>(k)] = in.real("tensor component");
    scan.entries.push_back(
        {tag, line,
         metric_from_file<Dim>(in, line, tensor_from_components<Dim>(v, per), "node tag " + std::to_string(tag))});
  }
  in.expect("$EndNodeData");
}

// With read_view false, $NodeData is skipped (the node tags and the $Elements line are read).
template <int Dim>
MshScan<Dim> scan_msh(const std::filesystem::path& path, const std::string& text, bool read_view) {
  TextCursor in(path, text);
  MshScan<Dim> scan;
  while (!in.at_end()) {
    const int line = in.next_line();
    const std::string_view t = in.token("a section");
    if (t.size() < 2 || t[0] != '$') in.fail_at(line, "expected a section, found " + TextCursor::quote(t));
    const std::string name(t.substr(1));
    if (name == "Nodes") {
      scan_nodes(in, scan.node_tags);
    } else if (name == "NodeData" && read_view) {
      read_node_data(in, scan, line);
    } else {
      if (name == "Elements") scan.elements_line = line;
      skip_section(in, name, line);
    }
  }
  if (read_view && scan.view_line == 0)
    in.fail(std::string("no $NodeData view: a background metric needs one with a ") +
            (Dim == 2 ? "3x3 or 2x2" : "3x3") + " tensor per node");
  return scan;
}

// The prism (Gmsh order: 0 1 2 below 3 4 5) as three tetrahedra. Every quadrilateral face is cut
// along its diagonal through its first node (the smallest index), so a face shared by two prisms
// is cut alike from both sides (J. Dompierre et al., *How to Subdivide Pyramids, Prisms and
// Hexahedra into Tetrahedra*, IMR 1999). With the prism turned so that its first node is vertex
// 0, the two faces at 0 are cut through 0: the tetrahedron (0 3 4 5), then the pyramid of apex 0
// over the face 1 2 5 4, cut along 1-5 or 2-4.
void split_prism(const NodeId* p, std::vector<std::array<NodeId, 4>>& out) {
  const int first = static_cast<int>(std::min_element(p, p + 6) - p);
  const int r = first % 3, top = first / 3;  // turn by r, and swap the triangles if first is on top
  std::array<NodeId, 6> v{};
  for (int i = 0; i < 3; ++i) {
    v[static_cast<std::size_t>(i)] = p[3 * top + (i + r) % 3];
    v[static_cast<std::size_t>(i + 3)] = p[3 * (1 - top) + (i + r) % 3];
  }
  out.push_back({v[0], v[3], v[4], v[5]});
  if (std::min(v[1], v[5]) < std::min(v[2], v[4])) {
    out.push_back({v[0], v[1], v[2], v[5]});
    out.push_back({v[0], v[1], v[5], v[4]});
  } else {
    out.push_back({v[0], v[1], v[2], v[4]});
    out.push_back({v[0], v[4], v[2], v[5]});
  }
}

// The linear simplices of the cells: their vertices (high-order nodes go); 2D quadrilaterals split
// along 0-2, 3D prisms by split_prism.
std::vector<std::array<NodeId, 3>> linear_simplices(const HybridMesh<2>& mesh) {
  std::vector<std::array<NodeId, 3>> out;
  for (const CellBlock& b : mesh.cells)
    for (std::size_t c = 0; c < b.size(); ++c) {
      const NodeId* v = b.cell(c);
      out.push_back({v[0], v[1], v[2]});
      if (b.type == CellType::Quadrilateral) out.push_back({v[0], v[2], v[3]});
    }
  return out;
}

std::vector<std::array<NodeId, 4>> linear_simplices(const HybridMesh<3>& mesh) {
  std::vector<std::array<NodeId, 4>> out;
  for (const CellBlock& b : mesh.cells)
    for (std::size_t c = 0; c < b.size(); ++c) {
      const NodeId* v = b.cell(c);
      if (b.type == CellType::Prism)
        split_prism(v, out);
      else
        out.push_back({v[0], v[1], v[2], v[3]});
    }
  return out;
}

}  // namespace

template <int Dim>
BackgroundMesh<Dim> read_background_msh(const std::filesystem::path& path) {
  // 1. The mesh part, validated by the MSH reader; its nodes are in file order.
  const MshMesh msh = read_msh41(path);
  // 2. Node tags and the metric view, once the mesh has the run's dimension: read from an ASCII
  //    MSH 4.1 file (the mesh reader takes 2.2 and binary files too; this scan does not).
  const std::string text = read_whole_file(path);
  TextCursor in(path, text);
  {
    const std::size_t at = text.find("$MeshFormat");
    const std::size_t line = text.find('\n', at);
    const std::string format = at == std::string::npos || line == std::string::npos ? "" : text.substr(line + 1, 7);
    if (format != "4.1 0 8")
      in.fail_at(2, "a background metric is read from an ASCII MSH 4.1 file (this one is '" + format.substr(0, 5) +
                        "...': save it as ASCII MSH 4.1, e.g. gmsh FILE -0 -format msh41 -save_all -o OUT.msh; "
                        "a .mesh/.sol pair works too)");
  }
  if (msh.dim != Dim)
    in.fail_at(scan_msh<Dim>(path, text, false).elements_line, "the background mesh is " + std::to_string(msh.dim) +
                                                                   "D; a " + std::to_string(Dim) + "D run needs a " +
                                                                   std::to_string(Dim) + "D background mesh");
  const MshScan<Dim> scan = scan_msh<Dim>(path, text, true);
  const HybridMesh<Dim>* mesh = nullptr;
  if constexpr (Dim == 2)
    mesh = &msh.mesh2;
  else
    mesh = &msh.mesh3;
  if (scan.node_tags.size() != mesh->nodes.size())
    in.fail_at(scan.elements_line, "node count mismatch between $Nodes and the mesh read");
  std::vector<typename BackgroundMesh<Dim>::Simplex> simplices = linear_simplices(*mesh);
  if (simplices.empty())
    in.fail_at(scan.elements_line, Dim == 2 ? "no triangles or quadrilaterals: the background mesh has no cells"
                                            : "no tetrahedra or prisms: the background mesh has no volume cells");
  // 3. Node tag -> index, then one metric per node.
  std::unordered_map<std::int64_t, std::size_t> index;
  index.reserve(scan.node_tags.size());
  for (std::size_t i = 0; i < scan.node_tags.size(); ++i) index.emplace(scan.node_tags[i], i);
  std::vector<Metric<Dim>> metrics(mesh->nodes.size());
  std::vector<bool> has_value(mesh->nodes.size(), false);
  for (const NodeDataEntry<Dim>& e : scan.entries) {
    const auto it = index.find(e.tag);
    if (it == index.end()) in.fail_at(e.line, "$NodeData refers to unknown node tag " + std::to_string(e.tag));
    if (has_value[it->second]) in.fail_at(e.line, "$NodeData gives node tag " + std::to_string(e.tag) + " twice");
    has_value[it->second] = true;
    metrics[it->second] = e.metric;
  }
  // 4. The vertices of the simplices, each with its metric.
  std::vector<typename BackgroundMesh<Dim>::Point> nodes(mesh->nodes.begin(), mesh->nodes.end());
  return compact_background_mesh<Dim>(
      std::move(nodes), std::move(simplices), std::move(metrics), has_value, [&](std::size_t i) {
        in.fail_at(scan.view_line, "view '" + scan.view_name + "' has no value at node tag " +
                                       std::to_string(scan.node_tags[i]) + ", a vertex of the mesh");
      });
}
template BackgroundMesh<2> read_background_msh<2>(const std::filesystem::path&);
template BackgroundMesh<3> read_background_msh<3>(const std::filesystem::path&);

}  // namespace metric
}  // namespace plaf
