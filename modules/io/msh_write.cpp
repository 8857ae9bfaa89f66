// SPDX-License-Identifier: MIT
// Implements write_msh41 (msh_io.h): the Gmsh MSH 4.1 ASCII writer (Gmsh reference manual, "MSH
// file format"); the layout of groups, entities and blocks is documented in msh_io.h.
#include "modules/io/msh_io.h"

#include <algorithm>
#include <array>
#include <set>
#include <utility>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/io/atomic_file.h"
#include "modules/io/text_cursor.h"

namespace plaf {
inline namespace io {
namespace {

struct Box {
  std::array<double, 3> lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity()};
  std::array<double, 3> hi{-lo[0], -lo[1], -lo[2]};
  bool empty() const { return lo[0] > hi[0]; }
  template <class P>
  void add(const P& p) {
    for (int d = 0; d < static_cast<int>(p.size()); ++d) {
      lo[d] = std::min(lo[d], p[d]);
      hi[d] = std::max(hi[d], p[d]);
    }
    for (int d = static_cast<int>(p.size()); d < 3; ++d) lo[d] = hi[d] = 0.0;
  }
};

void write_box(AtomicFile& f, const Box& b) {
  for (int k = 0; k < 6; ++k) {
    f.write_double(b.empty() ? 0.0 : (k < 3 ? b.lo[k] : b.hi[k - 3]));
    f.put(' ');
  }
}

template <int Dim>
void check_block(const HybridMesh<Dim>& mesh, const CellBlock& b, int dim, const std::filesystem::path& path) {
  auto fail = [&](const std::string& why) {
    throw Error("cannot write " + path.string() + ": " + std::string(cell_name(b.type)) + " block of order " +
                std::to_string(b.order) + " " + why);
  };
  if (ref_dim(b.type) != dim)
    fail("has dimension " + std::to_string(ref_dim(b.type)) + ", expected " + std::to_string(dim));
  if (b.order < 1 || b.order > max_order) fail("has an order outside 1.." + std::to_string(max_order));
  if (b.connectivity.size() % static_cast<std::size_t>(b.nodes_per_cell()) != 0)
    fail("has a connectivity length that is not a multiple of " + std::to_string(b.nodes_per_cell()));
  const auto n = static_cast<NodeId>(mesh.nodes.size());
  for (NodeId v : b.connectivity)
    if (v < 0 || v >= n) fail("refers to node " + std::to_string(v) + " of " + std::to_string(n));
}

// What the file's headers need, measured before the file system is touched: which tags get a
// facet group and entity and which a curve group and entity (3D), their bounding boxes, and the
// element and block counts.
struct MshLayout {
  std::vector<Box> tag_box, curve_box;  // per tag: of its boundary facets, of its curves
  std::vector<char> on_facets, on_curves;
  int num_facet_groups = 0, num_curve_groups = 0;
  Box domain_box;
  bool domain_group = false;  // the mesh has cells: a "domain" physical group
  // 3D: per facet tag, the curve tags (entity tags = tag index + 1) with an edge on the rim of
  // that tag's facets.
  std::vector<std::vector<int>> bounding_curves;
  std::int64_t num_elements = 0, num_blocks = 0;

  // A tag without facets (a curve tag, or an unused one) has no facet group or entity.
  bool facet_group(int t) const { return on_facets[static_cast<std::size_t>(t)] != 0; }
};

// 3D: the curve tags on the rim of each facet tag (edges, by their two vertices, that one facet of
// the tag uses: Gmsh's bounding curves of a surface; a curve inside a patch is not one).
template <int Dim>
std::vector<std::vector<int>> rim_curves(const HybridMesh<Dim>& mesh, int num_tags) {
  std::vector<std::vector<int>> result(static_cast<std::size_t>(num_tags));
  if (Dim != 3 || mesh.curves.empty()) return result;
  using Edge = std::pair<NodeId, NodeId>;
  auto edge = [](NodeId a, NodeId b) { return a < b ? Edge{a, b} : Edge{b, a}; };
  std::vector<std::set<Edge>> rim(static_cast<std::size_t>(num_tags));
  for (const CellBlock& b : mesh.boundary) {
    std::set<Edge>& r = rim[static_cast<std::size_t>(b.tag)];
    const int nv = num_vertices(b.type);
    for (std::size_t i = 0; i < b.size(); ++i) {
      const NodeId* c = b.cell(i);
      for (int k = 0; k < nv; ++k) {
        const Edge e = edge(c[k], c[(k + 1) % nv]);
        if (!r.erase(e)) r.insert(e);  // an edge two facets share is inside the patch
      }
    }
  }
  for (int t = 0; t < num_tags; ++t) {
    const std::set<Edge>& r = rim[static_cast<std::size_t>(t)];
    std::set<int> found;
    for (const CellBlock& b : mesh.curves)
      for (std::size_t i = 0; i < b.size() && !found.count(b.tag); ++i)
        if (r.count(edge(b.cell(i)[0], b.cell(i)[1]))) found.insert(b.tag);
    result[static_cast<std::size_t>(t)].assign(found.begin(), found.end());
  }
  return result;
}

// Validates the mesh (Error naming the path) and measures it.
template <int Dim>
MshLayout measure_msh(const HybridMesh<Dim>& mesh, const std::filesystem::path& path) {
  MshLayout l;
  const int num_tags = static_cast<int>(mesh.tags.size());
  for (const BoundaryTag& t : mesh.tags)
    if (t.name.find_first_of("\"\n\r") != std::string::npos)
      throw Error("cannot write " + path.string() + ": boundary tag name " + TextCursor::quote(t.name) +
                  " contains a quote or a line break");
  for (const CellBlock& b : mesh.cells) check_block(mesh, b, Dim, path);
  l.tag_box.resize(static_cast<std::size_t>(num_tags));
  for (const CellBlock& b : mesh.boundary) {
    check_block(mesh, b, Dim - 1, path);
    if (b.tag < 0 || b.tag >= num_tags)
      throw Error("cannot write " + path.string() + ": boundary block has tag index " + std::to_string(b.tag) +
                  " but the mesh has " + std::to_string(num_tags) + " tags");
    for (NodeId v : b.connectivity) l.tag_box[static_cast<std::size_t>(b.tag)].add(mesh.nodes[v]);
  }
  // Curves (3D): which tags they use.
  if (Dim != 3 && !mesh.curves.empty())
    throw Error("cannot write " + path.string() + ": a 2D mesh has curves blocks (curves are 3D only)");
  l.curve_box.resize(static_cast<std::size_t>(num_tags));
  l.on_facets.assign(static_cast<std::size_t>(num_tags), 0);
  l.on_curves = l.on_facets;
  for (const CellBlock& b : mesh.boundary)
    if (b.size() > 0) l.on_facets[static_cast<std::size_t>(b.tag)] = 1;
  for (const CellBlock& b : mesh.curves) {
    check_block(mesh, b, 1, path);
    if (b.tag < 0 || b.tag >= num_tags)
      throw Error("cannot write " + path.string() + ": curves block has tag index " + std::to_string(b.tag) +
                  " but the mesh has " + std::to_string(num_tags) + " tags");
    if (b.size() > 0) l.on_curves[static_cast<std::size_t>(b.tag)] = 1;
    for (NodeId v : b.connectivity) l.curve_box[static_cast<std::size_t>(b.tag)].add(mesh.nodes[v]);
  }
  for (int t = 0; t < num_tags; ++t) {
    l.num_facet_groups += l.facet_group(t) ? 1 : 0;
    l.num_curve_groups += l.on_curves[static_cast<std::size_t>(t)] ? 1 : 0;
  }
  for (const CellBlock& b : mesh.cells) l.domain_group = l.domain_group || b.size() > 0;
  l.bounding_curves = rim_curves(mesh, num_tags);
  for (const auto& x : mesh.nodes) l.domain_box.add(x);
  for (const auto* blocks : {&mesh.cells, &mesh.boundary, &mesh.curves})
    for (const CellBlock& b : *blocks)
      if (b.size() > 0) {
        l.num_elements += static_cast<std::int64_t>(b.size());
        ++l.num_blocks;
      }
  return l;
}

// The header and the physical groups: curve tags at dimension 1, boundary tags at dimension
// Dim-1, then the domain when there are cells (no group is empty).
template <int Dim>
void write_physical_names(AtomicFile& f, const HybridMesh<Dim>& mesh, const MshLayout& l) {
  const int num_tags = static_cast<int>(mesh.tags.size());
  f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
  f.write_int(l.num_facet_groups + l.num_curve_groups + (l.domain_group ? 1 : 0));
  f.put('\n');
  auto write_group = [&](int dim, int t) {
    f.write_int(dim);
    f.put(' ');
    f.write_int(t + 1);
    f.write(" \"");
    f.write(mesh.tags[static_cast<std::size_t>(t)].name);
    f.write("\"\n");
  };
  for (int t = 0; t < num_tags; ++t)
    if (l.on_curves[static_cast<std::size_t>(t)]) write_group(1, t);
  for (int t = 0; t < num_tags; ++t)
    if (l.facet_group(t)) write_group(Dim - 1, t);
  if (l.domain_group) {
    f.write_int(Dim);
    f.put(' ');
    f.write_int(num_tags + 1);
    f.write(" \"domain\"\n");
  }
  f.write("$EndPhysicalNames\n");
}

// Entities: no points; one curve entity per curve tag (3D), one facet entity per facet tag, and
// the domain entity (also without cells: it marks a 3D surface mesh as 3D), each with its
// bounding entities: the domain's are the facet entities, a 3D facet entity's the curve entities
// on its rim; curves have no bounding points (closed loops, or ends that are not entities).
template <int Dim>
void write_entities(AtomicFile& f, const HybridMesh<Dim>& mesh, const MshLayout& l) {
  const int num_tags = static_cast<int>(mesh.tags.size());
  f.write("$Entities\n0 ");
  if (Dim == 2) {
    f.write_int(l.num_facet_groups);
    f.write(" 1 0\n");
  } else {
    f.write_int(l.num_curve_groups);
    f.put(' ');
    f.write_int(l.num_facet_groups);
    f.write(" 1\n");
  }
  // An entity line: tag, bounding box, its physical group (none: 0), its bounding entities.
  auto write_entity = [&](int tag, const Box& box, int physical, const std::vector<int>& bounding) {
    f.write_int(tag);
    f.put(' ');
    write_box(f, box);
    if (physical > 0) {
      f.write("1 ");
      f.write_int(physical);
    } else {
      f.put('0');
    }
    f.put(' ');
    f.write_int(static_cast<std::int64_t>(bounding.size()));
    for (int b : bounding) {
      f.put(' ');
      f.write_int(b);
    }
    f.put('\n');
  };
  if (Dim == 3)
    for (int t = 0; t < num_tags; ++t)
      if (l.on_curves[static_cast<std::size_t>(t)]) write_entity(t + 1, l.curve_box[static_cast<std::size_t>(t)], t + 1, {});
  std::vector<int> facet_entities;
  for (int t = 0; t < num_tags; ++t)
    if (l.facet_group(t)) {
      std::vector<int> rim;
      for (int c : l.bounding_curves[static_cast<std::size_t>(t)]) rim.push_back(c + 1);
      write_entity(t + 1, l.tag_box[static_cast<std::size_t>(t)], t + 1, rim);
      facet_entities.push_back(t + 1);
    }
  write_entity(1, l.domain_box, l.domain_group ? num_tags + 1 : 0, facet_entities);
  f.write("$EndEntities\n");
}

// Nodes, all in the domain entity's block, tags 1..N.
template <int Dim>
void write_nodes(AtomicFile& f, const HybridMesh<Dim>& mesh) {
  const std::int64_t num_nodes = static_cast<std::int64_t>(mesh.nodes.size());
  f.write("$Nodes\n");
  if (num_nodes == 0) {
    f.write("0 0 0 0\n");
  } else {
    f.write("1 ");
    f.write_int(num_nodes);
    f.write(" 1 ");
    f.write_int(num_nodes);
    f.put('\n');
    f.write_int(Dim);
    f.write(" 1 0 ");
    f.write_int(num_nodes);
    f.put('\n');
    for (std::int64_t i = 1; i <= num_nodes; ++i) {
      f.write_int(i);
      f.put('\n');
    }
    for (const auto& x : mesh.nodes) f.write_point_line(x);
  }
  f.write("$EndNodes\n");
}

// Elements: volume blocks, boundary blocks, then curves, tags 1..M in that order.
template <int Dim>
void write_elements(AtomicFile& f, const HybridMesh<Dim>& mesh, const MshLayout& l) {
  f.write("$Elements\n");
  f.write_int(l.num_blocks);
  f.put(' ');
  f.write_int(l.num_elements);
  f.write(l.num_elements > 0 ? " 1 " : " 0 ");
  f.write_int(l.num_elements);
  f.put('\n');
  std::int64_t element_tag = 0;
  auto write_block = [&](const CellBlock& b, int entity_dim, int entity_tag) {
    if (b.size() == 0) return;
    f.write_int(entity_dim);
    f.put(' ');
    f.write_int(entity_tag);
    f.put(' ');
    f.write_int(gmsh_element_type(b.type, b.order));
    f.put(' ');
    f.write_int(static_cast<std::int64_t>(b.size()));
    f.put('\n');
    const int per = b.nodes_per_cell();
    for (std::size_t i = 0; i < b.size(); ++i) {
      f.write_int(++element_tag);
      const NodeId* c = b.cell(i);
      for (int k = 0; k < per; ++k) {
        f.put(' ');
        f.write_int(c[k] + 1);
      }
      f.put('\n');
    }
  };
  for (const CellBlock& b : mesh.cells) write_block(b, Dim, 1);
  for (const CellBlock& b : mesh.boundary) write_block(b, Dim - 1, b.tag + 1);
  for (const CellBlock& b : mesh.curves) write_block(b, 1, b.tag + 1);
  f.write("$EndElements\n");
}

}  // namespace

template <int Dim>
void write_msh41(const HybridMesh<Dim>& mesh, const std::filesystem::path& path) {
  // 1. Validate and measure before touching the file system.
  const MshLayout layout = measure_msh(mesh, path);
  AtomicFile f(path);
  // 2. The sections in the order of the format.
  write_physical_names(f, mesh, layout);
  write_entities(f, mesh, layout);
  write_nodes(f, mesh);
  write_elements(f, mesh, layout);
  f.commit();
}

template void write_msh41(const HybridMesh<2>&, const std::filesystem::path&);
template void write_msh41(const HybridMesh<3>&, const std::filesystem::path&);

}  // namespace io
}  // namespace plaf
