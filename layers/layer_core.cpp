// SPDX-License-Identifier: MIT
// The dimension-generic layer core (see layer_core.h for the steps and the paper's sections).
#include "layers/layer_core.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/elements/validity.h"

namespace plaf::layers {

template <int Dim>
double layer_height(const MetricField<Dim>& metric, const Eigen::Matrix<double, Dim, 1>& x,
                    const Eigen::Matrix<double, Dim, 1>& n, bool integrate) {
  using Vec = Eigen::Matrix<double, Dim, 1>;
  const double h = metric.evaluate(x).size_along(n);
  if (!integrate) return h;
  // Unit metric length along x + s n: fixed point s <- s / L(s) on L(s), the metric length of the
  // segment (3-point Gauss).
  double s = h;
  for (int it = 0; it < 8; ++it) {
    const double l = metric_length<Dim>(metric, x, Vec(x + s * n), 3);
    if (std::abs(l - 1) < 1e-10) break;
    s /= l;
  }
  return s;
}

template <int Dim>
double attenuate(std::vector<Eigen::Matrix<double, Dim, 1>>& tops,
                 const std::vector<Eigen::Matrix<double, Dim, 1>>& targets, const std::vector<double>& heights,
                 double f_atten) {
  double clipped = 0;
  for (std::size_t k = 0; k < tops.size(); ++k) {
    Eigen::Matrix<double, Dim, 1> d = targets[k] - tops[k];
    const double need = d.norm(), limit = f_atten * heights[k];
    if (need > limit) {
      d *= limit / need;
      clipped = std::max(clipped, need / heights[k]);
    }
    tops[k] += d;
  }
  return clipped;
}

template <int Dim>
bool is_isotropic(const Metric<Dim>& m) {
  const auto d = m.decompose();  // sizes ascending
  return d.sizes[0] >= 0.999 * d.sizes[Dim - 1];
}

namespace {

template <int Dim>
std::string point_text(const Eigen::Matrix<double, Dim, 1>& x) {
  std::string s;
  for (int d = 0; d < Dim; ++d) s += (d ? ", " : "") + std::to_string(x[d]);
  return s;
}

// Steps 2-3 of layer_core.h for one part and one layer: build, certify, test collisions, shrink
// and retry.
template <int Dim>
class LayerAttempts {
 public:
  LayerAttempts(FrontGrower<Dim>& grower, const LayerParams& p, int order, LayerResult<Dim>& r)
      : g_(grower), p_(p), q_(order), r_(r) {}

  // False when the layer still fails after the shrink attempts (its nodes are then rolled back).
  bool run(std::size_t part, int layer, std::vector<double>& scale, const std::vector<std::uint8_t>& stopped,
           double f_atten, LayerStats& st, BuiltLayer& built) {
    const std::array<CellType, 2> types = g_.cell_types();
    for (int attempt = 0; attempt <= p_.shrink_attempts; ++attempt) {
      const std::size_t nodes_before = r_.mesh.nodes.size();
      built = g_.build(part, layer, scale, stopped, f_atten);
      std::vector<LayerFailure> failures;
      std::string why = "invalid cells";
      Eigen::Matrix<double, Dim, 1> where = Eigen::Matrix<double, Dim, 1>::Zero();
      for (int b = 0; b < 2; ++b) {
        const int npc = num_nodes(types[static_cast<std::size_t>(b)], q_);
        const std::vector<NodeId>& cells = built.cells[static_cast<std::size_t>(b)];
        coords_.resize(static_cast<std::size_t>(npc * Dim));
        for (std::size_t c = 0; c * npc < cells.size(); ++c) {
          for (int k = 0; k < npc; ++k)
            for (int d = 0; d < Dim; ++d)
              coords_[static_cast<std::size_t>(Dim * k + d)] = r_.mesh.nodes[cells[c * npc + k]][d];
          if (certifier_.certify(types[static_cast<std::size_t>(b)], q_, coords_.data()).valid) continue;
          if (failures.empty()) where = r_.mesh.nodes[cells[c * npc]];
          failures.push_back({b, c});
        }
      }
      if (failures.empty()) {
        const std::vector<std::size_t> hits = g_.collisions(part);
        for (std::size_t h : hits) failures.push_back({LayerFailure::kFrontElement, h});
        if (!hits.empty()) {
          why = "front crossings (a collision)";
          where = g_.front_point(hits[0]);
        }
      }
      if (failures.empty()) return true;
      r_.mesh.nodes.resize(nodes_before);
      g_.shrink(part, failures, scale);
      st.shrinks += failures.size();
      r_.events.push_back("layer " + std::to_string(layer) + ", " + part_name(part) + ": " +
                          std::to_string(failures.size()) + " " + why + " (first at " + point_text<Dim>(where) +
                          "), heights halved around them");
    }
    return false;
  }

  std::string part_name(std::size_t part) const { return (Dim == 2 ? "loop " : "surface ") + g_.part_tag(part); }

 private:
  FrontGrower<Dim>& g_;
  const LayerParams& p_;
  int q_;
  LayerResult<Dim>& r_;
  JacobianCertifier certifier_;
  std::vector<double> coords_;
};

void append(std::array<CellBlock, 2>& blocks, const BuiltLayer& built) {
  for (std::size_t b = 0; b < 2; ++b)
    blocks[b].connectivity.insert(blocks[b].connectivity.end(), built.cells[b].begin(), built.cells[b].end());
}

}  // namespace

template <int Dim>
void grow_fronts(FrontGrower<Dim>& g, const MetricField<Dim>& metric, const LayerParams& p, int q,
                 LayerResult<Dim>& r) {
  const std::array<CellType, 2> types = g.cell_types();
  std::array<CellBlock, 2> blocks{CellBlock{types[0], q, -1, {}}, CellBlock{types[1], q, -1, {}}};
  const std::size_t parts = g.num_parts();
  std::vector<bool> growing(parts, true);
  std::vector<double> part_clip(parts, 0.0);
  std::vector<bool> part_linear(parts, false);
  LayerAttempts<Dim> attempts(g, p, q, r);
  for (int layer = 1; layer <= p.max_layers; ++layer) {
    LayerStats st;
    st.layer = layer;
    st.first_cell = blocks[0].size();
    bool any = false, all_linear = true;
    for (std::size_t part = 0; part < parts; ++part) {
      if (!growing[part]) continue;
      // 1. Isotropic stop: where the metric is isotropic at a front node, a layer would be as
      // tall as the metric's size in every direction: no more anisotropic layer is wanted there.
      const std::vector<typename FrontGrower<Dim>::Vec> points = g.stop_points(part);
      std::vector<std::uint8_t> stopped(points.size(), 0);
      if (p.isotropic_stop != IsotropicStop::Off) {
        std::size_t iso = 0;
        for (std::size_t e = 0; e < points.size(); ++e)
          if (is_isotropic<Dim>(metric.evaluate(points[e]))) {
            ++iso;
            stopped[e] = p.isotropic_stop == IsotropicStop::Node ? 1 : 0;
          }
        const std::size_t total = points.size();
        if (p.isotropic_stop == IsotropicStop::Node && iso == total) {
          growing[part] = false;
          r.events.push_back("layer " + std::to_string(layer) + ", " + attempts.part_name(part) +
                             ": stopped, the metric is isotropic at every node");
          continue;
        }
        if ((p.isotropic_stop == IsotropicStop::All && iso == total) ||
            (p.isotropic_stop == IsotropicStop::Any && iso > 0)) {
          growing[part] = false;
          r.events.push_back("layer " + std::to_string(layer) + ", " + attempts.part_name(part) +
                             ": stopped, the metric is isotropic at " + std::to_string(iso) + " of " +
                             std::to_string(total) + " nodes");
          continue;
        }
      }
      // 2-3. Build, certify, shrink.
      std::vector<double> scale(g.num_sites(part), 1.0);
      BuiltLayer built;
      if (!attempts.run(part, layer, scale, stopped, p.f_atten, st, built)) {
        growing[part] = false;
        r.events.push_back("layer " + std::to_string(layer) + ", " + attempts.part_name(part) +
                           ": stopped, cells still invalid or colliding after " + std::to_string(p.shrink_attempts) +
                           " shrinks");
        continue;
      }
      part_clip[part] = built.max_clipped_rel;
      part_linear[part] = built.linear;
      any = true;
      append(blocks, built);
      st.transition_cells += built.cells[1].size() / static_cast<std::size_t>(num_nodes(types[1], q));
      st.max_clipped_rel = std::max(st.max_clipped_rel, built.max_clipped_rel);
      all_linear = all_linear && built.linear;
      g.accept(part);
    }
    if (!any) break;
    // 4. The layer's row of the table.
    st.cells = blocks[0].size() - st.first_cell;
    st.linear = all_linear;
    r.layers.push_back(st);
    if (st.linear && r.linear_after < 0) r.linear_after = layer;
    if (st.linear && p.stop_when_linear) break;
  }
  // The fill (Sec. II.C) starts from a linear front. A part that stopped, or ran out of layers,
  // while its front is still curved gets one closing layer with straight tops (unlimited
  // attenuation), tall enough to clear its curved front: heights of 1.5, 3, then 6 times the
  // attenuation move still needed (at least the metric height). The paper stops the layers once
  // the front is linear and does not meet this case; a taller last cell is the robust choice (a
  // valid mesh over metric conformity there).
  if (p.close_linear) {
    LayerStats st;
    st.layer = static_cast<int>(r.layers.size()) + 1;
    st.first_cell = blocks[0].size();
    bool any = false;
    for (std::size_t part = 0; part < parts; ++part) {
      if (part_linear[part]) continue;
      const std::vector<std::uint8_t> stopped(g.stop_points(part).size(), 0);
      bool closed = false;
      for (double factor : {1.5, 3.0, 6.0}) {
        std::vector<double> scale(g.num_sites(part), std::max(1.0, factor * part_clip[part]));
        BuiltLayer built;
        const std::size_t nodes_before = r.mesh.nodes.size();
        if (!attempts.run(part, st.layer, scale, stopped, std::numeric_limits<double>::infinity(), st, built))
          continue;
        if (!built.linear) {
          r.mesh.nodes.resize(nodes_before);
          continue;
        }
        append(blocks, built);
        r.events.push_back("layer " + std::to_string(st.layer) + ", " + attempts.part_name(part) +
                           ": a closing layer with straight tops (heights x" + std::to_string(scale[0]) + ")");
        g.accept(part);
        part_linear[part] = closed = any = true;
        break;
      }
      if (!closed)
        r.events.push_back("layer " + std::to_string(st.layer) + ", " + attempts.part_name(part) +
                           ": no valid closing layer; the front stays curved");
    }
    if (any) {
      st.cells = blocks[0].size() - st.first_cell;
      st.linear = std::all_of(part_linear.begin(), part_linear.end(), [](bool b) { return b; });
      r.layers.push_back(st);
      if (st.linear && r.linear_after < 0) r.linear_after = st.layer;
    }
  }
  for (CellBlock& b : blocks)
    if (!b.connectivity.empty()) r.mesh.cells.push_back(std::move(b));
}

template double layer_height<2>(const MetricField<2>&, const Eigen::Vector2d&, const Eigen::Vector2d&, bool);
template double layer_height<3>(const MetricField<3>&, const Eigen::Vector3d&, const Eigen::Vector3d&, bool);
template double attenuate<2>(std::vector<Eigen::Vector2d>&, const std::vector<Eigen::Vector2d>&,
                             const std::vector<double>&, double);
template double attenuate<3>(std::vector<Eigen::Vector3d>&, const std::vector<Eigen::Vector3d>&,
                             const std::vector<double>&, double);
template bool is_isotropic<2>(const Metric<2>&);
template bool is_isotropic<3>(const Metric<3>&);
template void grow_fronts<2>(FrontGrower<2>&, const MetricField<2>&, const LayerParams&, int, LayerResult<2>&);
template void grow_fronts<3>(FrontGrower<3>&, const MetricField<3>&, const LayerParams&, int, LayerResult<3>&);

}  // namespace plaf::layers
