// SPDX-License-Identifier: MIT
// The curved spherical shell of prisms (spherical_shell.h) through everything downstream of the
// layers: conformity, certified quality, cell volumes, the MSH and VTU writers, the MSH reader,
// and Gmsh's own checks (skipped when `gmsh` is not on PATH).
#include "tests/modules/mesh/spherical_shell.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "modules/elements/cell_measure.h"
#include "modules/io/msh_io.h"
#include "modules/io/vtu_writer.h"
#include "modules/mesh/quality.h"
#include "modules/metric/metric.h"
#include "tests/gmsh_support.h"
#include "tests/test_support.h"
#include "tests/published_data.h"

using namespace plaf;
using namespace plaf::test;
using plaf::test::ShellBase;
using plaf::test::ShellOptions;
using plaf::test::SphericalShell;

namespace {

// The shells every test walks: thick and thin, closed (icosahedron) and half (octahedron, cut
// on z = 0), at every order.
std::vector<ShellOptions> shells() {
  std::vector<ShellOptions> out;
  for (int q = 1; q <= max_order; ++q)
    for (const double t : {0.3, 1e-5}) {
      out.push_back({q, 2, t, 2, ShellBase::Icosahedron, false});
      out.push_back({q, 2, t, 3, ShellBase::Octahedron, true});
    }
  return out;
}

std::string describe(const ShellOptions& o) {
  std::ostringstream s;
  s << (o.half ? "half octahedral" : "icosahedral") << " shell n=" << o.subdivisions << " t=" << o.thickness
    << " L=" << o.layers << " Q=" << o.order;
  return s.str();
}

double total_volume(const HybridMesh<3>& m) {
  double v = 0;
  std::vector<double> x;
  for (const CellBlock& b : m.cells) {
    x.resize(static_cast<std::size_t>(b.nodes_per_cell()) * 3);
    for (std::size_t i = 0; i < b.size(); ++i) {
      gather_coords(m, b, i, x.data());
      v += cell_measure(b.type, b.order, x.data());
    }
  }
  return v;
}

}  // namespace

TEST_CASE("shell: prism volumes sum to 4/3 pi ((1+t)^3 - 1) within the order-Q deviation of the wall from the sphere") {
  // The prisms' map is r(w) N(u, v) (spherical_shell.h), so their volumes add up to
  // ((1 + t)^3 - 1) V_N, and V_N / (4/3 pi) lies in [(1 - delta)^3, (1 + delta)^3] for delta
  // the largest deviation of the wall's interpolant from the unit sphere: an O(h^(Q+1)) bound.
  for (const ShellOptions& o : shells()) {
    INFO(describe(o));
    const SphericalShell s = plaf::test::spherical_shell(o);
    const double delta = s.radius_deviation;
    // The samples may miss the largest deviation by a little: a margin of 10% of delta.
    const double tol_rel = std::pow(1 + 1.1 * delta, 3) - 1 + 1e-12;
    const double v = total_volume(s.mesh);
    CHECK(std::abs(v / s.exact_volume - 1) <= tol_rel);
    if (o.thickness == 1e-5 && !o.half)
      MESSAGE(describe(o), ": volume ", v, " exact ", s.exact_volume, ", relative error ", v / s.exact_volume - 1,
              ", allowed ", tol_rel);
  }
  // Halving the wall's triangles divides the wall's deviation (the tolerance above) by about
  // 2^(Q+1), at least by 2^Q here, and the volume error too (Q = 1..3, where rounding does not
  // yet dominate).
  for (int q = 1; q <= max_order; ++q) {
    INFO("Q=", q);
    ShellOptions coarse{q, 2, 0.3, 2, ShellBase::Icosahedron, false}, fine = coarse;
    fine.subdivisions = 4;
    const SphericalShell a = plaf::test::spherical_shell(coarse), b = plaf::test::spherical_shell(fine);
    CHECK(b.radius_deviation < a.radius_deviation / (1 << q));
    if (q == max_order) continue;
    const double ea = std::abs(total_volume(a.mesh) / a.exact_volume - 1);
    const double eb = std::abs(total_volume(b.mesh) / b.exact_volume - 1);
    CHECK(eb < ea / (1 << q));
  }
}

TEST_CASE("shell: conforming, with facet counts from its wall, every prism certified valid, metric edge lengths") {
  for (const ShellOptions& o : shells()) {
    INFO(describe(o));
    const SphericalShell s = plaf::test::spherical_shell(o);
    // Interior: the triangles between layers, one quadrilateral per inner wall edge per layer.
    // Boundary: the wall and the outer front, the rim edges' quadrilaterals on the symmetry plane.
    const std::size_t f = s.wall_triangles, inner_edges = s.wall_edges - s.rim_edges;
    const auto layers = static_cast<std::size_t>(o.layers);
    CHECK(s.rim_edges == (o.half ? 4 * static_cast<std::size_t>(o.subdivisions) : 0));
    CHECK(2 * s.wall_edges == 3 * f + s.rim_edges);
    const ConformityReport c = check_conformity(s.mesh);
    CHECK(c.ok);
    CHECK(c.interior_facets == f * (layers - 1) + inner_edges * layers);
    CHECK(c.boundary_facets == 2 * f + s.rim_edges * layers);
    CHECK(c.first_problem.empty());

    CellQuality pc;
    const QualityReport r = assess_quality<3>(s.mesh, nullptr, QualityOptions{}, &pc);
    CHECK(r.ok());
    CHECK(r.cells_invalid == 0);
    CHECK(r.cells_total == f * layers);
    CHECK(r.scaled_jacobian_min > 0);
    // A prism's aspect ratio is its base over its height (quality.h): the longest wall edge
    // over the layer height t / L, within the base triangles' own distortion.
    const double height = o.thickness / o.layers;
    CHECK(r.aspect_ratio_max >= 0.5 * s.wall_edge_max / height);
    CHECK(r.aspect_ratio_max <= 2.0 * s.wall_edge_max / height);
    // Metric edge lengths in the unit metric (the curved edges' lengths), every distinct edge
    // once: the radial edges, V wall vertices (Euler: V - E + F = 2, or 1 for the half shell's
    // disk) times L, are straight and t / L long, the shortest; the wall edges at each of the
    // L + 1 levels are arcs, the longest at radius 1 + t a little over its chord.
    const UniformMetricField<3> unit(Metric<3>::isotropic(1.0));
    const QualityReport rm = assess_quality<3>(s.mesh, &unit, QualityOptions{});
    const std::size_t v = (o.half ? 1 : 2) + s.wall_edges - f;
    CHECK(rm.metric.count == v * layers + s.wall_edges * (layers + 1));
    CHECK(rm.metric.min == doctest::Approx(height).epsilon(1e-9));
    CHECK(rm.metric.max >= (1 + o.thickness) * s.wall_edge_max * (1 - 1e-12));
    CHECK(rm.metric.max <= (1 + o.thickness) * s.wall_edge_max * 1.05);
    if (o.order == 2 && o.thickness == 1e-5 && !o.half)
      MESSAGE(describe(o), ": min scaled Jacobian ", r.scaled_jacobian_min, ", max aspect ratio ", r.aspect_ratio_max,
              ", wall deviation ", s.radius_deviation);
  }
}

TEST_CASE("shell: MSH 4.1 round trip gives the identical mesh (prisms, triangles, quadrilaterals, curves)") {
  plaf::test::TempDir dir("shell_msh");
  for (const ShellOptions& o : shells()) {
    INFO(describe(o));
    const SphericalShell s = plaf::test::spherical_shell(o);
    write_msh41(s.mesh, dir / "shell.msh");
    const MshMesh back = read_msh41(dir / "shell.msh");
    REQUIRE(back.dim == 3);
    const HybridMesh<3>& m = back.mesh3;
    REQUIRE(m.nodes.size() == s.mesh.nodes.size());
    bool bitwise = true;
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      for (int d = 0; d < 3; ++d)
        bitwise =
            bitwise && std::bit_cast<std::uint64_t>(m.nodes[i][d]) == std::bit_cast<std::uint64_t>(s.mesh.nodes[i][d]);
    CHECK(bitwise);
    const auto same = [](const std::vector<CellBlock>& a, const std::vector<CellBlock>& b) {
      REQUIRE(a.size() == b.size());
      for (std::size_t k = 0; k < a.size(); ++k) {
        CHECK(a[k].type == b[k].type);
        CHECK(a[k].order == b[k].order);
        CHECK(a[k].tag == b[k].tag);
        CHECK(a[k].connectivity == b[k].connectivity);
      }
    };
    same(m.cells, s.mesh.cells);
    same(m.boundary, s.mesh.boundary);
    same(m.curves, s.mesh.curves);
    REQUIRE(m.tags.size() == s.mesh.tags.size());
    for (std::size_t k = 0; k < m.tags.size(); ++k) {
      CHECK(m.tags[k].name == s.mesh.tags[k].name);
      CHECK(m.tags[k].kind == s.mesh.tags[k].kind);
    }
    // The element blocks "entity-dim entity-tag type count": the prisms in the domain entity
    // (3, 1) as Gmsh type 6/13/90/91, the symmetry quadrilaterals in entity (2, 3) as type
    // 3/10/36/37 (Gmsh's GmshDefines.h; entity tag = tag index + 1, msh_io.h).
    const std::string text = test::read_text(dir / "shell.msh");
    const int prism_code[] = {6, 13, 90, 91}, quad_code[] = {3, 10, 36, 37};
    std::ostringstream prisms, quads;
    prisms << "\n3 1 " << prism_code[o.order - 1] << ' ' << s.wall_triangles * static_cast<std::size_t>(o.layers)
           << '\n';
    quads << "\n2 3 " << quad_code[o.order - 1] << ' ' << s.rim_edges * static_cast<std::size_t>(o.layers) << '\n';
    CHECK(text.find(prisms.str()) != std::string::npos);
    CHECK((text.find(quads.str()) != std::string::npos) == o.half);
    // The VTU writer takes it too (its node orders are tested against VTK's in vtu_writer_test).
    write_vtu(s.mesh, dir / "shell.vtu");
    CHECK(test::read_text(dir / "shell.vtu").find(o.order == 1 ? "13\n" : "73\n") != std::string::npos);
  }
}

TEST_CASE("shell: gmsh -check finds no error or duplicate node, Gmsh's Jacobians are positive, plaf check says valid") {
  if (!gmsh_on_path()) {
    plaf::test::request_skip("gmsh is not on PATH: Gmsh's checks not run (scripts/setup.sh does not install it)");
    return;
  }
  plaf::test::TempDir dir("shell_gmsh");
  for (const ShellOptions& o : shells()) {
    INFO(describe(o));
    const SphericalShell s = plaf::test::spherical_shell(o);
    write_msh41(s.mesh, dir / "shell.msh");
    // 1. Gmsh reads it and its coherence check (duplicate nodes within 1e-8 of the bounding
    //    box, duplicate elements, isolated nodes) finds nothing.
    // Gmsh 4.8 exits 1 after its FaceClosureFull error (orders 3 and 4): the exit code says
    // nothing here, its messages do.
    const GmshRun check = run_gmsh("shell.msh -check", dir);
    INFO(check.out);
    CHECK(gmsh_complaints(check.out).empty());
    CHECK(check.out.find("Checking for duplicate nodes") != std::string::npos);
    std::size_t elements = 0;
    for (const auto* blocks : {&s.mesh.cells, &s.mesh.boundary, &s.mesh.curves})
      for (const CellBlock& b : *blocks) elements += b.size();
    CHECK(check.out.find("Info    : " + std::to_string(s.mesh.nodes.size()) + " nodes\n") != std::string::npos);
    CHECK(check.out.find("Info    : " + std::to_string(elements) + " elements\n") != std::string::npos);
    // 2. Gmsh's Jacobian bounds: every prism valid, its worst ratio close to plaf's certified one.
    const GmshJacobians gj = gmsh_jacobians("shell.msh", dir);
    const QualityReport r = assess_quality<3>(s.mesh, nullptr, QualityOptions{});
    CHECK(gj.min_j > 0);
    CHECK(gj.worst_ratio == doctest::Approx(r.scaled_jacobian_min).epsilon(0.03));
    if (o.order == 2 && o.thickness == 1e-5 && !o.half)
      MESSAGE(describe(o), ": Gmsh minJ ", gj.min_j, ", worst minJ/maxJ ", gj.worst_ratio, ", plaf ",
              r.scaled_jacobian_min);
    // 3. plaf check on the file: valid and conforming (exit 0).
    const test::PlafResult plaf = test::run_plaf("check " + (dir / "shell.msh").string(), dir);
    CHECK(plaf.code == 0);
    CHECK(plaf.err.find("error") == std::string::npos);  // stderr carries its progress lines
  }
}

TEST_CASE("shell: Gmsh's checks and plaf check catch an inverted prism and a duplicated node") {
  if (!gmsh_on_path()) {
    plaf::test::request_skip("gmsh is not on PATH: Gmsh's checks not run (scripts/setup.sh does not install it)");
    return;
  }
  plaf::test::TempDir dir("shell_gmsh_bad");
  for (int q = 1; q <= max_order; ++q) {
    INFO("Q=", q);
    SphericalShell s = plaf::test::spherical_shell({q, 2, 1e-5, 2, ShellBase::Icosahedron, false});
    // A prism turned inside out: its bottom and top levels swapped (all nodes stay shared).
    {
      HybridMesh<3> m = s.mesh;
      CellBlock& b = m.cells[0];
      const LagrangeElement& e = lagrange_element(CellType::Prism, q);
      std::vector<NodeId> flipped(b.cell(0), b.cell(0) + b.nodes_per_cell());
      for (int k = 0; k < e.size(); ++k) {
        const Lattice l = e.lattice()[static_cast<std::size_t>(k)];
        flipped[static_cast<std::size_t>(k)] = b.cell(0)[e.find({l[0], l[1], q - l[2]})];
      }
      std::copy(flipped.begin(), flipped.end(), b.connectivity.begin());
      write_msh41(m, dir / "inverted.msh");
      CHECK(gmsh_jacobians("inverted.msh", dir).min_j < 0);
      CHECK(test::run_plaf("check " + (dir / "inverted.msh").string(), dir).code == 2);
    }
    // A node of the wall written twice: the second copy used by one prism (a crack).
    {
      HybridMesh<3> m = s.mesh;
      m.nodes.push_back(m.nodes[static_cast<std::size_t>(m.cells[0].connectivity[0])]);
      m.cells[0].connectivity[0] = static_cast<NodeId>(m.nodes.size() - 1);
      write_msh41(m, dir / "duplicate.msh");
      const GmshRun check = run_gmsh("duplicate.msh -check", dir);
      CHECK(check.out.find("1 duplicate node") != std::string::npos);
      CHECK(test::run_plaf("check " + (dir / "duplicate.msh").string(), dir).code == 2);
    }
  }
}
