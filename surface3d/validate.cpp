// SPDX-License-Identifier: MIT
// Validation of a triangle soup (the seven steps of validate.h). Everything up to the
// orientation fix works on the soup's index triples, because OpenMesh refuses non-manifold and
// inconsistently oriented faces; the half-edge surface is built only once the soup is known to be
// an oriented manifold. All steps are O(n log n): edges are found by sorting, fans and boundary
// loops by union-find, components by breadth-first search, and the nesting and self-intersection
// tests use the bounding-box tree.
#include "surface3d/validate.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "modules/geometry/aabb_tree.h"
#include "modules/base/error.h"
#include "modules/geometry/predicates.h"

namespace plaf {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Tri = std::array<int, 3>;

namespace {

// A component whose |volume| is below this x (its bounding-box diagonal)^3 is flat (a sheet
// folded onto itself): far below any real body (a 1 % thick plate has about 1e-3) and far above
// the rounding of the volume sum (about 1e-16 per triangle).
constexpr double kZeroVolumeRel = 1e-9;
// A plane normal component below this counts as zero when choosing a ray parallel to the
// symmetry planes.
constexpr double kParallelTol = 1e-12;

std::string fmt_point(const Vector3d& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", p.x(), p.y(), p.z());
  return buf;
}

std::string fmt_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

std::string plural(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}
std::string plural(std::size_t n, const std::string& one) {
  return plural(n, one, one + "s");
}

std::size_t idx(int i) {
  return static_cast<std::size_t>(i);
}

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int x) {
    while (parent_[idx(x)] != x) {
      parent_[idx(x)] = parent_[idx(parent_[idx(x)])];  // path halving
      x = parent_[idx(x)];
    }
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[idx(std::max(a, b))] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

// The working soup: triangles (in the input's order, possibly flipped) with their input index.
struct Work {
  const std::vector<Vector3d>* points = nullptr;
  std::vector<Tri> tris;
  std::vector<int> input_index;
  const Vector3d& p(int v) const { return (*points)[idx(v)]; }
  Vector3d centroid(int t) const {
    const Tri& x = tris[idx(t)];
    return (p(x[0]) + p(x[1]) + p(x[2])) / 3;
  }
};

// Edge-to-edge adjacency: neighbor[3 t + k] is 3 u + m when edge k of triangle t (from corner k
// to corner k + 1) is edge m of triangle u, -1 on a boundary. Returns the edges used more than
// twice (as the first use of each, 3 t + k).
std::vector<int> build_adjacency(const std::vector<Tri>& tris, std::vector<int>& neighbor) {
  struct Use {
    int a, b, slot;
  };
  std::vector<Use> uses;
  uses.reserve(3 * tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tris[t][idx(k)], b = tris[t][idx((k + 1) % 3)];
      uses.push_back({std::min(a, b), std::max(a, b), static_cast<int>(3 * t) + k});
    }
  std::sort(uses.begin(), uses.end(),
            [](const Use& x, const Use& y) { return std::tie(x.a, x.b, x.slot) < std::tie(y.a, y.b, y.slot); });
  neighbor.assign(uses.size(), -1);
  std::vector<int> non_manifold;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].a == uses[i].a && uses[j].b == uses[i].b) ++j;
    if (j - i == 2) {
      neighbor[idx(uses[i].slot)] = uses[i + 1].slot;
      neighbor[idx(uses[i + 1].slot)] = uses[i].slot;
    } else if (j - i > 2) {
      non_manifold.push_back(uses[i].slot);
    }
    i = j;
  }
  return non_manifold;
}

// Three distinct points are collinear iff all three coordinate projections are (exactly).
bool collinear(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (sign_orient2d({a[i], a[j]}, {b[i], b[j]}, {c[i], c[j]}) != 0) return false;
  }
  return true;
}

// A coordinate plane on which triangle abc projects without degenerating (exactly), as the two
// kept axes; {-1, -1} for a degenerate triangle.
std::pair<int, int> projection_axes(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (sign_orient2d({a[i], a[j]}, {b[i], b[j]}, {c[i], c[j]}) != 0) return {i, j};
  }
  return {-1, -1};
}

int side_2d(const std::pair<int, int>& ax, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  return sign_orient2d({a[ax.first], a[ax.second]}, {b[ax.first], b[ax.second]}, {c[ax.first], c[ax.second]});
}

// The closed segment pq meets the closed non-degenerate triangle abc (exact). Written out instead
// of triangles_intersect on the degenerate triangle (p, q, q), whose exactly zero projections
// always fall through to the slow exact stage; this test is the bulk of step 7.
bool segment_meets_triangle(const Vector3d& p, const Vector3d& q, const Vector3d& a, const Vector3d& b,
                            const Vector3d& c) {
  const int sp = sign_orient3d(a, b, c, p), sq = sign_orient3d(a, b, c, q);
  if (sp == sq && sp != 0) return false;
  if (sp != 0 || sq != 0) {
    // pq meets the plane at one point, inside the closed triangle iff the line pq passes on no
    // two different sides of the triangle's edges.
    const int s0 = sign_orient3d(p, q, a, b), s1 = sign_orient3d(p, q, b, c), s2 = sign_orient3d(p, q, c, a);
    return !((s0 > 0 || s1 > 0 || s2 > 0) && (s0 < 0 || s1 < 0 || s2 < 0));
  }
  // Coplanar: in a projection where the triangle keeps its area, an endpoint inside or an edge
  // crossed.
  const auto ax = projection_axes(a, b, c);
  if (ax.first < 0) return false;
  auto pr = [&](const Vector3d& x) { return Vector2d(x[ax.first], x[ax.second]); };
  const Vector2d p2 = pr(p), q2 = pr(q), a2 = pr(a), b2 = pr(b), c2 = pr(c);
  const int o = sign_orient2d(a2, b2, c2);
  auto inside = [&](const Vector2d& x) {
    return sign_orient2d(a2, b2, x) * o >= 0 && sign_orient2d(b2, c2, x) * o >= 0 && sign_orient2d(c2, a2, x) * o >= 0;
  };
  return inside(p2) || inside(q2) || segments_intersect(p2, q2, a2, b2) || segments_intersect(p2, q2, b2, c2) ||
         segments_intersect(p2, q2, c2, a2);
}

// A point where the closed triangles s and t meet (approximate, for the message): where an edge of
// one crosses the other, else the first's centroid.
Vector3d meeting_point(const std::array<Vector3d, 3>& s, const std::array<Vector3d, 3>& t) {
  for (int side = 0; side < 2; ++side) {
    const auto& e = side == 0 ? s : t;
    const auto& f = side == 0 ? t : s;
    const Vector3d n = (f[1] - f[0]).cross(f[2] - f[0]);
    for (int k = 0; k < 3; ++k) {
      const Vector3d& a = e[idx(k)];
      const Vector3d& b = e[idx((k + 1) % 3)];
      if (!segment_meets_triangle(a, b, f[0], f[1], f[2])) continue;
      const double da = n.dot(a - f[0]), db = n.dot(b - f[0]);
      if (da != db) return a + std::clamp(da / (da - db), 0.0, 1.0) * (b - a);
      return closest_point_on_triangle((a + b) / 2, f[0], f[1], f[2]);
    }
  }
  return (s[0] + s[1] + s[2]) / 3;
}

// Whether two triangles of a surface intersect beyond what they share (validate.h, step 7).
bool pair_intersects(const std::vector<Vector3d>& pts, const Tri& x, const Tri& y) {
  const std::array<Vector3d, 3> s = {pts[idx(x[0])], pts[idx(x[1])], pts[idx(x[2])]};
  const std::array<Vector3d, 3> t = {pts[idx(y[0])], pts[idx(y[1])], pts[idx(y[2])]};
  int shared = 0;
  std::array<int, 3> in_y{};  // for each corner of x, its corner in y or -1
  for (int i = 0; i < 3; ++i) {
    in_y[idx(i)] = -1;
    for (int j = 0; j < 3; ++j)
      if (x[idx(i)] == y[idx(j)]) in_y[idx(i)] = j;
    if (in_y[idx(i)] >= 0) ++shared;
  }
  if (shared == 0) return triangles_intersect(s.data(), t.data());
  if (shared >= 2) {
    // Sharing an edge (u, v): apart from it they meet only when folded flat onto each other, i.e.
    // coplanar with the far vertices on the same side of the edge.
    int far_x = 0;
    while (in_y[idx(far_x)] >= 0) ++far_x;
    int far_y = 0;
    while (far_y < 3 && (y[idx(far_y)] == x[0] || y[idx(far_y)] == x[1] || y[idx(far_y)] == x[2])) ++far_y;
    if (shared == 3 || far_y == 3) return true;  // the same triangle twice
    const Vector3d& u = s[idx((far_x + 1) % 3)];
    const Vector3d& v = s[idx((far_x + 2) % 3)];
    const Vector3d& w1 = s[idx(far_x)];
    const Vector3d& w2 = t[idx(far_y)];
    if (sign_orient3d(u, v, w1, w2) != 0) return false;
    const auto ax = projection_axes(u, v, w1);
    if (ax.first < 0) return true;  // degenerate triangles are refused before; be safe
    return side_2d(ax, u, v, w1) == side_2d(ax, u, v, w2);
  }
  // Sharing one vertex: beyond it they meet iff the edge opposite the shared vertex in one meets
  // the other (their intersection is convex, contains the shared vertex, and any segment from it
  // inside both leaves the smaller of the two through its opposite edge).
  int cx = 0;
  while (in_y[idx(cx)] < 0) ++cx;
  const int cy = in_y[idx(cx)];
  return segment_meets_triangle(s[idx((cx + 1) % 3)], s[idx((cx + 2) % 3)], t[0], t[1], t[2]) ||
         segment_meets_triangle(t[idx((cy + 1) % 3)], t[idx((cy + 2) % 3)], s[0], s[1], s[2]);
}

struct IntersectionCount {
  std::size_t count = 0;
  std::size_t tested = 0;
  int first_a = -1, first_b = -1;  // positions in the triangle list, first_a < first_b
  Vector3d point = Vector3d::Zero();
};

// Counts the intersecting pairs among tris (alive[t] != 0, or all when alive is empty); the first
// reported is the pair smallest by (key[a], key[b]).
IntersectionCount self_intersections(const std::vector<Vector3d>& pts, const std::vector<Tri>& tris,
                                     const TriangleTree& tree, const std::vector<char>& alive,
                                     const std::vector<int>& key) {
  IntersectionCount r;
  const std::vector<std::pair<int, int>> pairs = tree.overlapping_pairs();
  std::pair<int, int> best_key(-1, -1);
  for (const auto& [a, b] : pairs) {
    if (!alive.empty() && (!alive[idx(a)] || !alive[idx(b)])) continue;
    ++r.tested;
    if (!pair_intersects(pts, tris[idx(a)], tris[idx(b)])) continue;
    ++r.count;
    std::pair<int, int> k(key[idx(a)], key[idx(b)]);
    if (k.first > k.second) std::swap(k.first, k.second);
    if (best_key.first < 0 || k < best_key) {
      best_key = k;
      r.first_a = key[idx(a)] <= key[idx(b)] ? a : b;
      r.first_b = key[idx(a)] <= key[idx(b)] ? b : a;
    }
  }
  if (r.count > 0) r.point = meeting_point(tree.triangle(r.first_a), tree.triangle(r.first_b));
  return r;
}

// Ray parity along +axis from p against triangle abc: 1 crossed, 0 not, -1 degenerate (the ray
// grazes an edge or a vertex, or p lies on the triangle); exact.
int ray_crosses(const Vector3d& p, const Vector3d& far, int axis, const Vector3d& a, const Vector3d& b,
                const Vector3d& c) {
  const int s_p = sign_orient3d(a, b, c, p), s_far = sign_orient3d(a, b, c, far);
  if (s_p == s_far && s_p != 0) return 0;
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  const Vector2d q(p[i], p[j]), a2(a[i], a[j]), b2(b[i], b[j]), c2(c[i], c[j]);
  const int s0 = sign_orient2d(a2, b2, q), s1 = sign_orient2d(b2, c2, q), s2 = sign_orient2d(c2, a2, q);
  const bool pos = s0 > 0 || s1 > 0 || s2 > 0, neg = s0 < 0 || s1 < 0 || s2 < 0;
  if (pos && neg) return 0;
  if (s0 == 0 || s1 == 0 || s2 == 0 || s_p == 0) return -1;
  return 1;
}

}  // namespace

TriSurface validate_surface(const TriangleSoup& soup, const SurfaceCheckOptions& options, SurfaceCheckReport* report) {
  SurfaceCheckReport local;
  SurfaceCheckReport& rep = report ? *report : local;
  rep = SurfaceCheckReport{};
  rep.input_triangles = soup.triangles.size();
  const std::string& src = soup.source;
  const std::vector<Vector3d>& pts = soup.points;

  // 0. The soup must at least be readable: indices in range, finite points.
  for (std::size_t t = 0; t < soup.triangles.size(); ++t)
    for (const int v : soup.triangles[t])
      if (v < 0 || idx(v) >= pts.size())
        throw InputError(src + ": triangle " + std::to_string(t) + " refers to point " + std::to_string(v) +
                         " but there are " + plural(pts.size(), "point"));
  Eigen::AlignedBox3d bbox;
  for (const auto& tri : soup.triangles)
    for (const int v : tri) {
      const Vector3d& x = pts[idx(v)];
      if (!x.allFinite())
        throw InputError(src + ": point " + std::to_string(v) + " has a non-finite coordinate " + fmt_point(x));
      bbox.extend(x);
    }
  if (soup.triangles.empty()) throw InputError(src + ": the surface has no triangles");
  const double diag = bbox.diagonal().norm();

  Work w;
  w.points = &pts;

  // 1. Degenerate triangles.
  std::size_t zero_area = 0;
  std::size_t first_zero = 0, first_repeated = 0;
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    const Tri& x = soup.triangles[t];
    if (x[0] == x[1] || x[1] == x[2] || x[2] == x[0]) {
      if (rep.dropped_degenerate++ == 0) first_repeated = t;
      continue;
    }
    if (collinear(pts[idx(x[0])], pts[idx(x[1])], pts[idx(x[2])])) {
      if (zero_area++ == 0) first_zero = t;
      continue;
    }
    w.tris.push_back(x);
    w.input_index.push_back(static_cast<int>(t));
  }
  if (zero_area > 0) {
    const Tri& x = soup.triangles[first_zero];
    throw InputError(src + ": " + plural(zero_area, "triangle") +
                     " with zero area (three distinct collinear points); first: triangle " +
                     std::to_string(first_zero) + " at " +
                     fmt_point((pts[idx(x[0])] + pts[idx(x[1])] + pts[idx(x[2])]) / 3));
  }
  if (rep.dropped_degenerate > 0)
    rep.repairs.push_back(src + ": dropped " + plural(rep.dropped_degenerate, "triangle") +
                          " with a repeated vertex (first: triangle " + std::to_string(first_repeated) + ")");

  // 2. Duplicate triangles: sort by the sorted vertex triple, keep the first of each run.
  {
    std::vector<std::pair<Tri, int>> keyed;
    keyed.reserve(w.tris.size());
    for (std::size_t i = 0; i < w.tris.size(); ++i) {
      Tri k = w.tris[i];
      std::sort(k.begin(), k.end());
      keyed.emplace_back(k, static_cast<int>(i));
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<char> keep(w.tris.size(), 1);
    int first_dup = -1, first_original = -1;
    std::size_t run = 0;  // the first (kept) entry of the current run of equal keys
    for (std::size_t i = 1; i < keyed.size(); ++i) {
      if (keyed[i].first != keyed[run].first) {
        run = i;
        continue;
      }
      keep[idx(keyed[i].second)] = 0;
      ++rep.dropped_duplicate;
      const int dup = w.input_index[idx(keyed[i].second)];
      if (first_dup < 0 || dup < first_dup) {
        first_dup = dup;
        first_original = w.input_index[idx(keyed[run].second)];
      }
    }
    if (rep.dropped_duplicate > 0) {
      std::size_t n = 0;
      for (std::size_t i = 0; i < w.tris.size(); ++i)
        if (keep[i]) {
          w.tris[n] = w.tris[i];
          w.input_index[n++] = w.input_index[i];
        }
      w.tris.resize(n);
      w.input_index.resize(n);
      rep.repairs.push_back(src + ": dropped " + plural(rep.dropped_duplicate, "duplicate triangle") +
                            " (first: triangle " + std::to_string(first_dup) + ", a copy of triangle " +
                            std::to_string(first_original) + ")");
    }
  }
  const std::size_t n_tris = w.tris.size();
  if (n_tris == 0) throw InputError(src + ": no triangles left after dropping the degenerate ones");

  // 3. Non-manifold edges, then non-manifold vertices (more than one fan of triangles).
  std::vector<int> neighbor;
  {
    const std::vector<int> bad_edges = build_adjacency(w.tris, neighbor);
    if (!bad_edges.empty()) {
      const int slot = bad_edges.front();
      const Tri& x = w.tris[idx(slot / 3)];
      const Vector3d& a = pts[idx(x[idx(slot % 3)])];
      const Vector3d& b = pts[idx(x[idx((slot + 1) % 3)])];
      throw InputError(src + ": " + plural(bad_edges.size(), "non-manifold edge") +
                       " (used by more than two triangles); first: edge " + fmt_point(a) + " - " + fmt_point(b) +
                       " of triangle " + std::to_string(w.input_index[idx(slot / 3)]));
    }
    // Corners 3 t + k; two triangles across an edge put their corners at both ends in one fan.
    UnionFind fans(3 * n_tris);
    for (std::size_t s = 0; s < neighbor.size(); ++s) {
      const int o = neighbor[s];
      if (o < static_cast<int>(s)) continue;  // boundary, or done from the other side
      const int t = static_cast<int>(s / 3), u = o / 3;
      const Tri& x = w.tris[idx(t)];
      const Tri& y = w.tris[idx(u)];
      for (const int v : {x[s % 3], x[(s + 1) % 3]}) {
        int kx = 0, ky = 0;
        while (x[idx(kx)] != v) ++kx;
        while (y[idx(ky)] != v) ++ky;
        fans.unite(3 * t + kx, 3 * u + ky);
      }
    }
    std::vector<int> fan_of(pts.size(), -1);
    std::vector<char> counted(pts.size(), 0);
    std::size_t bad_vertices = 0;
    int first_bad = -1;
    for (std::size_t c = 0; c < 3 * n_tris; ++c) {
      const int v = w.tris[c / 3][c % 3];
      const int root = fans.find(static_cast<int>(c));
      if (fan_of[idx(v)] < 0) {
        fan_of[idx(v)] = root;
      } else if (fan_of[idx(v)] != root && !counted[idx(v)]) {
        counted[idx(v)] = 1;
        if (bad_vertices++ == 0) first_bad = v;
      }
    }
    if (bad_vertices > 0)
      throw InputError(src + ": " + plural(bad_vertices, "non-manifold vertex", "non-manifold vertices") +
                       " (triangles around it form more than one fan); first: point " + std::to_string(first_bad) +
                       " at " + fmt_point(pts[idx(first_bad)]));
  }

  // 4. Orientation: breadth-first over each component from its first triangle; a neighbour that
  // runs the shared edge the same way must be flipped relative to its parent.
  std::vector<int> comp(n_tris, -1);
  std::vector<std::vector<int>> comp_tris;
  {
    std::vector<char> flip(n_tris, 0);
    std::vector<int> queue;
    for (std::size_t start = 0; start < n_tris; ++start) {
      if (comp[start] >= 0) continue;
      const int c = static_cast<int>(comp_tris.size());
      comp_tris.emplace_back();
      comp[start] = c;
      queue.assign(1, static_cast<int>(start));
      for (std::size_t q = 0; q < queue.size(); ++q) {
        const int t = queue[q];
        comp_tris.back().push_back(t);
        for (int k = 0; k < 3; ++k) {
          const int o = neighbor[idx(3 * t + k)];
          if (o < 0) continue;
          const int u = o / 3;
          const bool same_way = w.tris[idx(t)][idx(k)] == w.tris[idx(u)][idx(o % 3)];
          const char want = static_cast<char>(flip[idx(t)] ^ (same_way ? 1 : 0));
          if (comp[idx(u)] < 0) {
            comp[idx(u)] = c;
            flip[idx(u)] = want;
            queue.push_back(u);
          } else if (flip[idx(u)] != want) {
            const Vector3d& a = pts[idx(w.tris[idx(t)][idx(k)])];
            const Vector3d& b = pts[idx(w.tris[idx(t)][idx((k + 1) % 3)])];
            throw InputError(src + ": a component (with triangle " + std::to_string(w.input_index[start]) +
                             ") is non-orientable; the orientation conflict closes at edge " + fmt_point(a) + " - " +
                             fmt_point(b));
          }
        }
      }
    }
    int first_flipped = -1;
    for (std::size_t t = 0; t < n_tris; ++t)
      if (flip[t]) {
        std::swap(w.tris[t][1], w.tris[t][2]);
        if (rep.flipped_inconsistent++ == 0) first_flipped = w.input_index[t];
      }
    if (rep.flipped_inconsistent > 0) {
      rep.repairs.push_back(src + ": flipped " + plural(rep.flipped_inconsistent, "triangle") +
                            " to agree with the orientation of their component (first: triangle " +
                            std::to_string(first_flipped) + ")");
      build_adjacency(w.tris, neighbor);
    }
  }
  const std::size_t n_comps = comp_tris.size();

  // 5. Open boundaries: boundary edges grouped into loops (each boundary vertex of a manifold
  // surface has one boundary edge in and one out); every edge must lie on a symmetry plane.
  std::vector<SymmetryPlane> planes = options.symmetry_planes;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const double len = planes[i].normal.norm();
    if (!(len > 0) || !std::isfinite(len) || !std::isfinite(planes[i].offset))
      throw InputError(src + ": symmetry plane " + std::to_string(i) + " has a zero or non-finite normal");
    planes[i].normal /= len;
    planes[i].offset /= len;
  }
  const double plane_tol = options.plane_tol_rel * diag;
  auto on_plane = [&](std::size_t i, const Vector3d& x) {
    return std::abs(planes[i].normal.dot(x) - planes[i].offset) <= plane_tol;
  };
  std::vector<int> boundary_slots;  // 3 t + k, edge k of t on the boundary
  for (std::size_t s = 0; s < neighbor.size(); ++s)
    if (neighbor[s] < 0) boundary_slots.push_back(static_cast<int>(s));
  auto slot_from = [&](int s) -> int { return w.tris[idx(s / 3)][idx(s % 3)]; };
  auto slot_to = [&](int s) -> int { return w.tris[idx(s / 3)][idx((s + 1) % 3)]; };
  // Per loop (indexed by its union-find root): the planes its edges lie on.
  std::vector<int> loop_of_slot(boundary_slots.size());
  std::vector<std::vector<char>> loop_planes;
  std::vector<int> loop_comp;
  {
    UnionFind loops(pts.size());
    for (const int s : boundary_slots) loops.unite(slot_from(s), slot_to(s));
    std::vector<int> loop_id(pts.size(), -1);
    std::vector<std::size_t> loop_edges;
    std::vector<int> loop_bad_slot;
    for (std::size_t i = 0; i < boundary_slots.size(); ++i) {
      const int s = boundary_slots[i];
      const int root = loops.find(slot_from(s));
      if (loop_id[idx(root)] < 0) {
        loop_id[idx(root)] = static_cast<int>(loop_edges.size());
        loop_edges.push_back(0);
        loop_bad_slot.push_back(-1);
        loop_planes.emplace_back(planes.size(), 0);
        loop_comp.push_back(comp[idx(s / 3)]);
      }
      const int l = loop_id[idx(root)];
      loop_of_slot[i] = l;
      ++loop_edges[idx(l)];
      bool on_any = false;
      for (std::size_t p = 0; p < planes.size(); ++p)
        if (on_plane(p, pts[idx(slot_from(s))]) && on_plane(p, pts[idx(slot_to(s))])) {
          loop_planes[idx(l)][p] = 1;
          on_any = true;
        }
      if (!on_any && loop_bad_slot[idx(l)] < 0) loop_bad_slot[idx(l)] = s;
    }
    std::size_t open = 0;
    int first_open = -1;
    for (std::size_t l = 0; l < loop_edges.size(); ++l)
      if (loop_bad_slot[l] >= 0 && open++ == 0) first_open = static_cast<int>(l);
    if (open > 0)
      throw InputError(src + ": " + plural(open, "open boundary loop") + " not on a symmetry plane; first: a loop of " +
                       plural(loop_edges[idx(first_open)], "edge") + " through " +
                       fmt_point(pts[idx(slot_from(loop_bad_slot[idx(first_open)]))]));
    rep.boundary_loops = loop_edges.size();
    rep.symmetry_edges = boundary_slots.size();
  }

  // 6. Volumes per component, each boundary loop closed by a fan from an apex on the planes it
  // lies on (the caps then lie in the planes, so the half model's volume is the mirrored body's
  // half and its sign is right); terms are taken about the component's first vertex so the sum
  // does not lose digits far from the origin.
  std::vector<Vector3d> loop_apex(loop_planes.size(), Vector3d::Zero());
  std::vector<double> loop_size(loop_planes.size(), 0.0);
  for (std::size_t i = 0; i < boundary_slots.size(); ++i) {
    loop_apex[idx(loop_of_slot[i])] += pts[idx(slot_from(boundary_slots[i]))];
    ++loop_size[idx(loop_of_slot[i])];
  }
  for (std::size_t l = 0; l < loop_planes.size(); ++l) {
    const Vector3d centre = loop_apex[l] / loop_size[l];
    std::vector<std::size_t> used;
    for (std::size_t p = 0; p < planes.size(); ++p)
      if (loop_planes[l][p]) used.push_back(p);
    if (used.empty()) {
      loop_apex[l] = centre;
      continue;
    }
    Eigen::MatrixXd n(static_cast<Eigen::Index>(used.size()), 3);
    Eigen::VectorXd r(static_cast<Eigen::Index>(used.size()));
    for (std::size_t i = 0; i < used.size(); ++i) {
      n.row(static_cast<Eigen::Index>(i)) = planes[used[i]].normal.transpose();
      r(static_cast<Eigen::Index>(i)) = planes[used[i]].offset - planes[used[i]].normal.dot(centre);
    }
    // The point of the planes' intersection nearest the loop (least squares, minimal norm).
    const Eigen::Vector3d shift = n.jacobiSvd(Eigen::ComputeFullU | Eigen::ComputeFullV).solve(r);
    loop_apex[l] = centre + shift;
  }
  std::vector<double> comp_volume(n_comps, 0.0);
  {
    for (std::size_t c = 0; c < n_comps; ++c) {
      const Vector3d o = pts[idx(w.tris[idx(comp_tris[c].front())][0])];
      double v6 = 0;
      for (const int t : comp_tris[c]) {
        const Tri& x = w.tris[idx(t)];
        v6 += (pts[idx(x[0])] - o).dot((pts[idx(x[1])] - o).cross(pts[idx(x[2])] - o));
      }
      comp_volume[c] = v6;
    }
    for (std::size_t i = 0; i < boundary_slots.size(); ++i) {
      const int s = boundary_slots[i];
      const int c = comp[idx(s / 3)];
      const Vector3d o = pts[idx(w.tris[idx(comp_tris[idx(c)].front())][0])];
      // The cap triangle (to, from, apex) runs the edge the other way, as a neighbour would.
      const Vector3d& q = loop_apex[idx(loop_of_slot[i])];
      comp_volume[idx(c)] += (pts[idx(slot_to(s))] - o).dot((pts[idx(slot_from(s))] - o).cross(q - o));
    }
    for (double& v : comp_volume) v /= 6;
  }
  std::vector<Eigen::AlignedBox3d> comp_box(n_comps);
  for (std::size_t t = 0; t < n_tris; ++t)
    for (const int v : w.tris[t]) comp_box[idx(comp[t])].extend(pts[idx(v)]);
  std::vector<char> comp_open(n_comps, 0);
  for (const int c : loop_comp) comp_open[idx(c)] = 1;
  int first_inward = -1;
  std::size_t inward_comps = 0;
  for (std::size_t c = 0; c < n_comps; ++c) {
    const double d = comp_box[c].diagonal().norm();
    if (!(std::abs(comp_volume[c]) > kZeroVolumeRel * d * d * d))
      throw InputError(src + ": a component of " + plural(comp_tris[c].size(), "triangle") +
                       " encloses (near) zero volume (" + fmt_number(comp_volume[c]) + "), e.g. triangle " +
                       std::to_string(w.input_index[idx(comp_tris[c].front())]) + " at " +
                       fmt_point(w.centroid(comp_tris[c].front())));
    if (comp_volume[c] < 0) {
      for (const int t : comp_tris[c]) std::swap(w.tris[idx(t)][1], w.tris[idx(t)][2]);
      rep.flipped_inward += comp_tris[c].size();
      comp_volume[c] = -comp_volume[c];
      if (inward_comps++ == 0) first_inward = w.input_index[idx(comp_tris[c].front())];
    }
  }
  if (inward_comps > 0)
    rep.repairs.push_back(src + ": flipped " + plural(inward_comps, "inward component") + " (" +
                          plural(rep.flipped_inward, "triangle") + "; first: the one with triangle " +
                          std::to_string(first_inward) + ")");

  const TriangleTree tree(pts, w.tris);
  std::vector<char> alive(n_tris, 1);
  if (n_comps > 1) {
    // Nesting by ray parity from a point inside a triangle of each component. The ray runs
    // parallel to all symmetry planes (if an axis allows), so it never crosses the planes that
    // close the open components; with no such axis, open components cannot contain others here.
    int axis = -1;
    for (int a = 0; a < 3 && axis < 0; ++a) {
      bool parallel = true;
      for (const auto& pl : planes) parallel = parallel && std::abs(pl.normal[a]) <= kParallelTol;
      if (parallel) axis = a;
    }
    const bool any_open = std::any_of(comp_open.begin(), comp_open.end(), [](char o) { return o != 0; });
    if (axis < 0) axis = 0;
    const bool open_can_contain = !any_open || std::all_of(planes.begin(), planes.end(), [&](const SymmetryPlane& pl) {
      return std::abs(pl.normal[axis]) <= kParallelTol;
    });
    std::vector<char> parity(n_comps, 0);
    std::vector<int> hits, touched;
    std::vector<int> inner_of(n_comps, -1);  // the component it lies in
    std::vector<Vector3d> inner_point(n_comps);
    for (std::size_t c = 0; c < n_comps; ++c) {
      const std::vector<int>& ct = comp_tris[c];
      constexpr int kTries = 8;
      for (int attempt = 0; attempt < kTries; ++attempt) {
        // Generic barycentric weights keep the start point off the other surfaces' edges.
        const Tri& x = w.tris[idx(ct[ct.size() * idx(attempt) / kTries])];
        const Vector3d p = 0.2137 * pts[idx(x[0])] + 0.3461 * pts[idx(x[1])] + 0.4402 * pts[idx(x[2])];
        Vector3d far = p;
        far[axis] = bbox.max()[axis] + diag + 1;
        hits.clear();
        tree.query(Eigen::AlignedBox3d(p.cwiseMin(far), p.cwiseMax(far)), hits);
        bool degenerate = false;
        for (const int t : hits) {
          const int b = comp[idx(t)];
          if (idx(b) == c || (comp_open[idx(b)] && !open_can_contain)) continue;
          const Tri& y = w.tris[idx(t)];
          const int r = ray_crosses(p, far, axis, pts[idx(y[0])], pts[idx(y[1])], pts[idx(y[2])]);
          if (r < 0) {
            degenerate = true;
            break;
          }
          if (r == 1) {
            if (!parity[idx(b)]) touched.push_back(b);
            parity[idx(b)] ^= 1;
          }
        }
        bool inside = false;
        for (const int b : touched) {
          if (parity[idx(b)] && !degenerate && !inside) {
            inside = true;
            inner_of[c] = b;
            inner_point[c] = p;
          }
          parity[idx(b)] = 0;
        }
        touched.clear();
        if (!degenerate) break;
      }
    }
    std::size_t nested = 0;
    int first_nested = -1;
    for (std::size_t c = 0; c < n_comps; ++c)
      if (inner_of[c] >= 0 && nested++ == 0) first_nested = static_cast<int>(c);
    if (nested > 0) {
      const std::size_t fc = idx(first_nested);
      const std::string what = plural(nested, "component") + " inside another; first: a component of " +
                               plural(comp_tris[fc].size(), "triangle") + " (with triangle " +
                               std::to_string(w.input_index[idx(comp_tris[fc].front())]) + ") at " +
                               fmt_point(inner_point[fc]) + " inside the component with triangle " +
                               std::to_string(w.input_index[idx(comp_tris[idx(inner_of[fc])].front())]);
      if (!options.drop_inner_components)
        throw InputError(src + ": " + what + " (set drop_inner_components to drop them)");
      for (std::size_t c = 0; c < n_comps; ++c)
        if (inner_of[c] >= 0) {
          for (const int t : comp_tris[c]) alive[idx(t)] = 0;
          rep.dropped_inner += comp_tris[c].size();
        }
      rep.repairs.push_back(src + ": dropped " + what + " (" + plural(rep.dropped_inner, "triangle") + ")");
    }
    for (std::size_t c = 0; c < n_comps; ++c)
      if (inner_of[c] < 0) ++rep.components;
  } else {
    rep.components = n_comps;
  }
  for (std::size_t c = 0; c < n_comps; ++c)
    if (alive[idx(comp_tris[c].front())]) rep.volume += comp_volume[c];

  // 7. Self-intersections.
  if (options.check_self_intersections) {
    const IntersectionCount si = self_intersections(pts, w.tris, tree, alive, w.input_index);
    rep.self_intersection_pairs_tested = si.tested;
    if (si.count > 0)
      throw InputError(src + ": " + plural(si.count, "self-intersecting triangle pair") + "; first: triangles " +
                       std::to_string(w.input_index[idx(si.first_a)]) + " and " +
                       std::to_string(w.input_index[idx(si.first_b)]) + " near " + fmt_point(si.point));
  }

  // The surface: the kept triangles on their used points only (no isolated vertices).
  TriangleSoup clean;
  clean.source = src;
  std::vector<int> new_index(pts.size(), -1);
  for (std::size_t t = 0; t < n_tris; ++t) {
    if (!alive[t]) continue;
    Tri y{};
    for (std::size_t k = 0; k < 3; ++k) {
      const int v = w.tris[t][k];
      if (new_index[idx(v)] < 0) {
        new_index[idx(v)] = static_cast<int>(clean.points.size());
        clean.points.push_back(pts[idx(v)]);
      }
      y[k] = new_index[idx(v)];
    }
    clean.triangles.push_back(y);
  }
  TriSurface s = surface_from_soup(clean);
  s.tags[0].name = options.wall_tag;
  rep.symmetry_edges = 0;
  int sym = -1;
  for (const auto e : s.mesh.edges()) {
    if (!s.mesh.is_boundary(e)) continue;
    if (sym < 0) sym = s.add_tag("symmetry", BoundaryKind::Symmetry);
    s.mesh.property(s.edge_tag, e) = sym;
    s.mesh.property(s.edge_feature, e) = EdgeFeature::Boundary;
    ++rep.symmetry_edges;
  }
  if (rep.dropped_inner > 0) {
    // Recount the loops of what is left.
    std::size_t loops = 0;
    for (std::size_t l = 0; l < loop_comp.size(); ++l)
      if (alive[idx(comp_tris[idx(loop_comp[l])].front())]) ++loops;
    rep.boundary_loops = loops;
  }
  rep.euler_characteristic = s.euler_characteristic();
  return s;
}

std::size_t count_self_intersections(const TriSurface& s, std::string* first) {
  std::vector<Vector3d> pts(s.mesh.n_vertices());
  for (const auto v : s.mesh.vertices()) pts[idx(v.idx())] = s.mesh.point(v);
  std::vector<Tri> tris;
  std::vector<int> face_id;
  for (const auto f : s.mesh.faces()) {
    const auto fv = s.face_vertices(f);
    tris.push_back({fv[0].idx(), fv[1].idx(), fv[2].idx()});
    face_id.push_back(f.idx());
  }
  const TriangleTree tree(pts, tris);
  const IntersectionCount si = self_intersections(pts, tris, tree, {}, face_id);
  if (first) {
    first->clear();
    if (si.count > 0)
      *first = "faces " + std::to_string(face_id[idx(si.first_a)]) + " and " +
               std::to_string(face_id[idx(si.first_b)]) + " near " + fmt_point(si.point);
  }
  return si.count;
}

}  // namespace plaf
