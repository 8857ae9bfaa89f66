// SPDX-License-Identifier: MIT
#include "modules/metric/background_metric.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/io/msh_io.h"
#include "tests/modules/metric/background_checks.h"
#include "tests/test_support.h"

using namespace plaf;
using Eigen::Matrix2d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using test::check_input_error;
using test::input_error;
using test::read_text;
using test::replace;
using test::TempDir;
using test::write_text;
namespace fs = std::filesystem;

namespace {

Matrix2d sym(double a, double b, double c) {
  Matrix2d m;
  m << a, b, b, c;
  return m;
}

double rel_diff(const Matrix2d& a, const Matrix2d& b) {
  return (a - b).norm() / b.norm();
}

// An irregular triangulation of [x0, x0 + n h] x [y0, y0 + n h]: interior lattice nodes moved
// by up to 0.3 h (so every cell stays convex), each cell split along a random diagonal, and the
// cells listed in `holes` left out (so some points inside the bounding box are outside).
BackgroundMesh<2> perturbed_square(int n, double h, Vector2d origin, unsigned seed,
                                   const std::vector<std::pair<int, int>>& holes = {}) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::bernoulli_distribution flip(0.5);
  BackgroundMesh<2> m;
  auto id = [n](int i, int j) { return static_cast<NodeId>(j * (n + 1) + i); };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      Vector2d p(i, j);
      if (i > 0 && i < n) p[0] += jitter(rng);
      if (j > 0 && j < n) p[1] += jitter(rng);
      m.nodes.push_back(origin + h * p);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const bool diag = flip(rng);
      if (std::find(holes.begin(), holes.end(), std::make_pair(i, j)) != holes.end()) continue;
      const NodeId a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if (diag) {
        m.simplices.push_back({a, b, c});
        m.simplices.push_back({a, c, d});
      } else {
        m.simplices.push_back({a, b, d});
        m.simplices.push_back({b, c, d});
      }
    }
  m.metrics.assign(m.nodes.size(), Metric<2>());
  return m;
}

// A field that is linear in log space: log M(x) = A + B u + C v, with (u, v) the coordinates
// relative to the domain (so the anisotropy does not depend on the scale).
struct LogLinear {
  Matrix2d a = sym(2.0, 0.5, -1.0), b = sym(-6.0, 3.0, 4.0), c = sym(1.0, -2.0, 3.5);
  Vector2d origin = Vector2d::Zero();
  double length = 1;
  Matrix2d log_at(const Vector2d& x) const {
    const Vector2d u = (x - origin) / length;
    return a + b * u[0] + c * u[1];
  }
  Matrix2d at(const Vector2d& x) const { return Metric<2>::exp(log_at(x)).matrix(); }
};

void set_metrics(BackgroundMesh<2>& m, const LogLinear& f) {
  for (std::size_t i = 0; i < m.nodes.size(); ++i) m.metrics[i] = Metric<2>::exp(f.log_at(m.nodes[i]));
}

Vector2d closest_on_segment(const Vector2d& x, const Vector2d& p, const Vector2d& q) {
  const Vector2d e = q - p;
  const double t = std::clamp((x - p).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return p + t * e;
}

// MSH 4.1 of mesh m with a $NodeData view of `components` (9 or 4) per node; node tags are
// 1..N (write_msh41), so view entry i belongs to node i.
void write_msh_background(const BackgroundMesh<2>& m, const fs::path& p, int components) {
  HybridMesh<2> h;
  h.nodes = m.nodes;
  CellBlock& b = h.block(CellType::Triangle, 1);
  for (const auto& t : m.simplices) b.connectivity.insert(b.connectivity.end(), t.begin(), t.end());
  write_msh41(h, p);
  std::ostringstream s;
  s.precision(17);  // reads back bit for bit
  s << read_text(p) << "$NodeData\n1\n\"metric\"\n1\n0\n3\n0\n" << components << "\n" << m.nodes.size() << "\n";
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const Matrix2d& t = m.metrics[i].matrix();
    s << i + 1 << " " << t(0, 0) << " " << t(0, 1) << " ";
    if (components == 9) s << "0 ";
    s << t(1, 0) << " " << t(1, 1);
    s << (components == 9 ? " 0 0 0 1\n" : "\n");
  }
  s << "$EndNodeData\n";
  write_text(p, s.str());
}

void write_meshb_background(const BackgroundMesh<2>& m, const fs::path& mesh, const fs::path& sol) {
  std::ostringstream t;
  t.precision(17);
  t << "MeshVersionFormatted 2\n\nDimension 2\n\nVertices\n" << m.nodes.size() << "\n";
  for (const Vector2d& x : m.nodes) t << x[0] << " " << x[1] << " 0\n";
  t << "\nTriangles\n" << m.simplices.size() << "\n";
  for (const auto& tri : m.simplices) t << tri[0] + 1 << " " << tri[1] + 1 << " " << tri[2] + 1 << " 1\n";
  t << "\nEnd\n";
  write_text(mesh, t.str());
  std::ostringstream s;
  s.precision(17);
  s << "MeshVersionFormatted 2\n\nDimension 2\n\nSolAtVertices\n" << m.nodes.size() << "\n1 3\n";
  for (const Metric<2>& g : m.metrics)
    s << g.matrix()(0, 0) << " " << g.matrix()(0, 1) << " " << g.matrix()(1, 1) << "\n";
  s << "\nEnd\n";
  write_text(sol, s.str());
}

}  // namespace

TEST_CASE("background: quadtree locate agrees with brute force inside, on edges and outside") {
  // Scales from 1e-8 to 1e8, away from the origin, with holes: 3 x 4200 points.
  struct Scale {
    double h;
    Vector2d origin;
  };
  const Scale scales[] = {{1e-8, {3e-7, -1e-7}}, {0.05, {0.0, 0.0}}, {1e8, {-4e9, 2e9}}};
  test::LocateCounts counts;
  for (const Scale& s : scales) {
    const int n = 16;
    const BackgroundMesh<2> mesh = perturbed_square(n, s.h, s.origin, 7, {{3, 4}, {4, 4}, {10, 11}, {0, 15}});
    const BackgroundMetricField<2> field(mesh, MetricMean::LogEuclidean);
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    std::uniform_int_distribution<std::size_t> pick(0, mesh.simplices.size() - 1);
    std::vector<Vector2d> points;
    for (int k = 0; k < 1400; ++k)  // anywhere around the domain, some in the holes
      points.push_back(s.origin + s.h * n * Vector2d(-0.2 + 1.4 * u01(rng), -0.2 + 1.4 * u01(rng)));
    for (int k = 0; k < 1400; ++k) {  // on edges and at vertices
      const auto& t = mesh.simplices[pick(rng)];
      const double a = k % 7 == 0 ? 0.0 : u01(rng);
      points.push_back((1 - a) * mesh.nodes[t[k % 3]] + a * mesh.nodes[t[(k + 1) % 3]]);
    }
    for (int k = 0; k < 1400; ++k) {  // strictly inside a triangle
      const auto& t = mesh.simplices[pick(rng)];
      Vector3d w(0.01 + u01(rng), 0.01 + u01(rng), 0.01 + u01(rng));
      w /= w.sum();
      points.push_back(w[0] * mesh.nodes[t[0]] + w[1] * mesh.nodes[t[1]] + w[2] * mesh.nodes[t[2]]);
    }
    test::check_locate(field, points, counts);
  }
  CHECK(counts.on_facets + counts.inside + counts.outside == 3 * 4200);
  CHECK(counts.on_facets >= 3000);
  CHECK(counts.outside >= 300);
}

TEST_CASE("background: log-Euclidean interpolation reproduces a field linear in log space") {
  for (double h : {1e-8, 1.0, 1e8}) {
    const int n = 10;
    BackgroundMesh<2> mesh = perturbed_square(n, h, Vector2d(2 * h, -h), 3);
    LogLinear f;
    f.origin = Vector2d(2 * h, -h);
    f.length = n * h;
    set_metrics(mesh, f);
    const BackgroundMetricField<2> field(mesh, MetricMean::LogEuclidean);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    double worst = 0;
    for (int k = 0; k < 2000; ++k) {
      const Vector2d x = f.origin + f.length * Vector2d(u01(rng), u01(rng));
      worst = std::max(worst, rel_diff(field.evaluate(x).matrix(), f.at(x)));
    }
    INFO("h = ", h);
    CHECK(worst < 1e-12);
    // The anisotropy is strong enough for the test to mean something (aspect ratio > 100).
    const auto d = field.evaluate(f.origin + f.length * Vector2d(1, 0)).decompose();
    CHECK(d.sizes[1] / d.sizes[0] > 100);
  }
}

TEST_CASE("background: affine-invariant interpolation commutes with congruence, means agree for commuting metrics") {
  BackgroundMesh<2> mesh = perturbed_square(6, 1.0, Vector2d::Zero(), 11);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (Metric<2>& m : mesh.metrics) {  // independent random anisotropic metrics
    Matrix2d r;
    const double a = 3.1 * u01(rng);
    r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    m = Metric<2>::from_directions(r, Vector2d(0.01 + u01(rng), 0.5 + 2 * u01(rng)));
  }
  Matrix2d g;
  g << 1.7, -0.4, 0.9, 0.3;  // invertible, neither orthogonal nor symmetric
  BackgroundMesh<2> congruent = mesh;
  for (Metric<2>& m : congruent.metrics) m = Metric<2>::from_matrix(g.transpose() * m.matrix() * g);
  const BackgroundMetricField<2> field(mesh, MetricMean::AffineInvariant);
  const BackgroundMetricField<2> field_g(congruent, MetricMean::AffineInvariant);
  double worst = 0;
  for (int k = 0; k < 300; ++k) {
    const Vector2d x = 6 * Vector2d(u01(rng), u01(rng));
    const Matrix2d expected = g.transpose() * field.evaluate(x).matrix() * g;
    worst = std::max(worst, rel_diff(field_g.evaluate(x).matrix(), expected));
  }
  CHECK(worst < 1e-9);

  // Commuting metrics (common eigenvectors): both means are exp(sum w_i log M_i).
  Matrix2d r;
  r << std::cos(0.7), -std::sin(0.7), std::sin(0.7), std::cos(0.7);
  for (Metric<2>& m : mesh.metrics) m = Metric<2>::from_directions(r, Vector2d(1e-3 + u01(rng), 0.1 + 10 * u01(rng)));
  const BackgroundMetricField<2> ai(mesh, MetricMean::AffineInvariant);
  const BackgroundMetricField<2> le(mesh, MetricMean::LogEuclidean);
  worst = 0;
  for (int k = 0; k < 300; ++k) {
    const Vector2d x = Vector2d(-1, -1) + 8 * Vector2d(u01(rng), u01(rng));  // some outside
    worst = std::max(worst, rel_diff(ai.evaluate(x).matrix(), le.evaluate(x).matrix()));
  }
  CHECK(worst < 1e-10);
}

TEST_CASE("background: the affine-invariant interpolant is the weighted Karcher mean of the vertex metrics") {
  // First-order optimality: sum w_i log(X^-1/2 M_i X^-1/2) = 0 at X, for far-apart, strongly
  // anisotropic vertex metrics (aspect ratios up to 250, random orientations).
  BackgroundMesh<2> mesh = perturbed_square(8, 1.0, Vector2d::Zero(), 23);
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (Metric<2>& m : mesh.metrics) {
    Matrix2d r;
    const double a = 3.1 * u01(rng);
    r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    m = Metric<2>::from_directions(r, Vector2d(0.01 + u01(rng), 0.5 + 2 * u01(rng)));
  }
  const BackgroundMetricField<2> field(mesh, MetricMean::AffineInvariant);
  double worst = 0;
  for (int k = 0; k < 500; ++k) {
    const Vector2d x = 8 * Vector2d(u01(rng), u01(rng));
    const int t = field.locate(x);
    REQUIRE(t >= 0);
    const Vector3d w = field.barycentric(t, x).cwiseMax(0.0) / field.barycentric(t, x).cwiseMax(0.0).sum();
    Eigen::SelfAdjointEigenSolver<Matrix2d> es(field.evaluate(x).matrix());
    const Matrix2d isqrt = es.operatorInverseSqrt();
    Matrix2d gradient = Matrix2d::Zero();
    for (int i = 0; i < 3; ++i)
      gradient += w[i] * Metric<2>::from_matrix(isqrt * mesh.metrics[mesh.simplices[t][i]].matrix() * isqrt).log();
    worst = std::max(worst, gradient.norm());
  }
  CHECK(worst < 1e-10);

  // A smooth field (the usual background mesh): the same as metric.h's affine_invariant_mean.
  LogLinear f;
  f.length = 8;
  set_metrics(mesh, f);
  const BackgroundMetricField<2> smooth(mesh, MetricMean::AffineInvariant);
  worst = 0;
  for (int k = 0; k < 300; ++k) {
    const Vector2d x = 8 * Vector2d(u01(rng), u01(rng));
    const int t = smooth.locate(x);
    const Vector3d w = smooth.barycentric(t, x).cwiseMax(0.0);
    const std::array<Metric<2>, 3> m{mesh.metrics[mesh.simplices[t][0]], mesh.metrics[mesh.simplices[t][1]],
                                     mesh.metrics[mesh.simplices[t][2]]};
    const std::array<double, 3> ws{w[0], w[1], w[2]};
    worst = std::max(worst, rel_diff(smooth.evaluate(x).matrix(), affine_invariant_mean<2>(m, ws).matrix()));
  }
  CHECK(worst < 1e-10);
}

TEST_CASE("background: a metric read from MSH 4.1 (9 and 4 components) and .mesh/.sol evaluates identically") {
  TempDir dir("background_io");
  BackgroundMesh<2> mesh = perturbed_square(8, 0.125, Vector2d(-0.5, 0.25), 21, {{2, 2}});
  LogLinear f;
  f.origin = Vector2d(-0.5, 0.25);
  set_metrics(mesh, f);
  write_msh_background(mesh, dir / "m9.msh", 9);
  write_msh_background(mesh, dir / "m4.msh", 4);
  write_meshb_background(mesh, dir / "m.mesh", dir / "m.sol");
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.7, 0.7);
  std::vector<Vector2d> points;
  for (int k = 0; k < 200; ++k) points.push_back(Vector2d(0, 0.75) + Vector2d(u(rng), u(rng)));
  test::check_read_alike<2>(mesh,
                            {read_background_msh<2>(dir / "m9.msh"), read_background_msh<2>(dir / "m4.msh"),
                             read_background_meshb<2>(dir / "m.mesh", dir / "m.sol")},
                            points);
}

TEST_CASE("background: MSH with sparse tags, a quadrilateral, a P2 triangle and comments reads its vertices") {
  TempDir dir("background_msh_small");
  // Unit square as a quad (nodes 10 20 30 40) and a P2 triangle on its right (nodes 20 50 30
  // with mid-edge nodes 60 70 80, which carry no value). Metric diag(1 + x, 4 + y).
  const std::string text =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
      "$Nodes\n1 8 10 80\n2 1 0 8\n10\n20\n30\n40\n50\n60\n70\n80\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0.5 0\n1.5 0.25 0\n1.5 0.75 0\n1 0.5 0\n$EndNodes\n"
      "$Elements\n2 2 1 2\n2 1 3 1\n1 10 20 30 40\n2 1 9 1\n2 20 50 30 60 70 80\n$EndElements\n"
      "$NodeData\n2\n\"metric\"\n\"interpolation\"\n1\n0.0\n4\n0\n4\n5\n0\n"
      "10 1 0 0 4\n20 2 0 0 4\n30 2 0 0 5\n40 1 0 0 5\n50 3 0 0 4.5\n$EndNodeData\n";
  write_text(dir / "small.msh", text);
  const BackgroundMesh<2> m = read_background_msh<2>(dir / "small.msh");
  CHECK(m.nodes.size() == 5);
  CHECK(m.simplices.size() == 3);
  const BackgroundMetricField<2> field(m, MetricMean::LogEuclidean);
  // Within the quad, at the nodes, diag entries are exact; at a P2 triangle vertex too.
  CHECK(rel_diff(field.evaluate(Vector2d(1, 1)).matrix(), sym(2, 0, 5)) < 1e-14);
  CHECK(rel_diff(field.evaluate(Vector2d(2, 0.5)).matrix(), sym(3, 0, 4.5)) < 1e-14);
  // Diagonal metrics commute: the log-Euclidean mean is the geometric mean of the entries.
  const Matrix2d mid = field.evaluate(Vector2d(0.5, 0)).matrix();
  CHECK(mid(0, 0) == doctest::Approx(std::sqrt(2.0)).epsilon(1e-13));
  CHECK(mid(1, 1) == doctest::Approx(4.0).epsilon(1e-13));
}

TEST_CASE("background: outside the mesh, the metric of the nearest point of the nearest triangle") {
  // Exact at a point beside a straight boundary: the closest point is (x_max, y).
  const int n = 12;
  BackgroundMesh<2> mesh = perturbed_square(n, 1.0 / n, Vector2d::Zero(), 17, {{5, 5}, {6, 5}, {5, 6}});
  LogLinear f;
  set_metrics(mesh, f);
  const BackgroundMetricField<2> field(mesh, MetricMean::LogEuclidean);
  CHECK(rel_diff(field.evaluate(Vector2d(1.5, 0.3)).matrix(), f.at(Vector2d(1, 0.3))) < 1e-12);
  CHECK(rel_diff(field.evaluate(Vector2d(-3, 0.7)).matrix(), f.at(Vector2d(0, 0.7))) < 1e-12);
  CHECK(rel_diff(field.evaluate(Vector2d(2, 2)).matrix(), f.at(Vector2d(1, 1))) < 1e-12);
  // Random points, also in the hole: against the brute-force closest point of the mesh.
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  int tested = 0;
  for (int k = 0; k < 600; ++k) {
    const Vector2d x =
        k % 3 == 0 ? Vector2d(0.4 + 0.25 * (u(rng) + 1) / 3, 0.4 + 0.25 * (u(rng) + 1) / 3) : Vector2d(u(rng), u(rng));
    if (field.locate(x) >= 0) continue;
    double best = std::numeric_limits<double>::infinity();
    Vector2d cp;
    for (const auto& t : mesh.simplices)
      for (int i = 0; i < 3; ++i) {
        const Vector2d p = closest_on_segment(x, mesh.nodes[t[i]], mesh.nodes[t[(i + 1) % 3]]);
        if ((p - x).norm() < best) {
          best = (p - x).norm();
          cp = p;
        }
      }
    INFO("x = ", x.transpose(), ", closest = ", cp.transpose());
    CHECK(rel_diff(field.evaluate(x).matrix(), field.evaluate(cp).matrix()) < 1e-12);
    ++tested;
  }
  CHECK(tested > 300);
  CHECK_THROWS_AS(field.evaluate(Vector2d(std::nan(""), 0.5)), MesherError);
}

TEST_CASE("background: bad MSH files throw InputError naming file and line") {
  TempDir dir("background_msh_bad");
  const std::string good =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"                               // 1-3
      "$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n"  // 4-13
      "$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n"                 // 14-18
      "$NodeData\n1\n\"metric\"\n1\n0\n3\n0\n4\n3\n"                         // 19-27
      "1 1 0 0 1\n2 2 0.5 0.5 1\n3 1 0 0 3\n$EndNodeData\n";                 // 28-31
  write_text(dir / "good.msh", good);
  CHECK(read_background_msh<2>(dir / "good.msh").simplices.size() == 1);
  struct Case {
    const char* what;
    std::string text;
    const char* fragment;
    int line;
  };
  const Case cases[] = {
      {"missing $NodeData", good.substr(0, good.find("$NodeData")), "no $NodeData view", 19},
      {"3 components", replace(good, "0\n4\n3\n", "0\n3\n3\n"), "has 3 components per node", 26},
      {"non-SPD tensor", replace(good, "2 2 0.5 0.5 1", "2 1 2 2 1"), "not positive definite", 29},
      {"non-symmetric tensor", replace(good, "2 2 0.5 0.5 1", "2 2 0.5 0.4 1"), "not symmetric", 29},
      {"node without value", replace(replace(good, "\n3 1 0 0 3", ""), "0\n4\n3\n", "0\n4\n2\n"),
       "no value at node tag 3", 19},
      {"unknown node tag", replace(good, "3 1 0 0 3", "7 1 0 0 3"), "unknown node tag 7", 30},
      {"node given twice", replace(good, "3 1 0 0 3", "2 1 0 0 3"), "node tag 2 twice", 30},
      {"too few integer tags", replace(good, "3\n0\n4\n3\n", "2\n0\n4\n"), "2 integer tags", 24},
      {"truncated view", good.substr(0, good.find("3 1 0 0 3")), "has no $EndNodeData", 19},
      {"bad value", replace(good, "2 2 0.5", "2 2x 0.5"), "bad tensor component '2x'", 29},
      {"3D mesh",
       replace(replace(good, "1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0",
                       "1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1"),
               "2 1 2 1\n1 1 2 3", "3 1 4 1\n1 1 2 3 4"),
       "a 2D run needs a 2D background mesh", 16},
      {"bad mesh part", replace(good, "1 1 2 3\n", "1 1 2 9\n"), "unknown node tag 9", 17},
      {"two views", good + good.substr(good.find("$NodeData")), "duplicate section $NodeData", 32},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    const fs::path p = dir / "bad.msh";
    write_text(p, c.text);
    check_input_error([&] { read_background_msh<2>(p); }, p, c.line, c.fragment);
  }
  CHECK_THROWS_AS(read_background_msh<2>(dir / "does_not_exist.msh"), InputError);
}

TEST_CASE("background: bad .mesh/.sol files throw InputError naming file and line") {
  TempDir dir("background_meshb_bad");
  const std::string mesh =
      "MeshVersionFormatted 2\n"                   // 1
      "# a comment\nDimension 2\n"                 // 2-3
      "Vertices\n4\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"  // 4-9
      "Edges\n1\n1 2 7\n"                          // 10-12, skipped
      "Triangles\n2\n1 2 3 0\n1 3 4 0\n"           // 13-16
      "End\n";                                     // 17
  const std::string sol =
      "MeshVersionFormatted 2\n"                                // 1
      "Dimension 2\n"                                           // 2
      "SolAtVertices\n4\n1 3\n1 0 1\n2 0.5 1\n1 0 2\n3 -1 1\n"  // 3-9
      "End\n";                                                  // 10
  write_text(dir / "good.mesh", mesh);
  write_text(dir / "good.sol", sol);
  CHECK(read_background_meshb<2>(dir / "good.mesh", dir / "good.sol").simplices.size() == 2);
  struct Case {
    const char* what;
    std::string mesh, sol;
    bool in_sol;
    const char* fragment;
    int line;
  };
  const Case cases[] = {
      {"truncated .sol", mesh, sol.substr(0, sol.find("1 0 2")), true, "unexpected end of file", 8},
      {"vector field", mesh, replace(sol, "1 3\n", "1 2\n"), true, "field types '2'", 5},
      {"scalar field", mesh, replace(sol, "1 3\n", "1 1\n"), true, "field types '1'", 5},
      {"two fields", mesh, replace(sol, "1 3\n", "2 3 1\n"), true, "field types '3 1'", 5},
      {"non-SPD tensor", mesh, replace(sol, "2 0.5 1", "1 2 1"), true, "not positive definite", 7},
      {"value count", mesh, replace(sol, "SolAtVertices\n4", "SolAtVertices\n3"), true, "has 4 vertices", 4},
      {"3D solution", mesh, replace(sol, "Dimension 2", "Dimension 3"), true, "Dimension 3", 2},
      {"no SolAtVertices", mesh, "MeshVersionFormatted 2\nDimension 2\nEnd\n", true, "no SolAtVertices", 3},
      {"3D mesh", replace(mesh, "Dimension 2", "Dimension 3"), sol, false, "a 2D run needs a 2D background mesh", 3},
      {"vertex index", replace(mesh, "1 3 4 0", "1 3 5 0"), sol, false, "vertex index 5 is outside 1..4", 16},
      {"truncated .mesh", mesh.substr(0, mesh.find("1 1 1")), sol, false, "truncated file?", 5},
      {"truncated .mesh data", mesh.substr(0, mesh.find("0 1 1\nEdges")), sol, false, "unexpected end of file", 9},
      {"no End", replace(mesh, "End\n", ""), sol, false, "expected a keyword (the file ends with End)", 17},
      {"no elements", replace(mesh, "Triangles\n2\n1 2 3 0\n1 3 4 0\n", ""), sol, false, "no Triangles", 13},
      {"garbage keyword", replace(mesh, "Edges", "17"), sol, false, "expected a keyword, found '17'", 10},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    const fs::path pm = dir / "bad.mesh", ps = dir / "bad.sol";
    write_text(pm, c.mesh);
    write_text(ps, c.sol);
    check_input_error([&] { read_background_meshb<2>(pm, ps); }, c.in_sol ? ps : pm, c.line, c.fragment);
  }
}

TEST_CASE("background: every truncation and random corruption of the files parses or throws InputError") {
  TempDir dir("background_fuzz");
  BackgroundMesh<2> mesh = perturbed_square(2, 0.5, Vector2d::Zero(), 2);
  set_metrics(mesh, LogLinear());
  write_msh_background(mesh, dir / "good.msh", 9);
  write_meshb_background(mesh, dir / "good.mesh", dir / "good.sol");
  test::check_background_files_fuzz(
      dir, [](const fs::path& p) { read_background_msh<2>(p); },
      [](const fs::path& m, const fs::path& s) { read_background_meshb<2>(m, s); });
}

TEST_CASE("background: an MSH 2.2 or binary background is refused with the way out, not misread") {
  // The mesh reader takes MSH 2.2 and binary 4.1; the metric's $NodeData scan reads ASCII 4.1.
  TempDir dir("background_msh_22");
  const std::string text =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
      "$Elements\n1\n1 2 2 1 1 1 2 3\n$EndElements\n"
      "$NodeData\n1\n\"metric\"\n1\n0.0\n3\n0\n9\n3\n1 1 0 0 0 1 0 0 0 1\n2 1 0 0 0 1 0 0 0 1\n3 1 0 0 0 1 0 0 0 1\n"
      "$EndNodeData\n";
  write_text(dir / "bg22.msh", text);
  try {
    (void)read_background_msh<2>(dir / "bg22.msh");
    FAIL("no InputError");
  } catch (const InputError& e) {
    const std::string what = e.what();
    CHECK(what.find("ASCII MSH 4.1") != std::string::npos);
    CHECK(what.find("-format msh41") != std::string::npos);
  }
}
