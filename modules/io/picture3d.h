// SPDX-License-Identifier: MIT
// PNG pictures of 3D meshes (cairo), drawn like the 2D pictures (picture.h):
//  - the cut: the mesh cut by a plane, in the plane's coordinates (u, v), framed on the wall's
//    crossing and the curved facets in the plane (and a quarter of their extent around them) where
//    the cut reaches a farfield beyond. Facets lying in the
//    plane (a symmetry plane's) are drawn as the 2D pictures draw cells: curved outlines, filled
//    light blue (straight), light orange (curved) or red (their cell invalid); every other facet
//    crossing the plane is cut along its curved surface (sampled on a fine sub-lattice), so the
//    cut cells' outlines show with their curvature; wall facets crossing it are drawn thicker.
//  - zoom panels of the cut (boxes in (u, v)), below it;
//  - a shaded view of the outer front (the facets tagged `layers_outer`; else, as with a fill, the
//    wall's, labelled so): an
//    orthographic view along `view`, each curved facet split into sub-triangles, painted back to
//    front with Lambert shading, facet outlines drawn thin. Where some columns of the layers ended
//    short (Picture3Options::short_columns) the view shows the wall instead, each facet coloured
//    by the fewest layers any of its corners' columns grew: blue all of them, yellow to red fewer,
//    red none (the coverage, seen).
// The plane's axes u, v: the two of x, y, z least aligned with its normal, in that order, made
// orthonormal in the plane (the plane z = 0: u = x, v = y; y = 0: u = x, v = z).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "modules/io/picture.h"
#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace io {

struct Picture3Options {
  int width = 1600;
  int height = 1200;
  std::string title;
  Eigen::Vector3d cut_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d cut_normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d view = Eigen::Vector3d(-1, -0.6, -0.8);  // the shaded view looks along this
  std::vector<ZoomBox> zooms;                              // boxes in the cut plane's (u, v)
  // A point to look at (a failed run's, apps/run.cpp): its box of half-width focus_radius in the
  // cut plane's (u, v) comes first among the zoom panels, and a red circle marks it in the
  // shaded view.
  std::optional<Eigen::Vector3d> focus;
  double focus_radius = 0;
  std::string focus_label;
  // The columns of the layers that ended short (LayerCoverage::short_columns): each one's wall
  // point and the layer it ended in; `layers` the stack the others grew (0: every column counts
  // as having grown none). Each is given to the wall corner nearest its point.
  struct ShortColumn {
    Eigen::Vector3d point;
    int layer = 0;
  };
  std::vector<ShortColumn> short_columns;
  int layers = 0;
};

// The default cut of a mesh: the plane of its first symmetry facet, if any, else the plane through
// the nodes' bounding-box centre normal to its shortest side.
void default_cut(const HybridMesh<3>& mesh, Eigen::Vector3d& point, Eigen::Vector3d& normal);

// The point x in the cut plane's (u, v) coordinates (the axes above; x need not lie in the
// plane: its projection), as Picture3Options::zooms take them.
Eigen::Vector2d cut_plane_uv(const Eigen::Vector3d& normal, const Eigen::Vector3d& x);

// valid: one flag per cell in block order (empty: all valid). Written atomically.
void write_png(const HybridMesh<3>& mesh, const std::vector<std::uint8_t>& valid, const std::filesystem::path& path,
               const Picture3Options& options);

}  // namespace io
}  // namespace plaf
