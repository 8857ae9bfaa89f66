// SPDX-License-Identifier: MIT
// VTK XML UnstructuredGrid (.vtu, ASCII or zlib-compressed binary) writer for a HybridMesh: one file of the cells of the
// mesh's own dimension (write_vtu), one of its boundary (write_boundary_vtu). Each file holds
// cells of one dimension only, so VTK's filters (and ParaView) never meet a curve among surfaces
// (VTK 9.1's surface filter crashes on Lagrange curve cells beside 2D cells at subdivision >= 2).
//
// Cell types: order-1 blocks are written as VTK's linear cells (3 line, 5 triangle,
// 9 quadrilateral, 10 tetrahedron, 13 wedge), which every VTK filter understands (vtkMeshQuality
// accepts only linear cells); blocks of order >= 2 as VTK 9 Lagrange cells (69 triangle,
// 70 quadrilateral, 71 tetrahedron, 73 wedge), except lines: VTK 9.1's surface filter (what
// ParaView draws with) crashes on every nonlinear 1D cell (68 Lagrange curve, 21 quadratic edge)
// at a Nonlinear Subdivision Level >= 2, so an order-q line is written as a polyline (4) through
// its q + 1 nodes in order along it. Curves are thus drawn through their nodes; their exact
// high-order form is in the MSH file and in the faces of the cells they bound. Nodes are permuted from Gmsh's order to VTK's by
// matching reference lattice points (lagrange.h). VTK's linear wedge orients its base triangle
// opposite to Gmsh's and to VTK's Lagrange wedge, so its vertices are written 0,2,1,3,5,4.
//
// Cell data: "block" (index of the cell's block in mesh.cells), then the caller's fields, then
// "HigherOrderDegrees" (3 ints per cell: the order along each parametric direction, 0 beyond the
// cell's dimension), marked as the CellData's HigherOrderDegrees attribute so that VTK >= 9 sets
// the order of quadrilaterals and wedges from it rather than from the point count.
// Points are written as Float64 (VTK's higher-order cells need double points) with z = 0 in 2D.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace io {

// ascii: every DataArray as text (format="ascii"); binary: each as zlib-compressed raw data in
// the file's <AppendedData> block (format="appended", compressor vtkZLibDataCompressor, header_type
// UInt64), what ParaView writes by default: several times smaller and faster to read.
enum class VtuEncoding { ascii, binary };

// One value per volume cell, in block order (all cells of mesh.cells[0], then mesh.cells[1], ...).
struct CellField {
  std::string name;
  std::vector<double> values;
};

// The VTK cell type written for a block of (type, order).
int vtk_cell_type(CellType type, int order);
// perm[k] = local Gmsh index of the node written at VTK position k, for that cell type.
std::vector<int> vtk_node_permutation(CellType type, int order);

// The cells, or for a mesh without cells (a surface mesh alone) its boundary facets; the fields
// then hold one value per boundary facet.
// Throws Error (naming the path) if a field has the wrong length or a reserved or repeated name,
// if a block refers to a missing node, or if the file cannot be written; never leaves a partial
// file behind (AtomicFile). Non-finite field values are written as "nan", "inf" and "-inf"; VTK
// 9.1's ASCII reader takes "nan" and "inf" but reads "-inf" as +inf.
template <int Dim>
void write_vtu(const HybridMesh<Dim>& mesh, const std::filesystem::path& path,
               const std::vector<CellField>& fields = {}, VtuEncoding encoding = VtuEncoding::ascii);

// The boundary of what write_vtu writes: the boundary facets of a mesh with cells, the curves of
// a 3D surface mesh. Written on the nodes they use (renumbered, order kept), with the cell field
// "tag" = the facet's tag index + 1 (the MSH file's physical tag of that boundary). Returns false
// and writes nothing when there is no such boundary (a 2D curve mesh alone, a surface without
// curves). Errors as write_vtu.
template <int Dim>
bool write_boundary_vtu(const HybridMesh<Dim>& mesh, const std::filesystem::path& path,
                        VtuEncoding encoding = VtuEncoding::ascii);

}  // namespace io
}  // namespace plaf
