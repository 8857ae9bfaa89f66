// SPDX-License-Identifier: MIT
// Implements read_background_meshb (background_metric.h): a background metric from a libMeshb /
// Medit ASCII pair, .mesh and .sol (as read by MMG and BAMG).
#include <array>
#include <cctype>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <utility>

#include "modules/io/text_cursor.h"
#include "modules/metric/background_metric.h"
#include "modules/metric/background_read.h"

namespace plaf {
inline namespace metric {
namespace {

bool is_keyword(std::string_view t) {
  return !t.empty() && std::isalpha(static_cast<unsigned char>(t[0]));
}

// Skips the data of a keyword plaf does not use: every token up to the next keyword.
void skip_keyword_data(TextCursor& in) {
  while (!in.at_end() && !is_keyword(in.peek())) in.token("data");
}

struct MeshbEnd {
  int line;        // of the End keyword
  bool dimension;  // whether a Dimension keyword came before it
};

// Reads a .mesh or .sol up to End: the header, Dimension (which must be 2), and every other
// keyword through read_section(keyword, line, dimension seen so far), which returns false for a
// keyword it does not use; the data of those is skipped.
template <class ReadSection>
MeshbEnd read_meshb_keywords(TextCursor& in, const ReadSection& read_section) {
  in.expect("MeshVersionFormatted");
  in.integer("mesh version", 1, 4);
  bool dimension = false;
  while (true) {
    const int line = in.next_line();
    const std::string_view kw = in.token("a keyword (the file ends with End)");
    if (kw == "End") return {line, dimension};
    if (kw == "Dimension") {
      const int dim_line = in.next_line();
      const std::int64_t dim = in.integer("dimension");
      if (dim != 2)
        in.fail_at(dim_line, "Dimension " + std::to_string(dim) + ": plaf reads 2D background meshes (Dimension 2)");
      dimension = true;
    } else if (!read_section(kw, line, dimension)) {
      if (!is_keyword(kw)) in.fail_at(line, "expected a keyword, found " + TextCursor::quote(kw));
      skip_keyword_data(in);
    }
  }
}

struct MeshbMesh {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<NodeId, 3>> triangles;  // quadrilaterals split along 0-2
};

// The .mesh: Dimension 2, Vertices (x y ref), Triangles and Quadrilaterals (1-based vertex
// indices and a ref); other keywords are skipped up to the next keyword.
MeshbMesh read_meshb_mesh(const std::filesystem::path& path) {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<NodeId, 3>> triangles;
  const std::string text = read_whole_file(path);
  TextCursor in(path, text, true);
  bool vertices = false;
  const MeshbEnd end = read_meshb_keywords(in, [&](std::string_view kw, int line, bool dimension) {
    if (kw == "Vertices") {
      if (!dimension) in.fail_at(line, "Vertices before Dimension");
      if (vertices) in.fail_at(line, "a second Vertices section");
      vertices = true;
      const std::int64_t n = in.count("number of vertices", 6);
      if (n > std::numeric_limits<NodeId>::max()) in.fail_at(line, "too many vertices: " + std::to_string(n));
      nodes.reserve(static_cast<std::size_t>(n));
      for (std::int64_t i = 0; i < n; ++i) {
        const double x = in.real("vertex coordinate");
        const double y = in.real("vertex coordinate");
        in.integer("vertex reference");
        nodes.emplace_back(x, y);
      }
      return true;
    }
    if (kw == "Triangles" || kw == "Quadrilaterals") {
      if (!vertices) in.fail_at(line, std::string(kw) + " before Vertices");
      const int per = kw == "Triangles" ? 3 : 4;
      const std::int64_t n = in.count("number of elements", 2 * static_cast<std::size_t>(per) + 2);
      std::array<NodeId, 4> v{};
      for (std::int64_t e = 0; e < n; ++e) {
        for (int k = 0; k < per; ++k)
          v[static_cast<std::size_t>(k)] =
              static_cast<NodeId>(in.integer("vertex index", 1, static_cast<std::int64_t>(nodes.size())) - 1);
        in.integer("element reference");
        triangles.push_back({v[0], v[1], v[2]});
        if (per == 4) triangles.push_back({v[0], v[2], v[3]});
      }
      return true;
    }
    return false;
  });
  if (!end.dimension) in.fail_at(end.line, "no Dimension keyword");
  if (!vertices) in.fail_at(end.line, "no Vertices section");
  if (triangles.empty()) in.fail_at(end.line, "no Triangles or Quadrilaterals: the background mesh has no elements");
  return {std::move(nodes), std::move(triangles)};
}

// The .sol: SolAtVertices with one symmetric-matrix field (type 3), stored xx xy yy, one value
// for each of the num_vertices vertices of mesh_path.
std::vector<Metric<2>> read_meshb_sol(const std::filesystem::path& sol_path, const std::filesystem::path& mesh_path,
                                      std::size_t num_vertices) {
  std::vector<Metric<2>> metrics;
  const std::string text = read_whole_file(sol_path);
  TextCursor in(sol_path, text, true);
  bool solution = false;
  const MeshbEnd end = read_meshb_keywords(in, [&](std::string_view kw, int line, bool dimension) {
    if (kw != "SolAtVertices") return false;
    if (!dimension) in.fail_at(line, "SolAtVertices before Dimension");
    if (solution) in.fail_at(line, "a second SolAtVertices section");
    solution = true;
    const int count_line = in.next_line();
    const std::int64_t n = in.count("number of values", 6);
    if (static_cast<std::size_t>(n) != num_vertices)
      in.fail_at(count_line, "SolAtVertices has " + std::to_string(n) + " values but " + mesh_path.string() + " has " +
                                 std::to_string(num_vertices) + " vertices");
    const int types_line = in.next_line();
    const std::int64_t num_fields = in.integer("number of fields", 1, 64);
    std::string types;
    bool symmetric_matrix = num_fields == 1;
    for (std::int64_t f = 0; f < num_fields; ++f) {
      const std::int64_t type = in.integer("field type");
      if (f > 0) types += ' ';
      types += std::to_string(type);
      symmetric_matrix = symmetric_matrix && type == 3;
    }
    if (!symmetric_matrix)
      in.fail_at(types_line, "SolAtVertices has field types '" + types +
                                 "'; a background metric is one field of type 3 (symmetric matrix)");
    metrics.reserve(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) {
      const int value_line = in.next_line();
      const double xx = in.real("metric component");
      const double xy = in.real("metric component");
      const double yy = in.real("metric component");
      Eigen::Matrix2d m;
      m << xx, xy, xy, yy;
      metrics.push_back(metric_from_file(in, value_line, m, "vertex " + std::to_string(i + 1)));
    }
    return true;
  });
  if (!solution) in.fail_at(end.line, "no SolAtVertices section");
  return metrics;
}

}  // namespace

BackgroundMesh read_background_meshb(const std::filesystem::path& mesh_path, const std::filesystem::path& sol_path) {
  MeshbMesh mesh = read_meshb_mesh(mesh_path);
  std::vector<Metric<2>> metrics = read_meshb_sol(sol_path, mesh_path, mesh.nodes.size());
  const std::vector<bool> has_value(mesh.nodes.size(), true);
  return compact_background_mesh(std::move(mesh.nodes), std::move(mesh.triangles), std::move(metrics), has_value,
                                 [](std::size_t) {});
}

}  // namespace metric
}  // namespace plaf
