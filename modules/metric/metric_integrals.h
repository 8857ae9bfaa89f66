// SPDX-License-Identifier: MIT
// Element counts predicted from a metric before meshing (issue 17's size budget): a mesh whose
// edges have unit length in M has about
//   - sum over curves of the metric length  L = integral of sqrt(t^T M t) ds   line elements,
//   - integral of sqrt(det M_t) dA / (sqrt(3)/4)                            triangles on a surface
//     (M_t: M restricted to the surface's tangent plane; sqrt(3)/4 the unit equilateral triangle),
//   - integral of sqrt(det M) dA / (sqrt(3)/4)    triangles, or integral of sqrt(det M) dA quads,
//   - integral of sqrt(det M) dV / (1/(6 sqrt 2)) tetrahedra (the unit regular tetrahedron).
// The integrals are quadratures on samples of the metric, meant for a budget (a factor of about
// 2 either way), not for meshing: the curves at 16 points per spline piece, regions on an
// adaptive quadtree/octree (a cell is split where the density sqrt(det M) at its corners and
// centre varies by more than a factor 2 or the cell crosses the region's boundary, and every cell
// of the first 4 (2D) or 3 (3D) levels, level by level
// until max_evaluations metric evaluations are spent), surfaces at the centroids of their
// triangles split four ways up to 3 times where the density varies. A near-wall layer thinner
// than the finest tree cell is under-counted by the region quadrature: callers count layers
// from their columns instead.
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <vector>

#include "modules/geometry/spline_loop.h"
#include "modules/metric/metric.h"

namespace plaf {
inline namespace metric {

// Unit-element shape factors: elements per unit of the integral of sqrt(det M).
inline constexpr double kTrianglesPerMetricArea = 2.3094010767585030;     // 4 / sqrt(3)
inline constexpr double kTetrahedraPerMetricVolume = 8.4852813742385702;  // 6 sqrt(2)

// The metric length of a closed spline loop.
double metric_length(const SplineLoop& loop, const MetricField<2>& metric);

// The integral of a density f >= 0 over {x in box : inside(x)} (the tree described above).
template <int Dim>
double region_integral(const Eigen::Matrix<double, Dim, 1>& lo, const Eigen::Matrix<double, Dim, 1>& hi,
                       const std::function<bool(const Eigen::Matrix<double, Dim, 1>&)>& inside,
                       const std::function<double(const Eigen::Matrix<double, Dim, 1>&)>& f,
                       long max_evaluations = 200000);

// The integral of sqrt(det M) over {x in box : inside(x)}.
template <int Dim>
double metric_measure(const Eigen::Matrix<double, Dim, 1>& lo, const Eigen::Matrix<double, Dim, 1>& hi,
                      const std::function<bool(const Eigen::Matrix<double, Dim, 1>&)>& inside,
                      const MetricField<Dim>& metric, long max_evaluations = 200000);

// The integral of sqrt(det M_t) over a triangulated surface: per triangle the density at its
// centre, its halves refined (up to 3 times) where the corners' densities differ by over 2x. The
// refinement's depth is the deepest whose worst case stays within max_evaluations of the metric
// (at least the centres): a budget's estimate, not a quadrature, on a fine input need not pay
// for a coarse one's depth (the published Orion capsule's 51,736 triangles at depth 3 took 110 s
// of curvature-metric evaluations; at depth 1, seconds).
double metric_surface_area(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<int, 3>>& triangles,
                           const MetricField<3>& metric, long max_evaluations = 1000000);

}  // namespace metric
}  // namespace plaf
