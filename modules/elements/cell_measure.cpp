// SPDX-License-Identifier: MIT
// Implements cell_measure (cell_measure.h): collapsed Gauss-Legendre quadrature of det J.
#include "modules/elements/cell_measure.h"

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/elements/mapping.h"

namespace plaf {
inline namespace elements {
namespace {

// Points of the largest rule: the order-4 prism's axis (degree 3Q-1 = 11) takes 7.
constexpr int max_points = 8;

struct GaussRule {
  std::array<double, max_points> x{}, w{};  // on [0, 1]
};

// The n-point Gauss-Legendre rule on [0, 1] (exact for degree 2n - 1): the roots of P_n by
// Newton's method from Chebyshev-like guesses, weights 2 / ((1 - t^2) P_n'(t)^2) on [-1, 1].
GaussRule gauss_legendre(int n) {
  GaussRule r;
  for (int i = 0; i < n; ++i) {
    double t = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 1;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1, p1 = t;  // P_0, P_1, then the recurrence up to P_n
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (t * p1 - p0) / (t * t - 1);  // P_n' from P_n and P_{n-1}
      const double step = p1 / dp;
      t -= step;
      if (std::abs(step) < 1e-16) break;
    }
    r.x[static_cast<std::size_t>(i)] = (1 + t) / 2;
    r.w[static_cast<std::size_t>(i)] = 1 / ((1 - t * t) * dp * dp);  // 2 / (...) halved for [0, 1]
  }
  return r;
}

const GaussRule& rule(int n) {
  static const auto rules = [] {
    std::array<GaussRule, max_points + 1> all;
    for (int k = 1; k <= max_points; ++k) all[static_cast<std::size_t>(k)] = gauss_legendre(k);
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
