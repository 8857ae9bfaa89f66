// SPDX-License-Identifier: MIT
#include "surface3d/graded_metric.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <deque>

#include "modules/base/error.h"

namespace plaf {

namespace {

// Whether g asks for a smaller size than m in some direction (relative 1e-6): the largest
// eigenvalue of g v = lambda m v exceeds one.
bool finer_somewhere(const Metric<3>& g, const Metric<3>& m) {
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> es(g.matrix(), m.matrix(), Eigen::EigenvaluesOnly);
  return es.eigenvalues().maxCoeff() > 1 + 1e-6;
}

}  // namespace

Metric<3> GradedMetricField::grown(const Metric<3>& m, const Eigen::Vector3d& d, double ln_beta) {
  const double eta = 1 + m.length(d) * ln_beta;
  return Metric<3>::from_matrix(m.matrix() / (eta * eta));
}

GradedMetricField::GradedMetricField(std::unique_ptr<MetricField<3>>&& raw, const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<std::array<int, 3>>& triangles, double beta)
    : points_(points), triangles_(triangles), ln_beta_(std::log(beta)) {
  // (Checked before the raw field is taken: a caller whose arguments are refused keeps it.)
  if (!(beta > 1)) throw ConfigError("gradation: beta must exceed 1");
  if (points_.empty() || triangles_.empty()) throw MesherError("gradation: the support has no triangles");
  raw_ = std::move(raw);
  const std::size_t n = points_.size();
  corrected_metrics_.reserve(n);
  for (const Eigen::Vector3d& p : points_) corrected_metrics_.push_back(raw_->evaluate(p));
  // Neighbours along the support's edges.
  std::vector<std::vector<int>> adj(n);
  for (const auto& t : triangles_)
    for (int k = 0; k < 3; ++k) {
      const int a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
      adj[static_cast<std::size_t>(a)].push_back(b);
      adj[static_cast<std::size_t>(b)].push_back(a);
    }
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  // The H-correction, a worklist over the points whose metric changed (all, at first).
  std::vector<std::uint8_t> queued(n, 1), changed(n, 0);
  std::deque<int> work;
  for (std::size_t p = 0; p < n; ++p) work.push_back(static_cast<int>(p));
  while (!work.empty()) {
    const std::size_t p = static_cast<std::size_t>(work.front());
    work.pop_front();
    queued[p] = 0;
    for (int qi : adj[p]) {
      const std::size_t q = static_cast<std::size_t>(qi);
      const Metric<3> g = grown(corrected_metrics_[p], points_[q] - points_[p], ln_beta_);
      if (!finer_somewhere(g, corrected_metrics_[q])) continue;
      corrected_metrics_[q] = intersect(corrected_metrics_[q], g);
      ++updates_;
      changed[q] = 1;
      if (!queued[q]) {
        queued[q] = 1;
        work.push_back(qi);
      }
    }
  }
  corrected_ = static_cast<std::size_t>(std::count(changed.begin(), changed.end(), 1));
  tree_ = TriangleTree(points_, triangles_);
}

Metric<3> GradedMetricField::evaluate(const Point& x) const {
  Metric<3> m = raw_->evaluate(x);
  const TriangleTree::Closest c = tree_.closest(x);
  for (int k = 0; k < 3; ++k) {
    const std::size_t v = static_cast<std::size_t>(triangles_[static_cast<std::size_t>(c.triangle)][static_cast<std::size_t>(k)]);
    const Metric<3> g = grown(corrected_metrics_[v], x - points_[v], ln_beta_);
    if (finer_somewhere(g, m)) m = intersect(m, g);
  }
  return m;
}

}  // namespace plaf
