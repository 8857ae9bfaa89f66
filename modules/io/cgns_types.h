// SPDX-License-Identifier: MIT
// CGNS element types (ElementType_t values of cgnslib.h, CGNS SIDS "Elements_t") for plaf's
// Lagrange cells, shared by the CGNS writer and reader (cgns_write.cpp, cgns_read.cpp) without
// exposing cgnslib.h. Internal to modules/io.
#pragma once

#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace io {

// The CGNS type code of (type, order 1..4): BAR_2..5, TRI_3/6/10/15, QUAD_4/9/16/25,
// TETRA_4/10/20/35, PENTA_6/18/40/75.
int cgns_element_type(CellType type, int order);
// Its name as the SIDS spells it ("PENTA_18").
std::string cgns_element_name(CellType type, int order);
// libcgns keeps its state in globals (open files, the goto position): every use holds this lock.
std::mutex& cgns_mutex();

// The inverse: (type, order) of a CGNS code, or nothing for a type plaf does not represent
// (serendipity elements such as QUAD_8, pyramids, hexahedra, polyhedra, MIXED).
std::optional<std::pair<CellType, int>> cell_of_cgns_type(int code);

}  // namespace io
}  // namespace plaf
