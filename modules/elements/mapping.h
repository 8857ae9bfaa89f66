// SPDX-License-Identifier: MIT
// The mapping Jacobian J(xi) = sum_k x_k (grad phi_k(xi))^T of a Lagrange cell whose reference
// dimension equals the space dimension Dim. Coordinates are taken relative to node 0 (the
// gradients sum to zero), so a cell far from the origin loses no digits to cancellation.
#pragma once

#include <Eigen/Core>

#include "modules/elements/lagrange.h"

namespace plaf {
inline namespace elements {

// J from the basis gradients at one point: dphi[k * Dim + d] = d phi_k / d xi_d, n nodes.
template <int Dim>
Eigen::Matrix<double, Dim, Dim> mapping_jacobian_from_gradients(int n, const double* coords, const double* dphi) {
  Eigen::Matrix<double, Dim, Dim> j = Eigen::Matrix<double, Dim, Dim>::Zero();
  for (int k = 1; k < n; ++k)
    for (int i = 0; i < Dim; ++i)
      for (int d = 0; d < Dim; ++d) j(i, d) += (coords[Dim * k + i] - coords[i]) * dphi[Dim * k + d];
  return j;
}

// coords: e.size() points, row-major (Dim per node), Gmsh order; dphi: scratch of e.size() * Dim.
template <int Dim>
Eigen::Matrix<double, Dim, Dim> mapping_jacobian(const LagrangeElement& e, const double* coords, const double* xi,
                                                 double* dphi) {
  e.eval_grad(xi, dphi);
  return mapping_jacobian_from_gradients<Dim>(e.size(), coords, dphi);
}

}  // namespace elements
}  // namespace plaf
