// SPDX-License-Identifier: MIT
// Implements the .vtu writer (VTK file formats, "XML File Formats": UnstructuredGrid) with
// VTK 9's Lagrange cells; see vtu_writer.h for the choices.
#include "modules/io/vtu_writer.h"

#include <algorithm>
#include <string_view>

#include "modules/io/atomic_file.h"
#include "modules/base/error.h"

namespace plaf {
inline namespace io {
namespace {

std::string xml_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void data_array(AtomicFile& f, const char* type, const std::string& name, int components) {
  f.write("        <DataArray type=\"");
  f.write(type);
  f.write("\" Name=\"");
  f.write(xml_escape(name));
  f.write("\"");
  if (components > 1) {
    f.write(" NumberOfComponents=\"");
    f.write_int(components);
    f.write("\"");
  }
  f.write(" format=\"ascii\">\n");
}

constexpr std::string_view end_data_array = "        </DataArray>\n";

}  // namespace

int vtk_cell_type(CellType type, int order) {
  check_order(order);
  const bool linear = order == 1;
  switch (type) {
    case CellType::Line:
      return linear ? 3 : 4;  // order >= 2: VTK_POLY_LINE through the nodes (vtu_writer.h)
    case CellType::Triangle:
      return linear ? 5 : 69;
    case CellType::Quadrilateral:
      return linear ? 9 : 70;
    case CellType::Tetrahedron:
      return linear ? 10 : 71;
    case CellType::Prism:
      return linear ? 13 : 73;
  }
  return 0;
}

std::vector<int> vtk_node_permutation(CellType type, int order) {
  if (order == 1) {
    std::vector<int> perm(static_cast<std::size_t>(num_vertices(type)));
    for (std::size_t k = 0; k < perm.size(); ++k) perm[k] = static_cast<int>(k);
    if (type == CellType::Prism) perm = {0, 2, 1, 3, 5, 4};  // VTK_WEDGE's base faces outward
    return perm;
  }
  if (type == CellType::Line) {  // the polyline runs end 0, the interior nodes in order, end 1
    std::vector<int> perm{0};
    for (int k = 2; k <= order; ++k) perm.push_back(k);
    perm.push_back(1);
    return perm;
  }
  const std::vector<Lattice> gmsh = gmsh_lattice(type, order);
  const std::vector<Lattice> vtk = vtk_lattice(type, order);
  std::vector<int> perm(vtk.size(), -1);
  for (std::size_t k = 0; k < vtk.size(); ++k)
    for (std::size_t i = 0; i < gmsh.size(); ++i)
      if (gmsh[i] == vtk[k]) perm[k] = static_cast<int>(i);
  for (int p : perm)
    if (p < 0) throw Error(std::string("VTK and Gmsh node lattices differ for a ") + cell_name(type));
  return perm;
}

namespace {

// The blocks written (all of one dimension) and their VTK node orders.
struct VtuBlocks {
  std::vector<const CellBlock*> blocks;  // pointers: the connectivity is not copied
  std::vector<std::vector<int>> perms;   // per block: the VTK node order (vtk_node_permutation)
  std::size_t num_cells = 0;
};

// Checks the blocks (of dimension block_dim) and the fields, before the file system is touched.
template <int Dim>
VtuBlocks vtu_blocks(const HybridMesh<Dim>& mesh, const std::vector<CellBlock>& source, int block_dim,
                     const std::filesystem::path& path, const std::vector<CellField>& fields) {
  auto fail = [&](const std::string& why) { throw Error("cannot write " + path.string() + ": " + why); };
  VtuBlocks v;
  for (const CellBlock& b : source) v.blocks.push_back(&b);
  for (const CellBlock* b : v.blocks) v.num_cells += b->size();
  const auto num_nodes = static_cast<NodeId>(mesh.nodes.size());
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const CellField& fi = fields[i];
    if (fi.name.empty() || fi.name == "block" || fi.name == "HigherOrderDegrees")
      fail("cell field name '" + fi.name + "' is empty or reserved");
    for (std::size_t j = 0; j < i; ++j)
      if (fields[j].name == fi.name) fail("two cell fields are named '" + fi.name + "'");
    if (fi.values.size() != v.num_cells)
      fail("cell field '" + fi.name + "' has " + std::to_string(fi.values.size()) + " values for " +
           std::to_string(v.num_cells) + " cells");
  }
  for (const CellBlock* bp : v.blocks) {
    const CellBlock& b = *bp;
    if (ref_dim(b.type) != block_dim || b.order < 1 || b.order > max_order)
      fail(std::string("a ") + cell_name(b.type) + " block of order " + std::to_string(b.order) +
           " is not a block of dimension " + std::to_string(block_dim));
    if (b.connectivity.size() % static_cast<std::size_t>(b.nodes_per_cell()) != 0)
      fail(std::string("the connectivity of a ") + cell_name(b.type) + " block has a partial cell");
    for (NodeId n : b.connectivity)
      if (n < 0 || n >= num_nodes)
        fail(std::string("a ") + cell_name(b.type) + " block refers to node " + std::to_string(n) + " of " +
             std::to_string(num_nodes));
    v.perms.push_back(vtk_node_permutation(b.type, b.order));
  }
  return v;
}

template <int Dim>
void write_points(AtomicFile& f, const HybridMesh<Dim>& mesh, std::size_t num_cells) {
  f.write(
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"");
  f.write_int(static_cast<NodeId>(mesh.nodes.size()));
  f.write("\" NumberOfCells=\"");
  f.write_int(static_cast<std::int64_t>(num_cells));
  f.write("\">\n      <Points>\n");
  data_array(f, "Float64", "Points", 3);
  for (const auto& x : mesh.nodes) f.write_point_line(x);
  f.write(end_data_array);
  f.write("      </Points>\n");
}

// Connectivity in VTK order, offsets, types.
void write_cells(AtomicFile& f, const VtuBlocks& v) {
  f.write("      <Cells>\n");
  data_array(f, "Int64", "connectivity", 1);
  for (std::size_t bi = 0; bi < v.blocks.size(); ++bi) {
    const CellBlock& b = *v.blocks[bi];
    const std::vector<int>& perm = v.perms[bi];
    for (std::size_t i = 0; i < b.size(); ++i) {
      const NodeId* c = b.cell(i);
      for (std::size_t k = 0; k < perm.size(); ++k) {
        if (k > 0) f.put(' ');
        f.write_int(c[perm[k]]);
      }
      f.put('\n');
    }
  }
  f.write(end_data_array);
  data_array(f, "Int64", "offsets", 1);
  std::int64_t offset = 0;
  for (std::size_t bi = 0; bi < v.blocks.size(); ++bi)
    for (std::size_t i = 0; i < v.blocks[bi]->size(); ++i) {
      offset += static_cast<std::int64_t>(v.perms[bi].size());
      f.write_int(offset);
      f.put('\n');
    }
  f.write(end_data_array);
  data_array(f, "UInt8", "types", 1);
  for (const CellBlock* bp : v.blocks) {
    const CellBlock& b = *bp;
    const int type = vtk_cell_type(b.type, b.order);
    for (std::size_t i = 0; i < b.size(); ++i) {
      f.write_int(type);
      f.put('\n');
    }
  }
  f.write(end_data_array);
  f.write("      </Cells>\n");
}

// Cell data: block index, the caller's fields, the Lagrange degrees.
void write_cell_data(AtomicFile& f, const VtuBlocks& v, const std::vector<CellField>& fields) {
  f.write("      <CellData Scalars=\"block\" HigherOrderDegrees=\"HigherOrderDegrees\">\n");
  data_array(f, "Int32", "block", 1);
  for (std::size_t bi = 0; bi < v.blocks.size(); ++bi)
    for (std::size_t i = 0; i < v.blocks[bi]->size(); ++i) {
      f.write_int(static_cast<std::int64_t>(bi));
      f.put('\n');
    }
  f.write(end_data_array);
  for (const CellField& field : fields) {
    data_array(f, "Float64", field.name, 1);
    for (double x : field.values) {
      f.write_double(x);
      f.put('\n');
    }
    f.write(end_data_array);
  }
  data_array(f, "Int32", "HigherOrderDegrees", 3);
  for (const CellBlock* bp : v.blocks) {
    const CellBlock& b = *bp;
    const int dim = ref_dim(b.type);
    for (std::size_t i = 0; i < b.size(); ++i)
      for (int d = 0; d < 3; ++d) {
        f.write_int(d < dim ? b.order : 0);
        f.put(d < 2 ? ' ' : '\n');
      }
  }
  f.write(end_data_array);
  f.write("      </CellData>\n");
}

// One file: the points, the blocks `source` (all of dimension block_dim), their cell data.
template <int Dim>
void write_blocks(const HybridMesh<Dim>& mesh, const std::vector<CellBlock>& source, int block_dim,
                  const std::filesystem::path& path, const std::vector<CellField>& fields) {
  // 1. Validate before touching the file system.
  const VtuBlocks blocks = vtu_blocks(mesh, source, block_dim, path, fields);
  AtomicFile f(path);
  // 2. Header and points, 3. cells, 4. cell data.
  write_points(f, mesh, blocks.num_cells);
  write_cells(f, blocks);
  write_cell_data(f, blocks, fields);
  f.write("    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
  f.commit();
}

}  // namespace

template <int Dim>
void write_vtu(const HybridMesh<Dim>& mesh, const std::filesystem::path& path, const std::vector<CellField>& fields) {
  const bool surface = mesh.cells.empty();
  write_blocks(mesh, surface ? mesh.boundary : mesh.cells, surface ? Dim - 1 : Dim, path, fields);
}

template <int Dim>
bool write_boundary_vtu(const HybridMesh<Dim>& mesh, const std::filesystem::path& path) {
  // The boundary of what write_vtu writes, checked against the mesh, then written on the nodes it
  // uses (renumbered in their order; the other nodes are not copied).
  const bool facets = !mesh.cells.empty();
  if (!facets && Dim != 3) return false;
  const std::vector<CellBlock>& source = facets ? mesh.boundary : mesh.curves;
  const int dim = facets ? Dim - 1 : 1;
  std::size_t cells = 0;
  for (const CellBlock& b : source) cells += b.size();
  if (cells == 0) return false;
  (void)vtu_blocks(mesh, source, dim, path, {});
  std::vector<NodeId> used;
  for (const CellBlock& b : source) used.insert(used.end(), b.connectivity.begin(), b.connectivity.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  HybridMesh<Dim> part;
  part.tags = mesh.tags;
  part.nodes.reserve(used.size());
  for (NodeId v : used) part.nodes.push_back(mesh.nodes[static_cast<std::size_t>(v)]);
  std::vector<CellBlock>& blocks = facets ? part.boundary : part.curves;
  blocks = source;
  CellField tag{"tag", {}};
  for (CellBlock& b : blocks) {
    for (NodeId& v : b.connectivity) v = static_cast<NodeId>(std::lower_bound(used.begin(), used.end(), v) - used.begin());
    tag.values.insert(tag.values.end(), b.size(), static_cast<double>(b.tag + 1));
  }
  write_blocks(part, blocks, dim, path, {tag});
  return true;
}

template void write_vtu(const HybridMesh<2>&, const std::filesystem::path&, const std::vector<CellField>&);
template void write_vtu(const HybridMesh<3>&, const std::filesystem::path&, const std::vector<CellField>&);
template bool write_boundary_vtu(const HybridMesh<2>&, const std::filesystem::path&);
template bool write_boundary_vtu(const HybridMesh<3>&, const std::filesystem::path&);

}  // namespace io
}  // namespace plaf
