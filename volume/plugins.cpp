// SPDX-License-Identifier: MIT
#include "volume/plugins.h"

#include "modules/base/error.h"
#include "modules/pipeline/run_state.h"
#include "modules/pipeline/stages.h"
#include "volume/advancing_front_2d.h"
#include "volume/farfield3d.h"
#include "volume/tetgen_fill.h"

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>
#include <unordered_map>

namespace plaf::volume {

namespace {

struct TetgenPlan {
  FarfieldParams3 farfield;
  TetFillParams tet;
};

TetgenPlan parse_tetgen(const ConfigNode& section) {
  TetgenPlan p;
  p.tet.max_radius_edge = section.get_in_range("max_radius_edge", p.tet.max_radius_edge, 0.0, 100.0);
  if (p.tet.max_radius_edge > 0 && p.tet.max_radius_edge < 1.1)
    throw ConfigError(section.where("max_radius_edge") + ": TetGen's quality bound must be 0 (off) or at least 1.1");
  p.tet.max_volume = section.get_in_range("max_volume", 0.0, 0.0, std::numeric_limits<double>::max());
  const ConfigNode f = section.child("farfield");
  FarfieldParams3& ff = p.farfield;
  ff.shape = f.get_choice("shape", ff.shape, {"sphere", "box"});
  ff.radius = f.get_in_range("radius", 0.0, 0.0, std::numeric_limits<double>::max());
  const std::vector<double> size = f.get_double_list("size", {0, 0, 0});
  if (size.size() != 3 || std::any_of(size.begin(), size.end(), [](double v) { return !(v >= 0); }))
    throw ConfigError(f.where("size") + ": three edge lengths >= 0 (0: 20 x the bodies' diagonal)");
  std::copy(size.begin(), size.end(), ff.size.begin());
  ff.has_center = f.has("center");
  const std::vector<double> c = f.get_double_list("center", {0, 0, 0});
  if (c.size() != 3) throw ConfigError(f.where("center") + ": three coordinates");
  ff.center = Eigen::Vector3d(c[0], c[1], c[2]);
  ff.h = f.get_in_range("h", 0.0, 0.0, std::numeric_limits<double>::max());
  return p;
}

// One point inside the layers of every connected part of their outer front (TetGen's holes:
// the bodies and their layers are not filled): the centroid of the vertices of a last-layer
// prism under a triangle of the part.
std::vector<Eigen::Vector3d> layer_holes(const LayerResult<3>& lr) {
  const LinearFront<3>& ff = lr.fill_front;
  const std::size_t n = ff.nodes.size();
  std::vector<std::size_t> root(n);
  std::iota(root.begin(), root.end(), std::size_t{0});
  auto find = [&](std::size_t a) {
    while (root[a] != a) a = root[a] = root[root[a]];
    return a;
  };
  std::vector<std::size_t> outer;  // the layers' outer triangles
  for (std::size_t t = 0; t < ff.triangles.size(); ++t) {
    if (ff.tags[static_cast<std::size_t>(ff.triangle_tag[t])].name != "layers_outer") continue;
    outer.push_back(t);
    const auto& tri = ff.triangles[t];
    root[find(static_cast<std::size_t>(tri[1]))] = find(static_cast<std::size_t>(tri[0]));
    root[find(static_cast<std::size_t>(tri[2]))] = find(static_cast<std::size_t>(tri[0]));
  }
  // Prisms by their top vertices (lattice nodes 3, 4, 5 in Gmsh order), sorted.
  std::map<std::array<NodeId, 3>, std::size_t> by_top;
  const CellBlock& prisms = lr.mesh.cells.at(0);
  for (std::size_t c = 0; c < prisms.size(); ++c) {
    std::array<NodeId, 3> top = {prisms.cell(c)[3], prisms.cell(c)[4], prisms.cell(c)[5]};
    std::sort(top.begin(), top.end());
    by_top.emplace(top, c);
  }
  std::map<std::size_t, Eigen::Vector3d> hole;
  for (std::size_t t : outer) {
    const std::size_t r = find(static_cast<std::size_t>(ff.triangles[t][0]));
    if (hole.count(r)) continue;
    std::array<NodeId, 3> key = ff.triangles[t];
    std::sort(key.begin(), key.end());
    const auto it = by_top.find(key);
    if (it == by_top.end()) continue;
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < 6; ++k) x += lr.mesh.nodes[static_cast<std::size_t>(prisms.cell(it->second)[k])] / 6;
    hole.emplace(r, x);
  }
  std::vector<Eigen::Vector3d> out;
  for (const auto& [r, x] : hole) out.push_back(x);
  return out;
}

}  // namespace

void register_plugins() {
  static const bool once = [] {
    stage_registry<2>(StageKind::Fill)
        .add("advancing_front", [](const ConfigNode& section) -> Stage<2> {
          AdvancingFrontParams p;
          p.max_triangles = static_cast<std::size_t>(section.get_int("max_triangles", 20000000, 1, 2000000000));
          return [p](RunState<2>& s, StageReport& rep) {
            if (!s.layers) throw MesherError("fill: no front to fill from");
            AdvancingFrontResult fill = advancing_front_fill(s.layers->fill_front, *s.metric, p);
            const AdvancingFrontStats& f = fill.stats;
            rep.add("steps", f.steps);
            rep.add("new_points", f.new_points);
            rep.add("merges", f.merges);
            rep.add("delaunay_apexes", f.delaunay_apexes);
            rep.add("max_front", f.max_front);
            rep.line("fill: " + std::to_string(f.steps) + " steps, " + std::to_string(f.new_points) + " new points, " +
                     std::to_string(f.merges) + " merges, " + std::to_string(f.delaunay_apexes) +
                     " Delaunay fallbacks, largest front " + std::to_string(f.max_front) + " edges");
            s.fill = static_cast<FillResult<2>&&>(std::move(fill));
          };
        });
    stage_registry<3>(StageKind::Fill).add("tetgen", [](const ConfigNode& section) -> Stage<3> {
      const TetgenPlan plan = parse_tetgen(section);
      return [plan](RunState<3>& s, StageReport& rep) {
        if (!s.layers || s.layers->layers.empty())
          throw MesherError("fill: tetgen fills around prism layers; the layer stage grew none");
        const LayerResult<3>& lr = *s.layers;
        if (lr.linear_after < 0)
          throw MesherError("fill: the layers' outer front is still curved (see layers.events); TetGen fills from a linear front");
        if (lr.outer.num_quads() > 0)
          throw MesherError("fill: the layers' outer front has " + std::to_string(lr.outer.num_quads()) +
                            " ridge-fan quadrilaterals; the TetGen fill meets triangles only so far (a run without ridge fans: "
                            "layers.corner_angle_deg above the body's sharpest ridge)");
        LinearFront<3> front = lr.fill_front;
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
        for (const auto& t : front.triangles)
          for (NodeId id : t) {
            lo = lo.cwiseMin(front.nodes[static_cast<std::size_t>(id)]);
            hi = hi.cwiseMax(front.nodes[static_cast<std::size_t>(id)]);
          }
        FarfieldParams3 fp = plan.farfield;
        if (fp.h <= 0) {
          // The metric's largest size at the farfield, at most a quarter of its extent.
          const Eigen::Vector3d c = farfield_center(fp, lo, hi);
          const double extent = fp.shape == "sphere" ? (fp.radius > 0 ? fp.radius : 10 * (hi - lo).norm())
                                                     : 0.5 * (fp.size[0] > 0 ? *std::min_element(fp.size.begin(), fp.size.end())
                                                                             : 20 * (hi - lo).norm());
          fp.h = std::min(s.metric->evaluate(c + extent * Eigen::Vector3d::UnitX()).max_size(), extent / 4);
        }
        const FarfieldMesh3 far = make_farfield(fp, lo, hi);
        const NodeId base = static_cast<NodeId>(front.nodes.size());
        front.nodes.insert(front.nodes.end(), far.nodes.begin(), far.nodes.end());
        const int tag = static_cast<int>(front.tags.size());
        front.tags.push_back({"farfield", BoundaryKind::Farfield});
        for (const auto& t : far.triangles) {
          front.triangles.push_back({base + t[0], base + t[1], base + t[2]});
          front.triangle_tag.push_back(tag);
        }
        front.holes = layer_holes(lr);
        // Sizes (TetGen's m): at a front node the mean length of its front edges, at the farfield
        // its h; TetGen grades between them.
        TetFillParams tp = plan.tet;
        tp.node_sizes.assign(front.nodes.size(), 0.0);
        std::vector<int> edges(front.nodes.size(), 0);
        for (const auto& t : front.triangles)
          for (int k = 0; k < 3; ++k) {
            const NodeId a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
            const double len = (front.nodes[static_cast<std::size_t>(a)] - front.nodes[static_cast<std::size_t>(b)]).norm();
            for (NodeId v : {a, b}) tp.node_sizes[static_cast<std::size_t>(v)] += len, ++edges[static_cast<std::size_t>(v)];
          }
        for (std::size_t v = 0; v < front.nodes.size(); ++v)
          if (edges[v] > 0) tp.node_sizes[v] /= edges[v];
        TetFillResult fill = tetgen_fill(front, tp);
        const TetFillStats& st = fill.stats;
        rep.add("farfield.shape", fp.shape);
        rep.add("farfield.h", fp.h);
        rep.add("farfield.triangles", far.triangles.size());
        rep.add("holes", front.holes.size());
        rep.add("tets", st.tets);
        rep.add("new_points", st.new_points);
        rep.add("min_dihedral_deg", st.min_dihedral_deg);
        rep.add("max_radius_edge", st.max_radius_edge);
        rep.add("switches", st.switches);
        rep.line("fill: " + std::to_string(st.tets) + " tetrahedra, " + std::to_string(st.new_points) +
                 " new points, min dihedral " + std::to_string(st.min_dihedral_deg) + " deg (TetGen -" + st.switches + ")");
        FillResult<3> out = static_cast<FillResult<3>&&>(std::move(fill));
        out.tags = {{"farfield", BoundaryKind::Farfield}};
        for (const auto& t : far.triangles) {
          out.boundary.push_back({base + t[0], base + t[1], base + t[2]});
          out.boundary_tag.push_back(0);
        }
        s.fill = std::move(out);
      };
    });
    return true;
  }();
  (void)once;
}

}  // namespace plaf::volume
