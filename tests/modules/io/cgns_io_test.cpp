// SPDX-License-Identifier: MIT
#include "modules/io/cgns_io.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "modules/base/error.h"
#include "modules/elements/lagrange.h"
#include "modules/io/msh_io.h"
#include "modules/io/vtu_writer.h"
#include "tests/modules/io/sample_meshes.h"
#include "tests/published_data.h"
#include "tests/test_support.h"

using namespace plaf;
using test::annulus_sector;
using test::cell_keys;
using test::check_same;
using test::read_text;
using test::TempDir;
using test::write_text;
namespace fs = std::filesystem;

TEST_CASE("io: CGNS node order is the SIDS's: corners, edges, faces, interior (cubic and quartic tables)") {
  // Lattice points of CGNS nodes N1, N2, ... transcribed from the SIDS tables and notes
  // ("Unstructured Grid Element Numbering Conventions"; cubic and quartic extensions of Yu and
  // Wang), with corners N1 = origin, N2 on the first axis, N3 on the second, N4 (and the prism's
  // top) on the third.
  using L = std::vector<Lattice>;
  CHECK(cgns_lattice(CellType::Triangle, 4) ==
        L{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {3, 1, 0}, {2, 2, 0},
          {1, 3, 0}, {0, 3, 0}, {0, 2, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}, {1, 2, 0}});
  CHECK(cgns_lattice(CellType::Quadrilateral, 4) ==
        L{{0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 1, 0}, {4, 2, 0},
          {4, 3, 0}, {3, 4, 0}, {2, 4, 0}, {1, 4, 0}, {0, 3, 0}, {0, 2, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0},
          {3, 1, 0}, {3, 2, 0}, {3, 3, 0}, {2, 3, 0}, {1, 3, 0}, {1, 2, 0}, {2, 2, 0}});
  CHECK(cgns_lattice(CellType::Tetrahedron, 2) ==
        L{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}});
  CHECK(cgns_lattice(CellType::Tetrahedron, 4) ==
        L{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0, 0, 4}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {3, 1, 0}, {2, 2, 0},
          {1, 3, 0}, {0, 3, 0}, {0, 2, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 2}, {0, 0, 3}, {3, 0, 1}, {2, 0, 2},
          {1, 0, 3}, {0, 3, 1}, {0, 2, 2}, {0, 1, 3}, {1, 1, 0}, {2, 1, 0}, {1, 2, 0}, {1, 0, 1}, {2, 0, 1},
          {1, 0, 2}, {2, 1, 1}, {1, 2, 1}, {1, 1, 2}, {0, 2, 1}, {0, 1, 1}, {0, 1, 2}, {1, 1, 1}});
  CHECK(cgns_lattice(CellType::Prism, 3) ==
        L{{0, 0, 0}, {3, 0, 0}, {0, 3, 0}, {0, 0, 3}, {3, 0, 3}, {0, 3, 3}, {1, 0, 0}, {2, 0, 0}, {2, 1, 0},
          {1, 2, 0}, {0, 2, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 2}, {3, 0, 1}, {3, 0, 2}, {0, 3, 1}, {0, 3, 2},
          {1, 0, 3}, {2, 0, 3}, {2, 1, 3}, {1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {1, 1, 0}, {1, 0, 1}, {2, 0, 1},
          {2, 0, 2}, {1, 0, 2}, {2, 1, 1}, {1, 2, 1}, {1, 2, 2}, {2, 1, 2}, {0, 2, 1}, {0, 1, 1}, {0, 1, 2},
          {0, 2, 2}, {1, 1, 3}, {1, 1, 1}, {1, 1, 2}});
  const L penta75 = cgns_lattice(CellType::Prism, 4);
  REQUIRE(penta75.size() == 75);
  // N34-36 (bottom face, in the order N1, N2, N3), N46-54 (face N2 N3 N6 N5: the ring from N2's
  // corner, then the centre), N64-66 (top), N67-75 (interior, layer by layer).
  CHECK(L(penta75.begin() + 33, penta75.begin() + 36) == L{{1, 1, 0}, {2, 1, 0}, {1, 2, 0}});
  CHECK(L(penta75.begin() + 45, penta75.begin() + 54) ==
        L{{3, 1, 1}, {2, 2, 1}, {1, 3, 1}, {1, 3, 2}, {1, 3, 3}, {2, 2, 3}, {3, 1, 3}, {3, 1, 2}, {2, 2, 2}});
  CHECK(L(penta75.begin() + 63, penta75.end()) == L{{1, 1, 4}, {2, 1, 4}, {1, 2, 4}, {1, 1, 1}, {2, 1, 1}, {1, 2, 1},
                                                     {1, 1, 2}, {2, 1, 2}, {1, 2, 2}, {1, 1, 3}, {2, 1, 3}, {1, 2, 3}});
  // Every type and order: a permutation of Gmsh's nodes.
  for (CellType t : {CellType::Line, CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron, CellType::Prism})
    for (int q = 1; q <= max_order; ++q) {
      std::vector<int> perm = cgns_node_permutation(t, q);
      std::sort(perm.begin(), perm.end());
      for (std::size_t k = 0; k < perm.size(); ++k) CHECK(perm[k] == static_cast<int>(k));
    }
}

namespace {

template <int Dim>
HybridMesh<Dim> by_tag(HybridMesh<Dim> m) {
  std::stable_sort(m.boundary.begin(), m.boundary.end(), [](const CellBlock& a, const CellBlock& b) {
    return std::tuple(a.tag, static_cast<int>(a.type), a.order) < std::tuple(b.tag, static_cast<int>(b.type), b.order);
  });
  return m;
}

}  // namespace

TEST_CASE("io: CGNS round-trips through plaf's reader: nodes bit for bit, cells, facets, tags and kinds") {
  TempDir dir("cgns");
  for (int q = 0; q <= max_order; ++q) {
    INFO("order ", q, " (0: mixed)");
    auto order = [q](int i, int j, int k) { return q > 0 ? q : 1 + (i + 2 * j + k) % max_order; };
    const HybridMesh<2> flat = annulus_sector<2>(3, 4, 1, 1.0, order);
    const HybridMesh<3> solid = annulus_sector<3>(2, 2, 2, 1.0, order);
    write_cgns(flat, dir / "flat.cgns");
    write_cgns(solid, dir / "solid.cgns");
    const MshMesh f = read_cgns(dir / "flat.cgns"), s = read_cgns(dir / "solid.cgns");
    REQUIRE(f.dim == 2);
    REQUIRE(s.dim == 3);
    // The same cells in the same blocks, the same tags; facets grouped by tag in the file (the
    // blocks compared in (tag, type, order) order).
    check_same(by_tag(flat), by_tag(f.mesh2));
    check_same(by_tag(solid), by_tag(s.mesh3));
  }
  // A 3D surface mesh (no cells): a base of cell dimension 2 in 3D, read back as a surface mesh
  // with its tags, a tag of two facet types included.
  for (int q = 1; q <= max_order; ++q) {
    HybridMesh<3> surface = annulus_sector<3>(2, 2, 2, 1.0, [q](int, int, int) { return q; });
    surface.cells.clear();
    // A curve on the surface's rim, tagged as a symmetry loop is.
    const int sym = surface.add_tag("symmetry_loop", BoundaryKind::Symmetry);
    const CellBlock& facet = surface.boundary.front();
    const LagrangeElement& e = lagrange_element(facet.type, facet.order);
    CellBlock& line = surface.curve_block(q, sym);
    for (int k : e.facet_nodes(0)) line.connectivity.push_back(facet.cell(0)[k]);
    write_cgns(surface, dir / "surface.cgns");
    const MshMesh back = read_cgns(dir / "surface.cgns");
    REQUIRE(back.dim == 3);
    CHECK(back.mesh3.cells.empty());
    check_same(by_tag(surface), by_tag(back.mesh3));
    // A 2D surface mesh: its lines.
    HybridMesh<2> lines = annulus_sector<2>(2, 2, 1, 1.0, [q](int, int, int) { return q; });
    lines.cells.clear();
    write_cgns(lines, dir / "lines.cgns");
    const MshMesh back2 = read_cgns(dir / "lines.cgns");
    REQUIRE(back2.dim == 2);
    check_same(by_tag(lines), by_tag(back2.mesh2));
  }
  // No temporary is left beside the file.
  for (const auto& e : fs::directory_iterator(dir.path)) CHECK(e.path().extension() == ".cgns");
}

TEST_CASE("io: CGNS names: long, clashing, reserved, blank and slashed tag names are written and read back distinct") {
  TempDir dir("cgns_names");
  HybridMesh<3> mesh = annulus_sector<3>(2, 2, 2, 1.0, [](int, int, int) { return 2; });
  REQUIRE(mesh.tags.size() == 4);
  mesh.tags[0].name = "wall_high_lift_configuration_element_slat";  // longer than 32, two facet types
  mesh.tags[1].name = "wall_high_lift_configuration_element_flap";  // the same first 32 characters
  mesh.tags[2].name = "wing/upper";
  mesh.tags[3].name = "domain";  // the zone's name
  write_cgns(mesh, dir / "names.cgns");
  const MshMesh back = read_cgns(dir / "names.cgns");
  REQUIRE(back.dim == 3);
  std::set<std::string> names;
  for (const BoundaryTag& t : back.mesh3.tags) {
    CHECK(t.name.size() <= 32);
    CHECK(t.name.find('/') == std::string::npos);
    names.insert(t.name);
  }
  CHECK(names.size() == 4);
  CHECK(cell_keys(mesh.boundary, mesh) == cell_keys(back.mesh3.boundary, back.mesh3));
  if (std::system("command -v cgnscheck > /dev/null 2>&1") == 0) {
    const std::string cmd = "cgnscheck '" + (dir / "names.cgns").string() + "' > '" + (dir / "c.txt").string() + "' 2>&1";
    CHECK(std::system(cmd.c_str()) == 0);
    CHECK(read_text(dir / "c.txt").find("ERROR") == std::string::npos);
  }
  // Blank names are named.
  mesh.tags[0].name = " ";
  write_cgns(mesh, dir / "blank.cgns");
  CHECK(read_cgns(dir / "blank.cgns").mesh3.tags.size() == 4);
}

TEST_CASE("io: bad CGNS files do not use up libcgns's open files: a good file reads after 300 bad ones") {
  TempDir dir("cgns_slots");
  const fs::path good = dir / "good.cgns";
  write_cgns(annulus_sector<2>(1, 1, 1, 1.0, [](int, int, int) { return 1; }), good);
  // A valid file cut short: libcgns opens it, then fails a check.
  const std::string bytes = read_text(good);
  const fs::path bad = write_text(dir / "bad.cgns", bytes.substr(0, bytes.size() / 2));
  for (int i = 0; i < 300; ++i) CHECK_THROWS_AS(read_cgns(bad), InputError);
  CHECK(read_cgns(good).dim == 2);
  write_cgns(annulus_sector<2>(1, 1, 1, 1.0, [](int, int, int) { return 1; }), dir / "again.cgns");
}

TEST_CASE("io: bad CGNS input throws InputError naming the file, and a broken mesh is not written") {
  TempDir dir("cgns_bad");
  CHECK_THROWS_AS(read_cgns(dir / "missing.cgns"), InputError);
  CHECK_THROWS_AS(read_cgns(write_text(dir / "text.cgns", "not a CGNS file\n")), InputError);
  try {
    read_cgns(write_text(dir / "garbage.cgns", std::string(4096, '\x42')));
    FAIL("no InputError");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).rfind((dir / "garbage.cgns").string() + ": ", 0) == 0);
  }
  HybridMesh<3> broken = annulus_sector<3>(1, 1, 1, 1.0, [](int, int, int) { return 2; });
  broken.cells[0].connectivity[0] = 1 << 30;
  CHECK_THROWS_AS(write_cgns(broken, dir / "broken.cgns"), Error);
  for (const auto& e : fs::directory_iterator(dir.path)) CHECK(e.path().filename().string().rfind("broken", 0) != 0);
}

TEST_CASE("io: cgnscheck finds no error in plaf's CGNS files, 2D, 3D and 3D surfaces, orders 1 to 4") {
  if (std::system("command -v cgnscheck > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("cgnscheck (cgns-convert) is not on PATH: the CGNS files not checked by it");
    return;
  }
  TempDir dir("cgnscheck");
  for (int q = 1; q <= max_order; ++q) {
    INFO("order ", q);
    write_cgns(annulus_sector<2>(2, 2, 1, 1.0, [q](int, int, int) { return q; }), dir / "flat.cgns");
    write_cgns(annulus_sector<3>(2, 2, 2, 1.0, [q](int, int, int) { return q; }), dir / "solid.cgns");
    HybridMesh<3> surface = annulus_sector<3>(2, 2, 2, 1.0, [q](int, int, int) { return q; });
    surface.cells.clear();
    write_cgns(surface, dir / "surface.cgns");
    HybridMesh<2> lines = annulus_sector<2>(2, 2, 1, 1.0, [q](int, int, int) { return q; });
    lines.cells.clear();
    write_cgns(lines, dir / "lines.cgns");
    for (const char* name : {"flat.cgns", "solid.cgns", "surface.cgns", "lines.cgns"}) {
      const std::string cmd =
          "cgnscheck '" + (dir / name).string() + "' > '" + (dir / "check.txt").string() + "' 2>&1";
      const int rc = std::system(cmd.c_str());
      const std::string out = read_text(dir / "check.txt");
      INFO(name, "\n", out);
      CHECK(rc == 0);
      CHECK(out.find("ERROR") == std::string::npos);
      CHECK(out.find("WARNING") == std::string::npos);
    }
  }
}

TEST_CASE("io: VTK's CGNS reader finds plaf's cells where plaf put them (quadratic, and cubic simplices/quads)") {
  if (std::system("/usr/bin/python3 -c 'import vtk; vtk.vtkCGNSReader' > /dev/null 2>&1") != 0) {
    plaf::test::request_skip("no Python vtk module with vtkCGNSReader (python3-vtk9): not checked");
    return;
  }
  TempDir dir("cgns_vtk");
  // VTK 9.1 reads these sections correctly (its PENTA_40 table misorders a face, quartic cells
  // are not read): TRI_6, QUAD_9, TETRA_10, PENTA_18, TRI_10, QUAD_16, TETRA_20.
  struct Case {
    int dim, order;
  };
  for (const Case c : {Case{2, 2}, Case{3, 2}, Case{2, 3}}) {
    INFO(c.dim, "D, order ", c.order);
    std::vector<std::vector<double>> expected;
    const fs::path file = dir / "m.cgns";
    // Each cell's points in VTK's order (what plaf's .vtu writer gives them), z = 0 in 2D.
    auto expect = [&](const auto& m) {
      write_cgns(m, file);
      for (const CellBlock& b : m.cells)
        for (std::size_t i = 0; i < b.size(); ++i) {
          std::vector<double> pts;
          for (int k : vtk_node_permutation(b.type, b.order)) {
            const auto& x = m.nodes[static_cast<std::size_t>(b.cell(i)[k])];
            for (int d = 0; d < 3; ++d) pts.push_back(d < x.size() ? x[d] : 0.0);
          }
          expected.push_back(pts);
        }
    };
    if (c.dim == 2)
      expect(annulus_sector<2>(2, 2, 1, 1.0, [&](int, int, int) { return c.order; }));
    else
      expect(annulus_sector<3>(2, 2, 2, 1.0, [&](int, int, int) { return c.order; }));
    // VTK's cells (of the zone's dimension) as their points in VTK's order, rounded to 1e-9: the
    // order plaf's .vtu writer gives them (vtk_node_permutation), if the CGNS order is right.
    const fs::path script = write_text(dir / "cells.py", R"(import sys, vtk
r = vtk.vtkCGNSReader()
r.SetFileName(sys.argv[1])
r.EnableAllCellArrays()
r.Update()
it = r.GetOutput().NewIterator()
it.InitTraversal()
while not it.IsDoneWithTraversal():
    g = it.GetCurrentDataObject()
    for c in range(g.GetNumberOfCells()):
        cell = g.GetCell(c)
        if cell.GetCellDimension() != int(sys.argv[2]):
            continue
        pts = [tuple(round(x, 9) + 0.0 for x in cell.GetPoints().GetPoint(k)) for k in range(cell.GetNumberOfPoints())]
        print(" ".join("%.9f" % x for p in pts for x in p))
    it.GoToNextItem()
)");
    const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + file.string() + "' " +
                            std::to_string(c.dim) + " > '" + (dir / "out.txt").string() + "' 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    std::vector<std::string> got, want;
    std::istringstream lines(read_text(dir / "out.txt"));
    for (std::string line; std::getline(lines, line);) got.push_back(line);
    for (const std::vector<double>& pts : expected) {
      std::vector<std::array<double, 3>> p;
      for (std::size_t k = 0; k < pts.size(); k += 3)
        p.push_back({std::round(pts[k] * 1e9) / 1e9 + 0.0, std::round(pts[k + 1] * 1e9) / 1e9 + 0.0,
                     std::round(pts[k + 2] * 1e9) / 1e9 + 0.0});
      std::string s;
      char buf[64];
      for (const auto& x : p)
        for (double v : x) {
          std::snprintf(buf, sizeof buf, "%.9f", v);
          if (!s.empty()) s.push_back(' ');
          s.append(buf);
        }
      want.push_back(s);
    }
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    CHECK(got.size() == want.size());
    CHECK(got == want);
  }
}
