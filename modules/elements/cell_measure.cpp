// SPDX-License-Identifier: MIT
// Implements cell_measure (cell_measure.h): collapsed Gauss-Legendre quadrature of det J.
#include "modules/elements/cell_measure.h"

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/elements/mapping.h"
#include "modules/metric/metric.h"

namespace plaf {
inline namespace elements {
namespace {

// Points of the largest rule: the order-4 prism's axis (degree 3Q-1 = 11) takes 7.
constexpr int max_points = 8;

struct GaussRule {
  std::array<double, max_points> x{}, w{};  // on [0, 1]
};

// The n-point Gauss-Legendre rules on [0, 1] (exact for degree 2n - 1), built once; the rule
// itself is the metric module's (gauss_legendre_01, metric.h), the one every quadrature of plaf uses.
const GaussRule& rule(int n) {
  static const auto rules = [] {
    std::array<GaussRule, max_points + 1> all;
    for (int k = 1; k <= max_points; ++k) {
      GaussRule& r = all[static_cast<std::size_t>(k)];
      gauss_legendre_01(k, r.x.data(), r.w.data());
    }
    return all;
  }();
  return rules[static_cast<std::size_t>(n)];
}

// Points for a polynomial of degree deg times up to two collapse factors (1 - b)(1 - c)^2 along
// one axis: 2n - 1 >= deg + 2.
int points_for(int deg) {
  return deg / 2 + 2;
}

}  // namespace

double cell_measure(CellType type, int order, const double* coords) {
  check_order(order);
  if (ref_dim(type) < 2) throw InputError(std::string("cell_measure: a ") + cell_name(type) + " has no area or volume");
  const LagrangeElement& e = lagrange_element(type, order);
  std::array<double, (max_order + 1) * (max_order + 1) * (max_order + 2) / 2 * 3> dphi{};
  const auto det = [&](double u, double v, double w) {
    const double xi[3] = {u, v, w};
    return e.dim() == 2 ? mapping_jacobian<2>(e, coords, xi, dphi.data()).determinant()
                        : mapping_jacobian<3>(e, coords, xi, dphi.data()).determinant();
  };
  const int q = order;
  double sum = 0;
  switch (type) {
    case CellType::Quadrilateral: {
      const GaussRule& g = rule(q);  // degree 2Q - 1 per axis
      for (int i = 0; i < q; ++i)
        for (int j = 0; j < q; ++j) sum += g.w[i] * g.w[j] * det(g.x[i], g.x[j], 0);
      break;
    }
    case CellType::Triangle:
    case CellType::Prism: {
      // (u, v) = (a (1 - b), b), du dv = (1 - b) da db; the prism's axis w by its own rule.
      const bool prism = type == CellType::Prism;
      const int n = points_for(prism ? 3 * q - 2 : 2 * (q - 1));
      const GaussRule& g = rule(n);
      const int nw = prism ? points_for(3 * q - 1) : 1;
      const GaussRule& gw = rule(nw);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          for (int k = 0; k < nw; ++k) {
            const double a = g.x[i], b = g.x[j];
            const double weight = g.w[i] * g.w[j] * (1 - b) * (prism ? gw.w[k] : 1.0);
            sum += weight * det(a * (1 - b), b, prism ? gw.x[k] : 0.0);
          }
      break;
    }
    case CellType::Tetrahedron: {
      // (u, v, w) = (a (1 - b)(1 - c), b (1 - c), c), du dv dw = (1 - b)(1 - c)^2 da db dc.
      const int n = points_for(3 * (q - 1));
      const GaussRule& g = rule(n);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          for (int k = 0; k < n; ++k) {
            const double a = g.x[i], b = g.x[j], c = g.x[k];
            sum += g.w[i] * g.w[j] * g.w[k] * (1 - b) * (1 - c) * (1 - c) * det(a * (1 - b) * (1 - c), b * (1 - c), c);
          }
      break;
    }
    case CellType::Line:
      break;
  }
  return sum;
}

}  // namespace elements
}  // namespace plaf
