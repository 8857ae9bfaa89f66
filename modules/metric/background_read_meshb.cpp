// SPDX-License-Identifier: MIT
// Implements read_background_meshb (background_metric.h): a background metric from a libMeshb /
// Medit ASCII pair, .mesh and .sol (as read by MMG and BAMG), in 2D and 3D.
#include <algorithm>
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

// Reads a .mesh or .sol up to End: the header, Dimension (which must be the run's, dim), and
// every other keyword through read_section(keyword, line, dimension seen so far), which returns
// false for a keyword it does not use; the data of those is skipped.
template <class ReadSection>
MeshbEnd read_meshb_keywords(TextCursor& in, int dim, const ReadSection& read_section) {
  in.expect("MeshVersionFormatted");
  in.integer("mesh version", 1, 4);
  bool dimension = false;
  while (true) {
    const int line = in.next_line();
    const std::string_view kw = in.token("a keyword (the file ends with End)");
    if (kw == "End") return {line, dimension};
    if (kw == "Dimension") {
      const int dim_line = in.next_line();
      const std::int64_t file_dim = in.integer("dimension");
      if (file_dim != dim)
        in.fail_at(dim_line, "Dimension " + std::to_string(file_dim) + ": a " + std::to_string(dim) + "D run needs a " +
                                 std::to_string(dim) + "D background mesh (Dimension " + std::to_string(dim) + ")");
      dimension = true;
    } else if (!read_section(kw, line, dimension)) {
      if (!is_keyword(kw)) in.fail_at(line, "expected a keyword, found " + TextCursor::quote(kw));
      skip_keyword_data(in);
    }
  }
}

template <int Dim>
struct MeshbMesh {
  std::vector<typename BackgroundMesh<Dim>::Point> nodes;
  std::vector<typename BackgroundMesh<Dim>::Simplex> simplices;
};

// The element keywords of a Dim-dimensional background mesh and their vertex counts: 2D
// Triangles and Quadrilaterals (split along 0-2), 3D Tetrahedra. The 3D cells that are not
// tetrahedra are refused: splitting them depends on their neighbours (background_metric.h).
struct ElementKeyword {
  std::string_view name;
  int vertices;
};
template <int Dim>
constexpr std::array<ElementKeyword, Dim == 2 ? 2 : 1> element_keywords() {
  if constexpr (Dim == 2)
    return {{{"Triangles", 3}, {"Quadrilaterals", 4}}};
  else
    return {{{"Tetrahedra", 4}}};
}
constexpr std::array<std::string_view, 4> refused_3d = {"Prisms", "Pentahedra", "Pyramids", "Hexahedra"};

// The .mesh: Dimension, Vertices (Dim coordinates and a ref) and the element keywords (1-based
// vertex indices and a ref); other keywords are skipped up to the next keyword.
template <int Dim>
MeshbMesh<Dim> read_meshb_mesh(const std::filesystem::path& path) {
  MeshbMesh<Dim> mesh;
  const std::string text = read_whole_file(path);
  TextCursor in(path, text, true);
  bool vertices = false;
  const MeshbEnd end = read_meshb_keywords(in, Dim, [&](std::string_view kw, int line, bool dimension) {
    if (kw == "Vertices") {
      if (!dimension) in.fail_at(line, "Vertices before Dimension");
      if (vertices) in.fail_at(line, "a second Vertices section");
      vertices = true;
      const std::int64_t n = in.count("number of vertices", 2 * Dim + 2);
      if (n > std::numeric_limits<NodeId>::max()) in.fail_at(line, "too many vertices: " + std::to_string(n));
      mesh.nodes.reserve(static_cast<std::size_t>(n));
      for (std::int64_t i = 0; i < n; ++i) {
        typename BackgroundMesh<Dim>::Point x;
        for (int d = 0; d < Dim; ++d) x[d] = in.coordinate("vertex coordinate");
        in.integer("vertex reference");
        mesh.nodes.push_back(x);
      }
      return true;
    }
    if constexpr (Dim == 3)
      for (std::string_view refused : refused_3d)
        if (kw == refused)
          in.fail_at(line, std::string(kw) + ": a 3D background mesh is made of Tetrahedra (split the " +
                               std::string(kw) + " into tetrahedra)");
    for (const ElementKeyword& element : element_keywords<Dim>()) {
      if (kw != element.name) continue;
      if (!vertices) in.fail_at(line, std::string(kw) + " before Vertices");
      const int per = element.vertices;
      const std::int64_t n = in.count("number of elements", 2 * static_cast<std::size_t>(per) + 2);
      std::array<NodeId, 4> v{};
      for (std::int64_t e = 0; e < n; ++e) {
        for (int k = 0; k < per; ++k)
          v[static_cast<std::size_t>(k)] =
              static_cast<NodeId>(in.integer("vertex index", 1, static_cast<std::int64_t>(mesh.nodes.size())) - 1);
        in.integer("element reference");
        typename BackgroundMesh<Dim>::Simplex s;
        std::copy_n(v.begin(), Dim + 1, s.begin());
        mesh.simplices.push_back(s);
        if constexpr (Dim == 2)
          if (per == 4) mesh.simplices.push_back({v[0], v[2], v[3]});
      }
      return true;
    }
    return false;
  });
  if (!end.dimension) in.fail_at(end.line, "no Dimension keyword");
  if (!vertices) in.fail_at(end.line, "no Vertices section");
  if (mesh.simplices.empty())
    in.fail_at(end.line, Dim == 2 ? "no Triangles or Quadrilaterals: the background mesh has no elements"
                                  : "no Tetrahedra: the background mesh has no elements");
  return mesh;
}

// The .sol: SolAtVertices with one symmetric-matrix field (type 3) of Dim (Dim + 1) / 2 values in
// libMeshb's order (symmetric_from_packed), one for each of the num_vertices vertices of
// mesh_path.
template <int Dim>
std::vector<Metric<Dim>> read_meshb_sol(const std::filesystem::path& sol_path, const std::filesystem::path& mesh_path,
                                        std::size_t num_vertices) {
  std::vector<Metric<Dim>> metrics;
  const std::string text = read_whole_file(sol_path);
  TextCursor in(sol_path, text, true);
  bool solution = false;
  const MeshbEnd end = read_meshb_keywords(in, Dim, [&](std::string_view kw, int line, bool dimension) {
    if (kw != "SolAtVertices") return false;
    if (!dimension) in.fail_at(line, "SolAtVertices before Dimension");
    if (solution) in.fail_at(line, "a second SolAtVertices section");
    solution = true;
    const int count_line = in.next_line();
    std::array<double, Dim*(Dim + 1) / 2> packed{};
    const std::int64_t n = in.count("number of values", 2 * packed.size());
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
      for (double& c : packed) c = in.real("metric component");
      metrics.push_back(
          metric_from_file<Dim>(in, value_line, symmetric_from_packed<Dim>(packed), "vertex " + std::to_string(i + 1)));
    }
    return true;
  });
  if (!solution) in.fail_at(end.line, "no SolAtVertices section");
  return metrics;
}

}  // namespace

template <int Dim>
BackgroundMesh<Dim> read_background_meshb(const std::filesystem::path& mesh_path,
                                          const std::filesystem::path& sol_path) {
  MeshbMesh<Dim> mesh = read_meshb_mesh<Dim>(mesh_path);
  std::vector<Metric<Dim>> metrics = read_meshb_sol<Dim>(sol_path, mesh_path, mesh.nodes.size());
  const std::vector<bool> has_value(mesh.nodes.size(), true);
  return compact_background_mesh<Dim>(std::move(mesh.nodes), std::move(mesh.simplices), std::move(metrics), has_value,
                                      [](std::size_t) {});
}
template BackgroundMesh<2> read_background_meshb<2>(const std::filesystem::path&, const std::filesystem::path&);
template BackgroundMesh<3> read_background_meshb<3>(const std::filesystem::path&, const std::filesystem::path&);

}  // namespace metric
}  // namespace plaf
