// SPDX-License-Identifier: MIT
// Surface readers: triangle soups from files, before any topology check (validate.h checks).
//
// - STL (ASCII and binary), OBJ, OFF, PLY are read through OpenMesh's readers with a soup
//   importer (so non-manifold input reaches our validation instead of being dropped by OpenMesh);
//   polygons are fanned into triangles. STL points are welded: exactly equal points become one
//   vertex, then points closer than weld_rel x the bounding-box diagonal. OBJ, OFF and PLY are not
//   welded (their vertices are shared by index); unreferenced vertices are dropped. STL and OFF
//   coordinates come through OpenMesh as floats. OpenMesh 9 is not safe on bad input (silent
//   wrong values, hangs), so each format is checked strictly before OpenMesh reads it.
// - Plot3D formatted ASCII multi-block structured surfaces (.fmt, .p3d, whole grid, no IBLANK;
//   first the number of blocks, then ni nj nk per block with nk = 1, then per block all x, all y,
//   all z with i fastest). Coincident nodes on block interfaces are merged (within weld_rel x the
//   bounding-box diagonal) and each quad (i,j)-(i+1,j)-(i+1,j+1)-(i,j+1) becomes two triangles
//   along its shorter diagonal; the triangles keep the quads' orientation and carry their block
//   in TriangleSoup::patch. Collapsed quads (a pole, a degenerate block edge) give no zero-area
//   triangle.
// Errors: InputError "<path>: <reason>" (missing file, unknown extension, malformed or
// truncated content with the line, no triangles). Never a crash on any input.
#pragma once

#include <filesystem>

#include "modules/geometry/tri_surface.h"

namespace plaf {

struct ReadSurfaceOptions {
  double weld_rel = 1e-9;  // STL and Plot3D: merge points closer than this x bbox diagonal
};

// By extension (case-insensitive): .stl .obj .off .ply .fmt .p3d
TriangleSoup read_surface_file(const std::filesystem::path& path, const ReadSurfaceOptions& options = {});
TriangleSoup read_plot3d(const std::filesystem::path& path, const ReadSurfaceOptions& options = {});

// Merges points closer than tol (absolute) into one, renumbering triangles; returns the number
// of points removed. Unreferenced points are dropped too.
std::size_t weld_points(TriangleSoup& soup, double tol);

}  // namespace plaf
