// SPDX-License-Identifier: MIT
// Metric tensors, their means and intersection, and metric lengths (see metric.h).
#include "modules/metric/metric.h"

#include <array>
#include <cmath>
#include <vector>

#include "modules/base/error.h"
#include "modules/elements/lagrange.h"

namespace plaf {
inline namespace metric {

template <int Dim>
Metric<Dim> Metric<Dim>::from_matrix(const Matrix& m) {
  if (!m.allFinite()) throw InputError("metric tensor is not finite");
  const double scale = m.cwiseAbs().maxCoeff();
  if (!(scale > 0)) throw InputError("metric tensor is zero (not positive definite)");
  if ((m - m.transpose()).cwiseAbs().maxCoeff() > 1e-10 * scale) throw InputError("metric tensor is not symmetric");
  const Matrix sym = 0.5 * (m + m.transpose());
  Eigen::SelfAdjointEigenSolver<Matrix> es(sym);
  if (es.eigenvalues().minCoeff() <= 0) throw InputError("metric tensor is not positive definite");
  return Metric(sym);
}

template <int Dim>
Metric<Dim> Metric<Dim>::isotropic(double h) {
  if (!(h > 0) || !std::isfinite(h)) throw InputError("metric size must be positive, got " + std::to_string(h));
  return Metric(Matrix::Identity() / (h * h));
}

template <int Dim>
Metric<Dim> Metric<Dim>::from_directions(const Matrix& directions, const Vector& sizes) {
  for (int i = 0; i < Dim; ++i)
    if (!(sizes[i] > 0) || !std::isfinite(sizes[i]))
      throw InputError("metric size must be positive, got " + std::to_string(sizes[i]));
  const Vector inv = sizes.array().square().inverse().matrix();
  const Matrix m = directions * inv.asDiagonal() * directions.transpose();
  return Metric(0.5 * (m + m.transpose()));
}

template <int Dim>
typename Metric<Dim>::Decomposition Metric<Dim>::decompose() const {
  Eigen::SelfAdjointEigenSolver<Matrix> es(m_);
  // Eigenvalues ascend, so sizes descend; reverse to ascending sizes.
  Decomposition d;
  for (int i = 0; i < Dim; ++i) {
    d.sizes[i] = 1.0 / std::sqrt(es.eigenvalues()[Dim - 1 - i]);
    d.directions.col(i) = es.eigenvectors().col(Dim - 1 - i);
  }
  return d;
}

template <int Dim>
double Metric<Dim>::max_size() const {
  Eigen::SelfAdjointEigenSolver<Matrix> es(m_, Eigen::EigenvaluesOnly);
  return 1.0 / std::sqrt(es.eigenvalues()[0]);
}

template <int Dim>
double Metric<Dim>::min_size() const {
  Eigen::SelfAdjointEigenSolver<Matrix> es(m_, Eigen::EigenvaluesOnly);
  return 1.0 / std::sqrt(es.eigenvalues()[Dim - 1]);
}

template <int Dim>
typename Metric<Dim>::Matrix Metric<Dim>::log() const {
  Eigen::SelfAdjointEigenSolver<Matrix> es(m_);
  const Vector l = es.eigenvalues().array().log().matrix();
  return es.eigenvectors() * l.asDiagonal() * es.eigenvectors().transpose();
}

template <int Dim>
Metric<Dim> Metric<Dim>::exp(const Matrix& symmetric) {
  Eigen::SelfAdjointEigenSolver<Matrix> es(symmetric);
  const Vector e = es.eigenvalues().array().exp().matrix();
  const Matrix m = es.eigenvectors() * e.asDiagonal() * es.eigenvectors().transpose();
  return Metric(0.5 * (m + m.transpose()));
}

namespace {

template <int Dim>
double total_weight(std::span<const Metric<Dim>> metrics, std::span<const double> weights) {
  if (metrics.empty() || metrics.size() != weights.size())
    throw Error("metric mean needs as many weights as metrics (and at least one)");
  double w = 0;
  for (double x : weights) {
    if (!(x >= 0)) throw Error("metric mean weights must be non-negative");
    w += x;
  }
  if (!(w > 0)) throw Error("metric mean weights sum to zero");
  return w;
}

template <int Dim>
using Mat = Eigen::Matrix<double, Dim, Dim>;

template <int Dim>
Mat<Dim> sym_fn(const Mat<Dim>& m, double (*fn)(double)) {
  Eigen::SelfAdjointEigenSolver<Mat<Dim>> es(0.5 * (m + m.transpose()));
  Eigen::Matrix<double, Dim, 1> v;
  for (int i = 0; i < Dim; ++i) v[i] = fn(es.eigenvalues()[i]);
  return es.eigenvectors() * v.asDiagonal() * es.eigenvectors().transpose();
}

double log_fn(double x) {
  return std::log(x);
}
double exp_fn(double x) {
  return std::exp(x);
}

}  // namespace

template <int Dim>
Metric<Dim> log_euclidean_mean(std::span<const Metric<Dim>> metrics, std::span<const double> weights) {
  const double w = total_weight(metrics, weights);
  Mat<Dim> acc = Mat<Dim>::Zero();
  for (std::size_t i = 0; i < metrics.size(); ++i)
    if (weights[i] > 0) acc += (weights[i] / w) * metrics[i].log();
  return Metric<Dim>::exp(acc);
}

template <int Dim>
Metric<Dim> affine_invariant_mean(std::span<const Metric<Dim>> metrics, std::span<const double> weights) {
  const double w = total_weight(metrics, weights);
  // The minimiser of sum w_i d(X, M_i)^2 with d(X, M) = |log(X^-1/2 M X^-1/2)|_F, by steepest
  // descent along geodesics in a whitened frame X = E E^T, from the log-Euclidean mean (exact for
  // commuting metrics). With W_i = E^-1 M_i E^-T the descent direction is T = sum w_i log W_i and
  // the geodesic X(tau) = E exp(tau T) E^T. The step tau is the secant root of the directional
  // derivative phi'(tau) = -<T(tau), T> between tau = 0 (-|T|^2) and tau = 1; the objective is
  // geodesically convex, so the step stays in (0, 1] and never overshoots (a unit step, the
  // plain fixed-point iteration, oscillates for strongly anisotropic, far-apart metrics).
  const std::size_t n = metrics.size();
  Mat<Dim> e = Metric<Dim>::exp(0.5 * log_euclidean_mean(metrics, weights).log()).matrix();
  std::vector<Mat<Dim>> wm(n), wl(n), wm1(n), wl1(n);
  const Mat<Dim> e_inv = e.inverse();
  for (std::size_t i = 0; i < n; ++i) {
    wm[i] = e_inv * metrics[i].matrix() * e_inv.transpose();
    wl[i] = sym_fn<Dim>(wm[i], log_fn);
  }
  auto direction = [&](const std::vector<Mat<Dim>>& logs) {
    Mat<Dim> t = Mat<Dim>::Zero();
    for (std::size_t i = 0; i < n; ++i)
      if (weights[i] > 0) t += (weights[i] / w) * logs[i];
    return t;
  };
  for (int it = 0; it < 100; ++it) {
    const Mat<Dim> t = direction(wl);
    const double g2 = t.squaredNorm();
    if (g2 <= 1e-24) break;
    Mat<Dim> r = sym_fn<Dim>(-0.5 * t, exp_fn);
    for (std::size_t i = 0; i < n; ++i) {
      wm1[i] = r * wm[i] * r;
      wl1[i] = sym_fn<Dim>(wm1[i], log_fn);
    }
    const double slope1 = -direction(wl1).cwiseProduct(t).sum();  // phi'(1)
    const double tau = slope1 > 0 ? g2 / (g2 + slope1) : 1.0;
    if (tau >= 0.999) {
      std::swap(wm, wm1);
      std::swap(wl, wl1);
    } else {
      r = sym_fn<Dim>(-0.5 * tau * t, exp_fn);
      for (std::size_t i = 0; i < n; ++i) {
        wm[i] = r * wm[i] * r;
        wl[i] = sym_fn<Dim>(wm[i], log_fn);
      }
    }
    e = (e * sym_fn<Dim>(0.5 * (tau >= 0.999 ? 1.0 : tau) * t, exp_fn)).eval();
  }
  const Mat<Dim> x = e * e.transpose();
  return Metric<Dim>::from_matrix(0.5 * (x + x.transpose()));
}

template <int Dim>
Metric<Dim> intersect(const Metric<Dim>& a, const Metric<Dim>& b) {
  // Generalised eigenvectors P of (b, a) diagonalise both: P^T a P = I, P^T b P = diag(mu).
  Eigen::GeneralizedSelfAdjointEigenSolver<Mat<Dim>> es(b.matrix(), a.matrix());
  const Mat<Dim> p = es.eigenvectors();
  Eigen::Matrix<double, Dim, 1> d;
  for (int i = 0; i < Dim; ++i) {
    const double la = p.col(i).dot(a.matrix() * p.col(i));
    const double lb = p.col(i).dot(b.matrix() * p.col(i));
    d[i] = std::max(la, lb);
  }
  const Mat<Dim> pinv = p.inverse();
  return Metric<Dim>::from_matrix(pinv.transpose() * d.asDiagonal() * pinv);
}

MetricMean parse_metric_mean(const std::string& name) {
  if (name == "log_euclidean") return MetricMean::LogEuclidean;
  if (name == "affine_invariant") return MetricMean::AffineInvariant;
  throw ConfigError("unknown metric mean '" + name + "' (known: log_euclidean, affine_invariant)");
}

void gauss_legendre_01(int n, double* points, double* weights) {
  if (n < 1 || n > 16) throw Error("Gauss-Legendre rule with " + std::to_string(n) + " points is not provided");
  // Newton iteration on P_n from Chebyshev guesses; mapped from [-1,1] to [0,1].
  for (int i = 0; i < n; ++i) {
    double x = std::cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double pk = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = pk;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    points[i] = 0.5 * (1.0 - x);
    weights[i] = 1.0 / ((1.0 - x * x) * dp * dp);  // (2/((1-x^2)P'^2)) / 2
  }
}

namespace {

// Cached Gauss-Legendre rules on [0,1].
struct GaussRule {
  std::array<double, 16> x{}, w{};
};
const GaussRule& gauss_rule(int n) {
  static const std::array<GaussRule, 17> rules = [] {
    std::array<GaussRule, 17> r{};
    for (int k = 1; k <= 16; ++k) gauss_legendre_01(k, r[k].x.data(), r[k].w.data());
    return r;
  }();
  if (n < 1 || n > 16) throw Error("Gauss-Legendre rule with " + std::to_string(n) + " points is not provided");
  return rules[n];
}

}  // namespace

template <int Dim>
double metric_length(const MetricField<Dim>& field, const Eigen::Matrix<double, Dim, 1>& a,
                     const Eigen::Matrix<double, Dim, 1>& b, int gauss_points) {
  const GaussRule& g = gauss_rule(gauss_points);
  const Eigen::Matrix<double, Dim, 1> t = b - a;
  double len = 0;
  for (int i = 0; i < gauss_points; ++i) len += g.w[i] * field.evaluate(a + g.x[i] * t).length(t);
  return len;
}

template <int Dim>
double metric_length_curved(const MetricField<Dim>& field, const double* coords, int order, int gauss_points) {
  const LagrangeElement& e = lagrange_element(CellType::Line, order);
  const GaussRule& g = gauss_rule(gauss_points);
  std::array<double, max_order + 1> phi{}, dphi{};
  double len = 0;
  for (int i = 0; i < gauss_points; ++i) {
    e.eval(&g.x[i], phi.data());
    e.eval_grad(&g.x[i], dphi.data());
    Eigen::Matrix<double, Dim, 1> x = Eigen::Matrix<double, Dim, 1>::Zero(), t = x;
    for (int k = 0; k <= order; ++k)
      for (int d = 0; d < Dim; ++d) {
        x[d] += phi[k] * coords[k * Dim + d];
        t[d] += dphi[k] * coords[k * Dim + d];
      }
    len += g.w[i] * field.evaluate(x).length(t);
  }
  return len;
}

template class Metric<2>;
template class Metric<3>;
template Metric<2> log_euclidean_mean(std::span<const Metric<2>>, std::span<const double>);
template Metric<3> log_euclidean_mean(std::span<const Metric<3>>, std::span<const double>);
template Metric<2> affine_invariant_mean(std::span<const Metric<2>>, std::span<const double>);
template Metric<3> affine_invariant_mean(std::span<const Metric<3>>, std::span<const double>);
template Metric<2> intersect(const Metric<2>&, const Metric<2>&);
template Metric<3> intersect(const Metric<3>&, const Metric<3>&);
template double metric_length(const MetricField<2>&, const Eigen::Vector2d&, const Eigen::Vector2d&, int);
template double metric_length(const MetricField<3>&, const Eigen::Vector3d&, const Eigen::Vector3d&, int);
template double metric_length_curved(const MetricField<2>&, const double*, int, int);
template double metric_length_curved(const MetricField<3>&, const double*, int, int);

}  // namespace metric
}  // namespace plaf
