// SPDX-License-Identifier: MIT
// Untangling the fill's tetrahedra at a curved outer front (untangle3d.h).
#include "modules/mesh/untangle3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "modules/elements/lagrange.h"
#include "modules/elements/validity.h"
#include "modules/geometry/predicates.h"

namespace plaf {
inline namespace mesh {

namespace {

// The cells around a node, judged together: fewer invalid first, then the larger smallest
// certified min det J over each cell's fixed scale (judge, below).
struct BallQuality {
  std::size_t layers_invalid = 0;  // of the layers' cells (all valid before: a move may not trade one in)
  std::size_t invalid = 0;
  double worst = std::numeric_limits<double>::infinity();
  bool better_than(const BallQuality& o) const {
    if (layers_invalid != o.layers_invalid) return layers_invalid < o.layers_invalid;
    if (invalid != o.invalid) return invalid < o.invalid;
    return worst > o.worst + 1e-9 * std::max(1.0, std::abs(o.worst));
  }
};

constexpr int kSweeps = 30;
constexpr std::size_t kMaxDirections = 8;  // the largest neighbour displacements tried per node
constexpr int kHalvings = 6;               // the compass search's step halvings per node and sweep
constexpr int kMaxSteps = 24;              // ... and its steps in all (each tries 20 directions)
// The work in all, in certified cells: the search stops there (the quality stage then reports
// what is left). Measured on the published spot (h0 1e-5 L, Q2, 32 inverted fill cells): 1,194,310
// cells certified within the 2.1 s of its whole assembly, so the bound is a few seconds.
constexpr std::size_t kMaxCertified = 2000000;
// The last resort's region per inverted cell: the cells made straight in turn, at most (a region
// runs down layer columns to the wall). Measured on the published spot (h0 1e-5 L, TetGen fill):
// 259 cells made straight in all at Q2, 2,760 at Q3, where a bound of 512 per cell left 3 cells
// inverted. The work is small next to the sweeps' (the Q3 assembly 137 s with 512, 138 s).
constexpr std::size_t kMaxStraightened = 2048;

// The compass search's directions: the axes and the cube's face diagonals (the worst cell's
// bound is a max-min of smooth functions, whose ridges axis steps alone cannot climb), and an
// extra one if given.
std::vector<Eigen::Vector3d> compass_directions(const Eigen::Vector3d& extra) {
  std::vector<Eigen::Vector3d> e = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      for (double sj : {1.0, -1.0}) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        d[i] = 1;
        d[j] = sj;
        e.push_back(d.normalized());
      }
  if (extra.norm() > 0) e.push_back(extra.normalized());
  return e;
}

// From *best, steps of `step` along each direction both ways (trial(p) moves *best to p when p is
// better), the step halved when none helps: kHalvings halvings, kMaxSteps steps at most.
template <class Trial>
void compass_search(const std::vector<Eigen::Vector3d>& dirs, double step, double floor, const Eigen::Vector3d* best,
                    Trial trial) {
  for (int halvings = 0, steps = 0; halvings < kHalvings && steps < kMaxSteps && step > floor; ++steps) {
    const Eigen::Vector3d from = *best;
    for (const Eigen::Vector3d& e : dirs)
      for (double sign : {1.0, -1.0}) trial(from + sign * step * e);
    if (*best == from) {
      step *= 0.5;
      ++halvings;
    }
  }
}

// The linear (order-1) weights of each node of a (type, order) cell on its corners:
// w[node * corners + corner].
std::vector<double> corner_weights(CellType type, int order) {
  const LagrangeElement& el = lagrange_element(type, order);
  const LagrangeElement& lin = lagrange_element(type, 1);
  std::vector<double> w(static_cast<std::size_t>(el.size() * lin.size()));
  for (int j = 0; j < el.size(); ++j) {
    const std::array<double, 3> xi = el.ref_node(j);
    lin.eval(xi.data(), &w[static_cast<std::size_t>(j * lin.size())]);
  }
  return w;
}

}  // namespace

FillUntangling untangle_fill_3d(HybridMesh<3>& mesh, std::size_t block, std::size_t first_cell, UntangleMoves moves) {
  FillUntangling s;
  if (block >= mesh.cells.size()) return s;
  const CellBlock& b = mesh.cells[block];
  const int q = b.order;
  if (b.type != CellType::Tetrahedron || q < 2 || first_cell >= b.size()) return s;
  const int np = b.nodes_per_cell();
  const std::vector<double> weight = corner_weights(CellType::Tetrahedron, q);
  std::vector<Eigen::Vector3d>& x = mesh.nodes;
  auto at = [&](NodeId id) -> Eigen::Vector3d& { return x[static_cast<std::size_t>(id)]; };
  const std::size_t nc = b.size() - first_cell;
  auto cell = [&](std::size_t c) { return b.cell(first_cell + c); };  // a fill cell
  auto linear = [&](std::size_t c, int k) {
    const NodeId* n = cell(c);
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) p += weight[static_cast<std::size_t>(4 * k + i)] * at(n[i]);
    return p;
  };
  auto size_of = [&](std::size_t c) {
    const NodeId* n = cell(c);
    double h = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) h = std::max(h, (at(n[i]) - at(n[j])).norm());
    return h;
  };

  JacobianCertifier certifier;
  std::vector<double> coords;
  std::map<std::pair<std::size_t, std::size_t>, double> scale;
  std::map<std::pair<std::size_t, std::size_t>, bool> corners_at_first;  // judge: positive corners when first seen
  // (valid, certified min det J over the cell's scale) of cell i of block k.
  auto judge = [&](std::size_t k, std::size_t i) {
    const CellBlock& cb = mesh.cells[k];
    const int n = cb.nodes_per_cell();
    coords.resize(static_cast<std::size_t>(3 * n));
    const NodeId* ids = cb.cell(i);
    for (int j = 0; j < n; ++j)
      for (int d = 0; d < 3; ++d) coords[static_cast<std::size_t>(3 * j + d)] = at(ids[j])[d];
    ++s.certified;
    const JacobianBounds jb = certifier.certify(cb.type, cb.order, coords.data());
    // Over a scale fixed per cell (its largest |det J| bound when first seen), so that a move is
    // judged by the smallest det J alone (over the current largest, bulging a cell would pass for
    // progress); a cell inverted everywhere has a scale too.
    // (A flat straight cell, a seed since TetGen's slivers are, has bounds near 0: its scale has a
    // floor of 1e-12 of its corners' span cubed, so that lifting it off flat scores as progress.)
    auto it = scale.find(std::make_pair(k, i));
    if (it == scale.end()) {  // the first time only (judge is the sweeps' inner loop)
      double span = 0;
      for (int v = 0; v < 4; ++v)
        for (int w = v + 1; w < 4; ++w) span = std::max(span, (at(ids[v]) - at(ids[w])).norm());
      it = scale.emplace(std::make_pair(k, i), std::max({jb.max_upper, std::abs(jb.min_lower), 1e-12 * span * span * span}))
               .first;
    }
    const double sc = it->second;
    const double r = sc > 0 ? jb.min_lower / sc : -std::numeric_limits<double>::infinity();
    // A tetrahedron whose corners spanned a positive volume when first judged must keep them so
    // (exact orient3d): a curved cell can be certified with its corner tetrahedron inverted,
    // which `gmsh -check` and solvers that measure cells by their vertices reject. (Not asked of
    // a cell whose corners were inverted from the start: requiring it made the published BWB at
    // h0 1e-5 L end with one cell no move mended.)
    if (cb.type == CellType::Tetrahedron) {
      const bool corners = positive_tet(at(ids[0]), at(ids[1]), at(ids[2]), at(ids[3]));
      const auto [c, fresh] = corners_at_first.emplace(std::make_pair(k, i), corners);
      if (c->second && !corners) return std::make_pair(false, std::min(r, 0.0) - 1);
    }
    return std::make_pair(jb.valid, r);
  };

  // 1. The curved fill cells and, of those, the invalid ones; and the straight cells flat
  // enough to be invalid: TetGen's slivers at a front (dihedral angles of 0.000000 degrees)
  // have a signed volume within rounding of 0, certified either way (the published 717 wing at
  // h0 1e-4 L: one such cell, 1e-8 of its edges' product, left the run invalid). Their free
  // vertices move them off flat like any invalid cell's.
  std::vector<std::size_t> invalid;
  for (std::size_t c = 0; c < nc; ++c) {
    const NodeId* n = cell(c);
    const double h = size_of(c), tol = 1e-12 * h;
    bool curved = false;
    for (int k = 4; k < np && !curved; ++k) curved = (at(n[k]) - linear(c, k)).norm() > tol;
    if (!curved) {
      const double volume6 = (at(n[1]) - at(n[0])).dot((at(n[2]) - at(n[0])).cross(at(n[3]) - at(n[0])));
      if (volume6 <= 1e-6 * h * h * h && !judge(block, first_cell + c).first) {
        ++s.flat;
        invalid.push_back(c);
      }
      continue;
    }
    ++s.curved;
    if (!judge(block, first_cell + c).first) invalid.push_back(c);
  }
  s.invalid_before = s.invalid_after = invalid.size();
  if (invalid.empty()) return s;

  // Movable: a high-order node (a vertex of no cell) on no boundary facet or curve (the wall's
  // nodes stay on the body, the planes' and the farfield's on their facets). The layers' own
  // high-order nodes are movable too: every cell around a moved node is judged.
  std::vector<std::uint8_t> on_boundary(x.size(), 0);
  for (const auto* group : {&mesh.boundary, &mesh.curves})
    for (const CellBlock& f : *group)
      for (NodeId id : f.connectivity) on_boundary[static_cast<std::size_t>(id)] = 1;
  std::vector<std::uint8_t> fixed = on_boundary;
  for (const CellBlock& cb : mesh.cells) {
    const int corners = cb.type == CellType::Prism ? 6 : 4;
    for (std::size_t i = 0; i < cb.size(); ++i)
      for (int k = 0; k < corners; ++k) fixed[static_cast<std::size_t>(cb.cell(i)[k])] = 1;
  }

  // 2. The region: the invalid cells and the fill cells sharing a vertex with one; its movable
  // nodes, and every cell of the mesh around each of them (the ball a move is judged on).
  std::unordered_set<NodeId> bad_vertices;
  for (std::size_t c : invalid)
    for (int i = 0; i < 4; ++i) bad_vertices.insert(cell(c)[i]);
  std::vector<NodeId> work;
  struct Around {
    std::vector<std::pair<std::size_t, std::size_t>> cells;  // (block, cell)
    std::size_t fill_cell = 0;                               // a fill tetrahedron holding it
    int local = -1;                                          // ... at this local index
  };
  std::unordered_map<NodeId, Around> ball;
  for (std::size_t c = 0; c < nc; ++c) {
    const NodeId* n = cell(c);
    if (!(bad_vertices.count(n[0]) || bad_vertices.count(n[1]) || bad_vertices.count(n[2]) || bad_vertices.count(n[3])))
      continue;
    for (int k = 4; k < np; ++k) {
      if (fixed[static_cast<std::size_t>(n[k])]) continue;
      const auto [it, added] = ball.emplace(n[k], Around{});
      if (!added) continue;
      it->second.fill_cell = c;
      it->second.local = k;
      work.push_back(n[k]);
    }
  }
  for (std::size_t k = 0; k < mesh.cells.size(); ++k) {
    const CellBlock& cb = mesh.cells[k];
    const int n = cb.nodes_per_cell();
    for (std::size_t i = 0; i < cb.size(); ++i)
      for (int j = 0; j < n; ++j) {
        const auto it = ball.find(cb.cell(i)[j]);
        if (it != ball.end()) it->second.cells.emplace_back(k, i);
      }
  }
  // The invalid cells' vertices off the boundary (the fill's own points, the layers' column nodes
  // off the wall and the planes) move too, when their high-order nodes cannot untangle a cell: a
  // vertex carries every node of the cells around it along by the node's linear weight on it, so
  // those cells keep their curvature, and no boundary node moves (a node with weight on a vertex
  // off the boundary lies on no boundary facet).
  struct Group {
    std::vector<std::pair<std::size_t, std::size_t>> cells;     // (block, cell) a shift changes
    std::vector<std::pair<NodeId, double>> carried;             // node, its weight in the shift
    double shortest = std::numeric_limits<double>::infinity();  // the shortest edge around (the step's scale)
  };
  std::unordered_map<NodeId, Group> vertex_ball;
  for (NodeId v : bad_vertices)
    if (moves.vertices && !on_boundary[static_cast<std::size_t>(v)]) vertex_ball.emplace(v, Group{});
  if (!vertex_ball.empty())
    for (std::size_t k = 0; k < mesh.cells.size(); ++k) {
      const CellBlock& cb = mesh.cells[k];
      const int n = cb.nodes_per_cell(), corners = cb.type == CellType::Prism ? 6 : 4;
      const std::vector<double> w = corner_weights(cb.type, cb.order);
      for (std::size_t i = 0; i < cb.size(); ++i)
        for (int c = 0; c < corners; ++c) {
          const auto it = vertex_ball.find(cb.cell(i)[c]);
          if (it == vertex_ball.end()) continue;
          Group& va = it->second;
          va.cells.emplace_back(k, i);
          for (int j = 0; j < n; ++j) {
            const double wj = w[static_cast<std::size_t>(j * corners + c)];
            if (std::abs(wj) > 1e-12) va.carried.emplace_back(cb.cell(i)[j], wj);
            if (j < corners && j != c)
              va.shortest = std::min(va.shortest, (at(cb.cell(i)[j]) - at(cb.cell(i)[c])).norm());
          }
        }
    }
  for (auto& [v, va] : vertex_ball) {
    std::sort(va.carried.begin(), va.carried.end());
    va.carried.erase(std::unique(va.carried.begin(), va.carried.end(),
                                 [](const auto& l, const auto& r) { return l.first == r.first; }),
                     va.carried.end());
  }
  // Each invalid cell's free nodes as one group (weight 1), judged on every cell around them.
  std::vector<Group> cell_groups;
  for (std::size_t c : moves.nodes ? invalid : std::vector<std::size_t>{}) {
    Group g;
    for (int k = 4; k < np; ++k) {
      const auto it = ball.find(cell(c)[k]);
      if (it == ball.end()) continue;
      g.carried.emplace_back(it->first, 1.0);
      g.cells.insert(g.cells.end(), it->second.cells.begin(), it->second.cells.end());
    }
    if (g.carried.size() < 2) continue;  // one node alone is the node moves' work
    std::sort(g.cells.begin(), g.cells.end());
    g.cells.erase(std::unique(g.cells.begin(), g.cells.end()), g.cells.end());
    const NodeId* n = cell(c);
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) g.shortest = std::min(g.shortest, (at(n[i]) - at(n[j])).norm());
    cell_groups.push_back(std::move(g));
  }
  // Every cell a move can change.
  std::vector<std::pair<std::size_t, std::size_t>> touched;
  for (std::size_t c : invalid) touched.emplace_back(block, first_cell + c);
  for (const auto& [id, a] : ball) touched.insert(touched.end(), a.cells.begin(), a.cells.end());
  for (const auto& [id, va] : vertex_ball) touched.insert(touched.end(), va.cells.begin(), va.cells.end());
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());

  auto ball_quality = [&](const std::vector<std::pair<std::size_t, std::size_t>>& cells) {
    BallQuality bq;
    for (const auto& [k, i] : cells) {
      const auto [ok, r] = judge(k, i);
      if (!ok) ++bq.invalid;
      if (!ok && (k != block || i < first_cell)) ++bq.layers_invalid;
      bq.worst = std::min(bq.worst, r);
    }
    return bq;
  };

  // A group's shift d moves each of its nodes by its weight times d; the best shift by a compass
  // search, judged on the group's cells. True when it moved.
  auto shift_group = [&](Group& g) {
    if (s.certified > kMaxCertified) return false;
    BallQuality best = ball_quality(g.cells);
    if (best.invalid == 0) return false;
    std::vector<Eigen::Vector3d> from(g.carried.size());
    for (std::size_t j = 0; j < g.carried.size(); ++j) from[j] = at(g.carried[j].first);
    auto place = [&](const Eigen::Vector3d& d) {
      for (std::size_t j = 0; j < g.carried.size(); ++j) at(g.carried[j].first) = from[j] + g.carried[j].second * d;
    };
    Eigen::Vector3d best_d = Eigen::Vector3d::Zero();
    auto trial = [&](const Eigen::Vector3d& d) {
      place(d);
      const BallQuality bq = ball_quality(g.cells);
      if (bq.better_than(best)) {
        best = bq;
        best_d = d;
      }
    };
    compass_search(compass_directions(Eigen::Vector3d::Zero()), 0.1 * g.shortest, 1e-9 * g.shortest, &best_d, trial);
    place(best_d);
    return best_d.norm() > 0;
  };

  // 3. Node by node: the move that most improves its ball.
  std::unordered_set<NodeId> moved, moved_vertices;
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    bool any = false;
    for (NodeId m : moves.nodes ? work : std::vector<NodeId>{}) {
      if (s.certified > kMaxCertified) break;
      const Around& a = ball[m];
      BallQuality best = ball_quality(a.cells);
      if (best.invalid == 0) continue;  // a move here could only make its own cells worse
      Eigen::Vector3d& xm = at(m);
      const Eigen::Vector3d start = xm;
      const Eigen::Vector3d lin = linear(a.fill_cell, a.local);
      // The displacements of the curved nodes of the fill cells around (one per node), the
      // largest first, and their mean.
      std::vector<std::pair<double, Eigen::Vector3d>> dirs;
      std::unordered_set<NodeId> seen{m};
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const auto& [k, i] : a.cells) {
        if (k != block || i < first_cell) continue;
        const std::size_t c = i - first_cell;
        const double tol = 1e-12 * size_of(c);
        for (int j = 4; j < np; ++j) {
          const NodeId id = cell(c)[j];
          if (!seen.insert(id).second) continue;
          const Eigen::Vector3d d = at(id) - linear(c, j);
          if (d.norm() <= tol) continue;
          dirs.emplace_back(d.norm(), d);
          mean += d;
        }
      }
      if (!dirs.empty()) {
        mean /= static_cast<double>(dirs.size());
        std::sort(dirs.begin(), dirs.end(), [](const auto& l, const auto& r) { return l.first > r.first; });
        if (dirs.size() > kMaxDirections) dirs.resize(kMaxDirections);
        dirs.emplace_back(mean.norm(), mean);
      }
      Eigen::Vector3d best_x = start;
      auto trial = [&](const Eigen::Vector3d& p) {
        xm = p;
        const BallQuality bq = ball_quality(a.cells);
        if (bq.better_than(best)) {
          best = bq;
          best_x = p;
        }
      };
      trial(lin);
      for (const auto& [len, d] : dirs)
        for (double share : {0.5, 1.0}) trial(lin + share * d);
      // Then a compass search from the best (the largest displacement one of its directions).
      const double size = size_of(a.fill_cell);
      compass_search(compass_directions(dirs.empty() ? Eigen::Vector3d::Zero() : dirs.front().second),
                     dirs.empty() ? 0.05 * size : 0.5 * dirs.front().first, 1e-9 * size, &best_x, trial);
      xm = best_x;
      if (best_x != start) {
        any = true;
        moved.insert(m);
      }
    }
    // Then the vertices of cells still invalid, and the free nodes of each invalid cell together
    // (where each node alone trades one cell for another): a compass search over the shift.
    for (auto& [v, va] : vertex_ball)
      if (shift_group(va)) {
        any = true;
        moved_vertices.insert(v);
      }
    for (Group& g : cell_groups)
      if (shift_group(g)) {
        any = true;
        for (const auto& [id, w] : g.carried) moved.insert(id);
      }
    std::size_t left = 0;
    for (const auto& [k, i] : touched) left += judge(k, i).first ? 0 : 1;
    s.invalid_after = left;
    if (left == 0 || !any || s.certified > kMaxCertified) break;
  }

  // 4. The last resort, for a fill cell still invalid: the cell made straight (valid when its
  // linear tetrahedron is: TetGen's are, and the moves above keep every fill cell's vertices where
  // no more cells around are invalid; a cell inverted even straight stops its region), and every
  // cell that turns invalid by it straight too, in turn, up to kMaxStraightened cells; kept when
  // every cell around every node it moved is then valid, else undone. Where such a cell's nodes
  // are on the boundary (a bare wall edge, where columns stopped before their first layer and
  // TetGen's ear spans a fold of the wall: the 717 wing's tip at h0 1e-4 L) the wall's curvature
  // is given up there, as the surface stage straightens a triangle it cannot curve validly:
  // counted and measured (FillUntangling::straightened, straightened_max).
  std::vector<std::pair<std::size_t, std::size_t>> left_cells;  // (block, cell)
  for (const auto& [k, i] : touched)
    if (k == block && i >= first_cell && !judge(k, i).first) left_cells.emplace_back(k, i);
  if (!left_cells.empty()) {  // its own bound (kMaxStraightened per cell), not the sweeps'
    // The cells around every node (CSR over the whole mesh, a cell by its index over all blocks:
    // built only on this path).
    std::vector<std::size_t> block_start(mesh.cells.size() + 1, 0);
    for (std::size_t k = 0; k < mesh.cells.size(); ++k) block_start[k + 1] = block_start[k] + mesh.cells[k].size();
    const auto global = [&](std::size_t k, std::size_t i) { return static_cast<std::uint32_t>(block_start[k] + i); };
    const auto local = [&](std::uint32_t g) {
      const std::size_t k =
          static_cast<std::size_t>(std::upper_bound(block_start.begin(), block_start.end(), g) - block_start.begin()) -
          1;
      return std::make_pair(k, g - block_start[k]);
    };
    std::vector<std::size_t> start(x.size() + 1, 0);
    for (const CellBlock& cb : mesh.cells)
      for (NodeId id : cb.connectivity) ++start[static_cast<std::size_t>(id) + 1];
    for (std::size_t i = 0; i < x.size(); ++i) start[i + 1] += start[i];
    std::vector<std::uint32_t> around(start.back());
    {
      std::vector<std::size_t> fill_at(start.begin(), start.end() - 1);
      for (std::size_t k = 0; k < mesh.cells.size(); ++k) {
        const CellBlock& cb = mesh.cells[k];
        const std::size_t n = static_cast<std::size_t>(cb.nodes_per_cell());
        for (std::size_t i = 0; i < cb.size(); ++i)
          for (std::size_t j = 0; j < n; ++j) around[fill_at[static_cast<std::size_t>(cb.cell(i)[j])]++] = global(k, i);
      }
    }
    std::vector<std::vector<double>> block_weights;
    for (const CellBlock& cb : mesh.cells) block_weights.push_back(corner_weights(cb.type, cb.order));
    // Cell (k, i) made straight: its nodes off their linear position by more than rounding
    // (straight_tolerance) moved there, each node's position before into `was` (first one kept).
    auto straighten = [&](std::size_t k, std::size_t i, std::unordered_map<NodeId, Eigen::Vector3d>& was) {
      const CellBlock& cb = mesh.cells[k];
      const int n = cb.nodes_per_cell(), corners = cb.type == CellType::Prism ? 6 : 4;
      const std::vector<double>& w = block_weights[k];
      const NodeId* ids = cb.cell(i);
      double size = 0;
      for (int c = 1; c < corners; ++c) size = std::max(size, (at(ids[c]) - at(ids[0])).norm());
      for (int j = corners; j < n; ++j) {
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        for (int c = 0; c < corners; ++c) p += w[static_cast<std::size_t>(j * corners + c)] * at(ids[c]);
        if ((at(ids[j]) - p).norm() <= straight_tolerance(size, p.norm())) continue;
        was.emplace(ids[j], at(ids[j]));
        at(ids[j]) = p;
      }
    };
    // The cells around the given nodes (each once).
    auto cells_around = [&](const std::vector<NodeId>& ids) {
      std::set<std::pair<std::size_t, std::size_t>> near;
      for (NodeId id : ids)
        for (std::size_t a = start[static_cast<std::size_t>(id)]; a < start[static_cast<std::size_t>(id) + 1]; ++a)
          near.insert(local(around[a]));
      return near;
    };
    // Two passes: a seed whose region outgrew the bound may be valid, or closer, after the others'.
    for (std::size_t pass = 0; pass < 2 * left_cells.size(); ++pass) {
      const auto& seed = left_cells[pass % left_cells.size()];
      if (judge(seed.first, seed.second).first) continue;  // made valid by an earlier seed's region
      std::unordered_map<NodeId, Eigen::Vector3d> was;
      std::set<std::pair<std::size_t, std::size_t>> region{seed}, straight;
      std::vector<std::pair<std::size_t, std::size_t>> queue{seed};
      bool ok = false;
      while (!queue.empty() && straight.size() <= kMaxStraightened) {
        const auto ki = queue.back();
        queue.pop_back();
        if (judge(ki.first, ki.second).first) continue;  // valid again by the cells made straight since
        // An invalid cell already straight: its linear self is inverted, no way on.
        if (!straight.insert(ki).second) break;
        std::unordered_map<NodeId, Eigen::Vector3d> step;
        straighten(ki.first, ki.second, step);
        std::vector<NodeId> ids;
        for (const auto& [id, p] : step) {
          ids.push_back(id);
          was.emplace(id, p);
        }
        // A cell the step inverts joins the region (a layers' cell too: straight, it hands its
        // bend to the cell under it, down to the wall if need be: on the published spot, h0 1e-5
        // L, Q2, 259 cells of a column and the fill beside it, 10 wall nodes moved by 0.0019); one
        // in the region already but not straight yet (valid when its turn came) is queued again,
        // and the cell itself once more (it is judged again, straight).
        queue.push_back(ki);
        for (const auto& nb : cells_around(ids))
          if (!judge(nb.first, nb.second).first && (region.insert(nb).second || !straight.count(nb)))
            queue.push_back(nb);
        // Done when the queue holds valid cells only: then every cell around every node moved is
        // checked below.
        if (std::all_of(queue.begin(), queue.end(), [&](const auto& c) { return judge(c.first, c.second).first; })) {
          std::vector<NodeId> all;
          for (const auto& [id, p] : was) all.push_back(id);
          const auto near = cells_around(all);
          ok = judge(seed.first, seed.second).first &&
               std::all_of(near.begin(), near.end(), [&](const auto& c) { return judge(c.first, c.second).first; });
          break;
        }
      }
      if (!ok) {
        for (const auto& [id, p] : was) at(id) = p;
        continue;
      }
      for (const auto& [id, p] : was) {
        if (!on_boundary[static_cast<std::size_t>(id)]) continue;
        ++s.straightened;
        s.straightened_max = std::max(s.straightened_max, (at(id) - p).norm());
      }
      s.cells_straightened += straight.size();
    }
    std::size_t left = 0;
    for (const auto& [k, i] : touched) left += judge(k, i).first ? 0 : 1;
    s.invalid_after = left;
  }
  s.nodes_moved = moved.size();
  s.vertices_moved = moved_vertices.size();
  return s;
}

}  // namespace mesh
}  // namespace plaf
