// SPDX-License-Identifier: MIT
// Implements cgns_types.h and cgns_node_permutation (cgns_io.h).
#include "modules/io/cgns_types.h"

#include <cgnslib.h>

#include <array>

#include "modules/base/error.h"
#include "modules/elements/lagrange.h"
#include "modules/io/cgns_io.h"

namespace plaf {
inline namespace io {
namespace {

struct CgnsType {
  CellType type;
  int order;
  CGNS_ENUMT(ElementType_t) code;
  const char* name;
};

constexpr std::array<CgnsType, 20> kTypes = {{
    {CellType::Line, 1, CGNS_ENUMV(BAR_2), "BAR_2"},
    {CellType::Line, 2, CGNS_ENUMV(BAR_3), "BAR_3"},
    {CellType::Line, 3, CGNS_ENUMV(BAR_4), "BAR_4"},
    {CellType::Line, 4, CGNS_ENUMV(BAR_5), "BAR_5"},
    {CellType::Triangle, 1, CGNS_ENUMV(TRI_3), "TRI_3"},
    {CellType::Triangle, 2, CGNS_ENUMV(TRI_6), "TRI_6"},
    {CellType::Triangle, 3, CGNS_ENUMV(TRI_10), "TRI_10"},
    {CellType::Triangle, 4, CGNS_ENUMV(TRI_15), "TRI_15"},
    {CellType::Quadrilateral, 1, CGNS_ENUMV(QUAD_4), "QUAD_4"},
    {CellType::Quadrilateral, 2, CGNS_ENUMV(QUAD_9), "QUAD_9"},
    {CellType::Quadrilateral, 3, CGNS_ENUMV(QUAD_16), "QUAD_16"},
    {CellType::Quadrilateral, 4, CGNS_ENUMV(QUAD_25), "QUAD_25"},
    {CellType::Tetrahedron, 1, CGNS_ENUMV(TETRA_4), "TETRA_4"},
    {CellType::Tetrahedron, 2, CGNS_ENUMV(TETRA_10), "TETRA_10"},
    {CellType::Tetrahedron, 3, CGNS_ENUMV(TETRA_20), "TETRA_20"},
    {CellType::Tetrahedron, 4, CGNS_ENUMV(TETRA_35), "TETRA_35"},
    {CellType::Prism, 1, CGNS_ENUMV(PENTA_6), "PENTA_6"},
    {CellType::Prism, 2, CGNS_ENUMV(PENTA_18), "PENTA_18"},
    {CellType::Prism, 3, CGNS_ENUMV(PENTA_40), "PENTA_40"},
    {CellType::Prism, 4, CGNS_ENUMV(PENTA_75), "PENTA_75"},
}};

const CgnsType& find(CellType type, int order) {
  check_order(order);
  for (const CgnsType& t : kTypes)
    if (t.type == type && t.order == order) return t;
  throw Error(std::string("no CGNS type for a ") + cell_name(type) + " of order " + std::to_string(order));
}

}  // namespace

std::mutex& cgns_mutex() {
  static std::mutex m;
  return m;
}

int cgns_element_type(CellType type, int order) { return static_cast<int>(find(type, order).code); }
std::string cgns_element_name(CellType type, int order) { return find(type, order).name; }

std::optional<std::pair<CellType, int>> cell_of_cgns_type(int code) {
  for (const CgnsType& t : kTypes)
    if (static_cast<int>(t.code) == code) return std::make_pair(t.type, t.order);
  return std::nullopt;
}

std::vector<int> cgns_node_permutation(CellType type, int order) {
  return lattice_permutation(gmsh_lattice(type, order), cgns_lattice(type, order));
}

}  // namespace io
}  // namespace plaf
