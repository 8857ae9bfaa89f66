// SPDX-License-Identifier: MIT
#include "modules/geometry/aabb_tree.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace plaf {
namespace {

using Eigen::Vector3d;

struct RandomTriangles {
  std::vector<Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
};

// n small triangles scattered in [0, scale]^3 (about a tenth of the box wide each), plus a few
// degenerate ones (a repeated point, collinear points).
RandomTriangles random_triangles(int n, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0), v(-0.08, 0.08);
  RandomTriangles r;
  for (int i = 0; i < n; ++i) {
    const Vector3d c(u(rng), u(rng), u(rng));
    const int k = static_cast<int>(r.points.size());
    r.points.push_back(scale * (c + Vector3d(v(rng), v(rng), v(rng))));
    r.points.push_back(scale * (c + Vector3d(v(rng), v(rng), v(rng))));
    if (i % 50 == 7)
      r.points.push_back(r.points[static_cast<std::size_t>(k)]);
    else if (i % 50 == 11)
      r.points.push_back((r.points[static_cast<std::size_t>(k)] + r.points[static_cast<std::size_t>(k + 1)]) / 2);
    else
      r.points.push_back(scale * (c + Vector3d(v(rng), v(rng), v(rng))));
    r.triangles.push_back({k, k + 1, k + 2});
  }
  return r;
}

Eigen::AlignedBox3d box_of(const std::array<Vector3d, 3>& t) {
  Eigen::AlignedBox3d b(t[0]);
  b.extend(t[1]);
  b.extend(t[2]);
  return b;
}

TEST_CASE("aabb_tree: closest point on a triangle is in it and beats every sampled point") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0), w(0.0, 1.0);
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(0.2, 0.9, 0.1);
  for (int trial = 0; trial < 300; ++trial) {
    const Vector3d p(2 * u(rng), 2 * u(rng), 2 * u(rng));
    Vector3d bary;
    const Vector3d q = closest_point_on_triangle(p, a, b, c, &bary);
    CHECK(bary.minCoeff() >= 0);
    CHECK(std::abs(bary.sum() - 1) < 1e-14);
    CHECK((bary[0] * a + bary[1] * b + bary[2] * c - q).norm() < 1e-14);
    const double d = (p - q).norm();
    for (int s = 0; s < 50; ++s) {
      double r1 = w(rng), r2 = w(rng);
      if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
      const Vector3d x = a + r1 * (b - a) + r2 * (c - a);
      CHECK(d <= (p - x).norm() + 1e-14);
    }
  }
  // Regions: above the face, beyond a vertex, beyond an edge.
  CHECK((closest_point_on_triangle({0.3, 0.2, 5}, a, b, Vector3d(0, 1, 0)) - Vector3d(0.3, 0.2, 0)).norm() < 1e-15);
  CHECK((closest_point_on_triangle({3, -1, 0}, a, b, Vector3d(0, 1, 0)) - b).norm() < 1e-15);
  CHECK((closest_point_on_triangle({0.5, -2, 1}, a, b, Vector3d(0, 1, 0)) - Vector3d(0.5, 0, 0)).norm() < 1e-15);
  // A degenerate triangle is its longest segment.
  Vector3d bary;
  const Vector3d q = closest_point_on_triangle({0.5, 1, 0}, a, b, Vector3d(2, 0, 0), &bary);
  CHECK((q - Vector3d(0.5, 0, 0)).norm() < 1e-15);
  CHECK(bary.minCoeff() >= 0);
  CHECK(closest_point_on_triangle({1, 1, 1}, a, a, a).norm() == 0);
}

TEST_CASE("aabb_tree: box queries, closest points and overlapping pairs match brute force") {
  for (const double scale : {1e-8, 1.0, 1e8}) {
    CAPTURE(scale);
    const RandomTriangles r = random_triangles(600, scale, 11);
    const TriangleTree tree(r.points, r.triangles);
    REQUIRE(tree.size() == r.triangles.size());
    const int n = static_cast<int>(tree.size());
    std::vector<Eigen::AlignedBox3d> boxes;
    for (int t = 0; t < n; ++t) boxes.push_back(box_of(tree.triangle(t)));

    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.2, 1.2), h(0.0, 0.2);
    for (int trial = 0; trial < 40; ++trial) {
      const Vector3d lo = scale * Vector3d(u(rng), u(rng), u(rng));
      const Eigen::AlignedBox3d q(lo, lo + scale * Vector3d(h(rng), h(rng), h(rng)));
      std::vector<int> got;
      tree.query(q, got);
      std::sort(got.begin(), got.end());
      std::vector<int> want;
      for (int t = 0; t < n; ++t)
        if (boxes[static_cast<std::size_t>(t)].intersects(q)) want.push_back(t);
      CHECK(got == want);
    }
    for (int trial = 0; trial < 200; ++trial) {
      const Vector3d p = scale * Vector3d(u(rng), u(rng), u(rng));
      const TriangleTree::Closest c = tree.closest(p);
      double best = std::numeric_limits<double>::infinity();
      for (int t = 0; t < n; ++t) {
        const auto& tri = tree.triangle(t);
        best = std::min(best, (closest_point_on_triangle(p, tri[0], tri[1], tri[2]) - p).squaredNorm());
      }
      REQUIRE(c.triangle >= 0);
      CHECK(c.distance2 == best);
      CHECK((c.point - p).squaredNorm() == c.distance2);
      const auto& tri = tree.triangle(c.triangle);
      const Vector3d from_bary = c.barycentric[0] * tri[0] + c.barycentric[1] * tri[1] + c.barycentric[2] * tri[2];
      CHECK((from_bary - c.point).norm() <= 1e-12 * scale);
    }
    std::vector<std::pair<int, int>> got = tree.overlapping_pairs();
    std::sort(got.begin(), got.end());
    std::vector<std::pair<int, int>> want;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        if (boxes[static_cast<std::size_t>(i)].intersects(boxes[static_cast<std::size_t>(j)])) want.emplace_back(i, j);
    CHECK(got.size() > 100);
    CHECK(got == want);
  }
}

TEST_CASE("aabb_tree: touching boxes count as overlapping, empty and single trees answer") {
  // Two triangles whose boxes share only the plane x = 1.
  const std::vector<Vector3d> pts = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0.5}, {2, 0, 0}, {2, 1, 0}};
  const TriangleTree tree(pts, {{0, 1, 2}, {3, 4, 5}});
  const auto pairs = tree.overlapping_pairs();
  REQUIRE(pairs.size() == 1);
  CHECK(pairs[0] == std::pair<int, int>(0, 1));

  const TriangleTree empty;
  CHECK(empty.size() == 0);
  CHECK(empty.closest({0, 0, 0}).triangle == -1);
  CHECK(empty.overlapping_pairs().empty());
  std::vector<int> out;
  empty.query(Eigen::AlignedBox3d(Vector3d(0, 0, 0), Vector3d(1, 1, 1)), out);
  CHECK(out.empty());

  const TriangleTree one(pts, {{0, 1, 2}});
  const auto c = one.closest({0.25, 0.25, 3});
  CHECK(c.triangle == 0);
  CHECK(c.distance2 == doctest::Approx(9));
  CHECK(one.overlapping_pairs().empty());
}

TEST_CASE("aabb_tree: first_hit finds the nearest triangle a ray meets, as a scan of every triangle does") {
  const RandomTriangles rt = random_triangles(600, 3.0, 11);
  const TriangleTree tree(rt.points, rt.triangles);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.5, 3.5), d(-1, 1);
  int hits = 0;
  for (int k = 0; k < 400; ++k) {
    const Vector3d o(u(rng), u(rng), u(rng));
    Vector3d dir(d(rng), d(rng), d(rng));
    if (k % 4 == 1) dir[k % 3] = 0;  // in a slab's plane: 0 * inf must not end the walk
    if (k % 4 == 3) dir = Vector3d::Unit(k % 3) * (k % 8 == 3 ? 1 : -1);
    const TriangleTree::Hit h = tree.first_hit(o, dir, 0, 10);
    // The scan: every triangle's hit by the same test on a one-triangle tree.
    double want = 10;
    int want_t = -1;
    for (std::size_t t = 0; t < rt.triangles.size(); ++t) {
      const TriangleTree one(rt.points, {rt.triangles[t]});
      const TriangleTree::Hit s = one.first_hit(o, dir, 0, 10);
      if (s.triangle == 0 && s.t <= want) {
        want = s.t;
        want_t = static_cast<int>(t);
      }
    }
    CHECK(h.triangle == want_t);
    CHECK(h.t == want);
    if (h.triangle >= 0) {
      ++hits;
      // The hit point lies on its triangle.
      const auto& tri = tree.triangle(h.triangle);
      const Vector3d x = o + h.t * dir;
      CHECK((closest_point_on_triangle(x, tri[0], tri[1], tri[2]) - x).norm() <= 1e-9);
    }
  }
  CHECK(hits > 50);

  // A unit square's two triangles at z = 1: a ray up from below meets them at t = 1 (t_min and
  // t_max bound the search), a ray beside the square meets nothing.
  const std::vector<Vector3d> sq = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const TriangleTree square(sq, {{0, 1, 2}, {0, 2, 3}});
  CHECK(square.first_hit({0.3, 0.6, 0}, {0, 0, 2}, 0, 10).t == doctest::Approx(0.5));
  CHECK(square.first_hit({0.3, 0.6, 0}, {0, 0, 1}, 0, 0.9).triangle == -1);
  CHECK(square.first_hit({0.3, 0.6, 0}, {0, 0, 1}, 0, 0.9).t == 0.9);
  CHECK(square.first_hit({0.3, 0.6, 1}, {0, 0, 1}, 1e-12, 10).triangle == -1);  // starts on it
  CHECK(square.first_hit({1.5, 0.5, 0}, {0, 0, 1}, 0, 10).triangle == -1);
  CHECK(TriangleTree().first_hit({0, 0, 0}, {1, 0, 0}, 0, 1).triangle == -1);
}

}  // namespace
}  // namespace plaf

namespace plaf {
namespace {

TEST_CASE("aabb_tree: a closest point does not depend on the queries before it") {
  // closest() starts from the thread's last answer on the same tree as a bound (aabb_tree.cpp):
  // the answer must be the same bit for bit whatever came before, ties included. A bent grid of
  // triangles sharing edges and vertices; queries above its vertices and edge midpoints (where
  // several triangles are equally close) and at random, asked in three orders and with queries
  // on another tree in between.
  RandomTriangles grid;
  const int n = 24;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = i / double(n), y = j / double(n);
      grid.points.emplace_back(x, y, 0.3 * std::sin(3 * x) * std::cos(2 * y));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j, b = a + n + 1;
      grid.triangles.push_back({a, b, b + 1});
      grid.triangles.push_back({a, b + 1, a + 1});
    }
  const TriangleTree tree(grid.points, grid.triangles);
  const RandomTriangles other_tris = random_triangles(200, 1.0, 3);
  const TriangleTree other(other_tris.points, other_tris.triangles);
  std::vector<Vector3d> queries;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.1, 1.1), h(-0.2, 0.2);
  for (const Vector3d& p : grid.points) queries.push_back(p + Vector3d(0, 0, 0.05));
  for (const auto& t : grid.triangles)
    queries.push_back(0.5 * (grid.points[static_cast<std::size_t>(t[0])] + grid.points[static_cast<std::size_t>(t[1])]) +
                      Vector3d(0, 0, h(rng)));
  for (int k = 0; k < 500; ++k) queries.emplace_back(u(rng), u(rng), h(rng));
  const auto answers = [&](const std::vector<std::size_t>& order, bool interleave) {
    std::vector<TriangleTree::Closest> out(queries.size());
    for (const std::size_t k : order) {
      if (interleave) (void)other.closest(queries[k]);
      out[k] = tree.closest(queries[k]);
    }
    return out;
  };
  std::vector<std::size_t> forward(queries.size());
  for (std::size_t k = 0; k < forward.size(); ++k) forward[k] = k;
  std::vector<std::size_t> backward(forward.rbegin(), forward.rend()), shuffled = forward;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const auto a = answers(forward, false), b = answers(backward, false), c = answers(shuffled, true);
  for (std::size_t k = 0; k < queries.size(); ++k) {
    CAPTURE(k);
    for (const auto* x : {&b[k], &c[k]}) {
      CHECK(x->triangle == a[k].triangle);
      CHECK(x->point == a[k].point);
      CHECK(x->barycentric == a[k].barycentric);
      CHECK(x->distance2 == a[k].distance2);
    }
  }
}

}  // namespace
}  // namespace plaf
