// SPDX-License-Identifier: MIT
// VTK XML UnstructuredGrid (.vtu, ASCII) writer for the volume cells of a HybridMesh.
//
// Cell types: order-1 blocks are written as VTK's linear cells (3 line, 5 triangle,
// 9 quadrilateral, 10 tetrahedron, 13 wedge), which every VTK filter understands (vtkMeshQuality
// accepts only linear cells); blocks of order >= 2 as VTK 9 Lagrange cells (68 curve, 69 triangle,
// 70 quadrilateral, 71 tetrahedron, 73 wedge). Nodes are permuted from Gmsh's order to VTK's by
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

// One value per volume cell, in block order (all cells of mesh.cells[0], then mesh.cells[1], ...).
struct CellField {
  std::string name;
  std::vector<double> values;
};

// The VTK cell type written for a block of (type, order).
int vtk_cell_type(CellType type, int order);
// perm[k] = local Gmsh index of the node written at VTK position k, for that cell type.
std::vector<int> vtk_node_permutation(CellType type, int order);

// A mesh without cells (a surface mesh alone) is written as its boundary facets, then (3D) its
// curves as line cells; the fields then hold one value per boundary facet, the curves get NaN.
// Throws Error (naming the path) if a field has the wrong length or a reserved or repeated name,
// if a block refers to a missing node, or if the file cannot be written; never leaves a partial
// file behind (AtomicFile). Non-finite field values are written as "nan", "inf" and "-inf"; VTK
// 9.1's ASCII reader takes "nan" and "inf" but reads "-inf" as +inf.
template <int Dim>
void write_vtu(const HybridMesh<Dim>& mesh, const std::filesystem::path& path,
               const std::vector<CellField>& fields = {});

}  // namespace io
}  // namespace plaf
