// SPDX-License-Identifier: MIT
// Implements read_background_msh (background_metric.h): a background metric from a Gmsh MSH 4.1
// file, format from the Gmsh reference manual, "MSH file format" (version 4.1, $NodeData). The
// mesh is read by read_msh41; a second pass reads the node tags and the metric view, which
// read_msh41 does not keep.
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

}  // namespace

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
  return compact_background_mesh(
      std::move(nodes), std::move(triangles), std::move(metrics), has_value, [&](std::size_t i) {
        in.fail_at(scan.view_line, "view '" + scan.view_name + "' has no value at node tag " +
                                       std::to_string(scan.node_tags[i]) + ", a vertex of the mesh");
      });
}

}  // namespace metric
}  // namespace plaf
