// SPDX-License-Identifier: MIT
// Gmsh MSH 4.1 reader and writer (ASCII and binary) for HybridMesh (format: Gmsh reference manual,
// "MSH file format", version 4.1). Implemented in msh_read.cpp, msh_write.cpp and, for the
// element type codes, gmsh_types.cpp.
//
// Writing: one physical group of dimension Dim-1 per boundary tag that has facets, named by the
// tag's name, with physical tag = tag index + 1; one physical group "domain" of dimension Dim with
// physical tag = number of tags + 1 when the mesh has cells. No physical group is empty: a tag
// without elements gets neither group nor entity (so it does not survive a round trip). One
// entity per such tag (entity tag = tag index + 1) and one domain entity (tag 1, written also
// without cells, where it marks a 3D surface mesh as 3D), each carrying its physical group, its
// bounding box and its bounding entities (gmsh.model.getBoundary): the domain is bounded by the
// facet entities; in 3D a facet entity by the curve entities with an edge on its rim (edges one
// facet of the tag uses); curves by no points. All nodes are written in
// the domain entity's node block; node tags are 1..N in HybridMesh order. Elements come in one
// block per (entity, element type): the volume blocks first, then the boundary blocks, with
// element tags 1..M in that order. 2D meshes are written with z = 0. Coordinates are written in
// the shortest form that reads back bit for bit.
// Curves of a 3D mesh (HybridMesh::curves): a tag used by curves blocks gets a physical group of
// dimension 1 (same name, physical tag = tag index + 1) and a curve entity (entity tag = tag index
// + 1) holding those line elements, written after the boundary blocks; a tag used by curves only
// gets no dimension-2 group or entity.
//
// Reading: the mesh dimension is the largest dimension of the elements present, except that a file
// of surface elements (no volume elements) declaring a volume entity or a physical group of
// dimension 3 is a 3D surface mesh (boundary facets and curves, no cells). Elements of that
// dimension become cells, elements of dimension Dim-1 become boundary facets tagged by the
// physical group of their entity; points are ignored. In 3D, line elements whose entity carries a
// physical group become curves blocks tagged by that group (plaf's own symmetry loops, Gmsh's
// physical curves); lines without a physical group (Gmsh's "save all") and line types plaf cannot
// represent are ignored. Tags come in the order of their physical tags (dimension Dim-1 and, in
// 3D, dimension 1), so a written mesh reads back with the same tag indices. A boundary tag's kind is
// inferred from its name (case-insensitive prefix): "wall*" -> Wall, "farfield*" -> Farfield,
// "symmetry*" -> Symmetry, else Named. So kinds survive a round trip only when the tag names
// follow that convention. An entity with several physical groups takes the first; a physical
// group without a name is called "physical_<tag>"; an entity without one "entity_<tag>".
// Sparse node tags are renumbered contiguously in file order. Unknown sections ($NodeData,
// $Periodic, ...) are skipped. Anything malformed throws InputError "path:line: reason".
// Binary files (file type 1, data size 8, as Gmsh writes with -bin) are read alike, in this
// machine's byte order (the header's integer 1 must read as 1); their lines are not counted inside
// the binary data, so a failure there names the line of its section's header.
// MSH 2.2 files (ASCII and binary, as write_msh22 and Gmsh write them) are read alike: an element's
// first tag is its physical group (its boundary tag, named by $PhysicalNames), elements without
// one are tagged "entity_<elementary tag>"; a 2.2 file is 3D when it has volume elements or names
// a physical group of dimension 3. An element Gmsh lists once per physical group (2.2 has no
// entities) is read once per listing, each copy tagged by its group.
#pragma once

#include <filesystem>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace io {

// Gmsh's element type number for (type, order), order 1..4 (Gmsh's GmshDefines.h).
int gmsh_element_type(CellType type, int order);

// ascii: file type 0; binary: file type 1 (Gmsh's binary MSH 4.1, as `gmsh -bin` writes: the
// $PhysicalNames section stays text; ints of 4 bytes, counts and tags as 8-byte size_t, doubles,
// in this machine's byte order). Both hold the same groups, entities, nodes and elements.
enum class MshEncoding { ascii, binary };

// Throws Error (naming the path) if the file cannot be written or the mesh refers to a missing
// node or tag; never leaves a partial file behind (AtomicFile).
template <int Dim>
void write_msh41(const HybridMesh<Dim>& mesh, const std::filesystem::path& path,
                 MshEncoding encoding = MshEncoding::ascii);

// Gmsh's legacy MSH 2.2, ASCII or binary, for the solvers and converters that read it (MFEM,
// NekMesh, HOPR): the same node order per element type, the same physical groups (names,
// dimensions, tags) as write_msh41, each element tagged with its physical group and its 4.1
// entity tag as elementary entity. Throws Error beyond 2^31 - 1 nodes or elements (4-byte ids).
template <int Dim>
void write_msh22(const HybridMesh<Dim>& mesh, const std::filesystem::path& path,
                 MshEncoding encoding = MshEncoding::ascii);

struct MshMesh {
  int dim = 0;  // 2 or 3: which of the two meshes is filled
  HybridMesh<2> mesh2;
  HybridMesh<3> mesh3;
};

MshMesh read_msh41(const std::filesystem::path& path);

}  // namespace io
}  // namespace plaf
