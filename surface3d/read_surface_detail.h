// SPDX-License-Identifier: MIT
// Internal to the surface readers (read_surface.h): what the triangle-file path
// (read_surface.cpp), the format scans (surface_file_scans.cpp) and the Plot3D reader
// (read_plot3d.cpp) share. Not part of the surface3d API.
//
// - Errors: InputError "<path>: <reason>" or "<path>:<line>: <reason>".
// - Point clustering (cluster_points.cpp): the representative of each point within tol, greedy
//   on a hash grid; the soup renumbered through the representatives and compacted.
// - Structural scans of STL, OBJ, OFF and PLY (surface_file_scans.cpp), run before OpenMesh reads
//   a file, because OpenMesh 9 trusts its input (silent wrong values, hangs): counts, numbers and
//   index ranges, failing with the line of the first problem. Each returns what OpenMesh must then
//   deliver.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "modules/base/error.h"
#include "modules/geometry/tri_surface.h"

namespace plaf::read_detail {

[[noreturn]] inline void fail(const std::filesystem::path& path, const std::string& reason) {
  throw InputError(path.string() + ": " + reason);
}

[[noreturn]] inline void fail_line(const std::filesystem::path& path, int line, const std::string& reason) {
  throw InputError(path.string() + ":" + std::to_string(line) + ": " + reason);
}

inline std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// The diagonal of the points' bounding box (0 for none).
double bbox_diagonal(const std::vector<Eigen::Vector3d>& points);

// For each point, the index of its cluster's representative: points are taken in order and each
// joins the nearest earlier representative within tol (ties: the lowest index), or becomes one.
// Greedy, so clusters do not chain: two points 1.5 tol apart with one in the middle stay two.
std::vector<int> cluster_points(const std::vector<Eigen::Vector3d>& points, double tol);

// Renumbers the triangles through rep (old index -> old index of its representative; null: no
// merging) and keeps only the points that triangles use, in the order of their first old index.
void renumber_and_compact(TriangleSoup& soup, const std::vector<int>* rep);

// What OpenMesh must deliver for a scanned file (-1: not known).
struct Expected {
  std::int64_t vertices = -1;
  std::int64_t faces = -1;
  std::int64_t max_faces = -1;  // STL: OpenMesh drops facets with repeated points
  bool binary = false;          // STL and PLY: the reader's binary mode
};

// STL, ASCII or binary; an ASCII solid's name that would start a facet in OpenMesh's reader is
// blanked in text_to_read.
Expected check_stl(const std::filesystem::path& path, std::string& text_to_read);
Expected check_obj(const std::filesystem::path& path, std::string_view text);
// ASCII OFF; '#' comments are allowed here but must be blanked (blank_comments) before OpenMesh
// reads the text.
Expected check_off(const std::filesystem::path& path, std::string_view text);
Expected check_ply(const std::filesystem::path& path, std::string_view text);

// '#' to the end of the line becomes blanks (the lines stay where they are).
void blank_comments(std::string& text);

}  // namespace plaf::read_detail
