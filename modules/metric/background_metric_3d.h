// SPDX-License-Identifier: MIT
// The background-mesh metric in 3D (background_metric.h has the 2D field and the readers of
// both): a metric at the nodes of a linear tetrahedral mesh, the metric of the previous
// adaptation step (paper Sec. II.D). Evaluation locates the containing tetrahedron with a
// bounding-volume tree over the tetrahedra's boxes (background_tet_tree.h; O(log n) per point
// for a mesh whose boxes overlap boundedly) and takes the weighted mean of its four vertex
// metrics with the point's barycentric weights: log-Euclidean exp(sum w_i log M_i) (default) or
// the affine-invariant Karcher mean (metric.h, affine_invariant_mean). A point outside the mesh
// takes the metric of the nearest tetrahedron at its closest point to the point, found by branch
// and bound over the same tree. Tetrahedra of zero volume (relative 1e-13) are never located.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "modules/metric/background_metric.h"
#include "modules/metric/metric.h"

namespace plaf {
inline namespace metric {

class BackgroundMetricField3 final : public MetricField<3> {
 public:
  // InputError if the mesh fails check_background_mesh or has no tetrahedron of positive volume.
  BackgroundMetricField3(BackgroundMesh<3> mesh, MetricMean mean);
  ~BackgroundMetricField3() override;
  Metric<3> evaluate(const Eigen::Vector3d& x) const override;

  // The tetrahedron containing x (closed, with a relative tolerance), or -1: for tests.
  int locate(const Eigen::Vector3d& x) const;
  // Barycentric coordinates of x in tetrahedron t (-1 components outside it).
  Eigen::Vector4d barycentric(int t, const Eigen::Vector3d& x) const;
  // The weights evaluate uses at x: its tetrahedron (the containing or the nearest one) and the
  // barycentric coordinates there (of x, or of the closest point), clipped to >= 0, summing to 1.
  struct Weights {
    int tetrahedron;
    Eigen::Vector4d w;
  };
  Weights weights(const Eigen::Vector3d& x) const;
  const BackgroundMesh<3>& mesh() const { return mesh_; }

 private:
  struct TetTree;
  BackgroundMesh<3> mesh_;
  MetricMean mean_;
  std::vector<Eigen::Matrix3d> logs_;  // log of every node metric, for the log-Euclidean mean
  std::unique_ptr<TetTree> tree_;
};

}  // namespace metric
}  // namespace plaf
