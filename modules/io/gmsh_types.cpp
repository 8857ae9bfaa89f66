// SPDX-License-Identifier: MIT
// Implements the table of Gmsh element types (gmsh_types.h) and gmsh_element_type (msh_io.h).
#include "modules/io/gmsh_types.h"

#include <string>

#include "modules/base/error.h"
#include "modules/io/msh_io.h"

namespace plaf {
inline namespace io {
namespace {

// Codes from Gmsh's GmshDefines.h (MSH_LIN_2 = 1, ...). Types plaf cannot represent are listed
// with their node counts so that their blocks can be read (and ignored when lower-dimensional).
constexpr GmshType gmsh_types[] = {
    {1, 1, 2, true, CellType::Line, 1},
    {8, 1, 3, true, CellType::Line, 2},
    {26, 1, 4, true, CellType::Line, 3},
    {27, 1, 5, true, CellType::Line, 4},
    {2, 2, 3, true, CellType::Triangle, 1},
    {9, 2, 6, true, CellType::Triangle, 2},
    {21, 2, 10, true, CellType::Triangle, 3},
    {23, 2, 15, true, CellType::Triangle, 4},
    {3, 2, 4, true, CellType::Quadrilateral, 1},
    {10, 2, 9, true, CellType::Quadrilateral, 2},
    {36, 2, 16, true, CellType::Quadrilateral, 3},
    {37, 2, 25, true, CellType::Quadrilateral, 4},
    {4, 3, 4, true, CellType::Tetrahedron, 1},
    {11, 3, 10, true, CellType::Tetrahedron, 2},
    {29, 3, 20, true, CellType::Tetrahedron, 3},
    {30, 3, 35, true, CellType::Tetrahedron, 4},
    {6, 3, 6, true, CellType::Prism, 1},
    {13, 3, 18, true, CellType::Prism, 2},
    {90, 3, 40, true, CellType::Prism, 3},
    {91, 3, 75, true, CellType::Prism, 4},
    // Not representable: points, order-5 lines, serendipity and incomplete cells, hexahedra,
    // pyramids, order >= 5.
    {15, 0, 1, false, CellType::Line, 0},
    {28, 1, 6, false, CellType::Line, 0},
    {16, 2, 8, false, CellType::Quadrilateral, 0},
    {20, 2, 9, false, CellType::Triangle, 0},
    {22, 2, 12, false, CellType::Triangle, 0},
    {24, 2, 15, false, CellType::Triangle, 0},
    {25, 2, 21, false, CellType::Triangle, 0},
    {38, 2, 36, false, CellType::Quadrilateral, 0},
    {5, 3, 8, false, CellType::Tetrahedron, 0},
    {12, 3, 27, false, CellType::Tetrahedron, 0},
    {17, 3, 20, false, CellType::Tetrahedron, 0},
    {92, 3, 64, false, CellType::Tetrahedron, 0},
    {93, 3, 125, false, CellType::Tetrahedron, 0},
    {7, 3, 5, false, CellType::Tetrahedron, 0},
    {14, 3, 14, false, CellType::Tetrahedron, 0},
    {19, 3, 13, false, CellType::Tetrahedron, 0},
    {18, 3, 15, false, CellType::Prism, 0},
    {31, 3, 56, false, CellType::Tetrahedron, 0},
};

}  // namespace

const GmshType* find_gmsh_type(std::int64_t code) {
  for (const GmshType& t : gmsh_types)
    if (t.code == code) return &t;
  return nullptr;
}

int gmsh_element_type(CellType type, int order) {
  for (const GmshType& t : gmsh_types)
    if (t.supported && t.type == type && t.order == order) return t.code;
  throw Error(std::string("no Gmsh element type for a ") + cell_name(type) + " of order " + std::to_string(order));
}

}  // namespace io
}  // namespace plaf
