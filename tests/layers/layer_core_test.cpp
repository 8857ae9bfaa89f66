// SPDX-License-Identifier: MIT
// The dimension-generic layer core (layer_core.h) driven by a scripted front: what counts as a
// linear layer when one part stops while still curved.
#include "layers/layer_core.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

using namespace plaf;
using Eigen::Vector2d;

namespace {

// Parts of one column of order-1 quadrilaterals each, stacked along y (part p at x in [3 p, 3 p
// + 1]): the plumbing every scripted front shares. A test's front says what each build holds
// (build_cells), and accepts it as the part's new base.
class ColumnFronts : public layers::FrontGrower<2> {
 public:
  ColumnFronts(HybridMesh<2>& mesh, std::size_t parts) : mesh_(mesh), base_(parts), pending_(parts), y_(parts, 0.0) {
    for (std::size_t p = 0; p < parts; ++p) base_[p] = {add({3.0 * static_cast<double>(p), 0}), add({3.0 * static_cast<double>(p) + 1, 0})};
  }
  std::array<CellType, 2> cell_types() const override { return {CellType::Quadrilateral, CellType::Triangle}; }
  std::size_t num_parts() const override { return base_.size(); }
  std::string part_name(std::size_t part) const override { return "part " + std::to_string(part); }
  std::size_t num_sites(std::size_t) const override { return 2; }
  std::vector<Vec> stop_points(std::size_t part) const override {
    return {mesh_.nodes[base_[part][0]], mesh_.nodes[base_[part][1]]};
  }
  std::size_t num_stop_points(std::size_t) const override { return 2; }
  std::vector<double> stop_point_measure(std::size_t) const override { return {0.5, 0.5}; }
  std::vector<std::size_t> collisions(std::size_t) const override { return {}; }
  Vec front_point(std::size_t) const override { return Vec::Zero(); }
  void rescale(std::size_t, const std::vector<layers::LayerFailure>&, double factor,
               std::vector<double>& scale) const override {
    for (double& s : scale) s *= factor;
  }
  void accept(std::size_t part) override {
    base_[part] = pending_[part];
    y_[part] += 1;
  }

 protected:
  NodeId add(const Vector2d& x) {
    mesh_.nodes.push_back(x);
    return static_cast<NodeId>(mesh_.nodes.size() - 1);
  }
  // The part's next cell, one layer up (its top swapped: inverted), made the pending base.
  std::vector<NodeId> next_cell(std::size_t part, bool inverted) {
    const double x0 = 3.0 * static_cast<double>(part), y = y_[part] + 1;
    // Gmsh order: (x0, y-1), (x0+1, y-1), (x0+1, y), (x0, y).
    const NodeId a = add({x0 + (inverted ? 1 : 0), y}), c = add({x0 + (inverted ? 0 : 1), y});
    pending_[part] = {a, c};
    return {base_[part][0], base_[part][1], c, a};
  }
  HybridMesh<2>& mesh_;
  std::vector<std::array<NodeId, 2>> base_;
  std::vector<std::array<NodeId, 2>> pending_;
  std::vector<double> y_;
};

// Two parts. Part 0 always builds a valid, linear layer. Part 1 builds a valid layer that
// reports itself curved (an attenuation need left) on its first layer, and from its second
// layer on only an inverted cell, so it stops, still curved, and no closing layer mends it.
class ScriptedFronts final : public ColumnFronts {
 public:
  explicit ScriptedFronts(HybridMesh<2>& mesh) : ColumnFronts(mesh, 2) {}
  layers::BuiltLayer build(std::size_t part, int layer, const std::vector<double>&, const std::vector<std::uint8_t>&,
                           double f_atten) override {
    layers::BuiltLayer b;
    b.cells[0] = next_cell(part, part == 1 && layer >= 2);
    b.linear = !(part == 1 && layer == 1 && std::isfinite(f_atten));
    b.max_clipped_rel = b.linear ? 0 : 0.5;
    return b;
  }
};

}  // namespace

TEST_CASE("layer core: a layer is linear only when every part's front is, a part that stopped curved included") {
  for (bool close : {false, true}) {
    CAPTURE(close);
    LayerResult<2> r;
    ScriptedFronts fronts(r.mesh);
    const UniformMetricField<2> metric(Metric<2>::isotropic(1));
    layers::LayerParams p;
    p.max_layers = 4;
    p.stop_when_linear = true;
    p.close_linear = close;
    layers::grow_fronts<2>(fronts, metric, p, 1, r);
    // Part 1 grew one curved layer, then stopped; part 0 went on with linear layers until the
    // maximum (it never counts as linear while part 1's front is curved).
    REQUIRE(r.layers.size() == 4);
    for (const LayerStats& st : r.layers) CHECK_FALSE(st.linear);
    CHECK(r.linear_after == -1);
    bool stopped = false;
    for (const std::string& e : r.events) stopped = stopped || e.find("part 1: stopped") != std::string::npos;
    CHECK(stopped);
    // The coverage: part 1 ended on a failure, so half of the wall has its requested stack; every
    // layer after the first covers part 0 alone; the first layer is the metric's height.
    CHECK(r.coverage.wall == doctest::Approx(2.0));
    CHECK(r.coverage.complete == doctest::Approx(0.5));
    CHECK(r.coverage.columns == 4);
    CHECK(r.coverage.columns_complete == 2);
    CHECK(r.layers[0].coverage == doctest::Approx(1.0));
    for (std::size_t k = 1; k < r.layers.size(); ++k) CHECK(r.layers[k].coverage == doctest::Approx(0.5));
  }
}

namespace {

// One column whose build from layer `empty_from` on holds no cell (its last columns ended in it).
class EndingFronts final : public ColumnFronts {
 public:
  EndingFronts(HybridMesh<2>& mesh, int empty_from) : ColumnFronts(mesh, 1), empty_from_(empty_from) {}
  layers::BuiltLayer build(std::size_t, int layer, const std::vector<double>&, const std::vector<std::uint8_t>&,
                           double) override {
    layers::BuiltLayer b;
    b.linear = true;
    if (layer >= empty_from_) {
      add({0.5, -1});  // a node the empty build made: rolled back
      return b;
    }
    b.cells[0] = next_cell(0, false);
    b.linear = false;
    b.max_clipped_rel = 0.5;
    return b;
  }

 private:
  int empty_from_;
};

}  // namespace

TEST_CASE("layer core: a build with no cell (its last columns ended) is no layer and ends the part, still curved") {
  LayerResult<2> r;
  EndingFronts fronts(r.mesh, 3);
  const UniformMetricField<2> metric(Metric<2>::isotropic(1));
  layers::LayerParams p;
  p.max_layers = 6;
  layers::grow_fronts<2>(fronts, metric, p, 1, r);
  CHECK(r.layers.size() == 2);  // layers 1 and 2; not 3 to 6 as empty rows
  CHECK(r.linear_after == -1);  // the front it ended on is curved, and an empty build does not change that
  CHECK(r.mesh.nodes.size() == 2 + 2 * 2);  // the empty build's node rolled back
  int ended = 0;
  for (const std::string& e : r.events) ended += e.find("layer 3, part 0: stopped, every column has ended") != std::string::npos ? 1 : 0;
  CHECK(ended == 1);
}
