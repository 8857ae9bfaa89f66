// SPDX-License-Identifier: MIT
// Implements the .vtu writer (VTK file formats, "XML File Formats": UnstructuredGrid) with
// VTK 9's Lagrange cells; see vtu_writer.h for the choices.
#include "modules/io/vtu_writer.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <type_traits>

#include "modules/io/atomic_file.h"
#include "modules/base/error.h"
#include "modules/base/parallel.h"

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

constexpr std::string_view end_data_array = "        </DataArray>\n";

// The data arrays as a sink writes them. TextSink: format="ascii", each value as text, rows on
// lines of their own, straight into the file. ZlibSink: format="appended" with an offset into the
// <AppendedData encoding="raw"> block at the end of the file, each array as VTK's compressed
// layout (header_type UInt64, compressor vtkZLibDataCompressor: the number of blocks, the block
// size, the last block's size, each block's compressed size, then the zlib streams); the XML is
// collected first (the offsets are known once the arrays before are), the data follows it.
class TextSink {
 public:
  explicit TextSink(AtomicFile& f) : f_(f) {}
  static constexpr const char* kCompressor = "";
  void xml(std::string_view text) { f_.write(text); }
  void begin_array(const char* type, const std::string& name, int components) {
    open_data_array(type, name, components);
    f_.write(" format=\"ascii\">\n");
  }
  template <class T>
  void value(T v, char after) {
    if constexpr (std::is_floating_point_v<T>)
      f_.write_double(v);
    else
      f_.write_int(static_cast<std::int64_t>(v));
    f_.put(after);
  }
  void end_array() { f_.write(end_data_array); }
  void finish() {}

 private:
  void open_data_array(const char* type, const std::string& name, int components) {
    f_.write("        <DataArray type=\"");
    f_.write(type);
    f_.write("\" Name=\"");
    f_.write(xml_escape(name));
    f_.write("\"");
    if (components > 1) {
      f_.write(" NumberOfComponents=\"");
      f_.write_int(components);
      f_.write("\"");
    }
  }
  AtomicFile& f_;
};

class ZlibSink {
 public:
  explicit ZlibSink(AtomicFile& f) : f_(f) {}
  static constexpr const char* kCompressor = " compressor=\"vtkZLibDataCompressor\"";
  void xml(std::string_view text) { xml_ += text; }
  void begin_array(const char* type, const std::string& name, int components) {
    xml_ += "        <DataArray type=\"";
    xml_ += type;
    xml_ += "\" Name=\"" + xml_escape(name) + "\"";
    if (components > 1) xml_ += " NumberOfComponents=\"" + std::to_string(components) + "\"";
    xml_ += " format=\"appended\" offset=\"" + std::to_string(data_.size()) + "\"/>\n";
    raw_.clear();
  }
  template <class T>
  void value(T v, char) {
    const std::size_t at = raw_.size();
    raw_.resize(at + sizeof v);
    std::memcpy(raw_.data() + at, &v, sizeof v);
  }
  void end_array() {
    // Blocks of kBlock bytes, each its own zlib stream (VTK's reader inflates them one by one),
    // compressed on the worker threads (modules/base/parallel.h), each into its own buffer.
    constexpr std::size_t kBlock = std::size_t{1} << 20;
    const std::size_t n = raw_.size(), num_blocks = n == 0 ? 0 : (n + kBlock - 1) / kBlock;
    std::vector<std::vector<char>> streams(num_blocks);
    parallel_chunks(num_blocks, 1, [&](unsigned, std::size_t begin, std::size_t end) {
      for (std::size_t b = begin; b < end; ++b) {
        const std::size_t size = std::min(kBlock, n - b * kBlock);
        uLongf bound = compressBound(static_cast<uLong>(size));
        streams[b].resize(bound);
        if (compress2(reinterpret_cast<Bytef*>(streams[b].data()), &bound,
                      reinterpret_cast<const Bytef*>(raw_.data() + b * kBlock), static_cast<uLong>(size),
                      Z_BEST_SPEED) != Z_OK)
          throw Error("cannot write " + f_.target().string() + ": zlib failed to compress a data array");
        streams[b].resize(bound);
      }
    });
    // The last block's size when it is partial, 0 when it is full (vtkXMLDataParser).
    std::vector<std::uint64_t> header{num_blocks, kBlock, n % kBlock};
    for (const std::vector<char>& s : streams) header.push_back(s.size());
    const auto* h = reinterpret_cast<const char*>(header.data());
    data_.insert(data_.end(), h, h + header.size() * sizeof(std::uint64_t));
    for (const std::vector<char>& s : streams) data_.insert(data_.end(), s.begin(), s.end());
    raw_.clear();
  }
  void finish() {
    f_.write(xml_);
    f_.write("  <AppendedData encoding=\"raw\">\n   _");
    f_.write_bytes(data_.data(), data_.size());
    f_.write("\n  </AppendedData>\n");
  }

 private:
  AtomicFile& f_;
  std::string xml_;
  std::vector<char> raw_, data_;
};

constexpr const char* kByteOrder = std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";

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
  return lattice_permutation(gmsh_lattice(type, order), vtk_lattice(type, order));
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

template <int Dim, class Sink>
void write_points(Sink& f, const HybridMesh<Dim>& mesh, std::size_t num_cells) {
  f.xml("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"");
  f.xml(kByteOrder);
  f.xml("\" header_type=\"UInt64\"");
  f.xml(Sink::kCompressor);
  f.xml(">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"");
  f.xml(std::to_string(mesh.nodes.size()));
  f.xml("\" NumberOfCells=\"");
  f.xml(std::to_string(num_cells));
  f.xml("\">\n      <Points>\n");
  f.begin_array("Float64", "Points", 3);
  for (const auto& x : mesh.nodes) {
    f.value(static_cast<double>(x[0]), ' ');
    f.value(static_cast<double>(x[1]), ' ');
    f.value(Dim == 3 ? static_cast<double>(x[Dim - 1]) : 0.0, '\n');  // z = 0 in 2D
  }
  f.end_array();
  f.xml("      </Points>\n");
}

// Connectivity in VTK order, offsets, types.
template <class Sink>
void write_cells(Sink& f, const VtuBlocks& v) {
  f.xml("      <Cells>\n");
  f.begin_array("Int64", "connectivity", 1);
  for (std::size_t bi = 0; bi < v.blocks.size(); ++bi) {
    const CellBlock& b = *v.blocks[bi];
    const std::vector<int>& perm = v.perms[bi];
    for (std::size_t i = 0; i < b.size(); ++i) {
      const NodeId* c = b.cell(i);
      for (std::size_t k = 0; k < perm.size(); ++k)
        f.value(static_cast<std::int64_t>(c[perm[k]]), k + 1 < perm.size() ? ' ' : '\n');
    }
  }
  f.end_array();
  f.begin_array("Int64", "offsets", 1);
  std::int64_t offset = 0;
  for (std::size_t bi = 0; bi < v.blocks.size(); ++bi)
    for (std::size_t i = 0; i < v.blocks[bi]->size(); ++i) {
      offset += static_cast<std::int64_t>(v.perms[bi].size());
      f.value(offset, '\n');
    }
  f.end_array();
  f.begin_array("UInt8", "types", 1);
  for (const CellBlock* bp : v.blocks) {
    const CellBlock& b = *bp;
    const auto type = static_cast<std::uint8_t>(vtk_cell_type(b.type, b.order));
    for (std::size_t i = 0; i < b.size(); ++i) f.value(type, '\n');
  }
  f.end_array();
  f.xml("      </Cells>\n");
}

// Cell data: block index, the caller's fields, the Lagrange degrees.
template <class Sink>
void write_cell_data(Sink& f, const VtuBlocks& v, const std::vector<CellField>& fields) {
  f.xml("      <CellData Scalars=\"block\" HigherOrderDegrees=\"HigherOrderDegrees\">\n");
  f.begin_array("Int32", "block", 1);
  for (std::size_t bi = 0; bi < v.blocks.size(); ++bi)
    for (std::size_t i = 0; i < v.blocks[bi]->size(); ++i) f.value(static_cast<std::int32_t>(bi), '\n');
  f.end_array();
  for (const CellField& field : fields) {
    f.begin_array("Float64", field.name, 1);
    for (double x : field.values) f.value(x, '\n');
    f.end_array();
  }
  f.begin_array("Int32", "HigherOrderDegrees", 3);
  for (const CellBlock* bp : v.blocks) {
    const CellBlock& b = *bp;
    const int dim = ref_dim(b.type);
    for (std::size_t i = 0; i < b.size(); ++i)
      for (int d = 0; d < 3; ++d) f.value(static_cast<std::int32_t>(d < dim ? b.order : 0), d < 2 ? ' ' : '\n');
  }
  f.end_array();
  f.xml("      </CellData>\n");
}

template <int Dim, class Sink>
void write_pieces(Sink& f, const HybridMesh<Dim>& mesh, const VtuBlocks& blocks, const std::vector<CellField>& fields) {
  // Header and points, cells, cell data.
  write_points(f, mesh, blocks.num_cells);
  write_cells(f, blocks);
  write_cell_data(f, blocks, fields);
  f.xml("    </Piece>\n  </UnstructuredGrid>\n");
  f.finish();
}

// One file: the points, the blocks `source` (all of dimension block_dim), their cell data.
template <int Dim>
void write_blocks(const HybridMesh<Dim>& mesh, const std::vector<CellBlock>& source, int block_dim,
                  const std::filesystem::path& path, const std::vector<CellField>& fields, VtuEncoding encoding) {
  // 1. Validate before touching the file system.
  const VtuBlocks blocks = vtu_blocks(mesh, source, block_dim, path, fields);
  AtomicFile f(path);
  // 2. The pieces, as text or as compressed appended data.
  if (encoding == VtuEncoding::binary) {
    ZlibSink sink(f);
    write_pieces(sink, mesh, blocks, fields);
  } else {
    TextSink sink(f);
    write_pieces(sink, mesh, blocks, fields);
  }
  f.write("</VTKFile>\n");
  f.commit();
}

}  // namespace

template <int Dim>
void write_vtu(const HybridMesh<Dim>& mesh, const std::filesystem::path& path, const std::vector<CellField>& fields,
               VtuEncoding encoding) {
  const bool surface = mesh.cells.empty();
  write_blocks(mesh, surface ? mesh.boundary : mesh.cells, surface ? Dim - 1 : Dim, path, fields, encoding);
}

template <int Dim>
bool write_boundary_vtu(const HybridMesh<Dim>& mesh, const std::filesystem::path& path, VtuEncoding encoding) {
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
  write_blocks(part, blocks, dim, path, {tag}, encoding);
  return true;
}

template void write_vtu(const HybridMesh<2>&, const std::filesystem::path&, const std::vector<CellField>&, VtuEncoding);
template void write_vtu(const HybridMesh<3>&, const std::filesystem::path&, const std::vector<CellField>&, VtuEncoding);
template bool write_boundary_vtu(const HybridMesh<2>&, const std::filesystem::path&, VtuEncoding);
template bool write_boundary_vtu(const HybridMesh<3>&, const std::filesystem::path&, VtuEncoding);

}  // namespace io
}  // namespace plaf
