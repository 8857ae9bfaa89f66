// SPDX-License-Identifier: MIT
#include "modules/io/vtu_writer.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "tests/modules/io/vtu_arrays.h"
#include "tests/published_data.h"
#include "tests/test_support.h"

using namespace plaf;
using test::read_text;
using test::TempDir;
namespace fs = std::filesystem;

namespace {

constexpr CellType all_types[] = {CellType::Line, CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron,
                                  CellType::Prism};

std::vector<double> data_array(const std::string& xml, const std::string& name) {
  return test::vtu_data_array(xml, name);
}

// Cells of every type of dimension Dim and every order, each with its own nodes placed at an
// affine image x = b + A xi of its reference nodes (A with positive determinant).
template <int Dim>
HybridMesh<Dim> affine_soup(std::mt19937& rng, std::vector<std::array<double, 12>>& maps) {
  using Point = typename HybridMesh<Dim>::Point;
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  HybridMesh<Dim> mesh;
  for (CellType t : all_types) {
    if (ref_dim(t) != Dim) continue;
    for (int q = 1; q <= max_order; ++q) {
      CellBlock& block = mesh.block(t, q);
      for (int cell = 0; cell < 2; ++cell) {
        std::array<double, 12> m{};  // A (row-major Dim x Dim, in a 3x3 layout) then b
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) m[r * 3 + c] = (r == c ? 1.0 : 0.0) + u(rng);
        for (int r = 0; r < 3; ++r) m[9 + r] = 10 * u(rng);
        maps.push_back(m);
        const LagrangeElement& e = lagrange_element(t, q);
        for (int k = 0; k < e.size(); ++k) {
          const auto xi = e.ref_node(k);
          Point x;
          for (int r = 0; r < Dim; ++r) {
            x[r] = m[9 + r];
            for (int c = 0; c < Dim; ++c) x[r] += m[r * 3 + c] * xi[c];
          }
          block.connectivity.push_back(static_cast<NodeId>(mesh.nodes.size()));
          mesh.nodes.push_back(x);
        }
      }
    }
  }
  return mesh;
}

template <int Dim>
void check_written(const HybridMesh<Dim>& mesh, const std::vector<std::array<double, 12>>& maps,
                   const std::vector<CellField>& fields, const std::string& xml) {
  const std::vector<double> points = data_array(xml, "Points");
  const std::vector<double> conn = data_array(xml, "connectivity");
  const std::vector<double> offsets = data_array(xml, "offsets");
  const std::vector<double> types = data_array(xml, "types");
  const std::vector<double> block = data_array(xml, "block");
  const std::vector<double> degrees = data_array(xml, "HigherOrderDegrees");
  REQUIRE(points.size() == 3 * mesh.nodes.size());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    for (int d = 0; d < 3; ++d) CHECK(points[3 * i + d] == (d < Dim ? mesh.nodes[i][d] : 0.0));
  const std::size_t n = mesh.num_cells();
  REQUIRE(offsets.size() == n);
  REQUIRE(types.size() == n);
  REQUIRE(block.size() == n);
  REQUIRE(degrees.size() == 3 * n);
  std::size_t cell = 0, pos = 0;
  for (std::size_t bi = 0; bi < mesh.cells.size(); ++bi) {
    const CellBlock& b = mesh.cells[bi];
    const std::vector<int> perm = vtk_node_permutation(b.type, b.order);
    const std::vector<Lattice> vtk = vtk_lattice(b.type, b.order);
    for (std::size_t i = 0; i < b.size(); ++i, ++cell) {
      INFO(cell_name(b.type), " order ", b.order, " cell ", i);
      CHECK(types[cell] == vtk_cell_type(b.type, b.order));
      CHECK(block[cell] == static_cast<double>(bi));
      for (int d = 0; d < 3; ++d) CHECK(degrees[3 * cell + d] == (d < ref_dim(b.type) ? b.order : 0));
      for (const CellField& f : fields) CHECK(data_array(xml, f.name)[cell] == f.values[cell]);
      REQUIRE(offsets[cell] == static_cast<double>(pos + perm.size()));
      const std::array<double, 12>& m = maps[cell];
      for (std::size_t k = 0; k < perm.size(); ++k, ++pos) {
        const auto id = static_cast<std::size_t>(conn[pos]);
        CHECK(id == static_cast<std::size_t>(b.cell(i)[perm[k]]));
        if (b.order == 1) continue;  // linear cells: vertex orders are checked separately
        // The node VTK finds at position k sits at the image of VTK's reference point k.
        for (int r = 0; r < Dim; ++r) {
          double x = m[9 + r];
          for (int c = 0; c < Dim; ++c) x += m[r * 3 + c] * vtk[k][c] / b.order;
          CHECK(points[3 * id + r] == doctest::Approx(x).epsilon(1e-12));
        }
      }
    }
  }
  CHECK(conn.size() == pos);
}

}  // namespace

TEST_CASE("io: VTK permutation maps each Gmsh node to the VTK node at the same lattice point") {
  for (CellType t : all_types)
    for (int q = 2; q <= max_order; ++q) {
      INFO(cell_name(t), " order ", q);
      if (t == CellType::Line) continue;  // a polyline, below
      const std::vector<int> perm = vtk_node_permutation(t, q);
      const std::vector<Lattice> gmsh = gmsh_lattice(t, q), vtk = vtk_lattice(t, q);
      REQUIRE(perm.size() == gmsh.size());
      std::vector<int> sorted = perm;
      std::sort(sorted.begin(), sorted.end());
      for (std::size_t k = 0; k < sorted.size(); ++k) CHECK(sorted[k] == static_cast<int>(k));  // a bijection
      for (std::size_t k = 0; k < perm.size(); ++k) CHECK(gmsh[perm[k]] == vtk[k]);
      bool identity = true;
      for (std::size_t k = 0; k < perm.size(); ++k) identity = identity && perm[k] == static_cast<int>(k);
      // Lines and triangles share Gmsh's order; a 9-node quadrilateral has one node per edge, so
      // edge directions cannot differ; quadrilaterals from order 3 and all wedges reorder.
      const bool same_order = t == CellType::Triangle || (t == CellType::Quadrilateral && q == 2);
      CHECK(identity == same_order);
    }
  // Hand-derived from the documented orders. Quadrilateral, order 3: Gmsh runs edge 2-3 from
  // vertex 2 and edge 3-0 from vertex 3 and its interior counter-clockwise; VTK runs those edges
  // along +u and +v and its interior row by row.
  CHECK(vtk_node_permutation(CellType::Quadrilateral, 3) ==
        std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 9, 8, 11, 10, 12, 13, 15, 14});
  // Prism, order 2 (Gmsh manual: edges 0-1, 0-2, 0-3, 1-2, 1-4, 2-5, 3-4, 3-5, 4-5, then faces
  // 0-1-4-3, 0-3-5-2, 1-2-5-4; VTK: edges 0-1, 1-2, 2-0, 3-4, 4-5, 5-3, 0-3, 1-4, 2-5, then faces
  // 0-1-4-3, 1-2-5-4, 2-0-3-5).
  CHECK(vtk_node_permutation(CellType::Prism, 2) ==
        std::vector<int>{0, 1, 2, 3, 4, 5, 6, 9, 7, 12, 14, 13, 8, 10, 11, 15, 17, 16});
  // A curved line is a polyline through its nodes along it (Gmsh: ends, then the interior from
  // end 0).
  CHECK(vtk_node_permutation(CellType::Line, 2) == std::vector<int>{0, 2, 1});
  CHECK(vtk_node_permutation(CellType::Line, 4) == std::vector<int>{0, 2, 3, 4, 1});
}

TEST_CASE("io: VTK cell types, order 1 uses linear cells and reverses the wedge base") {
  const int lagrange[] = {4, 69, 70, 71, 73}, linear[] = {3, 5, 9, 10, 13};  // curved lines: polylines
  for (int i = 0; i < 5; ++i) {
    CHECK(vtk_cell_type(all_types[i], 1) == linear[i]);
    for (int q = 2; q <= max_order; ++q) CHECK(vtk_cell_type(all_types[i], q) == lagrange[i]);
  }
  CHECK(vtk_node_permutation(CellType::Prism, 1) == std::vector<int>{0, 2, 1, 3, 5, 4});
  CHECK(vtk_node_permutation(CellType::Tetrahedron, 1) == std::vector<int>{0, 1, 2, 3});
  CHECK(vtk_node_permutation(CellType::Quadrilateral, 1) == std::vector<int>{0, 1, 2, 3});
}

TEST_CASE("io: a written .vtu reads back: points, connectivity in VTK order, types, cell data") {
  TempDir dir("vtu");
  std::mt19937 rng(5);
  SUBCASE("2D") {
    std::vector<std::array<double, 12>> maps;
    const HybridMesh<2> mesh = affine_soup<2>(rng, maps);
    std::vector<double> quality(mesh.num_cells());
    for (std::size_t i = 0; i < quality.size(); ++i) quality[i] = 1.0 / static_cast<double>(i + 3);
    const std::vector<CellField> fields = {{"scaled <jacobian>", quality}};
    write_vtu(mesh, dir.path / "m.vtu", fields);
    const std::string xml = read_text(dir.path / "m.vtu");
    CHECK(xml.find("Name=\"scaled &lt;jacobian&gt;\"") != std::string::npos);
    check_written(mesh, maps, {{"scaled &lt;jacobian&gt;", quality}}, xml);
  }
  SUBCASE("3D") {
    std::vector<std::array<double, 12>> maps;
    const HybridMesh<3> mesh = affine_soup<3>(rng, maps);
    write_vtu(mesh, dir.path / "m.vtu");
    check_written(mesh, maps, {}, read_text(dir.path / "m.vtu"));
  }
}

TEST_CASE("io: a binary .vtu (zlib-compressed appended data) holds what the ASCII one holds") {
  TempDir dir("vtu_binary");
  std::mt19937 rng(7);
  std::vector<std::array<double, 12>> maps2, maps3;
  const HybridMesh<2> flat = affine_soup<2>(rng, maps2);
  const HybridMesh<3> solid = affine_soup<3>(rng, maps3);
  std::vector<double> quality(flat.num_cells());
  for (std::size_t i = 0; i < quality.size(); ++i) quality[i] = i % 3 == 0 ? -1.0 / static_cast<double>(i + 3) : 0.0;
  write_vtu(flat, dir.path / "flat.vtu", {{"q", quality}}, VtuEncoding::binary);
  write_vtu(solid, dir.path / "solid.vtu", {}, VtuEncoding::binary);
  const std::string f = read_text(dir.path / "flat.vtu");
  CHECK(f.find("compressor=\"vtkZLibDataCompressor\"") != std::string::npos);
  CHECK(f.find("format=\"ascii\"") == std::string::npos);
  check_written(flat, maps2, {{"q", quality}}, f);
  check_written(solid, maps3, {}, read_text(dir.path / "solid.vtu"));

  // Arrays longer than one compression block (1 MiB), and an empty mesh.
  HybridMesh<3> big;
  for (int i = 0; i < 70000; ++i) big.nodes.push_back({i * 1e-3, std::sin(i), std::cos(i)});
  CellBlock& tets = big.block(CellType::Tetrahedron, 1);
  for (int i = 0; i + 3 < 70000; i += 2) tets.connectivity.insert(tets.connectivity.end(), {i, i + 1, i + 2, i + 3});
  write_vtu(big, dir.path / "big.vtu", {}, VtuEncoding::binary);
  write_vtu(big, dir.path / "big_ascii.vtu");
  const std::string b = read_text(dir.path / "big.vtu"), a = read_text(dir.path / "big_ascii.vtu");
  for (const char* name : {"Points", "connectivity", "offsets", "types", "block", "HigherOrderDegrees"}) {
    INFO(name);
    CHECK(data_array(b, name) == data_array(a, name));
  }
  CHECK(b.size() * 2 < a.size());
  HybridMesh<3> empty;
  empty.block(CellType::Tetrahedron, 1);
  write_vtu(empty, dir.path / "empty.vtu", {}, VtuEncoding::binary);
  CHECK(data_array(read_text(dir.path / "empty.vtu"), "Points").empty());

  // Boundary files too.
  HybridMesh<2> m;
  m.nodes = {{0, 0}, {1, 0}, {0, 1}};
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  m.block(CellType::Triangle, 1).connectivity = {0, 1, 2};
  m.boundary_block(CellType::Line, 1, wall).connectivity = {0, 1};
  REQUIRE(write_boundary_vtu(m, dir.path / "m_boundary.vtu", VtuEncoding::binary));
  CHECK(data_array(read_text(dir.path / "m_boundary.vtu"), "tag") == std::vector<double>{1});
}

TEST_CASE("io: VTK reads plaf's binary .vtu as the ASCII one: points, cells, types, cell data") {
  if (std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("no Python vtk module (python3-vtk9): VTK's reading of binary .vtu not checked");
    return;
  }
  TempDir dir("vtu_binary_vtk");
  std::mt19937 rng(11);
  std::vector<std::array<double, 12>> maps;
  const HybridMesh<3> mesh = affine_soup<3>(rng, maps);
  std::vector<double> q(mesh.num_cells());
  for (std::size_t i = 0; i < q.size(); ++i) q[i] = 0.25 * static_cast<double>(i);
  write_vtu(mesh, dir.path / "a.vtu", {{"q", q}});
  write_vtu(mesh, dir.path / "b.vtu", {{"q", q}}, VtuEncoding::binary);
  const fs::path script = dir.path / "compare.py";
  test::write_text(script, R"(import sys, vtk
from vtk.util.numpy_support import vtk_to_numpy as np_of
def read(p):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(p)
    r.Update()
    if r.GetErrorCode() != 0: sys.exit("VTK could not read " + p)
    return r.GetOutput()
a, b = read(sys.argv[1]), read(sys.argv[2])
assert a.GetNumberOfCells() == b.GetNumberOfCells() > 0
assert (np_of(a.GetPoints().GetData()) == np_of(b.GetPoints().GetData())).all()
assert (np_of(a.GetCellTypesArray()) == np_of(b.GetCellTypesArray())).all()
assert (np_of(a.GetCells().GetConnectivityArray()) == np_of(b.GetCells().GetConnectivityArray())).all()
for name in ("q", "block", "HigherOrderDegrees"):
    assert (np_of(a.GetCellData().GetArray(name)) == np_of(b.GetCellData().GetArray(name))).all(), name
print("same", a.GetNumberOfCells())
)");
  const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + (dir.path / "a.vtu").string() + "' '" +
                          (dir.path / "b.vtu").string() + "' > '" + (dir.path / "out.txt").string() + "' 2>&1";
  const int rc = std::system(cmd.c_str());
  INFO(read_text(dir.path / "out.txt"));
  CHECK(rc == 0);
  CHECK(read_text(dir.path / "out.txt").find("same " + std::to_string(mesh.num_cells())) != std::string::npos);
}

TEST_CASE("io: VTU writer rejects bad fields and broken blocks without leaving a file") {
  TempDir dir("vtu_bad");
  std::mt19937 rng(9);
  std::vector<std::array<double, 12>> maps;
  HybridMesh<2> mesh = affine_soup<2>(rng, maps);
  const std::vector<double> ok(mesh.num_cells(), 1.0);
  std::vector<CellField> fields;
  SUBCASE("wrong length") {
    fields = {{"q", std::vector<double>(mesh.num_cells() + 1, 1.0)}};
  }
  SUBCASE("reserved name") {
    fields = {{"block", ok}};
  }
  SUBCASE("repeated name") {
    fields = {{"q", ok}, {"q", ok}};
  }
  SUBCASE("node out of range") {
    mesh.cells[1].connectivity[0] = -1;
  }
  SUBCASE("facet block among the cells") {
    mesh.cells[0].type = CellType::Line;
  }
  CHECK_THROWS_AS(write_vtu(mesh, dir.path / "m.vtu", fields), Error);
  CHECK(fs::is_empty(dir.path));
}

TEST_CASE("io: a 3D surface mesh writes its triangles, and its curves as its boundary file") {
  TempDir dir("vtu_surface");
  HybridMesh<3> m;
  m.nodes = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5}, {0, 1, 0}, {0.5, 0, 0}, {1, 0.5, 0.2}, {0.5, 0.5, 0.3}};
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  const int symmetry = m.add_tag("symmetry", BoundaryKind::Symmetry);
  m.boundary_block(CellType::Triangle, 2, wall).connectivity = {0, 1, 2, 4, 5, 6};
  m.curve_block(2, symmetry).connectivity = {0, 1, 4, 1, 2, 5};
  m.curve_block(1, symmetry).connectivity = {2, 3};
  write_vtu(m, dir.path / "s.vtu", {{"q", {0.75}}});
  const std::string xml = read_text(dir.path / "s.vtu");
  // The surface file holds the triangle alone: no curve cell beside it.
  CHECK(xml.find("NumberOfCells=\"1\"") != std::string::npos);
  CHECK(data_array(xml, "types") == std::vector<double>{69});
  CHECK(data_array(xml, "q") == std::vector<double>{0.75});
  // A field with one value per cell including the curves is the wrong length.
  CHECK_THROWS_AS(write_vtu(m, dir.path / "bad.vtu", {{"q", {1, 2, 3, 4}}}), Error);

  REQUIRE(write_boundary_vtu(m, dir.path / "s_boundary.vtu"));
  const std::string b = read_text(dir.path / "s_boundary.vtu");
  // The curves, on the six nodes they use (node 6, the triangle's inner node, is dropped).
  CHECK(b.find("NumberOfPoints=\"6\" NumberOfCells=\"3\"") != std::string::npos);
  CHECK(data_array(b, "types") == std::vector<double>{4, 4, 3});
  CHECK(data_array(b, "offsets") == std::vector<double>{3, 6, 8});
  CHECK(data_array(b, "HigherOrderDegrees") == std::vector<double>{2, 0, 0, 2, 0, 0, 1, 0, 0});
  // The tag is the MSH physical tag of the curves' boundary (index 1 + 1).
  CHECK(data_array(b, "tag") == std::vector<double>{2, 2, 2});
  // Curved lines are polylines through their nodes in order: end, middle, end.
  CHECK(data_array(b, "connectivity") == std::vector<double>{0, 4, 1, 1, 5, 2, 2, 3});
  CHECK(data_array(b, "Points") ==
        std::vector<double>{0, 0, 0, 1, 0, 0, 1, 1, 0.5, 0, 1, 0, 0.5, 0, 0, 1, 0.5, 0.2});
}

TEST_CASE("io: a mesh with cells writes its boundary facets with their tags, a curve mesh has no boundary file") {
  TempDir dir("vtu_boundary");
  HybridMesh<2> m;
  m.nodes = {{0, 0}, {1, 0}, {0, 1}, {5, 5}};
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  const int far = m.add_tag("farfield", BoundaryKind::Farfield);
  m.block(CellType::Triangle, 1).connectivity = {0, 1, 2};
  m.boundary_block(CellType::Line, 1, wall).connectivity = {0, 1};
  m.boundary_block(CellType::Line, 1, far).connectivity = {1, 2, 2, 0};
  write_vtu(m, dir.path / "m.vtu");
  CHECK(data_array(read_text(dir.path / "m.vtu"), "types") == std::vector<double>{5});
  REQUIRE(write_boundary_vtu(m, dir.path / "m_boundary.vtu"));
  const std::string b = read_text(dir.path / "m_boundary.vtu");
  CHECK(b.find("NumberOfPoints=\"3\" NumberOfCells=\"3\"") != std::string::npos);
  CHECK(data_array(b, "types") == std::vector<double>{3, 3, 3});
  CHECK(data_array(b, "tag") == std::vector<double>{1, 2, 2});
  // Lines alone (a 2D surface mesh) have no boundary: nothing is written.
  HybridMesh<2> lines;
  lines.nodes = m.nodes;
  lines.tags = m.tags;
  lines.boundary = m.boundary;
  CHECK_FALSE(write_boundary_vtu(lines, dir.path / "l_boundary.vtu"));
  CHECK_FALSE(fs::exists(dir.path / "l_boundary.vtu"));
}
