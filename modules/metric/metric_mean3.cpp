// SPDX-License-Identifier: MIT
// Implements the closed-form weighted means of three 2D metrics (metric_mean3.h): log-Euclidean
// (Arsigny et al., SIAM J. Matrix Anal. Appl. 29, 2007) and affine-invariant (Pennec et al.,
// IJCV 66, 2006; the paper's ref. [15]).
#include "modules/metric/metric_mean3.h"

#include <cmath>

namespace plaf {
inline namespace metric {
namespace {

// The affine-invariant mean stops when its Riemannian gradient (dimensionless) is this small.
constexpr double karcher_gradient_tol = 1e-12;
constexpr int karcher_max_iterations = 100;

// A symmetric 2x2 matrix in closed form: S = l1 u u^T + l2 v v^T with u = (c, s), v = (-s, c).
// With m = tr(S)/2 and d = sqrt(((a-c)/2)^2 + b^2), l1,2 = m +- d, and u is at the angle theta
// with cos 2 theta = (a-c)/(2d), sin 2 theta = b/d; the half-angle branch keeps the larger of
// cos theta, sin theta exact. Functions of S are f(l1) u u^T + f(l2) v v^T, which keeps the
// small eigenvalue's share exact for axis-aligned S.
struct SymEig2 {
  double l1, l2, c, s;
};

SymEig2 sym_eig2(const Eigen::Matrix2d& m) {
  const double a = m(0, 0), b = 0.5 * (m(0, 1) + m(1, 0)), c = m(1, 1);
  const double mean = 0.5 * (a + c), r = 0.5 * (a - c), d = std::hypot(r, b);
  if (!(d > 0)) return {mean, mean, 1, 0};
  const double cos2 = r / d, sin2 = b / d;
  double ct, st;
  if (cos2 >= 0) {
    ct = std::sqrt(0.5 * (1 + cos2));
    st = sin2 / (2 * ct);
  } else {
    st = std::sqrt(0.5 * (1 - cos2));
    ct = sin2 / (2 * st);
  }
  return {mean + d, mean - d, ct, st};
}

Eigen::Matrix2d sym_compose(double f1, double f2, const SymEig2& e) {
  const double cc = e.c * e.c, ss = e.s * e.s, cs = e.c * e.s;
  Eigen::Matrix2d r;
  r << f1 * cc + f2 * ss, (f1 - f2) * cs, (f1 - f2) * cs, f1 * ss + f2 * cc;
  return r;
}

Eigen::Matrix2d spd_log2(const Eigen::Matrix2d& m) {
  const SymEig2 e = sym_eig2(m);
  return sym_compose(std::log(e.l1), std::log(e.l2), e);
}

// The metric exp(S): sizes exp(-l/2) along the eigenvectors (a size h means eigenvalue 1/h^2).
Metric<2> metric_exp2(const Eigen::Matrix2d& s) {
  const SymEig2 e = sym_eig2(s);
  Eigen::Matrix2d dirs;
  dirs << e.c, -e.s, e.s, e.c;
  return Metric<2>::from_directions(dirs, Eigen::Vector2d(std::exp(-0.5 * e.l1), std::exp(-0.5 * e.l2)));
}

// The SPD matrix x as a metric, without a second validation.
Metric<2> metric_from_spd(const Eigen::Matrix2d& x) {
  const SymEig2 e = sym_eig2(x);
  Eigen::Matrix2d dirs;
  dirs << e.c, -e.s, e.s, e.c;
  return Metric<2>::from_directions(dirs, Eigen::Vector2d(1 / std::sqrt(e.l1), 1 / std::sqrt(e.l2)));
}

// Weighted Karcher mean of three metrics in the affine-invariant distance (Pennec et al., the
// paper's ref. [15]): the minimiser of sum w_i d(X, M_i)^2, d(X, M) = |log(X^-1/2 M X^-1/2)|_F.
// Steepest descent in a whitened frame X = E E^T, from the log-Euclidean mean: with
// W_i = E^-1 M_i E^-T, the descent direction is T = sum w_i log W_i, and the geodesic
// X(tau) = E exp(tau T) E^T updates E <- E exp(tau T / 2), W_i <- R W_i R with R = exp(-tau T / 2).
// The step is the secant root of the directional derivative phi'(tau) = -<T(tau), T> between
// tau = 0 (-|T|^2) and tau = 1; the objective is geodesically convex, so phi'(1) >= 0 unless
// tau = 1 is itself short, and the secant step stays in (0, 1]. Near the mean (neighbouring
// background nodes) tau ~ 1 and one or two iterations suffice.
Metric<2> karcher_mean3(const std::array<const Eigen::Matrix2d*, 3>& m,
                        const std::array<const Eigen::Matrix2d*, 3>& logs, const Eigen::Vector3d& w) {
  const Eigen::Matrix2d l0 = w[0] * *logs[0] + w[1] * *logs[1] + w[2] * *logs[2];
  const SymEig2 e0 = sym_eig2(l0);
  const double h1 = std::exp(0.5 * e0.l1), h2 = std::exp(0.5 * e0.l2);
  Eigen::Matrix2d e = sym_compose(h1, h2, e0);
  const Eigen::Matrix2d e_inv = sym_compose(1 / h1, 1 / h2, e0);
  std::array<Eigen::Matrix2d, 3> wm, wl, wm1, wl1;
  for (std::size_t i = 0; i < 3; ++i) {
    wm[i] = e_inv * *m[i] * e_inv;
    wl[i] = spd_log2(wm[i]);
  }
  for (int it = 0; it < karcher_max_iterations; ++it) {
    const Eigen::Matrix2d t = w[0] * wl[0] + w[1] * wl[1] + w[2] * wl[2];
    const double g2 = t.squaredNorm();
    if (g2 <= karcher_gradient_tol * karcher_gradient_tol) break;
    // Trial step tau = 1.
    const SymEig2 et = sym_eig2(t);
    double r1 = std::exp(-0.5 * et.l1), r2 = std::exp(-0.5 * et.l2);
    Eigen::Matrix2d r = sym_compose(r1, r2, et);
    for (std::size_t i = 0; i < 3; ++i) {
      wm1[i] = r * wm[i] * r;
      wl1[i] = spd_log2(wm1[i]);
    }
    const Eigen::Matrix2d t1 = w[0] * wl1[0] + w[1] * wl1[1] + w[2] * wl1[2];
    const double slope1 = -t1.cwiseProduct(t).sum();  // phi'(1)
    const double tau = slope1 > 0 ? g2 / (g2 + slope1) : 1.0;
    constexpr double accept_unit_step = 0.999;
    if (tau >= accept_unit_step) {
      wm = wm1;
      wl = wl1;
      e = e * sym_compose(1 / r1, 1 / r2, et);
      continue;
    }
    r1 = std::exp(-0.5 * tau * et.l1);
    r2 = std::exp(-0.5 * tau * et.l2);
    r = sym_compose(r1, r2, et);
    for (std::size_t i = 0; i < 3; ++i) {
      wm[i] = r * wm[i] * r;
      wl[i] = spd_log2(wm[i]);
    }
    e = e * sym_compose(1 / r1, 1 / r2, et);
  }
  const Eigen::Matrix2d x = e * e.transpose();
  return metric_from_spd(0.5 * (x + x.transpose()));
}

}  // namespace

Metric<2> metric_mean3(MetricMean mean, const std::array<const Eigen::Matrix2d*, 3>& m,
                       const std::array<const Eigen::Matrix2d*, 3>& logs, const Eigen::Vector3d& w) {
  // Weighted log-Euclidean mean exp(sum w_i log M_i), or the affine-invariant (Karcher) mean.
  if (mean == MetricMean::LogEuclidean) return metric_exp2(w[0] * *logs[0] + w[1] * *logs[1] + w[2] * *logs[2]);
  return karcher_mean3(m, logs, w);
}

}  // namespace metric
}  // namespace plaf
