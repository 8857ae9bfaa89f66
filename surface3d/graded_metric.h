// SPDX-License-Identifier: MIT
// Metric gradation (issue 13): a size field whose sizes grow by a bounded factor between
// neighbours, so a surface refined by curvature at a leading edge or a blunt trailing edge's cap
// does not jump to the span size within one triangle (Borouchaki, Hecht & Frey, "Mesh gradation
// control", IJNME 43, 1998: the H-correction; its anisotropic, metric-space form from Alauzet,
// "Size gradation control of anisotropic meshes", Finite Elem. Anal. Des. 46, 2010).
//
// A metric M_p at p, grown to a point x, is M_p / eta^2 with eta = 1 + l_p(x - p) ln(beta),
// l_p the length of x - p in M_p: every size of M_p grows by ln(beta) per unit of its own length,
// the same in every direction of an anisotropic metric (so along a wall the tangential sizes and
// the normal one relax in proportion). Between unit-distant neighbours the sizes change by at
// most the factor 1 + ln(beta) (1.41 for beta = 1.5).
//
// The field is built on a support: points and triangles (the surface mesh a first pass of the
// remesher made on the raw field, so the support is fine where the raw sizes are small). The raw
// metric is sampled at the support points and H-corrected along the support's edges until no
// metric shrinks by more than 1e-6: M_q <- M_q intersect grown(M_p, q) (intersection as in
// metric.h) for every edge p-q, a worklist from the points that changed. The field at x is
// raw(x) intersected with the grown corrected metrics of the closest support triangle's three
// vertices, so at a support point it is that point's corrected metric and between them the raw
// field still decides wherever it is finer.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "modules/geometry/aabb_tree.h"
#include "modules/metric/metric.h"

namespace plaf {

class GradedMetricField final : public MetricField<3> {
 public:
  // beta > 1. The raw field is owned (the graded field replaces it in the run's state).
  GradedMetricField(std::unique_ptr<MetricField<3>>&& raw, const std::vector<Eigen::Vector3d>& points,
                    const std::vector<std::array<int, 3>>& triangles, double beta);
  Metric<3> evaluate(const Point& x) const override;

  // m grown from its point to the offset d (the header's eta).
  static Metric<3> grown(const Metric<3>& m, const Eigen::Vector3d& d, double ln_beta);

  // How many support points the correction made finer, and how many edge updates it took.
  std::size_t corrected_points() const { return corrected_; }
  std::size_t updates() const { return updates_; }

 private:
  std::unique_ptr<MetricField<3>> raw_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Metric<3>> corrected_metrics_;
  TriangleTree tree_;
  double ln_beta_;
  std::size_t corrected_ = 0, updates_ = 0;
};

}  // namespace plaf
