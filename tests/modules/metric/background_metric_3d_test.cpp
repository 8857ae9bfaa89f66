// SPDX-License-Identifier: MIT
// The background-mesh metric in 3D and its readers (background_metric.h):
// point location against brute force, exact reproduction of a field linear in log space, the
// means of metric.h, points outside, both file formats, prisms split conformingly, every error
// case, and a run of plaf with a 3D configuration whose metric is a background mesh.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/geometry/aabb_tree.h"
#include "modules/io/msh_io.h"
#include "modules/metric/background_metric.h"
#include "tests/modules/metric/background_checks.h"
#include "tests/test_support.h"

using namespace plaf;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::Vector4d;
using test::check_input_error;
using test::input_error;
using test::read_text;
using test::replace;
using test::TempDir;
using test::write_text;
namespace fs = std::filesystem;

namespace {

Matrix3d sym(double xx, double xy, double yy, double xz, double yz, double zz) {
  Matrix3d m;
  m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  return m;
}

double rel_diff(const Matrix3d& a, const Matrix3d& b) {
  return (a - b).norm() / b.norm();
}

double tet_det(const BackgroundMesh<3>& m, const BackgroundMesh<3>::Simplex& t) {
  Matrix3d e;
  e << m.nodes[t[1]] - m.nodes[t[0]], m.nodes[t[2]] - m.nodes[t[0]], m.nodes[t[3]] - m.nodes[t[0]];
  return e.determinant();
}

// The cube [0, n]^3 of lattice spacing h about `origin`, each unit cube split into the six
// tetrahedra around its main diagonal (Kuhn's subdivision, conforming across cubes), interior
// nodes moved by up to 0.15 h along each axis (every tetrahedron keeps a positive volume), the
// cubes listed in `holes` left out. Identity metrics.
BackgroundMesh<3> perturbed_cube(int n, double h, const Vector3d& origin, unsigned seed,
                                 const std::vector<std::array<int, 3>>& holes = {}) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  BackgroundMesh<3> m;
  const auto id = [n](int i, int j, int k) { return static_cast<NodeId>((k * (n + 1) + j) * (n + 1) + i); };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        Vector3d p(i, j, k);
        for (int d = 0; d < 3; ++d)
          if (p[d] > 0 && p[d] < n) p[d] += jitter(rng);
        m.nodes.push_back(origin + h * p);
      }
  // The six paths from corner 000 to 111, one axis at a time: one tetrahedron each.
  std::array<int, 3> axes = {0, 1, 2};
  std::vector<std::array<int, 3>> paths;
  do paths.push_back(axes);
  while (std::next_permutation(axes.begin(), axes.end()));
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if (std::find(holes.begin(), holes.end(), std::array<int, 3>{i, j, k}) != holes.end()) continue;
        for (const auto& path : paths) {
          std::array<int, 3> c = {i, j, k};
          BackgroundMesh<3>::Simplex t;
          t[0] = id(c[0], c[1], c[2]);
          for (std::size_t s = 0; s < 3; ++s) {
            ++c[static_cast<std::size_t>(path[s])];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          m.simplices.push_back(t);
        }
      }
  for (const auto& t : m.simplices) REQUIRE(std::abs(tet_det(m, t)) > 0.05 * h * h * h);
  m.metrics.assign(m.nodes.size(), Metric<3>());
  return m;
}

// A field linear in log space: log M(x) = A + B u + C v + D w, with (u, v, w) = (x - origin) /
// length, so that the anisotropy does not depend on the scale.
struct LogLinear {
  Matrix3d a = sym(2.0, 0.5, -1.0, 0.3, -0.2, 0.5), b = sym(-6.0, 3.0, 4.0, 1.0, -2.0, 0.5),
           c = sym(1.0, -2.0, 3.5, 0.5, 1.5, -3.0), d = sym(0.5, 1.0, -1.0, -2.0, 0.7, 4.0);
  Vector3d origin = Vector3d::Zero();
  double length = 1;
  Matrix3d log_at(const Vector3d& x) const {
    const Vector3d u = (x - origin) / length;
    return a + b * u[0] + c * u[1] + d * u[2];
  }
  Matrix3d at(const Vector3d& x) const { return Metric<3>::exp(log_at(x)).matrix(); }
};

void set_metrics(BackgroundMesh<3>& m, const LogLinear& f) {
  for (std::size_t i = 0; i < m.nodes.size(); ++i) m.metrics[i] = Metric<3>::exp(f.log_at(m.nodes[i]));
}

// Random anisotropic metrics (aspect ratios up to 250, random orientations).
void set_random_metrics(BackgroundMesh<3>& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  for (Metric<3>& metric : m.metrics) {
    const Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
    metric = Metric<3>::from_directions(q.normalized().toRotationMatrix(),
                                        Vector3d(0.01 + u01(rng), 0.1 + u01(rng), 0.5 + 2 * u01(rng)));
  }
}

// The closest point of the mesh to x, by brute force over every face of every tetrahedron.
Vector3d brute_closest(const BackgroundMesh<3>& m, const Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  Vector3d cp = x;
  for (const auto& t : m.simplices)
    for (int f = 0; f < 4; ++f) {
      std::array<Vector3d, 3> c;
      for (int i = 0, j = 0; i < 4; ++i)
        if (i != f) c[static_cast<std::size_t>(j++)] = m.nodes[t[static_cast<std::size_t>(i)]];
      const Vector3d p = closest_point_on_triangle(x, c[0], c[1], c[2]);
      if ((p - x).squaredNorm() < best) {
        best = (p - x).squaredNorm();
        cp = p;
      }
    }
  return cp;
}

// The $NodeData view of one tensor per node (node tags 1..N in order): `components` 9 (3x3,
// row-major) or 6 (xx xy yy xz yz zz).
std::string node_data(const std::vector<Metric<3>>& metrics, int components) {
  std::ostringstream s;
  s.precision(17);  // reads back bit for bit
  s << "$NodeData\n1\n\"metric\"\n1\n0\n3\n0\n" << components << "\n" << metrics.size() << "\n";
  for (std::size_t i = 0; i < metrics.size(); ++i) {
    const Matrix3d& t = metrics[i].matrix();
    s << i + 1;
    if (components == 9)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) s << " " << t(r, c);
    else
      s << " " << t(0, 0) << " " << t(0, 1) << " " << t(1, 1) << " " << t(0, 2) << " " << t(1, 2) << " " << t(2, 2);
    s << "\n";
  }
  s << "$EndNodeData\n";
  return s.str();
}

void write_msh_background(const BackgroundMesh<3>& m, const fs::path& p, int components) {
  HybridMesh<3> h;
  h.nodes = m.nodes;
  CellBlock& b = h.block(CellType::Tetrahedron, 1);
  for (const auto& t : m.simplices) b.connectivity.insert(b.connectivity.end(), t.begin(), t.end());
  write_msh41(h, p);
  write_text(p, read_text(p) + node_data(m.metrics, components));
}

void write_meshb_background(const BackgroundMesh<3>& m, const fs::path& mesh, const fs::path& sol) {
  std::ostringstream t;
  t.precision(17);
  t << "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n" << m.nodes.size() << "\n";
  for (const Vector3d& x : m.nodes) t << x[0] << " " << x[1] << " " << x[2] << " 0\n";
  t << "\nTetrahedra\n" << m.simplices.size() << "\n";
  for (const auto& s : m.simplices) t << s[0] + 1 << " " << s[1] + 1 << " " << s[2] + 1 << " " << s[3] + 1 << " 1\n";
  t << "\nEnd\n";
  write_text(mesh, t.str());
  std::ostringstream s;
  s.precision(17);
  s << "MeshVersionFormatted 2\n\nDimension 3\n\nSolAtVertices\n" << m.nodes.size() << "\n1 3\n";
  for (const Metric<3>& g : m.metrics) {
    const Matrix3d& x = g.matrix();
    s << x(0, 0) << " " << x(0, 1) << " " << x(1, 1) << " " << x(0, 2) << " " << x(1, 2) << " " << x(2, 2) << "\n";
  }
  s << "\nEnd\n";
  write_text(sol, s.str());
}

// The number of the first line of text that starts with `start` (lines count from 1).
int line_of(const std::string& text, const std::string& start) {
  const std::size_t at = text.find('\n' + start);
  REQUIRE(at != std::string::npos);
  return 2 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

}  // namespace

TEST_CASE("background 3D: the tree locates what brute force finds, inside, on faces and outside") {
  // Scales from 1e-8 to 1e8, away from the origin, with holes: 3 x 4000 points.
  struct Scale {
    double h;
    Vector3d origin;
  };
  const Scale scales[] = {{1e-8, {3e-7, -1e-7, 2e-8}}, {0.25, {0.0, 0.0, 0.0}}, {1e8, {-4e9, 2e9, 1e9}}};
  test::LocateCounts counts;
  for (const Scale& s : scales) {
    const int n = 6;
    const BackgroundMesh<3> mesh = perturbed_cube(n, s.h, s.origin, 7, {{2, 3, 3}, {3, 3, 3}, {0, 5, 1}});
    const BackgroundMetricField<3> field(mesh, MetricMean::LogEuclidean);
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    std::uniform_int_distribution<std::size_t> pick(0, mesh.simplices.size() - 1);
    std::vector<Vector3d> points;
    for (int k = 0; k < 1400; ++k)  // anywhere around the domain, some in the holes
      points.push_back(s.origin +
                       s.h * n * Vector3d(-0.2 + 1.4 * u01(rng), -0.2 + 1.4 * u01(rng), -0.2 + 1.4 * u01(rng)));
    for (int k = 0; k < 1400; ++k) {  // on faces, edges and at vertices
      const auto& t = mesh.simplices[pick(rng)];
      Vector3d w(u01(rng), u01(rng), k % 5 == 0 ? 0.0 : u01(rng));
      if (k % 7 == 0) w[1] = 0;
      w /= w.sum();
      points.push_back(w[0] * mesh.nodes[t[k % 4]] + w[1] * mesh.nodes[t[(k + 1) % 4]] +
                       w[2] * mesh.nodes[t[(k + 2) % 4]]);
    }
    for (int k = 0; k < 1200; ++k) {  // strictly inside a tetrahedron
      const auto& t = mesh.simplices[pick(rng)];
      Vector4d w(0.01 + u01(rng), 0.01 + u01(rng), 0.01 + u01(rng), 0.01 + u01(rng));
      w /= w.sum();
      points.push_back(w[0] * mesh.nodes[t[0]] + w[1] * mesh.nodes[t[1]] + w[2] * mesh.nodes[t[2]] +
                       w[3] * mesh.nodes[t[3]]);
    }
    test::check_locate(field, points, counts);
  }
  CHECK(counts.on_facets + counts.inside + counts.outside == 3 * 4000);
  CHECK(counts.on_facets >= 3000);
  CHECK(counts.inside >= 3000);
  CHECK(counts.outside >= 300);
}

TEST_CASE("background 3D: log-Euclidean interpolation reproduces a field linear in log space") {
  for (double h : {1e-8, 1.0, 1e8}) {
    const int n = 5;
    const Vector3d origin(2 * h, -h, 0.5 * h);
    BackgroundMesh<3> mesh = perturbed_cube(n, h, origin, 3);
    LogLinear f;
    f.origin = origin;
    f.length = n * h;
    set_metrics(mesh, f);
    const BackgroundMetricField<3> field(mesh, MetricMean::LogEuclidean);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    double worst = 0;
    for (int k = 0; k < 2000; ++k) {
      const Vector3d x = f.origin + f.length * Vector3d(u01(rng), u01(rng), u01(rng));
      worst = std::max(worst, rel_diff(field.evaluate(x).matrix(), f.at(x)));
    }
    INFO("h = ", h);
    CHECK(worst < 1e-12);
    // The anisotropy is strong enough for the test to mean something (aspect ratio > 100).
    const auto d = field.evaluate(f.origin + f.length * Vector3d(1, 0, 0)).decompose();
    CHECK(d.sizes[2] / d.sizes[0] > 100);
  }
}

TEST_CASE("background 3D: the interpolant is metric.h's weighted mean of the vertex metrics") {
  // Far-apart, strongly anisotropic vertex metrics: evaluate is log_euclidean_mean or
  // affine_invariant_mean (metric.h) with the barycentric weights; the affine-invariant mean
  // satisfies the first-order condition sum w_i log(X^-1/2 M_i X^-1/2) = 0 and commutes with
  // congruence; both means agree for commuting metrics.
  BackgroundMesh<3> mesh = perturbed_cube(4, 1.0, Vector3d::Zero(), 23);
  set_random_metrics(mesh, 31);
  const BackgroundMetricField<3> le(mesh, MetricMean::LogEuclidean), ai(mesh, MetricMean::AffineInvariant);
  Matrix3d g;
  g << 1.7, -0.4, 0.2, 0.9, 0.3, -0.5, 0.1, 0.6, 1.1;  // invertible, neither orthogonal nor symmetric
  BackgroundMesh<3> congruent = mesh;
  for (Metric<3>& m : congruent.metrics) m = Metric<3>::from_matrix(g.transpose() * m.matrix() * g);
  const BackgroundMetricField<3> ai_g(congruent, MetricMean::AffineInvariant);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 5.0);  // some outside
  double worst_le = 0, worst_ai = 0, worst_gradient = 0, worst_congruence = 0;
  for (int k = 0; k < 300; ++k) {
    const Vector3d x(u(rng), u(rng), u(rng));
    const BackgroundMetricField<3>::Located w = le.weights(x);
    CHECK(w.w.minCoeff() >= 0);
    CHECK(w.w.sum() == doctest::Approx(1.0).epsilon(1e-15));
    std::array<Metric<3>, 4> m;
    for (std::size_t i = 0; i < 4; ++i) m[i] = mesh.metrics[mesh.simplices[w.simplex][i]];
    const std::array<double, 4> ws{w.w[0], w.w[1], w.w[2], w.w[3]};
    worst_le = std::max(worst_le, rel_diff(le.evaluate(x).matrix(), log_euclidean_mean<3>(m, ws).matrix()));
    const Matrix3d mean = ai.evaluate(x).matrix();
    worst_ai = std::max(worst_ai, rel_diff(mean, affine_invariant_mean<3>(m, ws).matrix()));
    Eigen::SelfAdjointEigenSolver<Matrix3d> es(mean);
    const Matrix3d isqrt = es.operatorInverseSqrt();
    Matrix3d gradient = Matrix3d::Zero();
    for (std::size_t i = 0; i < 4; ++i) gradient += ws[i] * Metric<3>::from_matrix(isqrt * m[i].matrix() * isqrt).log();
    worst_gradient = std::max(worst_gradient, gradient.norm());
    worst_congruence = std::max(worst_congruence, rel_diff(ai_g.evaluate(x).matrix(), g.transpose() * mean * g));
  }
  CHECK(worst_le < 1e-14);
  CHECK(worst_ai < 1e-14);
  CHECK(worst_gradient < 1e-10);
  CHECK(worst_congruence < 1e-9);

  // Commuting metrics (common eigenvectors): both means are exp(sum w_i log M_i).
  const Matrix3d r = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (Metric<3>& m : mesh.metrics)
    m = Metric<3>::from_directions(r, Vector3d(1e-3 + u01(rng), 0.1 + u01(rng), 0.1 + 10 * u01(rng)));
  const BackgroundMetricField<3> le_c(mesh, MetricMean::LogEuclidean), ai_c(mesh, MetricMean::AffineInvariant);
  double worst = 0;
  for (int k = 0; k < 300; ++k) {
    const Vector3d x(u(rng), u(rng), u(rng));
    worst = std::max(worst, rel_diff(ai_c.evaluate(x).matrix(), le_c.evaluate(x).matrix()));
  }
  CHECK(worst < 1e-10);
}

TEST_CASE("background 3D: outside the mesh, the metric of the nearest point of the nearest tetrahedron") {
  // Exact beside a straight boundary: the closest point of the unit cube's face, edge or corner.
  const int n = 4;
  BackgroundMesh<3> mesh = perturbed_cube(n, 1.0 / n, Vector3d::Zero(), 17, {{1, 1, 1}, {2, 1, 1}, {1, 2, 1}});
  LogLinear f;
  set_metrics(mesh, f);
  for (MetricMean mean : {MetricMean::LogEuclidean, MetricMean::AffineInvariant}) {
    const BackgroundMetricField<3> field(mesh, mean);
    struct Case {
      Vector3d x, closest;
    };
    const Case cases[] = {{{1.5, 0.3, 0.4}, {1, 0.3, 0.4}},
                          {{-3, 0.7, 0.2}, {0, 0.7, 0.2}},
                          {{0.6, 0.3, 8}, {0.6, 0.3, 1}},
                          {{2, 2, 0.5}, {1, 1, 0.5}},
                          {{2, -2, 3}, {1, 0, 1}}};
    for (const Case& c : cases) {
      INFO("x = ", c.x.transpose());
      CHECK(field.locate(c.x) == -1);
      CHECK(rel_diff(field.evaluate(c.x).matrix(), field.evaluate(c.closest).matrix()) < 1e-12);
      // The log-Euclidean mean of log-linear data is the field itself, also on the boundary.
      if (mean == MetricMean::LogEuclidean) CHECK(rel_diff(field.evaluate(c.x).matrix(), f.at(c.closest)) < 1e-12);
    }
  }
  // Random points, also in the hole: against the brute-force closest point of the mesh.
  const BackgroundMetricField<3> field(mesh, MetricMean::LogEuclidean);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 2.0), hole(0.25, 0.75);
  int tested = 0;
  for (int k = 0; k < 400; ++k) {
    const Vector3d x = k % 3 == 0 ? Vector3d(hole(rng), hole(rng), hole(rng)) : Vector3d(u(rng), u(rng), u(rng));
    if (field.locate(x) >= 0) continue;
    const Vector3d cp = brute_closest(mesh, x);
    INFO("x = ", x.transpose(), ", closest = ", cp.transpose());
    CHECK(rel_diff(field.evaluate(x).matrix(), field.evaluate(cp).matrix()) < 1e-12);
    CHECK(rel_diff(field.evaluate(x).matrix(), f.at(cp)) < 1e-11);
    ++tested;
  }
  CHECK(tested > 200);
  CHECK_THROWS_AS(field.evaluate(Vector3d(std::nan(""), 0.5, 0.5)), MesherError);
}

TEST_CASE("background 3D: MSH 4.1 (9 and 6 components) and .mesh/.sol read the same mesh and metrics") {
  TempDir dir("background3d_io");
  const Vector3d origin(-0.5, 0.25, 1);
  BackgroundMesh<3> mesh = perturbed_cube(3, 0.25, origin, 21, {{1, 1, 1}});
  LogLinear f;
  f.origin = origin;
  set_metrics(mesh, f);
  write_msh_background(mesh, dir / "m9.msh", 9);
  write_msh_background(mesh, dir / "m6.msh", 6);
  write_meshb_background(mesh, dir / "m.mesh", dir / "m.sol");
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.2, 1.0);
  std::vector<Vector3d> points;
  for (int k = 0; k < 200; ++k) points.push_back(origin + Vector3d(u(rng), u(rng), u(rng)));
  test::check_read_alike<3>(mesh,
                            {read_background_msh<3>(dir / "m9.msh"), read_background_msh<3>(dir / "m6.msh"),
                             read_background_meshb<3>(dir / "m.mesh", dir / "m.sol")},
                            points);
  // The 2D readers refuse these files, and the 3D readers the 2D ones (background_metric_test.cpp).
  CHECK(input_error([&] { read_background_msh<2>(dir / "m9.msh"); }).find("a 2D run needs a 2D background mesh") !=
        std::string::npos);
  CHECK(input_error([&] { read_background_meshb<2>(dir / "m.mesh", dir / "m.sol"); }).find("Dimension 3") !=
        std::string::npos);
}

TEST_CASE("background 3D: MSH prisms split into conforming tetrahedra, high-order cells keep their vertices") {
  // Three layers of prisms over a triangulated square (the shape of plaf's own layer meshes),
  // nodes numbered in a random order so the diagonals' rule meets every case: the tetrahedra
  // fill the box (their volumes add up to n^2 x the height), every face is shared by two of them
  // or lies on the box, and a field linear in log space is reproduced everywhere.
  TempDir dir("background3d_prisms");
  const int n = 4, layers = 3;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::bernoulli_distribution flip(0.5);
  std::vector<Eigen::Vector2d> plane;  // the square's nodes, the same in every layer
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      plane.emplace_back(i + (i > 0 && i < n ? jitter(rng) : 0.0), j + (j > 0 && j < n ? jitter(rng) : 0.0));
  std::vector<Vector3d> points;
  for (int k = 0; k <= layers; ++k)
    for (const Eigen::Vector2d& p : plane) points.emplace_back(p.x(), p.y(), 0.5 * k);
  std::vector<NodeId> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);  // order[old] = new index
  const auto id = [&](int i, int j, int k) { return order[static_cast<std::size_t>((k * (n + 1) + j) * (n + 1) + i)]; };
  HybridMesh<3> h;
  h.nodes.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) h.nodes[static_cast<std::size_t>(order[i])] = points[i];
  CellBlock& prisms = h.block(CellType::Prism, 1);
  std::vector<std::array<std::array<int, 2>, 3>> triangles;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (flip(rng)) {
        triangles.push_back({{{i, j}, {i + 1, j}, {i + 1, j + 1}}});
        triangles.push_back({{{i, j}, {i + 1, j + 1}, {i, j + 1}}});
      } else {
        triangles.push_back({{{i, j}, {i + 1, j}, {i, j + 1}}});
        triangles.push_back({{{i + 1, j}, {i + 1, j + 1}, {i, j + 1}}});
      }
    }
  for (int k = 0; k < layers; ++k)
    for (const auto& t : triangles)
      for (int level : {k, k + 1})
        for (const auto& c : t) prisms.connectivity.push_back(id(c[0], c[1], level));
  write_msh41(h, dir / "prisms.msh");
  LogLinear f;
  f.length = n;
  std::vector<Metric<3>> metrics;
  for (const Vector3d& x : h.nodes) metrics.push_back(Metric<3>::exp(f.log_at(x)));
  write_text(dir / "prisms.msh", read_text(dir / "prisms.msh") + node_data(metrics, 6));

  const BackgroundMesh<3> mesh = read_background_msh<3>(dir / "prisms.msh");
  REQUIRE(mesh.simplices.size() == 3 * triangles.size() * layers);
  double volume = 0;
  std::map<std::array<NodeId, 3>, int> faces;
  for (const auto& t : mesh.simplices) {
    volume += std::abs(tet_det(mesh, t)) / 6;
    for (std::size_t opposite = 0; opposite < 4; ++opposite) {
      std::array<NodeId, 3> face;
      for (std::size_t i = 0, j = 0; i < 4; ++i)
        if (i != opposite) face[j++] = t[i];
      std::sort(face.begin(), face.end());
      ++faces[face];
    }
  }
  CHECK(volume == doctest::Approx(n * n * 0.5 * layers).epsilon(1e-12));
  int boundary = 0;
  for (const auto& [face, count] : faces) {
    CHECK(count <= 2);
    if (count == 1) {
      ++boundary;
      // A boundary face lies on the box: x = 0 or n, y = 0 or n, or the bottom or top layer.
      bool on_box = false;
      for (int d = 0; d < 2; ++d)
        for (double side : {0.0, static_cast<double>(n)})
          on_box = on_box || std::all_of(face.begin(), face.end(), [&](NodeId v) { return mesh.nodes[v][d] == side; });
      for (double side : {0.0, 0.5 * layers})
        on_box = on_box || std::all_of(face.begin(), face.end(), [&](NodeId v) { return mesh.nodes[v][2] == side; });
      CHECK(on_box);
    }
  }
  CHECK(boundary == 2 * static_cast<int>(triangles.size()) + 4 * n * layers * 2);
  const BackgroundMetricField<3> field(mesh, MetricMean::LogEuclidean);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  double worst = 0;
  for (int k = 0; k < 1000; ++k) {
    const Vector3d x(n * u01(rng), n * u01(rng), 0.5 * layers * u01(rng));
    worst = std::max(worst, rel_diff(field.evaluate(x).matrix(), f.at(x)));
  }
  CHECK(worst < 1e-12);

  // A P2 tetrahedron (mid-edge nodes without values) and sparse tags: its four vertices.
  const std::string p2 =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
      "$Nodes\n1 10 10 100\n3 1 0 10\n10\n20\n30\n40\n50\n60\n70\n80\n90\n100\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.5 0 0\n0.5 0.5 0\n0 0.5 0\n0 0 0.5\n0 0.5 0.5\n0.5 0 0.5\n$EndNodes\n"
      "$Elements\n1 1 1 1\n3 1 11 1\n1 10 20 30 40 50 60 70 80 90 100\n$EndElements\n"
      "$NodeData\n1\n\"metric\"\n1\n0.0\n3\n0\n6\n4\n"
      "10 1 0 1 0 0 1\n20 2 0 1 0 0 1\n30 1 0 3 0 0 1\n40 1 0 1 0 0 4\n$EndNodeData\n";
  write_text(dir / "p2.msh", p2);
  const BackgroundMesh<3> small = read_background_msh<3>(dir / "p2.msh");
  CHECK(small.nodes.size() == 4);
  CHECK(small.simplices.size() == 1);
  const BackgroundMetricField<3> p2_field(small, MetricMean::LogEuclidean);
  CHECK(rel_diff(p2_field.evaluate(Vector3d(0, 0, 1)).matrix(), sym(1, 0, 1, 0, 0, 4)) < 1e-14);
  // Diagonal metrics commute: the log-Euclidean mean is the geometric mean of the entries.
  const Matrix3d mid = p2_field.evaluate(Vector3d(0.5, 0, 0)).matrix();
  CHECK(mid(0, 0) == doctest::Approx(std::sqrt(2.0)).epsilon(1e-13));
  CHECK(mid(1, 1) == doctest::Approx(1.0).epsilon(1e-13));
}

TEST_CASE("background 3D: bad MSH files throw InputError naming file and line") {
  TempDir dir("background3d_msh_bad");
  const std::string good =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"                                                    // 1-3
      "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"             // 4-15
      "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n"                                    // 16-20
      "$NodeData\n1\n\"metric\"\n1\n0\n3\n0\n9\n4\n"                                              // 21-29
      "1 1 0 0 0 1 0 0 0 1\n2 2 0.5 0 0.5 1 0 0 0 1\n3 1 0 0 0 3 0 0 0 1\n4 1 0 0 0 1 0 0 0 2\n"  // 30-33
      "$EndNodeData\n";                                                                           // 34
  write_text(dir / "good.msh", good);
  CHECK(read_background_msh<3>(dir / "good.msh").simplices.size() == 1);
  const std::string six =
      replace(replace(replace(replace(replace(good, "0\n9\n4\n", "0\n6\n4\n"), "1 1 0 0 0 1 0 0 0 1", "1 1 0 1 0 0 1"),
                              "2 2 0.5 0 0.5 1 0 0 0 1", "2 2 0.5 1 0 0 1"),
                      "3 1 0 0 0 3 0 0 0 1", "3 1 0 3 0 0 1"),
              "4 1 0 0 0 1 0 0 0 2", "4 1 0 1 0 0 2");
  write_text(dir / "six.msh", six);
  const BackgroundMesh<3> from_six = read_background_msh<3>(dir / "six.msh"),
                          from_nine = read_background_msh<3>(dir / "good.msh");
  for (std::size_t i = 0; i < 4; ++i) CHECK(from_six.metrics[i].matrix() == from_nine.metrics[i].matrix());
  // A 3D surface mesh (triangles of a volume entity, as write_msh41 writes one) has no cells.
  HybridMesh<3> surface;
  surface.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  surface.tags.push_back({"wall", BoundaryKind::Wall});
  CellBlock& faces = surface.boundary_block(CellType::Triangle, 1, 0);
  faces.connectivity = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
  write_msh41(surface, dir / "surface.msh");
  const std::string surface_text = read_text(dir / "surface.msh") + node_data(std::vector<Metric<3>>(4), 9);
  const std::string hexahedron =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"                               // 1-3
      "$Nodes\n1 8 1 8\n3 1 0 8\n1\n2\n3\n4\n5\n6\n7\n8\n"                   // 4-14
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n$EndNodes\n"  // 15-23
      "$Elements\n1 1 1 1\n3 1 5 1\n1 1 2 3 4 5 6 7 8\n$EndElements\n" +     // 24-28
      node_data(std::vector<Metric<3>>(8), 9);
  struct Case {
    const char* what;
    std::string text;
    const char* fragment;
    int line;
  };
  const Case cases[] = {
      {"missing $NodeData", good.substr(0, good.find("$NodeData")), "no $NodeData view", 21},
      {"4 components", replace(good, "0\n9\n4\n", "0\n4\n4\n"), "has 4 components per node", 28},
      {"non-SPD tensor", replace(good, "2 2 0.5 0 0.5 1", "2 1 2 0 2 1"), "not positive definite", 31},
      {"non-SPD packed tensor", replace(six, "2 2 0.5 1 0 0 1", "2 1 0 1 0 0 -1"), "not positive definite", 31},
      {"non-symmetric tensor", replace(good, "2 2 0.5 0 0.5 1", "2 2 0.5 0 0.4 1"), "not symmetric", 31},
      {"node without value", replace(replace(good, "\n4 1 0 0 0 1 0 0 0 2", ""), "0\n9\n4\n", "0\n9\n3\n"),
       "no value at node tag 4", 21},
      {"unknown node tag", replace(good, "4 1 0 0 0 1 0 0 0 2", "7 1 0 0 0 1 0 0 0 2"), "unknown node tag 7", 33},
      {"2D mesh",
       replace(replace(good, "1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1",
                       "1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n1 1 0"),
               "3 1 4 1\n1 1 2 3 4", "2 1 2 1\n1 1 2 3"),
       "the background mesh is 2D; a 3D run needs a 3D background mesh", 16},
      {"surface mesh", surface_text, "no tetrahedra or prisms", line_of(surface_text, "$Elements")},
      {"hexahedron", hexahedron, "unsupported Gmsh element type 5", 26},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    const fs::path p = dir / "bad.msh";
    write_text(p, c.text);
    check_input_error([&] { read_background_msh<3>(p); }, p, c.line, c.fragment);
  }
}

TEST_CASE("background 3D: bad .mesh/.sol files throw InputError naming file and line") {
  TempDir dir("background3d_meshb_bad");
  const std::string mesh =
      "MeshVersionFormatted 2\n"                                    // 1
      "Dimension 3\n"                                               // 2
      "Vertices\n5\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n1 1 1 1\n"  // 3-9
      "Triangles\n1\n1 2 3 7\n"                                     // 10-12, the boundary: skipped
      "Tetrahedra\n2\n1 2 3 4 0\n2 3 4 5 0\n"                       // 13-16
      "End\n";                                                      // 17
  const std::string sol =
      "MeshVersionFormatted 2\n"                                                                      // 1
      "Dimension 3\n"                                                                                 // 2
      "SolAtVertices\n5\n1 3\n1 0 1 0 0 1\n2 0.5 1 0 0 1\n1 0 2 0 0 1\n1 0 1 0.5 0 3\n1 0 1 0 0 1\n"  // 3-10
      "End\n";                                                                                        // 11
  write_text(dir / "good.mesh", mesh);
  write_text(dir / "good.sol", sol);
  const BackgroundMesh<3> read = read_background_meshb<3>(dir / "good.mesh", dir / "good.sol");
  CHECK(read.simplices.size() == 2);
  CHECK(read.metrics[3].matrix() == sym(1, 0, 1, 0.5, 0, 3));  // xx xy yy xz yz zz
  struct Case {
    const char* what;
    std::string mesh, sol;
    bool in_sol;
    const char* fragment;
    int line;
  };
  const Case cases[] = {
      {"truncated .sol", mesh, sol.substr(0, sol.find("1 0 2 0")), true, "truncated file?", 4},
      {"vector field", mesh, replace(sol, "1 3\n", "1 2\n"), true, "field types '2'", 5},
      {"non-SPD tensor", mesh, replace(sol, "2 0.5 1 0 0 1", "1 2 1 0 0 1"), true, "not positive definite", 7},
      {"value count", mesh, replace(sol, "SolAtVertices\n5", "SolAtVertices\n4"), true, "has 5 vertices", 4},
      {"2D solution", mesh, replace(sol, "Dimension 3", "Dimension 2"), true,
       "Dimension 2: a 3D run needs a 3D background mesh", 2},
      {"2D mesh", replace(mesh, "Dimension 3", "Dimension 2"), sol, false,
       "Dimension 2: a 3D run needs a 3D background mesh", 2},
      {"prisms", replace(mesh, "Tetrahedra\n2\n1 2 3 4 0\n2 3 4 5 0\n", "Prisms\n1\n1 2 3 4 5 1 0\n"), sol, false,
       "Prisms: a 3D background mesh is made of Tetrahedra", 13},
      {"hexahedra", replace(mesh, "Triangles", "Hexahedra"), sol, false, "Hexahedra: a 3D background mesh", 10},
      {"no tetrahedra", replace(mesh, "Tetrahedra\n2\n1 2 3 4 0\n2 3 4 5 0\n", ""), sol, false, "no Tetrahedra", 13},
      {"vertex index", replace(mesh, "2 3 4 5 0", "2 3 4 6 0"), sol, false, "vertex index 6 is outside 1..5", 16},
      {"2D vertices", replace(mesh, "1 1 1 1\n", "1 1\n"), sol, false, "bad vertex coordinate 'Triangles'", 10},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    const fs::path pm = dir / "bad.mesh", ps = dir / "bad.sol";
    write_text(pm, c.mesh);
    write_text(ps, c.sol);
    check_input_error([&] { read_background_meshb<3>(pm, ps); }, c.in_sol ? ps : pm, c.line, c.fragment);
  }
  // A mesh whose tetrahedra all have zero volume, and one that refers to a missing node.
  BackgroundMesh<3> flat;
  flat.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  flat.simplices = {{0, 1, 2, 3}};
  flat.metrics.assign(4, Metric<3>());
  CHECK(input_error([&] { BackgroundMetricField<3>(flat, MetricMean::LogEuclidean); }) ==
        "background mesh has no tetrahedron of positive volume");
  flat.simplices = {{0, 1, 2, 4}};
  CHECK(input_error([&] { BackgroundMetricField<3>(flat, MetricMean::LogEuclidean); }).find("refers to node 4") !=
        std::string::npos);
}

TEST_CASE("background 3D: every truncation and random corruption of the files parses or throws InputError") {
  TempDir dir("background3d_fuzz");
  BackgroundMesh<3> mesh = perturbed_cube(1, 0.5, Vector3d::Zero(), 2);
  set_metrics(mesh, LogLinear());
  write_msh_background(mesh, dir / "good.msh", 6);
  write_meshb_background(mesh, dir / "good.mesh", dir / "good.sol");
  test::check_background_files_fuzz(
      dir, [](const fs::path& p) { read_background_msh<3>(p); },
      [](const fs::path& m, const fs::path& s) { read_background_meshb<3>(m, s); });
}

TEST_CASE("background 3D: a sphere meshed through a configuration with a background metric") {
  // Background: the cube [-2, 2]^3 in 8^3 cubes of six tetrahedra, with the isotropic size
  // h(x) = h0 exp(a . x). log M = -2 log h I is linear in x, so the log-Euclidean interpolation
  // of the vertex metrics is M(x) itself. On the unit sphere, a triangle of side h covers
  // sqrt(3)/4 h^2, so the surface has about
  //   (4 / sqrt(3)) \int_S h^-2 dA = (4 / sqrt(3)) (4 pi / h0^2) sinh(2 |a|) / (2 |a|)
  // triangles (the integral of e^{-2 a.x} over the unit sphere is 4 pi sinh(2|a|) / (2|a|)).
  const double h0 = 0.25;
  const Vector3d a(0.3, -0.2, 0.1);
  BackgroundMesh<3> mesh = perturbed_cube(8, 0.5, Vector3d(-2, -2, -2), 5);
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    mesh.metrics[i] = Metric<3>::isotropic(h0 * std::exp(a.dot(mesh.nodes[i])));
  const TempDir d("background3d_cli");
  write_msh_background(mesh, d / "bg.msh", 9);
  write_meshb_background(mesh, d / "bg.mesh", d / "bg.sol");
  const std::string head = "name: bg\norder: 2\ngeometry: {type: sphere}\noutput: {formats: [msh, report]}\n";
  write_text(d / "msh.yaml", head + "metric: {type: background, file: bg.msh}\n");
  write_text(d / "meshb.yaml", head + "metric: {type: background, file: bg.mesh, sol: bg.sol, mean: log_euclidean}\n");
  for (const char* run : {"msh", "meshb"}) {
    const test::PlafResult r = test::run_plaf(
        std::string("run ") + (d / (std::string(run) + ".yaml")).string() + " --out " + (d / run).string(), d);
    INFO(run << ": " << r.err);
    REQUIRE(r.code == 0);
  }
  // The same metric at the same nodes: the same surface, bit for bit.
  CHECK(read_text(d / "msh" / "bg.msh") == read_text(d / "meshb" / "bg.msh"));
  const std::string report = read_text(d / "msh" / "bg.report.json");
  const auto number = [&](const std::string& key, std::size_t from) {
    const std::size_t at = report.find("\"" + key + "\": ", from);
    return at == std::string::npos ? -1.0 : std::strtod(report.c_str() + at + key.size() + 4, nullptr);
  };
  const double expected = 4 / std::sqrt(3.0) * 4 * M_PI / (h0 * h0) * std::sinh(2 * a.norm()) / (2 * a.norm());
  const double triangles = number("triangles", report.find("\"surface\": {"));
  INFO("triangles ", triangles, ", expected about ", expected);
  CHECK(triangles >= expected / 1.5);
  CHECK(triangles <= expected * 1.5);
  CHECK(number("unit_fraction", report.find("\"metric\": {")) >= 0.9);

  // The wrong file: a 2D background in a 3D run is one line naming the file and the line, exit 1.
  const std::string flat =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n"
      "$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n";
  write_text(d / "flat.msh",
             flat + "$NodeData\n1\n\"m\"\n1\n0\n3\n0\n4\n3\n1 1 0 0 1\n2 1 0 0 1\n3 1 0 0 1\n$EndNodeData\n");
  write_text(d / "flat.yaml", head + "metric: {type: background, file: flat.msh}\n");
  const test::PlafResult r = test::run_plaf("run " + (d / "flat.yaml").string() + " --out " + (d / "flat").string(), d);
  CHECK(r.code == 1);
  CHECK_MESSAGE(r.err.find((d / "flat.msh").string() + ":14: the background mesh is 2D; a 3D run needs a 3D "
                                                       "background mesh") != std::string::npos,
                r.err);
}
