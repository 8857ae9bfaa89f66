// SPDX-License-Identifier: MIT
// The Plot3D surface reader (see read_surface.h): formatted ASCII multi-block structured grids
// with nk = 1, their interface nodes merged, each quad split into two triangles along its
// shorter diagonal.
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "modules/io/text_cursor.h"
#include "surface3d/read_surface.h"
#include "surface3d/read_surface_detail.h"

namespace plaf {

namespace fs = std::filesystem;
using Vec3 = Eigen::Vector3d;
using read_detail::fail;

namespace {

struct Block {
  std::int64_t ni, nj;
  std::size_t first;  // index of its first point
};

// The grid as read: the blocks, and all their points, block after block with i fastest.
struct Plot3dGrid {
  std::vector<Block> blocks;
  std::vector<Vec3> points;
};

// Block count, ni nj nk per block, then per block all x, all y, all z (no IBLANK).
Plot3dGrid parse_plot3d(const fs::path& path, const std::string& text) {
  TextCursor c(path, text);
  const std::int64_t nblocks = c.count("block count", 18);
  if (nblocks == 0) c.fail("no blocks");
  Plot3dGrid grid;
  std::vector<Block>& blocks = grid.blocks;
  blocks.resize(static_cast<std::size_t>(nblocks));
  std::size_t total = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const std::int64_t ni = c.integer("ni", 1, std::numeric_limits<int>::max());
    const std::int64_t nj = c.integer("nj", 1, std::numeric_limits<int>::max());
    const std::int64_t nk = c.integer("nk", 1, std::numeric_limits<int>::max());
    if (nk != 1)
      c.fail("block " + std::to_string(b + 1) + " has nk = " + std::to_string(nk) + ": a surface grid has nk = 1");
    // Each value takes at least two characters ("0 ").
    if (static_cast<std::uint64_t>(ni) * static_cast<std::uint64_t>(nj) > text.size() / 6 + 1)
      c.fail("block " + std::to_string(b + 1) + " of " + std::to_string(ni) + " x " + std::to_string(nj) +
             " points exceeds what the file can hold (truncated file?)");
    blocks[b] = {ni, nj, total};
    total += static_cast<std::size_t>(ni * nj);
  }
  if (total > text.size() / 6 + 1)
    c.fail("the blocks' " + std::to_string(total) + " points exceed what the file can hold");
  std::vector<Vec3>& raw = grid.points;
  raw.resize(total);
  static constexpr const char* axis_name[3] = {"x coordinate", "y coordinate", "z coordinate"};
  for (const Block& bl : blocks) {
    const auto n = static_cast<std::size_t>(bl.ni * bl.nj);
    for (int d = 0; d < 3; ++d)
      for (std::size_t k = 0; k < n; ++k) raw[bl.first + k][d] = c.coordinate(axis_name[d]);
  }
  if (!c.at_end())
    c.fail("unexpected " + TextCursor::quote(c.peek()) + " after the last block (IBLANK is not supported)");
  return grid;
}

// The quads of each block as triangle pairs on the merged nodes (rep: each point's
// representative), carrying their block in soup.patch.
void triangulate_blocks(const Plot3dGrid& grid, const std::vector<int>& rep, TriangleSoup& soup) {
  const std::vector<Vec3>& raw = grid.points;
  for (std::size_t b = 0; b < grid.blocks.size(); ++b) {
    const Block& bl = grid.blocks[b];
    const auto node = [&](std::int64_t i, std::int64_t j) {
      return rep[bl.first + static_cast<std::size_t>(j * bl.ni + i)];
    };
    for (std::int64_t j = 0; j + 1 < bl.nj; ++j)
      for (std::int64_t i = 0; i + 1 < bl.ni; ++i) {
        // The quad in i, j order (outward in these files); both triangles keep its orientation.
        const std::array<int, 4> q = {node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)};
        const auto at = [&](int k) -> const Vec3& {
          return raw[static_cast<std::size_t>(q[static_cast<std::size_t>(k)])];
        };
        std::array<std::array<int, 3>, 2> tris;
        if ((at(2) - at(0)).squaredNorm() <= (at(3) - at(1)).squaredNorm()) {
          tris = {{{q[0], q[1], q[2]}, {q[0], q[2], q[3]}}};
        } else {
          tris = {{{q[0], q[1], q[3]}, {q[1], q[2], q[3]}}};
        }
        for (const auto& t : tris) {
          // A collapsed quad (merged corners) leaves a triangle with a repeated node: no area.
          if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
          soup.triangles.push_back(t);
          soup.patch.push_back(static_cast<int>(b));
        }
      }
  }
}

}  // namespace

TriangleSoup read_plot3d(const fs::path& path, const ReadSurfaceOptions& options) {
  const std::string text = read_whole_file(path);
  if (text.empty()) fail(path, "the file is empty");
  const Plot3dGrid grid = parse_plot3d(path, text);
  // Coincident nodes on block interfaces (and at poles or collapsed block edges) become one.
  const std::vector<int> rep =
      read_detail::cluster_points(grid.points, options.weld_rel * read_detail::bbox_diagonal(grid.points));
  TriangleSoup soup;
  soup.source = path.string();
  soup.points = grid.points;
  triangulate_blocks(grid, rep, soup);
  read_detail::renumber_and_compact(soup, nullptr);
  if (soup.triangles.empty()) fail(path, "no triangles (every block is a line or collapsed)");
  return soup;
}

}  // namespace plaf
