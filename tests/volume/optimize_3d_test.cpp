// SPDX-License-Identifier: MIT
#include "volume/optimize_3d.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"
#include "tests/volume/box_front.h"
#include "volume/tetgen_fill.h"

using namespace plaf;
using Vec = Eigen::Vector3d;
using Tet = std::array<NodeId, 4>;

namespace {

// A metric whose sizes grow along x: h(x) = h0 + slope x (isotropic).
class GradedMetric final : public MetricField<3> {
 public:
  GradedMetric(double h0, double slope) : h0_(h0), slope_(slope) {}
  Metric<3> evaluate(const Point& x) const override { return Metric<3>::isotropic(h0_ + slope_ * std::abs(x.x())); }

 private:
  double h0_, slope_;
};

FillResult<3> as_fill(const LinearFront<3>& f, const volume::TetFillResult& r) {
  FillResult<3> fill;
  fill.nodes = r.nodes;
  fill.simplices = r.simplices;
  fill.boundary = f.triangles;
  fill.boundary_tag = f.triangle_tag;
  fill.tags = f.tags;
  return fill;
}

double volume_of(const FillResult<3>& fill, const Tet& t) {
  const Vec &a = fill.nodes[t[0]], &b = fill.nodes[t[1]], &c = fill.nodes[t[2]], &d = fill.nodes[t[3]];
  return (b - a).cross(c - a).dot(d - a) / 6;
}

// The contract of optimize_3d.h on a result: the fixed nodes bit-identical, every tet positive
// (exact), every boundary triangle a face of exactly one tet, on its normal's side (the front's
// normals point into the region), no tet repeated, the volume kept. Returns the volume.
double check_optimized(const LinearFront<3>& f, const FillResult<3>& fill) {
  std::size_t moved = 0;
  for (std::size_t i = 0; i < f.nodes.size(); ++i) moved += fill.nodes[i] != f.nodes[i];
  CHECK(moved == 0);
  std::map<Tet, int> seen;
  std::size_t non_positive = 0, repeated = 0;
  double volume = 0;
  for (const Tet& t : fill.simplices) {
    non_positive += orient3d(fill.nodes[t[0]], fill.nodes[t[1]], fill.nodes[t[2]], fill.nodes[t[3]]) < 0 ? 0 : 1;
    Tet s = t;
    std::sort(s.begin(), s.end());
    repeated += seen[s]++ > 0 ? 1 : 0;
    volume += volume_of(fill, t);
  }
  CHECK(non_positive == 0);
  CHECK(repeated == 0);
  const test::FaceApexes apexes = test::face_apexes(fill.simplices);
  std::size_t open_faces = 0;
  for (const auto& [face, apex] : apexes) open_faces += apex.size() == 1 ? 1 : 0;
  const test::FrontUse use = test::front_use(f, fill.nodes, apexes);
  CHECK(use.not_once == 0);
  CHECK(use.behind == 0);
  CHECK(open_faces == f.triangles.size());  // no face of one tet but the boundary's: no hole opened
  return volume;
}

}  // namespace

TEST_CASE("volume 3D optimiser: a box filled by TetGen moves toward unit edges in a uniform metric, fronts frozen") {
  LinearFront<3> f;
  test::add_cube(f, Vec(0, 0, 0), 1.0, 8, test::Normals::In, "farfield");
  volume::TetFillParams tp;
  tp.max_radius_edge = 0;  // coarse: TetGen's first tetrahedralisation, long interior edges
  const volume::TetFillResult r = volume::tetgen_fill(f, tp);
  FillResult<3> fill = as_fill(f, r);
  const UniformMetricField<3> metric(Metric<3>::isotropic(1.0 / 8));
  const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, f.nodes.size(), metric);
  const double volume = check_optimized(f, fill);
  CHECK(std::abs(volume - 1) <= 1e-12);
  MESSAGE("box: " << st.before.tets << " -> " << st.after.tets << " tets; unit edges " << st.before.unit_fraction
                  << " -> " << st.after.unit_fraction << "; length max " << st.before.length_max << " -> "
                  << st.after.length_max << "; quality min " << st.before.quality_min << " -> " << st.after.quality_min
                  << "; min dihedral " << st.before.min_dihedral_deg << " -> " << st.after.min_dihedral_deg << "; "
                  << st.splits << " splits, " << st.collapses << " collapses, " << st.swaps << " swaps, " << st.moves
                  << " moves");
  CHECK(st.splits > 0);
  CHECK(st.after.unit_fraction >= 0.9);
  CHECK(st.after.length_max <= 3);
  CHECK(st.after.quality_min > st.before.quality_min);
  CHECK(st.after.flat == 0);
  // The measure agrees with a fresh one.
  const volume::FillShape3 again = volume::measure_fill_3d(fill, f.nodes.size(), metric);
  CHECK(again.tets == fill.simplices.size());
  CHECK(again.unit_fraction == doctest::Approx(st.after.unit_fraction));
}

TEST_CASE("volume 3D optimiser: an anisotropic uniform metric (sizes 1, 1, 0.1) gives tets whose edges measure unit in it") {
  LinearFront<3> f;
  test::add_box(f, Vec(0, 0, 0), Vec(6, 6, 0.6), {6, 6, 6}, test::Normals::In, "farfield");
  const volume::TetFillResult r = volume::tetgen_fill(f, {});
  FillResult<3> fill = as_fill(f, r);
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m(2, 2) = 100;  // size 0.1 along z
  const UniformMetricField<3> metric(Metric<3>::from_matrix(m));
  const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, f.nodes.size(), metric);
  const double volume = check_optimized(f, fill);
  CHECK(std::abs(volume - 21.6) <= 1e-11);
  MESSAGE("anisotropic box: " << st.before.tets << " -> " << st.after.tets << " tets; unit edges "
                              << st.before.unit_fraction << " -> " << st.after.unit_fraction << "; length min "
                              << st.before.length_min << " -> " << st.after.length_min << "; quality min "
                              << st.before.quality_min << " -> " << st.after.quality_min << "; " << st.collapses
                              << " collapses");
  CHECK(st.collapses > 0);
  CHECK(st.after.unit_fraction >= 0.85);
  CHECK(st.after.unit_fraction > st.before.unit_fraction);
}

TEST_CASE("volume 3D optimiser: a flat sliver between two fixed pyramids is swapped away") {
  // An octahedron whose square's diagonals are both edges: the top uses p0 p2, the bottom p1 p3,
  // and the tet p0 p1 p2 p3 between them is a sliver (eps > 0) or flat (eps = 0, orient3d 0, as
  // TetGen's at a front). Every node is fixed: only a swap can mend it.
  for (double eps : {1e-3, 0.0}) {
    CAPTURE(eps);
    LinearFront<3> f;
    f.nodes = {Vec(1, 0, eps), Vec(0, 1, -eps), Vec(-1, 0, eps), Vec(0, -1, -eps), Vec(0, 0, 1), Vec(0, 0, -1)};
    const NodeId t = 4, s = 5;
    f.tags.push_back({"farfield", BoundaryKind::Farfield});
    for (NodeId k = 0; k < 4; ++k) {  // hull faces, normals inward
      const NodeId a = k, b = (k + 1) % 4;
      f.triangles.push_back({a, t, b});
      f.triangles.push_back({a, b, s});
      f.triangle_tag.insert(f.triangle_tag.end(), {0, 0});
    }
    FillResult<3> fill;
    fill.nodes = f.nodes;
    auto oriented = [&](Tet tet) {
      if (!(orient3d(fill.nodes[tet[0]], fill.nodes[tet[1]], fill.nodes[tet[2]], fill.nodes[tet[3]]) < 0))
        std::swap(tet[0], tet[1]);
      return tet;
    };
    fill.simplices = {oriented({0, 1, 2, t}), oriented({0, 2, 3, t}), oriented({1, 2, 3, s}), oriented({1, 3, 0, s}),
                      {0, 1, 2, 3}};
    if (eps > 0) fill.simplices.back() = oriented(fill.simplices.back());
    fill.boundary = f.triangles;
    fill.boundary_tag = f.triangle_tag;
    fill.tags = f.tags;
    // Size 2: every edge is at most unit long, so nothing is split (a split of p0 p2 would mend it too).
    const UniformMetricField<3> metric(Metric<3>::isotropic(2.0));
    const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, f.nodes.size(), metric);
    CHECK(st.before.min_dihedral_deg < 0.2);
    CHECK(st.before.flat == (eps == 0 ? 1 : 0));
    CHECK(st.splits == 0);
    CHECK(st.swaps >= 1);
    CHECK(st.after.flat == 0);
    CHECK(st.after.min_dihedral_deg > 30);
    check_optimized(f, fill);
  }
}

TEST_CASE("volume 3D optimiser: randomised fills in a graded metric never invert a tet or touch the fronts") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    CAPTURE(trial);
    LinearFront<3> f;
    test::add_cube(f, Vec(-1, -1, -1), 3.0, 6, test::Normals::In, "farfield");
    test::add_cube(f, Vec(0, 0, 0), 1.0, 3, test::Normals::Out, "body");
    f.holes.push_back(Vec(0.5, 0.5, 0.5));
    volume::TetFillParams tp;
    tp.max_volume = std::uniform_real_distribution<double>(0.005, 0.05)(rng);
    const volume::TetFillResult r = volume::tetgen_fill(f, tp);
    FillResult<3> fill = as_fill(f, r);
    // Shake the free nodes (each by a share of its shortest edge that keeps its tets positive).
    std::vector<double> room(fill.nodes.size(), 1e300);
    for (const Tet& t : fill.simplices)
      for (int k = 0; k < 4; ++k)
        for (int l = 0; l < 4; ++l)
          if (k != l) room[t[k]] = std::min(room[t[k]], (fill.nodes[t[k]] - fill.nodes[t[l]]).norm());
    std::uniform_real_distribution<double> u(-1, 1);
    for (std::size_t v = f.nodes.size(); v < fill.nodes.size(); ++v) {
      const Vec from = fill.nodes[v];
      fill.nodes[v] += 0.05 * room[v] * Vec(u(rng), u(rng), u(rng));
      for (const Tet& t : fill.simplices)
        if (std::find(t.begin(), t.end(), static_cast<NodeId>(v)) != t.end() &&
            !(orient3d(fill.nodes[t[0]], fill.nodes[t[1]], fill.nodes[t[2]], fill.nodes[t[3]]) < 0))
          fill.nodes[v] = from;
    }
    // Sizes from 0.25-0.35 at the body (its triangles' legs are 1/3) to 0.45-0.55 at the farfield
    // (1/2): a metric the frozen fronts agree with.
    const GradedMetric metric(std::uniform_real_distribution<double>(0.25, 0.35)(rng), 0.1);
    const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, f.nodes.size(), metric);
    const double volume = check_optimized(f, fill);
    CHECK(std::abs(volume - 26) <= 1e-11);
    CHECK(st.after.flat == 0);
    // Splits may halve the worst of their ring (optimize_3d.h); swaps and moves never lower it.
    CHECK(st.after.quality_min >= 0.5 * std::min(st.before.quality_min, 0.2));
    CHECK(st.after.unit_fraction > st.before.unit_fraction + 0.2);
    MESSAGE("trial " << trial << ": " << st.before.tets << " -> " << st.after.tets << " tets, unit edges "
                     << st.before.unit_fraction << " -> " << st.after.unit_fraction << ", quality min "
                     << st.before.quality_min << " -> " << st.after.quality_min << ", "
                     << st.splits + st.collapses + st.swaps + st.moves << " changes");
  }
}

TEST_CASE("volume 3D optimiser: a free node on a front triangle's edge, in two flat tets, is lifted off it") {
  // An octahedron (every node fixed, its 8 faces the front) starred from a free node that lies on
  // its edge p0 p1: the two tets over the faces through that edge are flat (orient3d exactly 0),
  // as around the Steiner point TetGen put on a front triangle's edge of the published 717 wing.
  LinearFront<3> f;
  f.nodes = {Vec(1, 0, 0), Vec(0, 1, 0), Vec(-1, 0, 0), Vec(0, -1, 0), Vec(0, 0, 1), Vec(0, 0, -1)};
  f.tags.push_back({"farfield", BoundaryKind::Farfield});
  for (NodeId k = 0; k < 4; ++k) {  // normals inward
    const NodeId a = k, b = (k + 1) % 4;
    f.triangles.push_back({a, 4, b});
    f.triangles.push_back({a, b, 5});
    f.triangle_tag.insert(f.triangle_tag.end(), {0, 0});
  }
  FillResult<3> fill;
  fill.nodes = f.nodes;
  fill.nodes.push_back(Vec(0.5, 0.5, 0));  // on p0 p1, exactly
  const auto v = static_cast<NodeId>(f.nodes.size());
  std::size_t flat = 0;
  for (const auto& tri : f.triangles) {
    Tet t{tri[0], tri[1], tri[2], v};  // v on the side of the face's normal
    const int s = sign_orient3d(fill.nodes[t[0]], fill.nodes[t[1]], fill.nodes[t[2]], fill.nodes[t[3]]);
    REQUIRE(s <= 0);  // positive (plaf's order: orient3d < 0) or flat
    flat += s == 0 ? 1 : 0;
    fill.simplices.push_back(t);
  }
  REQUIRE(flat == 2);
  fill.boundary = f.triangles;
  fill.boundary_tag = f.triangle_tag;
  fill.tags = f.tags;
  const UniformMetricField<3> metric(Metric<3>::isotropic(1.0));
  const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, f.nodes.size(), metric);
  CHECK(st.before.flat == 2);
  CHECK(st.after.flat == 0);
  CHECK(st.after.quality_min > 0.3);
  CHECK(std::abs(check_optimized(f, fill) - 4.0 / 3) <= 1e-12);
}

TEST_CASE("volume 3D optimiser: swaps, moves and sliver repairs never lower the worst tet") {
  // Two passes: no splits or collapses (optimize_3d.h), a uniform metric: what is left (swaps,
  // sliver repairs, moves) may only better the worst tet. TetGen without its quality bound in a
  // metric of sizes 0.5, 0.5, 0.1 leaves slivers (in the metric) for step 4 to repair.
  LinearFront<3> f;
  test::add_box(f, Vec(0, 0, 0), Vec(2, 2, 1), {12, 12, 6}, test::Normals::In, "farfield");
  volume::TetFillParams tp;
  tp.max_radius_edge = 0;
  FillResult<3> fill = as_fill(f, volume::tetgen_fill(f, tp));
  const UniformMetricField<3> metric(Metric<3>::from_matrix(Eigen::Vector3d(4, 4, 100).asDiagonal()));
  volume::Optimize3Params p;
  p.passes = 2;
  const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, f.nodes.size(), metric, p);
  MESSAGE("quality min " << st.before.quality_min << " -> " << st.after.quality_min << ", " << st.swaps << " swaps, "
                         << st.repairs << " repairs, " << st.moves << " moves");
  CHECK(st.splits + st.collapses == 0);
  CHECK(st.swaps + st.repairs + st.moves > 0);
  CHECK(st.after.quality_min >= st.before.quality_min);
  check_optimized(f, fill);
}

TEST_CASE("volume 3D optimiser: a boundary node stays though it is not among the fixed ones") {
  LinearFront<3> f;
  test::add_cube(f, Vec(0, 0, 0), 1.0, 6, test::Normals::In, "farfield");
  volume::TetFillParams tp;
  tp.max_radius_edge = 0;
  FillResult<3> fill = as_fill(f, volume::tetgen_fill(f, tp));
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.3));  // coarser than the front: collapses
  const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, 0, metric);
  CHECK(st.collapses + st.moves > 0);
  CHECK(std::abs(check_optimized(f, fill) - 1) <= 1e-12);
}

TEST_CASE("volume 3D optimiser: no passes leave the fill as TetGen made it, and a node out of range is an InputError") {
  LinearFront<3> f;
  test::add_cube(f, Vec(0, 0, 0), 1.0, 3, test::Normals::In, "farfield");
  FillResult<3> fill = as_fill(f, volume::tetgen_fill(f, {}));
  const FillResult<3> before = fill;
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.1));
  volume::Optimize3Params p;
  p.passes = 0;
  const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, f.nodes.size(), metric, p);
  CHECK(fill.nodes == before.nodes);
  CHECK(fill.simplices == before.simplices);
  CHECK(st.before.tets == st.after.tets);
  fill.simplices.push_back({0, 1, 2, static_cast<NodeId>(fill.nodes.size())});
  const FillResult<3> bad = fill;
  CHECK_THROWS_AS(volume::optimize_fill_3d(fill, f.nodes.size(), metric), InputError);
  CHECK(fill.simplices == bad.simplices);
}

TEST_CASE("volume 3D optimiser: the stretched tets are those where the metric asks 10:1, measured by their own stretch") {
  // A regular unit tet squashed along z by 12 (its own stretch 12), another regular one (stretch 1),
  // in a metric of sizes 1, 1, 1/12 along z (stretch 12): both counted, one stretched 10:1.
  const double s = 1.0 / 12;
  FillResult<3> fill;
  const Vec regular[4] = {Vec(0, 0, 0), Vec(1, 0, 0), Vec(0.5, std::sqrt(3.0) / 2, 0), Vec(0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0))};
  for (const Vec& x : regular) fill.nodes.push_back(Vec(x.x(), x.y(), s * x.z()));
  for (const Vec& x : regular) fill.nodes.push_back(x + Vec(5, 0, 0));
  fill.simplices = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m(2, 2) = 144;
  const volume::FillShape3 shape = volume::measure_fill_3d(fill, 0, UniformMetricField<3>(Metric<3>::from_matrix(m)));
  CHECK(shape.stretched.tets == 2);
  CHECK(shape.stretched.metric_p50 == doctest::Approx(12));
  CHECK(shape.stretched.stretch_p10 == doctest::Approx(1));
  CHECK(shape.stretched.stretch_p90 == doctest::Approx(12));
  CHECK(shape.stretched.at_least_10 == doctest::Approx(0.5));
  // The squashed tet is regular in the metric (mean ratio 1: the upper median of two), the other
  // is not (the least quality).
  CHECK(shape.stretched.quality_p50 == doctest::Approx(1));
  CHECK(shape.quality_min < 0.5);
  // An isotropic metric stretches nothing.
  CHECK(volume::measure_fill_3d(fill, 0, UniformMetricField<3>(Metric<3>::isotropic(1))).stretched.tets == 0);
}

TEST_CASE("volume 3D optimiser: a plane's own nodes slide in their plane, exactly on it, the other fixed nodes stay") {
  // The box's face z = 0 stands for a symmetry plane: its nodes inside the face may move in it.
  LinearFront<3> f;
  test::add_box(f, Vec(0, 0, 0), Vec(4, 4, 4), {5, 5, 5}, test::Normals::In, "farfield");
  const volume::TetFillResult r = volume::tetgen_fill(f, {});
  FillResult<3> fill = as_fill(f, r);
  volume::Optimize3Params params;
  std::vector<char> sliding(f.nodes.size(), 0);
  for (std::size_t i = 0; i < f.nodes.size(); ++i) {
    const Vec& x = f.nodes[i];
    if (x.z() == 0 && x.x() > 0 && x.x() < 4 && x.y() > 0 && x.y() < 4) {
      params.in_plane.emplace_back(static_cast<NodeId>(i), 2);
      sliding[i] = 1;
    }
  }
  REQUIRE(params.in_plane.size() == 16);
  const GradedMetric metric(0.3, 0.3);  // finer near x = 0: the face's uniform nodes are not ideal
  const volume::Optimize3Stats st = volume::optimize_fill_3d(fill, f.nodes.size(), metric, params);
  std::size_t slid = 0, moved_other = 0, off_plane = 0;
  for (std::size_t i = 0; i < f.nodes.size(); ++i) {
    if (sliding[i]) {
      slid += fill.nodes[i] != f.nodes[i];
      off_plane += fill.nodes[i].z() != 0;
    } else {
      moved_other += fill.nodes[i] != f.nodes[i];
    }
  }
  CHECK(slid > 0);
  CHECK(off_plane == 0);
  CHECK(moved_other == 0);
  // The rest of the contract, with the front where the slides left it.
  LinearFront<3> after = f;
  std::copy(fill.nodes.begin(), fill.nodes.begin() + static_cast<std::ptrdiff_t>(f.nodes.size()), after.nodes.begin());
  CHECK(std::abs(check_optimized(after, fill) - 64) <= 1e-10);
  CHECK(st.after.flat == 0);
  // An axis out of range is an InputError, and so is a node on a boundary triangle off its plane
  // (a corner of the face z = 0 is on the faces x = 0 and y = 0 too).
  volume::Optimize3Params bad;
  bad.in_plane.emplace_back(0, 3);
  CHECK_THROWS_AS(volume::optimize_fill_3d(fill, f.nodes.size(), metric, bad), InputError);
  std::size_t corner = f.nodes.size();
  for (std::size_t i = 0; i < f.nodes.size(); ++i)
    if (f.nodes[i] == Vec(0, 0, 0)) corner = i;
  REQUIRE(corner < f.nodes.size());
  volume::Optimize3Params edge;
  edge.in_plane.emplace_back(static_cast<NodeId>(corner), 2);
  FillResult<3> again = as_fill(f, r);
  CHECK_THROWS_AS(volume::optimize_fill_3d(again, f.nodes.size(), metric, edge), InputError);
}
