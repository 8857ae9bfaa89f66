// SPDX-License-Identifier: MIT
// How far the final surface mesh is from the body it meshes (issue 13): the two-sided (Hausdorff)
// distance between the order-Q surface and the reference, each side sampled:
//  - mesh -> reference: every curved triangle at the points of its 2Q-sub-lattice (Q = 1: 2),
//    interior included, projected onto the reference (reference.h): the largest |x - project(x)|;
//  - reference -> mesh: points of the body, from the input triangulation: a surface file's own
//    vertices, edge midpoints and face centroids (it is the body), or the points of an analytic
//    body's initial triangulation on its triangles' 8-sub-lattice projected onto it; each sample's
//    closest point on the mesh is found on the Q-sub-lattice's flat sub-triangles (an AABB tree)
//    and refined on the curved triangle (Gauss-Newton kept inside it): the largest distance.
// The Hausdorff distance is the larger of the two; relative is it over the reference samples'
// bounding-box diagonal. A notch cut into a trailing edge shows on the reference -> mesh side;
// a bulge or fold on the mesh -> reference side.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "modules/geometry/reference.h"
#include "modules/geometry/tri_surface.h"
#include "modules/metric/metric.h"

namespace plaf {

struct FidelityReport {
  double to_reference = 0;                            // mesh -> reference
  Eigen::Vector3d worst_on_mesh = Eigen::Vector3d::Zero();
  double to_mesh = 0;                                 // reference -> mesh
  Eigen::Vector3d worst_on_reference = Eigen::Vector3d::Zero();
  double hausdorff = 0, diagonal = 0, relative = 0;
  Eigen::Vector3d worst = Eigen::Vector3d::Zero();    // the point of the larger side
  std::size_t mesh_samples = 0, reference_samples = 0;
  // The samples (either side) farther than measure_fidelity's far_over, with their distances:
  // where the surface must be finer to come within its tolerance.
  std::vector<std::pair<Eigen::Vector3d, double>> far;
};

// Points on the reference from a triangulation of it (see above); input_is_reference: the input
// is the body itself (a surface file), so its points are taken as they are.
std::vector<Eigen::Vector3d> reference_samples(const TriSurface& input, const ReferenceGeometry<3>& reference,
                                               bool input_is_reference);

// The diagonal of the samples' bounding box (what FidelityReport::relative divides by).
double samples_diagonal(const std::vector<Eigen::Vector3d>& samples);

// The fidelity of `surface` (its high-order nodes set, or straight) to the reference; the samples
// farther than far_over are listed in FidelityReport::far.
FidelityReport measure_fidelity(const TriSurface& surface, const ReferenceGeometry<3>& reference,
                                const std::vector<Eigen::Vector3d>& samples,
                                double far_over = std::numeric_limits<double>::infinity());

// The surface's sizes made finer where it left its body (the fidelity loop of the surface stage,
// plugins.cpp): around each spot the inner field's sizes are multiplied by the spot's factor
// within a third of its radius, the factor ramping linearly back to 1 at the radius (the
// smallest factor of the spots around a point decides). Sizes scale, directions stay.
class FidelityRefinedField final : public MetricField<3> {
 public:
  struct Spot {
    Eigen::Vector3d point;
    double factor = 1;  // (0, 1]
    double radius = 0;  // > 0
  };
  // inner owned (the refined field replaces it in the run's state), or only referred to.
  FidelityRefinedField(std::unique_ptr<MetricField<3>>&& inner, std::vector<Spot> spots);
  FidelityRefinedField(const MetricField<3>& inner, std::vector<Spot> spots);
  Metric<3> evaluate(const Point& x) const override;
  // The factor at x (1 away from every spot).
  double factor(const Eigen::Vector3d& x) const;
  std::size_t num_spots() const { return spots_.size(); }

 private:
  std::unique_ptr<MetricField<3>> owned_;
  const MetricField<3>* inner_ = nullptr;
  std::vector<Spot> spots_;
  double cell_ = 1;                                               // the hash grid's cell: the largest radius
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid_;  // spots by the cells they touch
  std::int64_t key(std::int64_t i, std::int64_t j, std::int64_t k) const;
};

}  // namespace plaf
