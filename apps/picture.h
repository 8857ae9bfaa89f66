// SPDX-License-Identifier: MIT
// `plaf picture`: the picture of any mesh plaf reads (a Gmsh MSH 4.1 or 2.2 file, ASCII or binary,
// or a CGNS file; plaf's own or another tool's), drawn as a run draws its own
// (modules/io/picture.h, picture3d.h): every cell certified first, the invalid ones red.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace plaf {

struct PictureRequest {
  std::filesystem::path mesh;
  std::optional<std::filesystem::path> out;  // default: beside the mesh, MESH_STEM.picture.png
  // 3D: the cut plane (a point and its normal); default: the mesh's default cut (the first
  // symmetry facet's plane, else the mid-plane across the bounding box's shortest side) moved
  // through the worst cell.
  std::optional<std::array<double, 6>> cut;
  // Zoom panels: a point and a half-width each (2D: x, y, r; 3D: x, y, z, r, the point taken
  // into the cut plane's (u, v)).
  std::vector<std::vector<double>> zooms;
  std::optional<std::array<double, 3>> view;  // 3D: the shaded view's direction
  int width = 1600, height = 1200;
};

// Reads, certifies (the summary on stdout, as `plaf check` prints it) and draws; the first zoom
// panel is always the cell of the smallest certified scaled Jacobian (an invalid one when any).
// Returns 0 when every cell is valid, 2 when some is not (the picture is written either way).
int picture_command(const PictureRequest& request);

// The "X,Y,Z" numbers of a command-line value, min_count to max_count of them, else an InputError
// naming the option.
std::vector<double> parse_numbers(const std::string& option, const std::string& value, std::size_t min_count,
                                  std::size_t max_count);

}  // namespace plaf
