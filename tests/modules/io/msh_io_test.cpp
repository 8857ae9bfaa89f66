// SPDX-License-Identifier: MIT
#include "modules/io/msh_io.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "modules/base/coordinates.h"
#include "modules/io/atomic_file.h"
#include "modules/base/error.h"
#include "tests/modules/io/sample_meshes.h"
#include "tests/test_support.h"
#include "tests/published_data.h"

using namespace plaf;
using test::annulus_sector;
using test::cell_keys;
using test::check_same;
using test::read_text;
using test::TempDir;
using test::write_text;
namespace fs = std::filesystem;

namespace {


// Node k of every cell sits at the affine image of its reference lattice point (cells with
// straight edges), to a tolerance relative to the cell size.
template <int Dim>
void check_nodes_on_lattice(const HybridMesh<Dim>& mesh, const CellBlock& b) {
  const std::vector<Lattice> lattice = gmsh_lattice(b.type, b.order);
  const int nv = num_vertices(b.type);
  for (std::size_t i = 0; i < b.size(); ++i) {
    const NodeId* c = b.cell(i);
    const auto& o = mesh.nodes[c[0]];
    const double size_abs = (mesh.nodes[c[1]] - o).norm();
    for (std::size_t k = 0; k < lattice.size(); ++k) {
      auto x = o;
      // Reference vertex e+1 of triangles, tetrahedra and prisms is the unit point on axis e;
      // quadrilaterals use vertices 1 and 3; the prism's third axis ends at vertex 3.
      const int axis_vertex[3] = {1, b.type == CellType::Quadrilateral ? 3 : 2, 3};
      for (int e = 0; e < ref_dim(b.type); ++e)
        x += (mesh.nodes[c[axis_vertex[e]]] - o) * (static_cast<double>(lattice[k][e]) / b.order);
      INFO(cell_name(b.type), " cell ", i, " node ", k, " of ", nv, " vertices");
      CHECK((mesh.nodes[c[k]] - x).norm() <= 1e-10 * size_abs);
    }
  }
}

}  // namespace

TEST_CASE("io: MSH round trip keeps nodes bit for bit, blocks, tags and kinds (2D quads + triangles)") {
  TempDir dir("msh2d");
  for (int q = 1; q <= max_order; ++q)
    for (double scale : {1e-8, 1.0, 1e8}) {
      INFO("order ", q, " scale ", scale);
      HybridMesh<2> mesh = annulus_sector<2>(3, 4, 1, scale, [&](int, int, int) { return q; });
      REQUIRE(check_conformity(mesh).ok);
      // Extreme values survive too (stored as extra, unused nodes), up to the readers' range.
      for (double v : {-0.0, 5e-324, kMaxCoordinate, std::nextafter(kMaxCoordinate, 0.0), 0.1, -1.0 / 3.0})
        mesh.nodes.push_back(HybridMesh<2>::Point(v, -v));
      write_msh41(mesh, dir / "m.msh");
      const MshMesh back = read_msh41(dir / "m.msh");
      CHECK(back.dim == 2);
      check_same(mesh, back.mesh2);
    }
}

TEST_CASE("io: MSH round trip in 3D: tetrahedra + prisms of every order, and mixed orders") {
  TempDir dir("msh3d");
  for (int q = 0; q <= max_order; ++q) {
    INFO("order ", q, " (0: mixed)");
    const HybridMesh<3> mesh = annulus_sector<3>(
        2, 2, 2, 1.0, [&](int i, int j, int k) { return q > 0 ? q : 1 + (i + 2 * j + k) % max_order; });
    if (q > 0) REQUIRE(check_conformity(mesh).ok);
    write_msh41(mesh, dir / "m.msh");
    const MshMesh back = read_msh41(dir / "m.msh");
    CHECK(back.dim == 3);
    check_same(mesh, back.mesh3);
  }
}

TEST_CASE("io: MSH writer uses Gmsh's element type numbers (Gmsh's GmshDefines.h)") {
  struct Row {
    CellType type;
    int codes[max_order];
  };
  const Row table[] = {{CellType::Line, {1, 8, 26, 27}},
                       {CellType::Triangle, {2, 9, 21, 23}},
                       {CellType::Quadrilateral, {3, 10, 36, 37}},
                       {CellType::Tetrahedron, {4, 11, 29, 30}},
                       {CellType::Prism, {6, 13, 90, 91}}};
  for (const Row& r : table)
    for (int q = 1; q <= max_order; ++q) CHECK(gmsh_element_type(r.type, q) == r.codes[q - 1]);
  CHECK_THROWS_AS(gmsh_element_type(CellType::Prism, 5), Error);
}

// Written by Gmsh 4.8.4: `gmsh -2 -order 2 -save_parametric` on the unit square with physical
// curves "Wall_bottom" (y = 0), "farfield" (x = 1, y = 1), an unnamed group 7 (x = 0), and
// physical surface "fluid".
constexpr const char* gmsh_square_tri6 = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
3
1 1 "Wall_bottom"
1 2 "farfield"
2 8 "fluid"
$EndPhysicalNames
$Entities
4 4 1 0
1 0 0 0 0 
2 1 0 0 0 
3 1 1 0 0 
4 0 1 0 0 
1 0 0 0 1 0 0 1 1 2 1 -2 
2 1 0 0 1 1 0 1 2 2 2 -3 
3 0 1 0 1 1 0 1 2 2 3 -4 
4 0 0 0 0 1 0 1 7 2 4 -1 
1 0 0 0 1 1 0 1 8 4 1 2 3 4 
$EndEntities
$Nodes
9 13 1 13
0 1 0 1
1
0 0 0
0 2 0 1
2
1 0 0
0 3 0 1
3
1 1 0
0 4 0 1
4
0 1 0
1 1 1 1
5
0.4999999999986718 0 0 0.4999999999986718
1 2 1 1
6
1 0.4999999999986718 0 0.4999999999986718
1 3 1 1
7
0.5000000000013305 1 0 0.4999999999986696
1 4 1 1
8
0 0.5000000000013305 0 0.4999999999986696
2 1 1 5
9
10
11
12
13
0.5 0.5 0 0.5 0.5
0.75 0.25 0 0.25 0.75
0.25 0.25 0 0.25 0.25
0.25 0.75 0 0.75 0.25
0.75 0.75 0 0.75 0.75
$EndNodes
$Elements
5 8 1 8
1 1 8 1
1 1 2 5 
1 2 8 1
2 2 3 6 
1 3 8 1
3 3 4 7 
1 4 8 1
4 4 1 8 
2 1 9 4
5 1 2 9 5 10 11 
6 4 1 9 8 11 12 
7 2 3 9 6 13 10 
8 3 4 9 7 12 13 
$EndElements
)";

// Written by Gmsh 4.8.4: `gmsh -3 -order 2` on the triangle (0,0), (1,0), (0,1) extruded by 0.5
// in one recombined layer, with physical surfaces "wall" (z = 0), "symmetry_top" (z = 0.5),
// "outlet" (the sides) and physical volume "fluid". Note the empty node blocks.
constexpr const char* gmsh_prism18 = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
4
2 1 "wall"
2 2 "symmetry_top"
2 3 "outlet"
3 4 "fluid"
$EndPhysicalNames
$Entities
6 9 5 1
1 0 0 0 0 
2 1 0 0 0 
3 0 1 0 0 
4 0 0 0.5 0 
5 1 0 0.5 0 
9 0 1 0.5 0 
1 0 0 0 1 0 0 0 2 1 -2 
2 0 0 0 1 1 0 0 2 2 -3 
3 0 0 0 0 1 0 0 2 3 -1 
5 0 0 0.5 1 0 0.5 0 2 4 -5 
6 0 0 0.5 1 1 0.5 0 2 5 -9 
7 0 0 0.5 0 1 0.5 0 2 9 -4 
9 0 0 0 0 0 0.5 0 2 1 -4 
10 1 0 0 1 0 0.5 0 2 2 -5 
14 0 1 0 0 1 0.5 0 2 3 -9 
1 0 0 0 1 1 0 1 1 3 1 2 3 
11 0 0 0 1 0 0.5 1 3 4 1 10 -5 -9 
15 0 0 0 1 1 0.5 1 3 4 2 14 -6 -10 
19 0 0 0 0 1 0.5 1 3 4 3 9 -7 -14 
20 0 0 0.5 1 1 0.5 1 2 3 5 6 7 
1 0 0 0 1 1 0.5 1 4 5 -1 20 11 15 19 
$EndEntities
$Nodes
21 18 1 18
0 1 0 1
1
0 0 0
0 2 0 1
2
1 0 0
0 3 0 1
3
0 1 0
0 4 0 1
4
0 0 0.5
0 5 0 1
5
1 0 0.5
0 9 0 1
6
0 1 0.5
1 1 0 1
7
0.4999999999986718 0 0
1 2 0 1
8
0.5000000000013294 0.4999999999986707 0
1 3 0 1
9
0 0.5000000000013305 0
1 5 0 1
10
0.4999999999986718 0 0.5
1 6 0 1
11
0.5000000000013294 0.4999999999986707 0.5
1 7 0 1
12
0 0.5000000000013305 0.5
1 9 0 1
13
0 0 0.2499999999993359
1 10 0 1
14
1 0 0.2499999999993359
1 14 0 1
15
0 1 0.2499999999993359
2 1 0 0
2 11 0 1
16
0.4999999999986717 0 0.2499999999993359
2 15 0 1
17
0.5000000000013294 0.4999999999986706 0.2499999999993359
2 19 0 1
18
0 0.5000000000013305 0.2499999999993359
2 20 0 0
3 1 0 0
$EndNodes
$Elements
6 6 1 6
2 1 9 1
1 1 2 3 7 8 9 
2 11 10 1
2 1 2 5 4 7 14 10 13 16 
2 15 10 1
3 2 3 6 5 8 15 11 14 17 
2 19 10 1
4 3 1 4 6 9 13 12 15 18 
2 20 9 1
5 4 5 6 10 11 12 
3 1 13 1
6 1 2 3 4 5 6 7 9 13 8 14 15 10 12 11 16 18 17 
$EndElements
)";

TEST_CASE("io: MSH reader takes Gmsh's own files: physical names, kinds, parametric and empty node blocks") {
  TempDir dir("gmsh_files");
  SUBCASE("2D, second-order triangles") {
    write_text(dir / "square.msh", gmsh_square_tri6);
    const MshMesh m = read_msh41(dir / "square.msh");
    REQUIRE(m.dim == 2);
    const HybridMesh<2>& mesh = m.mesh2;
    REQUIRE(mesh.cells.size() == 1);
    CHECK(mesh.cells[0].type == CellType::Triangle);
    CHECK(mesh.cells[0].order == 2);
    check_nodes_on_lattice(mesh, mesh.cells[0]);
    // Every facet is interior or tagged, and the tags come from the physical groups.
    const ConformityReport conformity = check_conformity(mesh);
    CHECK_MESSAGE(conformity.ok, conformity.first_problem);
    REQUIRE(mesh.tags.size() == 3);
    CHECK(mesh.tags[0].name == "Wall_bottom");
    CHECK(mesh.tags[0].kind == BoundaryKind::Wall);
    CHECK(mesh.tags[1].name == "farfield");
    CHECK(mesh.tags[1].kind == BoundaryKind::Farfield);
    CHECK(mesh.tags[2].name == "physical_7");
    CHECK(mesh.tags[2].kind == BoundaryKind::Named);
    for (const CellBlock& b : mesh.boundary)
      for (NodeId v : b.connectivity) {
        const auto& x = mesh.nodes[v];
        if (b.tag == 0) CHECK(x[1] == 0.0);
        if (b.tag == 2) CHECK(x[0] == 0.0);
      }
    // The triangles tile the unit square.
    double area = 0;
    const CellBlock& b = mesh.cells[0];
    for (std::size_t i = 0; i < b.size(); ++i) {
      const auto e1 = mesh.nodes[b.cell(i)[1]] - mesh.nodes[b.cell(i)[0]];
      const auto e2 = mesh.nodes[b.cell(i)[2]] - mesh.nodes[b.cell(i)[0]];
      area += std::abs(e1[0] * e2[1] - e1[1] * e2[0]) / 2;
    }
    CHECK(area == doctest::Approx(1.0).epsilon(1e-12));
  }
  SUBCASE("3D, second-order prism with triangle and quadrilateral facets") {
    write_text(dir / "prism.msh", gmsh_prism18);
    const MshMesh m = read_msh41(dir / "prism.msh");
    REQUIRE(m.dim == 3);
    const HybridMesh<3>& mesh = m.mesh3;
    REQUIRE(mesh.cells.size() == 1);
    CHECK(mesh.cells[0].type == CellType::Prism);
    CHECK(mesh.cells[0].order == 2);
    check_nodes_on_lattice(mesh, mesh.cells[0]);
    for (const CellBlock& b : mesh.boundary) check_nodes_on_lattice(mesh, b);
    const ConformityReport conformity = check_conformity(mesh);
    CHECK_MESSAGE(conformity.ok, conformity.first_problem);
    REQUIRE(mesh.tags.size() == 3);
    CHECK(mesh.tags[0].kind == BoundaryKind::Wall);
    CHECK(mesh.tags[1].kind == BoundaryKind::Symmetry);
    CHECK(mesh.tags[2].name == "outlet");
    CHECK(mesh.tags[2].kind == BoundaryKind::Named);
  }
}

namespace {

// One triangle in the plane, no $Entities: the smallest valid file.
constexpr const char* minimal_msh = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$Nodes
1 3 1 3
2 1 0 3
1
2
3
0 0 0
1 0 0
0 1 0
$EndNodes
$Elements
2 2 1 2
2 1 2 1
1 1 2 3
1 5 1 1
2 1 2
$EndElements
)";

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const std::size_t at = s.find(from);
  REQUIRE(at != std::string::npos);
  return s.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("io: MSH reader accepts a minimal file without $Entities, facets without physicals get entity tags") {
  TempDir dir("msh_minimal");
  write_text(dir / "m.msh", minimal_msh);
  const MshMesh m = read_msh41(dir / "m.msh");
  REQUIRE(m.dim == 2);
  REQUIRE(m.mesh2.tags.size() == 1);
  CHECK(m.mesh2.tags[0].name == "entity_5");
  REQUIRE(m.mesh2.boundary.size() == 1);
  CHECK(m.mesh2.boundary[0].connectivity == std::vector<NodeId>{0, 1});
  // Sparse node tags map to contiguous indices in file order.
  write_text(dir / "sparse.msh",
             replace(replace(replace(replace(minimal_msh, "1 3 1 3", "1 3 10 3000"), "1\n2\n3\n", "3000\n10\n200\n"),
                             "1 1 2 3", "1 200 3000 10"),
                     "2 1 2\n$End", "2 3000 10\n$End"));
  const MshMesh s = read_msh41(dir / "sparse.msh");
  CHECK(s.mesh2.cells[0].connectivity == std::vector<NodeId>{2, 0, 1});
  CHECK(s.mesh2.boundary[0].connectivity == std::vector<NodeId>{0, 1});
}

TEST_CASE("io: malformed MSH files throw InputError \"path:line: reason\", never crash") {
  TempDir dir("msh_bad");
  struct Case {
    const char* what;
    std::string text;
    const char* fragment;
    int line;  // expected line in the message; 0: not checked
  };
  const std::string m = minimal_msh;
  const std::vector<Case> cases = {
      {"empty file", "", "unexpected end of file", 1},
      {"not an MSH file", "solid cube\nfacet normal 0 0 1\n", "expected $MeshFormat", 1},
      {"MSH 4.0", replace(m, "4.1 0 8", "4.0 0 8"), "MSH version '4.0' is not supported", 2},
      {"a 4.1 body under a 2.2 header", replace(m, "4.1 0 8", "2.2 0 8"), "expected $EndNodes, found '1'", 6},
      {"MSH 2.2 element with a node out of range",
       "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
       "$Elements\n1\n1 2 2 1 1 1 2 7\n$EndElements\n",
       "unknown node tag 7", 12},
      {"MSH 2.2 absurd count", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n99999999999\n$EndNodes\n",
       "exceeds what the rest of the file", 5},
      {"binary MSH without its binary data", replace(m, "4.1 0 8", "4.1 1 8"), "binary MSH: the integer 1 after the header reads as", 3},
      {"bad number", replace(m, "1 0 0\n0 1 0", "1 0 0\n0 1x 0"), "bad node coordinate '1x'", 12},
      {"non-finite coordinate", replace(m, "1 0 0\n", "1 nan 0\n"), "bad node coordinate 'nan'", 11},
      {"truncated in $Nodes", m.substr(0, m.find("0 1 0\n$EndNodes")), "unexpected end of file", 12},
      {"missing $Elements", m.substr(0, m.find("$Elements")), "missing $Elements section", 0},
      {"missing $Nodes", m.substr(0, m.find("$Nodes")), "missing $Nodes section", 0},
      {"misspelled section", replace(m, "$Nodes", "$Nodez"), "section $Nodez has no $EndNodez", 4},
      {"unknown node tag", replace(m, "1 1 2 3", "1 1 2 99"), "unknown node tag 99", 17},
      {"duplicate node tag", replace(m, "1\n2\n3\n", "1\n2\n2\n"), "duplicate node tag 2", 9},
      {"hexahedra", replace(m, "2 1 2 1\n1 1 2 3", "3 1 5 1\n1 1 2 3 1 2 3 1 2"), "unsupported Gmsh element type 5",
       16},
      {"unknown element type", replace(m, "2 1 2 1", "2 1 999 1"), "unsupported Gmsh element type 999", 16},
      {"type and entity dimension differ", replace(m, "2 1 2 1", "1 1 2 1"),
       "has dimension 2 but its entity has dimension 1", 16},
      {"more nodes than announced", replace(m, "1 3 1 3", "1 2 1 3"), "more nodes than the 2 announced", 6},
      {"fewer elements than announced", replace(m, "2 2 1 2", "2 3 1 2"), "element blocks hold 2 elements", 19},
      {"absurd count", replace(m, "1 3 1 3", "1 999999999999 1 999999999999"), "exceeds what the rest of the file", 5},
      {"negative count", replace(m, "1 3 1 3", "1 -3 1 3"), "negative number of nodes", 5},
      {"wrong end keyword", replace(m, "$EndNodes", "$EndNode"), "expected $EndNodes, found '$EndNode'", 13},
      {"unterminated unknown section", m + "$NodeData\n1\n\"u\"\n", "section $NodeData has no $EndNodeData", 21},
      {"no nodes, extreme tag range",
       "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n0 0 -9223372036854775807 9223372036854775807\n$EndNodes\n"
       "$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n",
       "unknown node tag 1", 10},
      {"elements before nodes", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Elements\n0 0 0 0\n$EndElements\n",
       "$Elements must come after $Nodes", 4},
      {"only points",
       "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n0 1 0 1\n1\n0 0 0\n$EndNodes\n"
       "$Elements\n1 1 1 1\n0 1 15 1\n1 1\n$EndElements\n",
       "no line, 2D or 3D elements", 10},
      {"node off the plane", replace(m, "0 1 0\n$EndNodes", "0 1 0.25\n$EndNodes"), "off the plane z = 0", 12},
      {"unknown entity", replace(m, "$Nodes", "$Entities\n0 0 1 0\n1 0 0 0 1 1 0 0 0\n$EndEntities\n$Nodes"),
       "entity (dimension 1, tag 5) missing from $Entities", 22},
      {"unterminated physical name", replace(m, "$Nodes", "$PhysicalNames\n1\n1 5 \"wall\n$EndPhysicalNames\n$Nodes"),
       "unterminated physical name", 6},
      {"duplicate section", m + "$Nodes\n0 0 0 0\n$EndNodes\n", "duplicate section $Nodes", 21},
      {"garbage after the header", replace(m, "$Nodes", "\x01\x02\xff"), "expected a section such as $Nodes", 4},
  };
  for (const Case& c : cases) {
    INFO(std::string(c.what));
    const fs::path p = dir / "bad.msh";
    write_text(p, c.text);
    std::string message;
    try {
      read_msh41(p);
    } catch (const InputError& e) {
      message = e.what();
    }
    REQUIRE_MESSAGE(!message.empty(), "no InputError for: ", std::string(c.what));
    CHECK_MESSAGE(message.find(c.fragment) != std::string::npos, message);
    CHECK(message.find('\n') == std::string::npos);
    CHECK(message.rfind(p.string() + ":", 0) == 0);
    if (c.line > 0) CHECK_MESSAGE(message.rfind(p.string() + ":" + std::to_string(c.line) + ": ", 0) == 0, message);
  }
  CHECK_THROWS_AS(read_msh41(dir / "does_not_exist.msh"), InputError);
}

TEST_CASE("io: every truncation and random corruption of an MSH file parses or throws InputError") {
  TempDir dir("msh_fuzz");
  const HybridMesh<2> mesh = annulus_sector<2>(1, 2, 1, 1.0, [](int, int, int) { return 2; });
  write_msh41(mesh, dir / "good.msh");
  const std::string good = read_text(dir / "good.msh");
  const fs::path p = dir / "bad.msh";
  auto outcome = [&](const std::string& text) {
    write_text(p, text);
    try {
      read_msh41(p);
      return 0;
    } catch (const InputError&) {
      return 1;
    }  // any other exception fails the test case
  };
  // Every proper prefix misses at least the final $EndElements.
  int rejected = 0;
  for (std::size_t n = 0; n + 1 < good.size(); ++n) rejected += outcome(good.substr(0, n));
  CHECK(rejected == static_cast<int>(good.size()) - 1);
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::size_t> pos(0, good.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int trial = 0; trial < 300; ++trial) {
    std::string text = good;
    for (int k = 0; k < 1 + trial % 4; ++k) text[pos(rng)] = static_cast<char>(byte(rng));
    outcome(text);
  }
}

TEST_CASE("io: AtomicFile leaves no file on failure and replaces the target on commit") {
  TempDir dir("atomic");
  const fs::path target = dir / "out.txt";
  SUBCASE("an exception mid-write leaves neither the target nor the temporary") {
    fs::path temp;
    try {
      AtomicFile f(target);
      temp = f.temp_path();
      f.write("partial");
      CHECK(fs::exists(temp));
      throw std::runtime_error("writer failed");
    } catch (const std::runtime_error&) {
    }
    CHECK(!temp.empty());
    CHECK(!fs::exists(target));
    CHECK(!fs::exists(temp));
  }
  SUBCASE("a failed write keeps the previous file; commit replaces it") {
    write_text(target, "old");
    try {
      AtomicFile f(target);
      f.write("new but failed");
      throw std::runtime_error("writer failed");
    } catch (const std::runtime_error&) {
    }
    CHECK(read_text(target) == "old");
    fs::path temp;
    {
      AtomicFile f(target);
      temp = f.temp_path();
      f.write("new");
      CHECK(read_text(target) == "old");
      f.commit();
    }
    CHECK(read_text(target) == "new");
    CHECK(!fs::exists(temp));
  }
  SUBCASE("numbers round-trip through the buffer, across several flushes") {
    std::mt19937_64 rng(3);
    std::vector<double> values = {0.0, -0.0, 5e-324, std::numeric_limits<double>::max(), 0.1, 1.0 / 3.0};
    while (values.size() < 200000) {  // about 4 MB: several buffer flushes
      const double v = std::bit_cast<double>(rng());
      if (std::isfinite(v)) values.push_back(v);
    }
    {
      AtomicFile f(target);
      f.write_int(std::numeric_limits<std::int64_t>::min());
      f.put('\n');
      for (double v : values) {
        f.write_double(v);
        f.put('\n');
      }
      f.write(std::string(3 << 20, 'x'));  // larger than the buffer
      f.commit();
    }
    std::istringstream in(read_text(target));
    std::string token;
    in >> token;
    CHECK(token == std::to_string(std::numeric_limits<std::int64_t>::min()));
    for (double v : values) {
      in >> token;
      const double back = std::strtod(token.c_str(), nullptr);
      REQUIRE(std::bit_cast<std::uint64_t>(back) == std::bit_cast<std::uint64_t>(v));
    }
    in >> token;
    CHECK(token.size() == (3u << 20));
  }
  SUBCASE("an unwritable target throws Error naming the path") {
    const fs::path bad = dir / "no_such_dir" / "out.msh";
    try {
      AtomicFile f(bad);
      FAIL("no error");
    } catch (const Error& e) {
      CHECK(std::string(e.what()).find(bad.string()) != std::string::npos);
    }
  }
}

TEST_CASE("io: MSH writer rejects a broken mesh without leaving a file") {
  TempDir dir("msh_broken");
  HybridMesh<2> mesh = annulus_sector<2>(1, 2, 1, 1.0, [](int, int, int) { return 3; });
  const fs::path p = dir / "m.msh";
  SUBCASE("node out of range") {
    mesh.cells[0].connectivity[5] = static_cast<NodeId>(mesh.nodes.size());
  }
  SUBCASE("missing tag") {
    mesh.boundary[0].tag = 7;
  }
  SUBCASE("quote in a tag name") {
    mesh.tags[0].name = "wall \"a\"";
  }
  SUBCASE("partial cell") {
    mesh.cells[0].connectivity.pop_back();
  }
  CHECK_THROWS_AS(write_msh41(mesh, p), Error);
  CHECK(fs::is_empty(dir.path));
}

TEST_CASE("io: a file of lines alone reads as a 2D surface mesh (boundary loops, no cells)") {
  TempDir dir("msh_lines");
  HybridMesh<2> m;
  m.nodes = {{0, 0}, {1, 0}, {0, 1}, {0.5, -0.1}, {0.6, 0.6}, {-0.1, 0.5}};
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  m.boundary_block(CellType::Line, 2, wall).connectivity = {0, 1, 3, 1, 2, 4, 2, 0, 5};
  write_msh41(m, dir / "loop.msh");
  const MshMesh r = read_msh41(dir / "loop.msh");
  CHECK(r.dim == 2);
  CHECK(r.mesh2.cells.empty());
  REQUIRE(r.mesh2.boundary.size() == 1);
  CHECK(r.mesh2.boundary[0].connectivity == m.boundary[0].connectivity);
  CHECK(r.mesh2.tags.at(static_cast<std::size_t>(r.mesh2.boundary[0].tag)).kind == BoundaryKind::Wall);
}

TEST_CASE("io: a 3D surface mesh with curves round-trips: curve entities of dimension 1 with their own groups") {
  TempDir dir("msh_curves");
  // Two order-2 triangles bent out of the plane (a 3D surface), its rim a "symmetry" curve.
  HybridMesh<3> m;
  m.nodes = {{0, 0, 0},     {1, 0, 0},     {1, 1, 0.5}, {0, 1, 0},      {0.5, 0, 0},
             {1, 0.5, 0.2}, {0.5, 1, 0.2}, {0, 0.5, 0}, {0.5, 0.5, 0.3}};
  const int symmetry = m.add_tag("symmetry_rim", BoundaryKind::Symmetry);
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  const int both = m.add_tag("edge_and_face", BoundaryKind::Named);
  m.boundary_block(CellType::Triangle, 2, wall).connectivity = {0, 1, 2, 4, 5, 8};
  m.boundary_block(CellType::Triangle, 2, both).connectivity = {0, 2, 3, 8, 6, 7};
  m.curve_block(2, symmetry).connectivity = {0, 1, 4, 1, 2, 5, 2, 3, 6};
  m.curve_block(2, both).connectivity = {3, 0, 7};
  REQUIRE(check_conformity(m).ok);
  write_msh41(m, dir / "surface.msh");
  const std::string text = read_text(dir / "surface.msh");
  // Curve tags are physical groups of dimension 1; a tag used by curves alone has none of dimension 2.
  CHECK(text.find("1 1 \"symmetry_rim\"") != std::string::npos);
  CHECK(text.find("2 1 \"symmetry_rim\"") == std::string::npos);
  CHECK(text.find("1 3 \"edge_and_face\"") != std::string::npos);
  CHECK(text.find("2 3 \"edge_and_face\"") != std::string::npos);
  CHECK(text.find("2 2 \"wall\"") != std::string::npos);
  CHECK(text.find("$Entities\n0 2 2 1\n") != std::string::npos);
  const MshMesh back = read_msh41(dir / "surface.msh");
  REQUIRE(back.dim == 3);
  CHECK(back.mesh3.cells.empty());
  check_same(m, back.mesh3);
  REQUIRE(back.mesh3.curves.size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(back.mesh3.curves[i].type == CellType::Line);
    CHECK(back.mesh3.curves[i].order == 2);
    CHECK(back.mesh3.curves[i].tag == m.curves[i].tag);
    CHECK(back.mesh3.curves[i].connectivity == m.curves[i].connectivity);
  }
  CHECK(check_conformity(back.mesh3).ok);

  // Lines of an entity without a physical group are ignored in 3D (Gmsh's "save all").
  const std::string entity_line = "1 0 0 0 1 1 0.5 1 1 0\n";  // curve entity 1 with physical 1
  REQUIRE(text.find(entity_line) != std::string::npos);
  write_text(dir / "unnamed.msh", replace(text, entity_line, "1 0 0 0 1 1 0.5 0 0\n"));
  const MshMesh unnamed = read_msh41(dir / "unnamed.msh");
  REQUIRE(unnamed.mesh3.curves.size() == 1);
  CHECK(unnamed.mesh3.curves[0].connectivity == m.curves[1].connectivity);

  // A 2D mesh may not carry curves.
  HybridMesh<2> flat;
  flat.nodes = {{0, 0}, {1, 0}};
  flat.add_tag("c", BoundaryKind::Named);
  flat.curves.push_back(CellBlock{CellType::Line, 1, 0, {0, 1}});
  CHECK_THROWS_AS(write_msh41(flat, dir / "flat.msh"), Error);
}

TEST_CASE("io: curves of a 3D volume mesh round-trip next to its cells") {
  TempDir dir("msh_volume_curves");
  HybridMesh<3> mesh = annulus_sector<3>(2, 2, 2, 1.0, [](int, int, int) { return 2; });
  REQUIRE(!mesh.boundary.empty());
  // The first boundary facet's first edge as a tagged curve.
  const CellBlock& f = mesh.boundary[0];
  const LagrangeElement& e = lagrange_element(f.type, f.order);
  const std::vector<int>& edge = e.edge_nodes(0);
  const int tag = mesh.add_tag("symmetry_line", BoundaryKind::Symmetry);
  CellBlock& c = mesh.curve_block(2, tag);
  c.connectivity = {f.cell(0)[edge.front()], f.cell(0)[edge.back()], f.cell(0)[edge[1]]};
  write_msh41(mesh, dir / "m.msh");
  const MshMesh back = read_msh41(dir / "m.msh");
  REQUIRE(back.dim == 3);
  check_same(mesh, back.mesh3);
  REQUIRE(back.mesh3.curves.size() == 1);
  CHECK(back.mesh3.curves[0].connectivity == c.connectivity);
  CHECK(back.mesh3.tags[static_cast<std::size_t>(back.mesh3.curves[0].tag)].name == "symmetry_line");
}

TEST_CASE("io: MSH entities list their bounding entities and no physical group is empty") {
  TempDir dir("msh_bounding");
  SUBCASE("2D: the domain is bounded by its boundary curves; an unused tag and no cells give no group") {
    HybridMesh<2> m;
    m.nodes = {{0, 0}, {1, 0}, {0, 1}};
    const int wall = m.add_tag("wall", BoundaryKind::Wall);
    m.add_tag("unused", BoundaryKind::Named);
    const int far = m.add_tag("farfield", BoundaryKind::Farfield);
    m.block(CellType::Triangle, 1).connectivity = {0, 1, 2};
    m.boundary_block(CellType::Line, 1, wall).connectivity = {0, 1};
    m.boundary_block(CellType::Line, 1, far).connectivity = {1, 2, 2, 0};
    write_msh41(m, dir / "m.msh");
    const std::string text = read_text(dir / "m.msh");
    CHECK(text.find("$PhysicalNames\n3\n1 1 \"wall\"\n1 3 \"farfield\"\n2 4 \"domain\"\n") != std::string::npos);
    CHECK(text.find("unused") == std::string::npos);
    // Two curve entities (tags 1 and 3, no bounding points), the surface bounded by both.
    CHECK(text.find("$Entities\n0 2 1 0\n1 0 0 0 1 0 0 1 1 0\n3 0 0 0 1 1 0 1 3 0\n1 0 0 0 1 1 0 1 4 2 1 3\n") !=
          std::string::npos);
    const MshMesh back = read_msh41(dir / "m.msh");
    REQUIRE(back.mesh2.tags.size() == 2);
    CHECK(back.mesh2.tags[0].name == "wall");
    CHECK(back.mesh2.tags[1].name == "farfield");

    // The same lines without the triangle: the surface entity stays (bounded), its group goes.
    m.cells.clear();
    write_msh41(m, dir / "lines.msh");
    const std::string lines = read_text(dir / "lines.msh");
    CHECK(lines.find("domain") == std::string::npos);
    CHECK(lines.find("\n1 0 0 0 1 1 0 0 2 1 3\n$EndEntities") != std::string::npos);
    CHECK(read_msh41(dir / "lines.msh").dim == 2);
  }
  SUBCASE("3D surface: a patch is bounded by the curves on its rim, not by one inside it") {
    HybridMesh<3> m;
    m.nodes = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const int rim = m.add_tag("symmetry", BoundaryKind::Symmetry);
    const int inner = m.add_tag("crease", BoundaryKind::Named);
    const int wall = m.add_tag("wall", BoundaryKind::Wall);
    m.boundary_block(CellType::Triangle, 1, wall).connectivity = {0, 1, 2, 0, 2, 3};
    m.curve_block(1, rim).connectivity = {0, 1, 1, 2};
    m.curve_block(1, inner).connectivity = {0, 2};  // the diagonal two triangles share
    write_msh41(m, dir / "s.msh");
    const std::string text = read_text(dir / "s.msh");
    CHECK(text.find("domain") == std::string::npos);
    CHECK(text.find("\n3 0 0 0 1 1 0 1 3 1 1\n") != std::string::npos);   // wall: bounded by curve 1
    CHECK(text.find("\n1 0 0 0 1 1 0 0 1 3\n$EndEntities") != std::string::npos);  // volume: no group
    const MshMesh back = read_msh41(dir / "s.msh");
    CHECK(back.dim == 3);
    CHECK(back.mesh3.curves.size() == 2);
  }
}

TEST_CASE("io: Gmsh's API finds plaf's bounding entities and no empty physical group") {
  // Gmsh's own eye, where its Python module is installed (python3-gmsh).
  if (std::system("/usr/bin/python3 -c 'import gmsh' > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("no Python gmsh module (python3-gmsh): Gmsh's reader not run");
    return;
  }
  TempDir dir("msh_gmsh_api");
  HybridMesh<3> mesh = annulus_sector<3>(2, 2, 2, 1.0, [](int, int, int) { return 2; });
  write_msh41(mesh, dir / "m.msh");
  write_text(dir / "api.py",
             "import gmsh, sys\n"
             "gmsh.initialize()\n"
             "gmsh.option.setNumber('General.Terminal', 0)\n"
             "gmsh.open(sys.argv[1])\n"
             "b = gmsh.model.getBoundary([(3, 1)], oriented=False, combined=False)\n"
             "print('bounding', len(b))\n"
             "for dim, p in gmsh.model.getPhysicalGroups():\n"
             "    n = 0\n"
             "    for e in gmsh.model.getEntitiesForPhysicalGroup(dim, p):\n"
             "        n += sum(len(t) for t in gmsh.model.mesh.getElements(dim, e)[1])\n"
             "    if n == 0: print('empty', gmsh.model.getPhysicalName(dim, p))\n"
             "gmsh.finalize()\n");
  const std::string out_file = (dir / "api.txt").string();
  REQUIRE(std::system(("/usr/bin/python3 " + (dir / "api.py").string() + " " + (dir / "m.msh").string() + " > " +
                       out_file + " 2>&1")
                          .c_str()) == 0);
  const std::string out = read_text(dir / "api.txt");
  int tags_with_facets = 0;
  for (std::size_t t = 0; t < mesh.tags.size(); ++t)
    for (const CellBlock& b : mesh.boundary) {
      if (b.tag == static_cast<int>(t) && b.size() > 0) {
        ++tags_with_facets;
        break;
      }
    }
  REQUIRE(tags_with_facets > 0);
  CHECK(out.find("bounding " + std::to_string(tags_with_facets) + "\n") != std::string::npos);
  CHECK(out.find("empty") == std::string::npos);
}

TEST_CASE("io: MSH node coordinates beyond +-1e12 are refused with the line") {
  TempDir dir("msh_huge");
  HybridMesh<2> m;
  m.nodes = {{0, 0}, {1, 0}, {0, 1}};
  m.block(CellType::Triangle, 1).connectivity = {0, 1, 2};
  write_msh41(m, dir / "m.msh");
  const std::string text = read_text(dir / "m.msh");
  const std::string node = "\n1 0 0\n";  // node 2's coordinates
  REQUIRE(text.find(node) != std::string::npos);
  write_text(dir / "far.msh", replace(text, node, "\n1.5e308 0 0\n"));
  CHECK_THROWS_WITH_AS(read_msh41(dir / "far.msh"), doctest::Contains("far.msh:"), InputError);
  CHECK_THROWS_WITH_AS(read_msh41(dir / "far.msh"), doctest::Contains("node coordinate '1.5e308' is beyond +-1e+12"),
                       InputError);
}

namespace {

// Binary MSH 4.1 by the format's description (Gmsh reference manual, "MSH file format"): ints of
// 4 bytes, size_t of 8, doubles, in this machine's byte order; one linear tetrahedron in volume 1.
std::string binary_tet_msh() {
  std::string b;
  auto put = [&b](const auto v) { b.append(reinterpret_cast<const char*>(&v), sizeof v); };
  auto size = [&put](std::uint64_t v) { put(v); };
  auto i32 = [&put](std::int32_t v) { put(v); };
  b += "$MeshFormat\n4.1 1 8\n";
  i32(1);
  b += "\n$EndMeshFormat\n$Entities\n";
  for (std::uint64_t n : {0, 0, 0, 1}) size(n);
  i32(1);
  for (double x : {0.0, 0.0, 0.0, 1.0, 1.0, 1.0}) put(x);
  size(0);  // physical tags
  size(0);  // bounding surfaces
  b += "\n$EndEntities\n$Nodes\n";
  for (std::uint64_t n : {1, 4, 1, 4}) size(n);
  i32(3), i32(1), i32(0), size(4);
  for (std::uint64_t t : {1, 2, 3, 4}) size(t);
  for (double x : {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}) put(x);
  b += "\n$EndNodes\n$Elements\n";
  for (std::uint64_t n : {1, 1, 1, 1}) size(n);
  i32(3), i32(1), i32(4), size(1);
  for (std::uint64_t t : {1, 1, 2, 3, 4}) size(t);
  b += "\n$EndElements\n";
  return b;
}


}  // namespace

TEST_CASE("io: binary MSH 4.1 reads as its description says, and every truncation throws InputError") {
  // Issue 37, item 9: plaf check refused binary MSH, the norm for large meshes.
  TempDir dir("msh_binary");
  const std::string bytes = binary_tet_msh();
  const MshMesh m = read_msh41(write_text(dir / "tet.msh", bytes));
  REQUIRE(m.dim == 3);
  REQUIRE(m.mesh3.nodes.size() == 4);
  CHECK(m.mesh3.nodes[3] == Eigen::Vector3d(0, 0, 1));
  REQUIRE(m.mesh3.cells.size() == 1);
  CHECK(m.mesh3.cells[0].type == CellType::Tetrahedron);
  CHECK(m.mesh3.cells[0].connectivity == std::vector<NodeId>{0, 1, 2, 3});
  for (std::size_t cut = 0; cut + 1 < bytes.size(); ++cut) {
    CAPTURE(cut);
    CHECK_THROWS_AS(read_msh41(write_text(dir / "cut.msh", bytes.substr(0, cut))), InputError);
  }
}

TEST_CASE("io: Gmsh's binary MSH 4.1 of a plaf mesh reads as the ASCII one: the same nodes and cells") {
  if (std::system("command -v gmsh > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("gmsh is not on PATH: its binary files not made (scripts/setup.sh does not install it)");
    return;
  }
  TempDir dir("msh_binary_gmsh");
  const HybridMesh<3> mesh = annulus_sector<3>(2, 2, 2, 1.0, [](int, int, int) { return 2; });
  write_msh41(mesh, dir / "ascii.msh");
  const std::string cmd = "gmsh '" + (dir / "ascii.msh").string() + "' -0 -bin -format msh41 -o '" +
                          (dir / "binary.msh").string() + "' > /dev/null 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  CHECK(read_text(dir / "binary.msh").find("4.1 1 8") != std::string::npos);
  const MshMesh a = read_msh41(dir / "ascii.msh"), b = read_msh41(dir / "binary.msh");
  REQUIRE(b.dim == 3);
  REQUIRE(a.mesh3.nodes.size() == b.mesh3.nodes.size());
  CHECK(cell_keys(a.mesh3.cells, a.mesh3) == cell_keys(b.mesh3.cells, b.mesh3));
}

TEST_CASE("io: plaf's binary MSH 4.1 round-trips bit for bit and holds what the ASCII file holds") {
  TempDir dir("msh_binary_write");
  for (int q = 1; q <= max_order; ++q) {
    INFO("order ", q);
    HybridMesh<2> flat = annulus_sector<2>(3, 4, 1, 1.0, [&](int, int, int) { return q; });
    for (double v : {-0.0, 5e-324, kMaxCoordinate, 0.1, -1.0 / 3.0}) flat.nodes.push_back(HybridMesh<2>::Point(v, -v));
    const HybridMesh<3> solid = annulus_sector<3>(2, 2, 2, 1.0, [&](int i, int j, int k) { return 1 + (i + j + k + q) % max_order; });
    write_msh41(flat, dir / "flat.msh", MshEncoding::binary);
    write_msh41(solid, dir / "solid.msh", MshEncoding::binary);
    CHECK(read_text(dir / "flat.msh").rfind("$MeshFormat\n4.1 1 8\n", 0) == 0);
    const MshMesh f = read_msh41(dir / "flat.msh"), s = read_msh41(dir / "solid.msh");
    REQUIRE(f.dim == 2);
    check_same(flat, f.mesh2);
    REQUIRE(s.dim == 3);
    check_same(solid, s.mesh3);
  }
  // A 3D surface mesh with curves (no cells) keeps its curve groups in binary too.
  HybridMesh<3> surface = annulus_sector<3>(2, 2, 1, 1.0, [](int, int, int) { return 2; });
  surface.cells.clear();
  write_msh41(surface, dir / "ascii.msh");
  write_msh41(surface, dir / "binary.msh", MshEncoding::binary);
  const MshMesh a = read_msh41(dir / "ascii.msh"), b = read_msh41(dir / "binary.msh");
  CHECK(a.dim == 3);
  CHECK(b.dim == 3);
  check_same(a.mesh3, b.mesh3);
}

TEST_CASE("io: Gmsh reads plaf's binary MSH 4.1 as plaf's ASCII one: the same nodes and cells") {
  if (std::system("command -v gmsh > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("gmsh is not on PATH: plaf's binary file not checked by Gmsh");
    return;
  }
  TempDir dir("msh_binary_by_gmsh");
  const HybridMesh<3> mesh = annulus_sector<3>(2, 2, 2, 1.0, [](int i, int, int) { return 1 + i; });
  write_msh41(mesh, dir / "binary.msh", MshEncoding::binary);
  // Gmsh reads the binary file and writes it back as ASCII; plaf reads that.
  const std::string cmd = "gmsh '" + (dir / "binary.msh").string() + "' -0 -format msh41 -o '" +
                          (dir / "by_gmsh.msh").string() + "' > '" + (dir / "gmsh.log").string() + "' 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string log = read_text(dir / "gmsh.log");
  INFO(log);
  CHECK(log.find("Error") == std::string::npos);
  const MshMesh back = read_msh41(dir / "by_gmsh.msh");
  REQUIRE(back.dim == 3);
  CHECK(cell_keys(mesh.cells, mesh) == cell_keys(back.mesh3.cells, back.mesh3));
  CHECK(cell_keys(mesh.boundary, mesh) == cell_keys(back.mesh3.boundary, back.mesh3));
  REQUIRE(back.mesh3.tags.size() == mesh.tags.size());
  for (std::size_t t = 0; t < mesh.tags.size(); ++t) CHECK(back.mesh3.tags[t].name == mesh.tags[t].name);
}

TEST_CASE("io: MSH 2.2, ASCII and binary, round-trips through plaf's reader: nodes bit for bit, blocks, tags") {
  TempDir dir("msh22");
  for (MshEncoding e : {MshEncoding::ascii, MshEncoding::binary})
    for (int q = 1; q <= max_order; ++q) {
      INFO("order ", q, (e == MshEncoding::binary ? " binary" : " ascii"));
      HybridMesh<2> flat = annulus_sector<2>(3, 4, 1, 1.0, [&](int, int, int) { return q; });
      for (double v : {-0.0, 5e-324, kMaxCoordinate, 0.1}) flat.nodes.push_back(HybridMesh<2>::Point(v, -v));
      const HybridMesh<3> solid = annulus_sector<3>(2, 2, 2, 1.0, [&](int i, int j, int k) { return 1 + (i + j + k + q) % max_order; });
      write_msh22(flat, dir / "flat.msh", e);
      write_msh22(solid, dir / "solid.msh", e);
      CHECK(read_text(dir / "solid.msh").rfind(e == MshEncoding::binary ? "$MeshFormat\n2.2 1 8\n" : "$MeshFormat\n2.2 0 8\n", 0) == 0);
      const MshMesh f = read_msh41(dir / "flat.msh"), s = read_msh41(dir / "solid.msh");
      REQUIRE(f.dim == 2);
      check_same(flat, f.mesh2);
      REQUIRE(s.dim == 3);
      check_same(solid, s.mesh3);
      // A 3D surface mesh (no cells) still reads as 3D: its "domain" group names dimension 3.
      HybridMesh<3> surface = solid;
      surface.cells.clear();
      write_msh22(surface, dir / "surface.msh", e);
      const MshMesh back = read_msh41(dir / "surface.msh");
      REQUIRE(back.dim == 3);
      check_same(surface, back.mesh3);
    }
  // Truncations of a binary 2.2 file throw InputError, never crash.
  const HybridMesh<3> small = annulus_sector<3>(1, 1, 1, 1.0, [](int, int, int) { return 2; });
  write_msh22(small, dir / "small.msh", MshEncoding::binary);
  const std::string bytes = read_text(dir / "small.msh");
  for (std::size_t cut = 0; cut + 1 < bytes.size(); cut += 7) {
    CAPTURE(cut);
    CHECK_THROWS_AS(read_msh41(write_text(dir / "cut.msh", bytes.substr(0, cut))), InputError);
  }
}

TEST_CASE("io: Gmsh reads plaf's MSH 2.2 and plaf reads Gmsh's: the same cells, boundary facets and groups") {
  if (std::system("command -v gmsh > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("gmsh is not on PATH: MSH 2.2 not checked against Gmsh");
    return;
  }
  TempDir dir("msh22_gmsh");
  const HybridMesh<3> mesh = annulus_sector<3>(2, 2, 2, 1.0, [](int i, int j, int) { return 1 + i + j; });
  for (const char* flag : {"", " -bin"}) {
    INFO("binary flag '", flag, "'");
    // plaf 2.2 -> Gmsh -> 4.1 -> plaf
    write_msh22(mesh, dir / "plaf22.msh", *flag ? MshEncoding::binary : MshEncoding::ascii);
    std::string cmd = "gmsh '" + (dir / "plaf22.msh").string() + "' -0 -format msh41 -o '" +
                      (dir / "gmsh41.msh").string() + "' > '" + (dir / "gmsh.log").string() + "' 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    CHECK(read_text(dir / "gmsh.log").find("Error") == std::string::npos);
    const MshMesh a = read_msh41(dir / "gmsh41.msh");
    REQUIRE(a.dim == 3);
    CHECK(cell_keys(mesh.cells, mesh) == cell_keys(a.mesh3.cells, a.mesh3));
    CHECK(cell_keys(mesh.boundary, mesh) == cell_keys(a.mesh3.boundary, a.mesh3));
    // plaf 4.1 -> Gmsh -> 2.2 (ASCII or binary) -> plaf
    write_msh41(mesh, dir / "plaf41.msh");
    cmd = "gmsh '" + (dir / "plaf41.msh").string() + "' -0" + flag + " -format msh22 -o '" +
          (dir / "gmsh22.msh").string() + "' > '" + (dir / "gmsh.log").string() + "' 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    CHECK(read_text(dir / "gmsh22.msh").rfind(*flag ? "$MeshFormat\n2.2 1 8" : "$MeshFormat\n2.2 0 8", 0) == 0);
    const MshMesh b = read_msh41(dir / "gmsh22.msh");
    REQUIRE(b.dim == 3);
    CHECK(cell_keys(mesh.cells, mesh) == cell_keys(b.mesh3.cells, b.mesh3));
    CHECK(cell_keys(mesh.boundary, mesh) == cell_keys(b.mesh3.boundary, b.mesh3));
    std::vector<std::string> names_a, names_b;
    for (const BoundaryTag& t : mesh.tags) names_a.push_back(t.name);
    for (const BoundaryTag& t : b.mesh3.tags) names_b.push_back(t.name);
    std::sort(names_a.begin(), names_a.end());
    std::sort(names_b.begin(), names_b.end());
    CHECK(names_a == names_b);
  }
}

TEST_CASE("io: meshio reads plaf's MSH 2.2 and binary MSH 4.1 with the cells of the ASCII 4.1 file") {
  if (std::system("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("no Python meshio module (python3-meshio): not checked");
    return;
  }
  TempDir dir("msh_meshio");
  const HybridMesh<3> mesh = annulus_sector<3>(2, 2, 2, 1.0, [](int, int, int) { return 2; });
  write_msh41(mesh, dir / "a41.msh");
  write_msh41(mesh, dir / "b41.msh", MshEncoding::binary);
  write_msh22(mesh, dir / "a22.msh");
  write_msh22(mesh, dir / "b22.msh", MshEncoding::binary);
  const std::filesystem::path script = write_text(dir / "counts.py", R"(import sys, meshio
for p in sys.argv[1:]:
    m = meshio.read(p)
    count = {}
    for c in m.cells:
        count[c.type] = count.get(c.type, 0) + len(c.data)
    print(p.rsplit("/", 1)[-1], len(m.points), sorted(count.items()))
)");
  const std::string cmd = "/usr/bin/python3 '" + script.string() + "' " + (dir / "a41.msh").string() + " " +
                          (dir / "b41.msh").string() + " " + (dir / "a22.msh").string() + " " +
                          (dir / "b22.msh").string() + " > '" + (dir / "out.txt").string() + "' 2>&1";
  const int rc = std::system(cmd.c_str());
  const std::string out = read_text(dir / "out.txt");
  INFO(out);
  REQUIRE(rc == 0);
  std::istringstream lines(out);
  std::vector<std::string> rows;
  for (std::string line; std::getline(lines, line);)
    if (line.find(".msh ") != std::string::npos) rows.push_back(line.substr(line.find(' ')));
  REQUIRE(rows.size() == 4);
  CHECK(rows[0].find("tetra10") != std::string::npos);
  for (std::size_t i = 1; i < rows.size(); ++i) CHECK(rows[i] == rows[0]);
}

TEST_CASE("io: Gmsh's Python API reads plaf's binary MSH 4.1 with plaf's element counts and types") {
  if (std::system("/usr/bin/python3 -c 'import gmsh' > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("no Python gmsh module (python3-gmsh): not checked");
    return;
  }
  TempDir dir("msh_binary_gmsh_api");
  for (int q = 1; q <= max_order; ++q) {
    INFO("order ", q);
    const HybridMesh<3> mesh = annulus_sector<3>(2, 2, 2, 1.0, [q](int, int, int) { return q; });
    write_msh41(mesh, dir / "binary.msh", MshEncoding::binary);
    std::map<int, std::size_t> expected;  // Gmsh type -> elements
    for (const auto* blocks : {&mesh.cells, &mesh.boundary})
      for (const CellBlock& b : *blocks) expected[gmsh_element_type(b.type, b.order)] += b.size();
    const fs::path script = write_text(dir / "count.py", R"(import sys, gmsh
gmsh.initialize(["", "-v", "0"])
gmsh.open(sys.argv[1])
count = {}
for dim in (2, 3):
    types, tags, nodes = gmsh.model.mesh.getElements(dim)
    for t, e in zip(types, tags):
        count[t] = count.get(t, 0) + len(e)
print(" ".join("%d:%d" % kv for kv in sorted(count.items())))
gmsh.finalize()
)");
    const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + (dir / "binary.msh").string() + "' > '" +
                            (dir / "out.txt").string() + "' 2>&1";
    const int rc = std::system(cmd.c_str());
    const std::string out = read_text(dir / "out.txt");
    INFO(out);
    REQUIRE(rc == 0);
    std::string want;
    for (const auto& [type, n] : expected) {
      if (!want.empty()) want.push_back(' ');
      want.append(std::to_string(type)).append(":").append(std::to_string(n));
    }
    CHECK(out.find(want) != std::string::npos);
  }
}
