// SPDX-License-Identifier: MIT
// Implements write_msh41 (msh_io.h): the Gmsh MSH 4.1 writer, ASCII or binary (Gmsh reference
// manual, "MSH file format"); the layout of groups, entities and blocks is documented in msh_io.h.
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

// A section's fields as MSH 4.1 stores them, mirroring the reader's TextFields / BinaryFields
// (msh_read.cpp): text tokens separated by spaces and line ends (file type 0), or Gmsh's binary
// layout (file type 1: ints of 4 bytes, size_t counts and tags of 8, doubles, no separators, and
// a line end after the section's data). One writer per section serves both.
struct TextOut {
  AtomicFile& f;
  void int32(std::int64_t v) { f.write_int(v); }
  void size(std::int64_t v) { f.write_int(v); }
  void real(double v) { f.write_double(v); }
  void sep() { f.put(' '); }
  void eol() { f.put('\n'); }
  void end() {}
};

struct BinaryOut {
  AtomicFile& f;
  void int32(std::int64_t v) {
    const auto x = static_cast<std::int32_t>(v);
    f.write_bytes(&x, sizeof x);
  }
  void size(std::int64_t v) {
    const auto x = static_cast<std::uint64_t>(v);
    f.write_bytes(&x, sizeof x);
  }
  void real(double v) { f.write_bytes(&v, sizeof v); }
  void sep() {}
  void eol() {}
  void end() { f.put('\n'); }  // the data ends with a line end before $End<Section>
};

template <class Out>
void write_box(Out& o, const Box& b) {
  for (int k = 0; k < 6; ++k) {
    o.real(b.empty() ? 0.0 : (k < 3 ? b.lo[k] : b.hi[k - 3]));
    o.sep();
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
// Dim-1, then the domain when there are cells (no group is empty). Both are text in a binary file
// too, the header followed by the integer 1 that tells the reader the byte order.
template <int Dim>
void write_physical_names(AtomicFile& f, const HybridMesh<Dim>& mesh, const MshLayout& l, MshEncoding encoding) {
  const int num_tags = static_cast<int>(mesh.tags.size());
  if (encoding == MshEncoding::binary) {
    f.write("$MeshFormat\n4.1 1 8\n");
    const std::int32_t one = 1;
    f.write_bytes(&one, sizeof one);
    f.write("\n$EndMeshFormat\n$PhysicalNames\n");
  } else {
    f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
  }
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
template <int Dim, class Out>
void write_entities(AtomicFile& f, Out o, const HybridMesh<Dim>& mesh, const MshLayout& l) {
  const int num_tags = static_cast<int>(mesh.tags.size());
  f.write("$Entities\n");
  const std::int64_t counts[4] = {0, Dim == 2 ? l.num_facet_groups : l.num_curve_groups,
                                  Dim == 2 ? 1 : l.num_facet_groups, Dim == 2 ? 0 : 1};
  for (int d = 0; d < 4; ++d) {
    o.size(counts[d]);
    if (d < 3) o.sep();
  }
  o.eol();
  // An entity: tag, bounding box, its physical group (none: 0), its bounding entities.
  auto write_entity = [&](int tag, const Box& box, int physical, const std::vector<int>& bounding) {
    o.int32(tag);
    o.sep();
    write_box(o, box);
    if (physical > 0) {
      o.size(1);
      o.sep();
      o.int32(physical);
    } else {
      o.size(0);
    }
    o.sep();
    o.size(static_cast<std::int64_t>(bounding.size()));
    for (int b : bounding) {
      o.sep();
      o.int32(b);
    }
    o.eol();
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
  o.end();
  f.write("$EndEntities\n");
}

// Nodes, all in the domain entity's block, tags 1..N; 2D points with z = 0.
template <int Dim, class Out>
void write_nodes(AtomicFile& f, Out o, const HybridMesh<Dim>& mesh) {
  const std::int64_t num_nodes = static_cast<std::int64_t>(mesh.nodes.size());
  f.write("$Nodes\n");
  const std::int64_t header[4] = {num_nodes > 0 ? 1 : 0, num_nodes, num_nodes > 0 ? 1 : 0, num_nodes};
  for (int k = 0; k < 4; ++k) {
    o.size(header[k]);
    if (k < 3) o.sep();
  }
  o.eol();
  if (num_nodes > 0) {
    o.int32(Dim);
    o.sep();
    o.int32(1);
    o.sep();
    o.int32(0);
    o.sep();
    o.size(num_nodes);
    o.eol();
    for (std::int64_t i = 1; i <= num_nodes; ++i) {
      o.size(i);
      o.eol();
    }
    for (const auto& x : mesh.nodes) {
      o.real(x[0]);
      o.sep();
      o.real(x[1]);
      o.sep();
      o.real(Dim == 3 ? x[Dim - 1] : 0.0);
      o.eol();
    }
  }
  o.end();
  f.write("$EndNodes\n");
}

// Elements: volume blocks, boundary blocks, then curves, tags 1..M in that order.
template <int Dim, class Out>
void write_elements(AtomicFile& f, Out o, const HybridMesh<Dim>& mesh, const MshLayout& l) {
  f.write("$Elements\n");
  const std::int64_t header[4] = {l.num_blocks, l.num_elements, l.num_elements > 0 ? 1 : 0, l.num_elements};
  for (int k = 0; k < 4; ++k) {
    o.size(header[k]);
    if (k < 3) o.sep();
  }
  o.eol();
  std::int64_t element_tag = 0;
  auto write_block = [&](const CellBlock& b, int entity_dim, int entity_tag) {
    if (b.size() == 0) return;
    o.int32(entity_dim);
    o.sep();
    o.int32(entity_tag);
    o.sep();
    o.int32(gmsh_element_type(b.type, b.order));
    o.sep();
    o.size(static_cast<std::int64_t>(b.size()));
    o.eol();
    const int per = b.nodes_per_cell();
    for (std::size_t i = 0; i < b.size(); ++i) {
      o.size(++element_tag);
      const NodeId* c = b.cell(i);
      for (int k = 0; k < per; ++k) {
        o.sep();
        o.size(c[k] + 1);
      }
      o.eol();
    }
  };
  for (const CellBlock& b : mesh.cells) write_block(b, Dim, 1);
  for (const CellBlock& b : mesh.boundary) write_block(b, Dim - 1, b.tag + 1);
  for (const CellBlock& b : mesh.curves) write_block(b, 1, b.tag + 1);
  o.end();
  f.write("$EndElements\n");
}

template <int Dim, class Out>
void write_sections(AtomicFile& f, Out o, const HybridMesh<Dim>& mesh, const MshLayout& l) {
  write_entities(f, o, mesh, l);
  write_nodes(f, o, mesh);
  write_elements(f, o, mesh, l);
}

// ---- MSH 2.2 (Gmsh reference manual, "Legacy formats": MSH file format version 2) ----------
// The same physical groups as 4.1 (names, dimensions and tags), nodes 1..N, and every element
// with two tags: its physical group and its elementary entity (the 4.1 entity tags). ASCII:
// "id type 2 physical elementary nodes..." per line; binary: per block of one type, the header
// (type, count, 2) then per element id, the two tags, the nodes, all 4-byte ints; nodes as an int
// id and three doubles. A 3D mesh without cells names its "domain" group all the same (there are
// no entities in 2.2), so that a reader takes the file as 3D.
template <int Dim>
void write_msh22_file(const HybridMesh<Dim>& mesh, const MshLayout& l, AtomicFile& f, MshEncoding encoding) {
  const bool binary = encoding == MshEncoding::binary;
  const int num_tags = static_cast<int>(mesh.tags.size());
  f.write(binary ? "$MeshFormat\n2.2 1 8\n" : "$MeshFormat\n2.2 0 8\n");
  if (binary) {
    const std::int32_t one = 1;
    f.write_bytes(&one, sizeof one);
    f.put('\n');
  }
  f.write("$EndMeshFormat\n$PhysicalNames\n");
  const bool domain = l.domain_group || Dim == 3;
  f.write_int(l.num_facet_groups + l.num_curve_groups + (domain ? 1 : 0));
  f.put('\n');
  auto group = [&](int dim, int tag, const std::string& name) {
    f.write_int(dim);
    f.put(' ');
    f.write_int(tag);
    f.write(" \"");
    f.write(name);
    f.write("\"\n");
  };
  for (int t = 0; t < num_tags; ++t)
    if (l.on_curves[static_cast<std::size_t>(t)]) group(1, t + 1, mesh.tags[static_cast<std::size_t>(t)].name);
  for (int t = 0; t < num_tags; ++t)
    if (l.facet_group(t)) group(Dim - 1, t + 1, mesh.tags[static_cast<std::size_t>(t)].name);
  if (domain) group(Dim, num_tags + 1, "domain");
  f.write("$EndPhysicalNames\n$Nodes\n");
  f.write_int(static_cast<std::int64_t>(mesh.nodes.size()));
  f.put('\n');
  std::int32_t id = 0;
  for (const auto& x : mesh.nodes) {
    ++id;
    const double xyz[3] = {x[0], x[1], Dim == 3 ? x[Dim - 1] : 0.0};
    if (binary) {
      f.write_bytes(&id, sizeof id);
      f.write_bytes(xyz, sizeof xyz);
    } else {
      f.write_int(id);
      for (double c : xyz) {
        f.put(' ');
        f.write_double(c);
      }
      f.put('\n');
    }
  }
  if (binary) f.put('\n');
  f.write("$EndNodes\n$Elements\n");
  f.write_int(l.num_elements);
  f.put('\n');
  std::int32_t element = 0;
  auto write_block = [&](const CellBlock& b, int physical, int elementary) {
    if (b.size() == 0) return;
    const std::int32_t type = gmsh_element_type(b.type, b.order);
    const int per = b.nodes_per_cell();
    if (binary) {
      const std::int32_t header[3] = {type, static_cast<std::int32_t>(b.size()), 2};
      f.write_bytes(header, sizeof header);
    }
    std::vector<std::int32_t> row(static_cast<std::size_t>(3 + per));
    for (std::size_t i = 0; i < b.size(); ++i) {
      row[0] = ++element;
      row[1] = physical;
      row[2] = elementary;
      for (int k = 0; k < per; ++k) row[static_cast<std::size_t>(3 + k)] = b.cell(i)[k] + 1;
      if (binary) {
        f.write_bytes(row.data(), row.size() * sizeof(std::int32_t));
        continue;
      }
      f.write_int(row[0]);
      f.put(' ');
      f.write_int(type);
      f.write(" 2");
      for (std::size_t k = 1; k < row.size(); ++k) {
        f.put(' ');
        f.write_int(row[k]);
      }
      f.put('\n');
    }
  };
  for (const CellBlock& b : mesh.cells) write_block(b, num_tags + 1, 1);
  for (const CellBlock& b : mesh.boundary) write_block(b, b.tag + 1, b.tag + 1);
  for (const CellBlock& b : mesh.curves) write_block(b, b.tag + 1, b.tag + 1);
  if (binary) f.put('\n');
  f.write("$EndElements\n");
}

}  // namespace

template <int Dim>
void write_msh22(const HybridMesh<Dim>& mesh, const std::filesystem::path& path, MshEncoding encoding) {
  const MshLayout layout = measure_msh(mesh, path);
  // MSH 2.2 stores ids and node numbers as ints of 4 bytes.
  if (static_cast<std::int64_t>(mesh.nodes.size()) > std::numeric_limits<std::int32_t>::max() ||
      layout.num_elements > std::numeric_limits<std::int32_t>::max())
    throw Error("cannot write " + path.string() + ": MSH 2.2 numbers nodes and elements with 4-byte ints; this mesh has " +
                std::to_string(mesh.nodes.size()) + " nodes and " + std::to_string(layout.num_elements) +
                " elements (write MSH 4.1)");
  AtomicFile f(path);
  write_msh22_file(mesh, layout, f, encoding);
  f.commit();
}

template void write_msh22(const HybridMesh<2>&, const std::filesystem::path&, MshEncoding);
template void write_msh22(const HybridMesh<3>&, const std::filesystem::path&, MshEncoding);

template <int Dim>
void write_msh41(const HybridMesh<Dim>& mesh, const std::filesystem::path& path, MshEncoding encoding) {
  // 1. Validate and measure before touching the file system.
  const MshLayout layout = measure_msh(mesh, path);
  AtomicFile f(path);
  // 2. The sections in the order of the format.
  write_physical_names(f, mesh, layout, encoding);
  if (encoding == MshEncoding::binary)
    write_sections(f, BinaryOut{f}, mesh, layout);
  else
    write_sections(f, TextOut{f}, mesh, layout);
  f.commit();
}

template void write_msh41(const HybridMesh<2>&, const std::filesystem::path&, MshEncoding);
template void write_msh41(const HybridMesh<3>&, const std::filesystem::path&, MshEncoding);

}  // namespace io
}  // namespace plaf
