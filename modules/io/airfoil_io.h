// SPDX-License-Identifier: MIT
// Reading 2D body contours from coordinate files (UIUC airfoil database formats) and checking
// that the loops are simple and disjoint.
//
// Accepted: two numeric columns (x y) separated by blanks or tabs, numbers like `-.00316` or
// `1.5e-3`; an optional first line that is not two numbers (the title); then either
// - Selig order: one contour TE -> upper -> LE -> lower -> TE (or any closed contour), or
// - Lednicer order: a line with two point counts (e.g. `61. 61.`), a blank line, the upper
//   surface LE -> TE, a blank line, the lower surface LE -> TE.
// A repeated closing point (first == last) is dropped and the trailing edge is sharp: that
// point is a corner. An open contour (first != last, e.g. a blunt trailing edge) is closed by a
// straight segment between its two end points, which become two corners. The loop is then
// oriented clockwise (the body convention of spline_loop.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "modules/base/coordinates.h"

namespace plaf {
inline namespace io {

struct BodyContour {
  std::string file;
  std::string title;
  std::vector<Eigen::Vector2d> points;  // clockwise, no repeated closing point
  std::vector<int> lines;               // the file line (1-based) of each point
  std::vector<int> corners;             // forced corners: the sharp TE, or the two blunt TE ends
  bool blunt = false;                   // closed by a straight segment
};

// Coordinates are at most this in magnitude (modules/base/coordinates.h: every reader's range).
inline constexpr double kMaxContourCoordinate = kMaxCoordinate;

// Throws InputError "file:line: reason" for: a missing or empty file, a file that is not a regular
// file, a line that is not two numbers (one column, text, NaN/inf; the token printed with its
// unprintable bytes as \xNN), a coordinate beyond kMaxContourCoordinate, fewer than 4 points,
// repeated consecutive points, a self-intersecting contour.
BodyContour read_body_contour(const std::filesystem::path& path);

// A contour from points in Selig order (TE -> upper -> LE -> lower -> TE, or any closed loop),
// closed, checked and oriented exactly as a file's points are; `name` stands for the file in
// messages and each point's "line" is its 1-based index. For generated sections (naca_section.h).
BodyContour contour_from_points(const std::vector<Eigen::Vector2d>& points, const std::string& name);

// Throws InputError naming both files and lines if two contours intersect or one lies inside
// the other.
void check_disjoint(const std::vector<BodyContour>& bodies);

}  // namespace io
}  // namespace plaf
