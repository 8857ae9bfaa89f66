// SPDX-License-Identifier: MIT
// Gmsh's element types (codes from Gmsh's GmshDefines.h: MSH_LIN_2 = 1, ...), shared by the MSH
// reader (msh_read.cpp) and writer (msh_write.cpp); gmsh_element_type is declared in msh_io.h.
// Internal to modules/io.
#pragma once

#include <cstdint>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace io {

struct GmshType {
  int code;
  int dim;
  int nodes;
  bool supported;  // a Lagrange element plaf represents
  CellType type;
  int order;
};

// The type of a Gmsh element code, or nullptr if plaf does not know it. Types plaf cannot
// represent are listed too (supported false) with their node counts, so that their blocks can be
// read (and ignored when lower-dimensional).
const GmshType* find_gmsh_type(std::int64_t code);

}  // namespace io
}  // namespace plaf
