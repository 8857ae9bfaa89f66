// SPDX-License-Identifier: MIT
// Riemannian metric tensors and metric fields, the single source of every size in plaf.
//
// Convention (written once, here): a metric M is a symmetric positive definite Dim x Dim matrix.
// The length of a vector v is sqrt(v^T M v); a size h along a unit direction e means
// e^T M e = 1 / h^2, so M = R diag(1/h_i^2) R^T for directions R (columns) and sizes h_i.
// Interpolation is log-Euclidean by default (Arsigny et al., SIAM J. Matrix Anal. Appl. 29,
// 2007) and affine-invariant on request (Pennec et al., IJCV 66, 2006; the paper's ref. [15]).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "modules/base/error.h"

namespace plaf {
inline namespace metric {

template <int Dim>
class Metric {
 public:
  using Matrix = Eigen::Matrix<double, Dim, Dim>;
  using Vector = Eigen::Matrix<double, Dim, 1>;

  Metric() : m_(Matrix::Identity()) {}
  // Throws InputError unless m is symmetric (relative 1e-10) and positive definite.
  static Metric from_matrix(const Matrix& m);
  static Metric isotropic(double h);
  // Orthonormal directions (columns) with the size along each.
  static Metric from_directions(const Matrix& directions, const Vector& sizes);

  const Matrix& matrix() const { return m_; }

  // Sizes h_i (ascending) and their unit directions (columns, matching order).
  struct Decomposition {
    Vector sizes;
    Matrix directions;
  };
  Decomposition decompose() const;

  // sqrt(v^T M v).
  double length(const Vector& v) const { return std::sqrt(v.dot(m_ * v)); }
  // The size along a unit direction: 1 / sqrt(e^T M e).
  double size_along(const Vector& unit) const { return 1.0 / std::sqrt(unit.dot(m_ * unit)); }
  // Largest and smallest sizes.
  double max_size() const;
  double min_size() const;

  // Matrix logarithm / exponential through the eigen-decomposition.
  Matrix log() const;
  static Metric exp(const Matrix& symmetric);

 private:
  explicit Metric(const Matrix& m) : m_(m) {}
  Matrix m_;
};

// Weighted means of metrics (weights >= 0, not all zero; they are normalised).
template <int Dim>
Metric<Dim> log_euclidean_mean(std::span<const Metric<Dim>> metrics, std::span<const double> weights);
// Karcher mean in the affine-invariant Riemannian distance, iterated to relative 1e-12.
template <int Dim>
Metric<Dim> affine_invariant_mean(std::span<const Metric<Dim>> metrics, std::span<const double> weights);
// Intersection by simultaneous reduction: the largest metric (smallest sizes) contained in
// both unit balls' intersection along the common eigenvectors (Frey & George, Mesh Generation).
template <int Dim>
Metric<Dim> intersect(const Metric<Dim>& a, const Metric<Dim>& b);

enum class MetricMean { LogEuclidean, AffineInvariant };
MetricMean parse_metric_mean(const std::string& name);  // "log_euclidean" | "affine_invariant"

// A metric at every point of space. evaluate() is called from several threads at once (the
// quality stage measures edges on worker threads, modules/base/parallel.h): an implementation
// keeps no mutable state (no caches without their own locking).
template <int Dim>
class MetricField {
 public:
  using Point = Eigen::Matrix<double, Dim, 1>;
  virtual ~MetricField() = default;
  virtual Metric<Dim> evaluate(const Point& x) const = 0;
};

template <int Dim>
class UniformMetricField final : public MetricField<Dim> {
 public:
  explicit UniformMetricField(const Metric<Dim>& m) : m_(m) {}
  Metric<Dim> evaluate(const typename MetricField<Dim>::Point&) const override { return m_; }

 private:
  Metric<Dim> m_;
};

// The intersection of several fields (`metric: {intersect: [...]}`, run_config.h): at every point
// the first field's metric intersected with each other's in turn (intersect above: along the
// common eigenvectors of each pair the smaller size, so the unit ball lies inside every field's;
// with three or more fields the result may depend on their order where no common basis exists).
// Throws Error on an empty list.
template <int Dim>
class IntersectedMetricField final : public MetricField<Dim> {
 public:
  using Fields = std::vector<std::shared_ptr<const MetricField<Dim>>>;
  explicit IntersectedMetricField(Fields fields) : fields_(std::move(fields)) {
    if (fields_.empty()) throw Error("IntersectedMetricField: no field to intersect");
  }
  Metric<Dim> evaluate(const typename MetricField<Dim>::Point& x) const override {
    Metric<Dim> m = fields_.front()->evaluate(x);
    for (std::size_t i = 1; i < fields_.size(); ++i) m = intersect(m, fields_[i]->evaluate(x));
    return m;
  }

 private:
  Fields fields_;
};

// Metric length of the straight segment a -> b, by Gauss-Legendre quadrature of
// sqrt(t^T M(x) t) (exact for a constant metric).
template <int Dim>
double metric_length(const MetricField<Dim>& field, const Eigen::Matrix<double, Dim, 1>& a,
                     const Eigen::Matrix<double, Dim, 1>& b, int gauss_points = 5);

// Metric length of a curved Lagrange edge of order q = nodes - 1 given in Gmsh line order
// (end, end, interior...), row-major coordinates: integral of sqrt(x'(u)^T M(x(u)) x'(u)) du.
template <int Dim>
double metric_length_curved(const MetricField<Dim>& field, const double* coords, int order, int gauss_points = 8);

// Gauss-Legendre points on [0,1] and weights (n = 1..16).
void gauss_legendre_01(int n, double* points, double* weights);

}  // namespace metric
}  // namespace plaf
