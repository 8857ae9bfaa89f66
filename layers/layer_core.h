// SPDX-License-Identifier: MIT
// The dimension-generic core of the prismatic layers of K. J. Fidkowski, "Anisotropic
// Metric-Based Curved Meshing Using Prismatic Layers" (PLAF), Sec. II.A-B (2D) and II.E (3D):
// everything a layer does that does not depend on the shape of the front.
//
// Per layer, for every part of the front (a loop in 2D, a connected surface in 3D):
//  1. stop rules: a part stops when it runs out of layers, when the metric is isotropic at its
//     nodes (isotropic_stop), when a layer cannot be made valid, or when every column has ended
//     (isotropic at some, stopped locally at the rest; a build left with no cell is no layer and
//     does not make the front linear); a column stops where its
//     stack would fill more than its share of the gap to a facing wall, or where a concave front's
//     columns would run into their focus (proximity, where the front supports it:
//     FrontGrower::stop_point_room, graded_room);
//  2. the front's specifics (FrontGrower: normals, corner fans and concave merges in 2D, ridge and
//     corner fans in 3D) build the new cells, with heights from the metric (layer_height) and the
//     high-order nodes of the new front attenuated toward their linear positions (attenuate,
//     Fig. 5);
//  3. certify-and-shrink: every new cell is certified (Bezier bounds of its Jacobian, validity.h)
//     and the new front is tested for collisions (FrontGrower::collisions); where either fails the
//     heights around the failure are halved (never below 1/16 of the metric's) and the layer is
//     rebuilt, shrink_attempts times; when
//     that fails on an attenuated build, the part's layer is rebuilt with f_atten halved (up to 4
//     times: the attenuation folds cells that no height shrink mends, e.g. f_atten = 1 on a thin
//     layer; a retry with more failures ends them, at the f_atten before it; none in a layer
//     whose attenuation is fixed, BuiltLayer::fixed_f_atten); a part that
//     still fails stops growing (an event);
//     (3D, FrontGrower::stops_locally) where the failures remain with their heights at the floor,
//     the stop points behind them stop there (their columns end; the part's layer becomes
//     tetrahedra around them, grow_layers_3d.h, whose tops attenuate by at most 0.05 of the
//     height, a pull those tetrahedra can follow) and the layer is rebuilt, the rest of the part
//     growing on to its stop rule: a failure ends the stack locally, not on the whole part;
//  4. the per-layer table (LayerStats), the coverage (LayerCoverage: how much of the wall each
//     layer covers, whether each column reached its stop rule, the first layer's height against
//     the metric's) and the events record what happened.
// With close_linear, a part that stops while its front is still curved gets one closing layer
// with straight tops (unlimited attenuation), so the fill starts from a linear front: its heights
// start at the metric's and double around every cell still invalid (a straight top too low over
// its curved base's sag) and halve around crossings, up to closing_attempts builds, then the
// whole part's heights are raised to 1.5, 3 and 6 times its attenuation need (layer_core.cpp).
// Where none of those is valid and the front stops locally, the part closes around its stopped
// columns (and, round by round, those behind closing cells that still fail): their faces keep
// their curve, which the fill meets with curved tetrahedra (volume/hybrid_fill3d.h).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "modules/elements/lagrange.h"
#include "modules/mesh/curved_front.h"
#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/linear_front.h"
#include "modules/metric/metric.h"

namespace plaf::layers {

// Where the metric is isotropic at a front node (a layer would be as tall as the metric's size
// in every direction): stop that node alone (Node; its elements stay in the front, and
// transition cells join them to the moving neighbours), stop the part when it is so at every
// node (All) or at any node (Any), or never (Off).
enum class IsotropicStop { Off, Node, Any, All };

// The height of a high-order front node: its own metric height along its own normal (Own), or the
// interpolation of its element's vertex heights (Interpolated: a node the attenuation pulled
// toward its chord does not feed back a smaller wall-law height); Default is Interpolated in 2D
// and 3D. With Own that feedback is unstable where layers grow as tall as a curved front's
// elements: at the NACA 0012's leading edge (h0 1e-6 c, g 1.5, Q3) the attenuation need rose
// from 2.2 to 15 heights over layers 16-22 and the front dented until no layer could close it
// (issue 12); interpolated, the same run is linear after 20 layers with every layer's min scaled
// Jacobian 0.66. A smooth 2D section and its extrusion grow the same layers
// (tests/layers/extrusion_match_test.cpp).
enum class HighOrderHeights { Default, Own, Interpolated };

struct LayerParams {
  int max_layers = 24;
  bool stop_when_linear = false;
  double f_atten = 0.2;
  double corner_angle_deg = 30.0;  // |turning angle| (2D) or dihedral deviation (3D) of a corner/ridge
  double fan_angle_deg = 45.0;     // largest angle between adjacent normals of a convex fan
  // 3D: a ridge fan may end where its ridge fades (grow_layers_3d.h, step 6: a fade narrows it
  // and closes it to the node's merged normal); false: such a chain keeps the merged normal
  // along its whole ridge.
  bool fan_fades = false;
  bool integrate_height = false;   // unit metric length along the normal instead of the size
  bool smooth_normals = false;     // 2D: one Laplacian pass over each new layer's normals; 3D: the
                                   // relaxation of grow_layers_3d.h, step 2
  IsotropicStop isotropic_stop = IsotropicStop::Off;
  HighOrderHeights high_order_heights = HighOrderHeights::Default;
  int shrink_attempts = 4;
  // The run fails below this coverage of the requested stack (LayerCoverage::complete; the layer
  // plugins give the verdict).
  double min_coverage = 0.95;
  // Local stops (step 3) where the front supports them; false stops the whole part instead.
  bool local_stops = true;
  // The proximity rule (step 1): the share of its half of the gap to a facing wall (along its
  // column, from its wall) that a column's stack may fill; a column stops before the layer whose
  // metric height would take it beyond (from the second layer on: every column that can grows its
  // first layer). Two facing stacks of share 0.8 leave a fifth of the gap
  // to the fill. 0 turns the rule off. A column so stopped reached its stop rule (the stack that
  // fits there), and the coverage says how much of the wall stopped so (LayerCoverage::proximity).
  // Where the front is concave a layer also takes at most half the distance to where its
  // column meets a neighbour (graded_room; 2D and 3D), whatever `proximity` is above 0.
  double proximity = 0.8;
  // End with a linear front (for the fill): a part whose front is still curved when it stops
  // gets a closing layer with straight tops.
  bool close_linear = false;
  // Where the table's layer heights are measured (LayerStats::height_*): the columns whose base
  // this accepts (empty: every column). An extruded section's run measures at mid-span.
  std::function<bool(const Eigen::Vector3d& base)> height_probe;
  // Told each layer as it is accepted, its row of the table (the quality columns not yet
  // measured): the run's progress (modules/pipeline/layer_table.h, layer_progress). May be empty.
  std::function<void(const LayerStats& accepted)> on_layer;
};

// The layer's height along unit normal n at x (Sec. II.B): the metric size h = 1/sqrt(n^T M n),
// or (integrate) the distance to unit metric length along the normal.
template <int Dim>
double layer_height(const MetricField<Dim>& metric, const Eigen::Matrix<double, Dim, 1>& x,
                    const Eigen::Matrix<double, Dim, 1>& n, bool integrate);

// Curvature attenuation (Fig. 5): moves each of the n tops[k] toward targets[k] (its position on
// the linear element) by at most f_atten * heights[k]. Returns the largest needed move over its
// height among the clipped nodes (0 when none was clipped: the element is now linear). Pointers,
// not vectors: it runs on every high-order node of every layer and allocates nothing.
template <int Dim>
double attenuate(Eigen::Matrix<double, Dim, 1>* tops, const Eigen::Matrix<double, Dim, 1>* targets,
                 const double* heights, std::size_t n, double f_atten);

// True when the metric is isotropic to 0.1 % (its largest size within 0.999 of its smallest).
template <int Dim>
bool is_isotropic(const Metric<Dim>& m);

// The proximity rule's dimension-generic half (step 1), for FrontGrower::stop_point_room. Per
// stop point k of a part: its place x[k], the unit direction its column grows along (unit[k];
// zero where unknown), its edges to the neighbouring stop points (index, length), the height of
// its stack above its wall (below[k]) and the stack height a facing wall allows it (allowed[k],
// infinite where none faces it). The allowances are graded over the front, A_k <= A_j +
// kProximityGrade |x_k - x_j| (a shortest path over the edges), so a stop ramps down over the
// front instead of ending in a cliff beside columns that grow on; their room is A - below.
// A concave front focuses: two neighbouring columns k, j meet where their edge e = x[j] - x[k]
// shrinks to nothing along itself, at |e|^2 / -((unit[j] - unit[k]) . e) ahead (the radius of a
// concave arc through them), and its cells invert there whether or not a wall faces them (a
// cow's neck, a leg's root, an airfoil's cove under a tall stack: rays meet no wall there and
// the layers failed at the focus). A column's room is also at most kFocalShare of the distance
// to its nearest focus, graded in the same way (a distance from the front: no wall depth in it).
// Returns the room (infinite where nothing limits the column). Not in the paper (its bodies'
// stacks stay far from their foci); the robust choice, shared by 2D and 3D so that an extruded
// section grows the section's layers.
inline constexpr double kFocalShare = 0.5;
inline constexpr double kProximityGrade = 0.5;
template <int Dim>
std::vector<double> graded_room(const std::vector<Eigen::Matrix<double, Dim, 1>>& x,
                                const std::vector<Eigen::Matrix<double, Dim, 1>>& unit,
                                const std::vector<std::vector<std::pair<std::size_t, double>>>& edges,
                                const std::vector<double>& below, std::vector<double> allowed);

// What a front's specifics built for one layer of one part: the new cells of the two cell types
// (cell_types()), each in Gmsh order over LayerResult::mesh.nodes.
struct BuiltLayer {
  std::array<std::vector<NodeId>, 2> cells;
  double max_clipped_rel = 0;
  bool linear = true;
  // Above 0: the fraction of the height the tops' attenuation used instead of f_atten (a 3D
  // layer with stopped columns, grow_layers_3d.h step 7); no smaller f_atten is tried, and the
  // table's f_atten is this one.
  double fixed_f_atten = 0;
  // The layer's height along every vertex column grown along a normal (2D: regular, concave and
  // fan normals; 3D: the same, a fan's arc directions left out): its base (z = 0 in 2D),
  // |top - base| and the height scale it was built with (1: the metric's height; below after
  // shrinks, above in a closing layer). The core summarises them into LayerStats::height_* and
  // the first layer's LayerCoverage::first_*.
  std::vector<std::array<double, 5>> columns;
};

// A failure of the last build: cell `index` of cell type `block`, or (block == kFrontElement)
// element `index` of the new front.
struct LayerFailure {
  static constexpr int kFrontElement = -1;
  int block = 0;
  std::size_t index = 0;
};

// The front's specifics, one implementation per dimension (grow_layers_2d.h, grow_layers_3d.h).
// It appends the nodes it creates to the mesh it was built on; the core rolls them back when a
// build is rejected.
template <int Dim>
class FrontGrower {
 public:
  using Vec = Eigen::Matrix<double, Dim, 1>;
  virtual ~FrontGrower() = default;
  virtual std::array<CellType, 2> cell_types() const = 0;  // main, transition
  virtual std::size_t num_parts() const = 0;
  // How events name a part ("loop wall").
  virtual std::string part_name(std::size_t part) const = 0;
  // The number of height scale entries of a part (one per front node).
  virtual std::size_t num_sites(std::size_t part) const = 0;
  // The nodes whose metric decides the isotropic stop; `stopped` in build() is indexed like them.
  virtual std::vector<Vec> stop_points(std::size_t part) const = 0;
  // Their number (without gathering them: the isotropic stop is off in most runs).
  virtual std::size_t num_stop_points(std::size_t part) const = 0;
  // One layer on a part; heights are multiplied by scale[site].
  virtual BuiltLayer build(std::size_t part, int layer, const std::vector<double>& scale,
                           const std::vector<std::uint8_t>& stopped, double f_atten) = 0;
  // Elements of the last build's new front that cross another part's front or itself.
  virtual std::vector<std::size_t> collisions(std::size_t part) const = 0;
  // What collisions() finds, for the events ("front crossings" in 2D; 3D adds folds).
  virtual std::string collision_kind() const { return "front crossings"; }
  // A point of element e of the last build's new front (for events).
  virtual Vec front_point(std::size_t e) const = 0;
  // Multiplies the heights around the failures of the last build by `factor` (0.5: a shrink; 2: a
  // closing layer's cell too low for the sag of its curved base).
  virtual void rescale(std::size_t part, const std::vector<LayerFailure>& failures, double factor,
                       std::vector<double>& scale) const = 0;
  // The last build becomes the part's front.
  virtual void accept(std::size_t part) = 0;

  // Local stops (step 3): a front that can stop single stop points (`stopped` in build()) where
  // no valid cell can be grown even at the height floor, while the rest of the part grows on.
  virtual bool stops_locally() const { return false; }
  // The stop points behind the failures of the last build (what a local stop stops).
  virtual std::vector<std::size_t> failure_stop_points(std::size_t /*part*/,
                                                       const std::vector<LayerFailure>& /*failures*/) const {
    return {};
  }
  // The wall measure (2D length, 3D area) each stop point stands for, for the coverage.
  virtual std::vector<double> stop_point_measure(std::size_t part) const = 0;
  // The proximity rule (step 1): per stop point, the height its column may still grow before its
  // stack fills `share` of its half of the gap to a facing wall (infinite where no wall faces
  // it); empty for a front without the rule.
  virtual std::vector<double> stop_point_room(std::size_t /*part*/, double /*share*/) const { return {}; }
};

// Grows layers on every part of `grower` into r.mesh (whose nodes the grower appends to),
// filling r.layers, r.linear_after and r.events (steps 1-4 above, and the closing layer).
template <int Dim>
void grow_fronts(FrontGrower<Dim>& grower, const MetricField<Dim>& metric, const LayerParams& params, int order,
                 LayerResult<Dim>& r);

}  // namespace plaf::layers
