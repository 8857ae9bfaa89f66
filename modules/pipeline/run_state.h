// SPDX-License-Identifier: MIT
// RunState<Dim>: what the stages of one run have produced so far, in core types only. The driver
// (apps/) hands it from stage to stage in the order of the pipeline (DESIGN.md):
//   geometry -> metric -> surface mesh -> layers -> fill -> assembly -> quality -> writers.
// A stage reads the fields earlier stages filled and fills its own; stages never call each other.
#pragma once

#include <functional>
#include <memory>
#include <optional>

#include "modules/geometry/geometry2d.h"
#include "modules/geometry/reference.h"
#include "modules/geometry/tri_surface.h"
#include "modules/mesh/annulus.h"
#include "modules/mesh/curved_front.h"
#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/linear_front.h"
#include "modules/metric/metric.h"
#include "modules/pipeline/progress.h"
#include "modules/pipeline/run_config.h"

namespace plaf {
inline namespace pipeline {

template <int Dim>
struct RunState;

template <>
struct RunState<2> {
  static constexpr int dim = 2;
  explicit RunState(const RunConfig& c) : config(c) {}
  const RunConfig& config;
  Progress* progress = &silent_progress();  // where long stages report as they go (never null)
  Geometry2D geometry;                      // geometry: the spline loops (none for the annulus)
  std::optional<AnnulusParams> annulus;     // geometry: the annulus (its surface stage meshes it)
  std::unique_ptr<MetricField<2>> metric;   // metric
  std::optional<CurvedFront<2>> front;      // surface mesh of the loops
  std::optional<LayerResult<2>> layers;     // layers (or the front itself, without layers)
  std::optional<FillResult<2>> fill;        // fill
  HybridMesh<2> mesh;                       // the assembled mesh (the annulus: its surface stage)
  bool mesh_done = false;                   // a surface stage that makes the whole mesh sets it
  const MetricField<2>* measure() const { return metric.get(); }
};

template <>
struct RunState<3> {
  static constexpr int dim = 3;
  explicit RunState(const RunConfig& c) : config(c) {}
  const RunConfig& config;
  Progress* progress = &silent_progress();  // where long stages report as they go (never null)
  TriSurface surface;                               // geometry: the input; surface: remeshed and curved
  // geometry: what the surface lives on (shared: a metric may keep it to measure distances to the
  // body, wall_metric_3d.h, while the surface stage replaces it with an equal one built with the
  // triangulation)
  std::shared_ptr<ReferenceGeometry<3>> reference;
  // geometry, for an analytic body: builds its initial triangulation (and the same reference) at
  // size h; the surface stage calls it with surface_base()'s size at body_center. Files need none.
  std::function<void(RunState<3>&, double h)> build_body;
  Eigen::Vector3d body_center = Eigen::Vector3d::Zero();
  std::unique_ptr<MetricField<3>> metric;           // metric
  // metric, where the surface mesh follows other sizes than `metric` (null: metric itself): a
  // boundary-layer metric's sizes along the wall, its normal size being the layers' (wall_metric_3d.h)
  std::unique_ptr<MetricField<3>> surface_sizes;
  std::unique_ptr<MetricField<3>> surface_metric;   // surface: the metric it followed (curvature)
  std::optional<CurvedFront<3>> front;
  std::optional<LayerResult<3>> layers;
  std::optional<FillResult<3>> fill;
  HybridMesh<3> mesh;
  bool mesh_done = false;
  // The sizes the surface stage meshes to (before its curvature metric).
  const MetricField<3>& surface_base() const { return surface_sizes ? *surface_sizes : *metric; }
  // What the quality stage measures the mesh in: the run's metric for a volume mesh (layers), the
  // metric the surface followed for a surface mesh.
  const MetricField<3>* measure() const {
    if (layers) return metric.get();
    return surface_metric ? surface_metric.get() : surface_sizes ? surface_sizes.get() : metric.get();
  }
};

}  // namespace pipeline
}  // namespace plaf
