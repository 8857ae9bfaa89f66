// SPDX-License-Identifier: MIT
// CGNS (CFD General Notation System, SIDS) writer and reader for HybridMesh, through Debian's
// libcgns (the mid-level library, HDF5 files).
//
// Writing: one base ("plaf", cell dimension = physical dimension = Dim) holding one unstructured
// zone ("domain"): the coordinates CoordinateX/Y(/Z) in double precision; one element section per
// cell block (named by its CGNS type, e.g. PENTA_18, then a count when a type repeats), element
// numbers 1..C in block order; then per boundary tag one section per facet block (named by the
// tag, e.g. "wall", "wall_QUAD_9" for a second type), numbered on after the cells, so that each
// tag's facets are one range of element numbers. Each tag with facets gets a family of its name
// (Family_t with a FamilyBC_t) and a BC_t of its name on that PointRange with GridLocation
// FaceCenter (3D) or EdgeCenter (2D), carrying its family name. BC types from the tag's kind:
// wall -> BCWall, farfield -> BCFarfield, symmetry -> BCSymmetryPlane, other -> BCTypeUserDefined.
// A mesh without cells (a surface run) is written as a base of cell dimension Dim - 1: its facet
// sections are the zone's cells, named by tag as above, without BCs; in 3D its curves follow as
// BAR sections by tag, each tag with its family and a BC_t at EdgeCenter (the surface's boundary).
// The curves of a 3D volume mesh (symmetry loops) are not written: its BCs are on faces. Element orders 1..4 of lines, triangles, quadrilaterals, tetrahedra and
// prisms map to BAR_2..5, TRI_3/6/10/15, QUAD_4/9/16/25, TETRA_4/10/20/35, PENTA_6/18/40/75,
// their nodes permuted from Gmsh's order to the SIDS order (cgns_node_permutation).
//
// Reading: the first zone of the first base (unstructured); sections of these types become cells
// (of the base's cell dimension) or boundary facets (one dimension less); lower-dimensional
// sections are ignored; a base of cell dimension one below its physical dimension is a surface
// mesh (facets, no cells; in 3D its BAR sections are its curves). A
// facet is tagged by the BC_t whose element range or list holds it (named by the BC's family
// name if it has one, else its own name; kind from its BC type, else from the name as read_msh41
// does); facets no BC names are tagged by their section's name, less a "_<CGNS type>" suffix
// when a section of that prefix came before ("wall", then "wall_QUAD_9").
// Anything malformed, or a type plaf cannot represent, throws InputError "path: reason".
#pragma once

#include <filesystem>
#include <vector>

#include "modules/io/msh_io.h"
#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace io {

// perm[k] = local Gmsh index of the node at CGNS position k, for (type, order), order 1..4.
std::vector<int> cgns_node_permutation(CellType type, int order);

// Throws Error naming the path if the file cannot be written or the mesh is broken; leaves no
// partial file behind (written to a temporary beside the target, renamed on success).
template <int Dim>
void write_cgns(const HybridMesh<Dim>& mesh, const std::filesystem::path& path);

// The mesh of a CGNS file (dim 2 or 3 as its base's cell dimension), as read_msh41 returns.
MshMesh read_cgns(const std::filesystem::path& path);

// A mesh file by its suffix: .cgns (any case) through read_cgns, anything else as MSH (4.1 or
// 2.2, ASCII or binary) through read_msh41. What `plaf check` and `plaf picture` read.
MshMesh read_mesh_file(const std::filesystem::path& path);

}  // namespace io
}  // namespace plaf
