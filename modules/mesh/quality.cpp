// SPDX-License-Identifier: MIT
#include "modules/mesh/quality.h"

#include <memory>

#include "modules/base/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "modules/elements/mapping.h"

namespace plaf {
inline namespace mesh {

namespace {

// The progress's share of the quality stage for the cells' certification, the rest for the
// metric lengths of their edges (assess_quality, step 2).
constexpr double kCellsShareOfWork = 0.8;

// Reference-to-regular maps W (columns: edge vectors of the regular cell from vertex 0).
Eigen::Matrix3d regular_cell_map(CellType t) {
  Eigen::Matrix3d w = Eigen::Matrix3d::Identity();
  const double s3 = std::sqrt(3.0);
  switch (t) {
    case CellType::Triangle:
    case CellType::Prism:
      w(0, 1) = 0.5;
      w(1, 1) = s3 / 2;
      break;
    case CellType::Tetrahedron:
      w.col(1) = Eigen::Vector3d(0.5, s3 / 2, 0);
      w.col(2) = Eigen::Vector3d(0.5, s3 / 6, std::sqrt(2.0 / 3.0));
      break;
    default:
      break;
  }
  return w;
}

std::array<double, 3> centroid(CellType t) {
  switch (t) {
    case CellType::Triangle:
      return {1.0 / 3, 1.0 / 3, 0};
    case CellType::Quadrilateral:
      return {0.5, 0.5, 0};
    case CellType::Tetrahedron:
      return {0.25, 0.25, 0.25};
    case CellType::Prism:
      return {1.0 / 3, 1.0 / 3, 0.5};
    default:
      return {0.5, 0, 0};
  }
}

template <int Dim>
double aspect_ratio(const LagrangeElement& e, const double* coords, double* grad) {
  const auto xi = centroid(e.type());
  const Eigen::Matrix<double, Dim, Dim> j = mapping_jacobian<Dim>(e, coords, xi.data(), grad);
  const Eigen::Matrix<double, Dim, Dim> w = regular_cell_map(e.type()).template topLeftCorner<Dim, Dim>();
  const Eigen::Matrix<double, Dim, Dim> m = j * w.inverse();
  Eigen::JacobiSVD<Eigen::Matrix<double, Dim, Dim>> svd(m);
  const auto s = svd.singularValues();
  return s[Dim - 1] > 0 ? s[0] / s[Dim - 1] : std::numeric_limits<double>::infinity();
}

std::string type_key(const CellBlock& b) {
  return std::string(cell_name(b.type)) + "_Q" + std::to_string(b.order);
}

// Accumulates edge lengths into one EdgeLengthStats (finish() turns the sums into statistics).
class EdgeLengthAccumulator {
 public:
  EdgeLengthAccumulator(EdgeLengthStats& out, int bins) : out_(out), bins_(bins) {
    // Bins of log2(L) over [-3, 3] (L in [1/8, 8]), the outer bins open-ended.
    out.bin_edges.resize(bins + 1);
    for (int k = 0; k <= bins; ++k) out.bin_edges[k] = std::exp2(-3.0 + 6.0 * k / bins);
    out.histogram.assign(bins, 0);
    out.min = std::numeric_limits<double>::infinity();
  }
  // Adds one length; true when it is the longest so far (the caller then sets max_at).
  bool add(double len) {
    ++out_.count;
    sum_ += len;
    out_.min = std::min(out_.min, len);
    const bool longest = out_.count == 1 || len > out_.max;
    out_.max = std::max(out_.max, len);
    if (len >= 1 / std::sqrt(2.0) && len <= std::sqrt(2.0)) ++unit_;
    // Clamped as a double: a collapsed edge (len 0) gives pos = -inf, whose cast is undefined.
    const double pos = (std::log2(len) + 3.0) / 6.0 * bins_;
    out_.histogram[pos > 0 ? static_cast<int>(std::min(std::floor(pos), bins_ - 1.0)) : 0]++;
    return longest;
  }
  void finish() {
    if (out_.count) {
      out_.mean = sum_ / static_cast<double>(out_.count);
      out_.unit_fraction = static_cast<double>(unit_) / static_cast<double>(out_.count);
    } else {
      out_.min = 0;
    }
  }

 private:
  EdgeLengthStats& out_;
  int bins_;
  double sum_ = 0;
  std::size_t unit_ = 0;
};

// Metric lengths of the distinct edges of the cells, each measured once as the curved Lagrange
// edge it is: into all, and (when simplices is not null) the edges of the simplex cells
// (triangles in 2D, tetrahedra in 3D) into simplices too.
template <int Dim>
void measure_edges(const HybridMesh<Dim>& mesh, const std::vector<CellBlock>& blocks, const MetricField<Dim>& metric,
                   int bins, EdgeLengthStats& all, EdgeLengthStats* simplices,
                   const std::function<void(std::size_t done, std::size_t total)>& progress) {
  const CellType simplex = Dim == 2 ? CellType::Triangle : CellType::Tetrahedron;
  EdgeLengthAccumulator acc_all(all, bins);
  std::optional<EdgeLengthAccumulator> acc_simplex;
  if (simplices) acc_simplex.emplace(*simplices, bins);
  // The distinct edges in order of first appearance (block, cell, local edge), then their
  // lengths on worker threads (modules/base/parallel.h; the metric fields are read-only), then
  // the statistics in that order, so the result does not depend on the workers.
  struct EdgeRef {
    std::uint32_t block, k;
    std::size_t cell;
  };
  std::unordered_map<std::uint64_t, std::size_t> index;
  std::vector<EdgeRef> refs;
  std::vector<std::uint8_t> in_simplex;
  for (std::size_t bi = 0; bi < blocks.size(); ++bi) {
    const CellBlock& b = blocks[bi];
    const bool simplex_block = simplices && b.type == simplex;
    const CellTopology& topo = topology(b.type);
    for (std::size_t i = 0; i < b.size(); ++i) {
      const NodeId* c = b.cell(i);
      for (std::size_t k = 0; k < topo.edges.size(); ++k) {
        const NodeId v0 = c[topo.edges[k][0]], v1 = c[topo.edges[k][1]];
        const std::uint64_t key =
            (static_cast<std::uint64_t>(std::min(v0, v1)) << 32) | static_cast<std::uint32_t>(std::max(v0, v1));
        const auto [it, fresh] = index.try_emplace(key, refs.size());
        if (fresh) {
          refs.push_back({static_cast<std::uint32_t>(bi), static_cast<std::uint32_t>(k), i});
          in_simplex.push_back(0);
        }
        if (simplex_block) in_simplex[it->second] = 1;
      }
    }
  }
  std::vector<double> length(refs.size());
  std::atomic<std::size_t> measured{0};
  parallel_chunks(refs.size(), 1024, [&](unsigned, std::size_t begin, std::size_t end) {
    std::vector<double> edge;
    for (std::size_t r = begin; r < end; ++r) {
      const CellBlock& b = blocks[refs[r].block];
      const LagrangeElement& e = lagrange_element(b.type, b.order);
      const NodeId* c = b.cell(refs[r].cell);
      edge.resize(static_cast<std::size_t>(b.order + 1) * Dim);
      // Gmsh line order: the two ends, then the interior nodes.
      const auto& en = e.edge_nodes(static_cast<int>(refs[r].k));
      for (int d = 0; d < Dim; ++d) {
        edge[d] = mesh.nodes[c[en.front()]][d];
        edge[Dim + d] = mesh.nodes[c[en.back()]][d];
      }
      for (int s = 1; s < b.order; ++s)
        for (int d = 0; d < Dim; ++d) edge[(s + 1) * Dim + d] = mesh.nodes[c[en[s]]][d];
      length[r] = metric_length_curved<Dim>(metric, edge.data(), b.order);
    }
    if (progress) progress(measured.fetch_add(end - begin) + (end - begin), refs.size());
  });
  // The midpoint of an edge's end nodes, for the report's max_at.
  const auto midpoint = [&](std::size_t r) {
    const CellBlock& b = blocks[refs[r].block];
    const auto& en = lagrange_element(b.type, b.order).edge_nodes(static_cast<int>(refs[r].k));
    const NodeId* c = b.cell(refs[r].cell);
    std::ostringstream w;
    w << "(";
    for (int d = 0; d < Dim; ++d) w << (d ? ", " : "") << 0.5 * (mesh.nodes[c[en.front()]][d] + mesh.nodes[c[en.back()]][d]);
    w << ")";
    return w.str();
  };
  for (std::size_t r = 0; r < refs.size(); ++r) {
    if (acc_all.add(length[r])) all.max_at = midpoint(r);
    if (acc_simplex && in_simplex[r] && acc_simplex->add(length[r])) simplices->max_at = midpoint(r);
  }
  acc_all.finish();
  if (acc_simplex) acc_simplex->finish();
}

// Records one certified cell in the report and the per-cell results; `where` describes it
// ("<type> cell i of block b at (x, y)") and is called for the first invalid cell and whenever
// the smallest scaled Jacobian so far drops (rarely: a few dozen times per mesh).
template <class Where>
void record_cell(const JacobianBounds& jb, double sj, double ar, QualityReport& r, CellQuality* per_cell,
                 Where&& where, bool corners_positive = true) {
  if (!jb.valid && r.cells_invalid++ == 0) r.first_invalid = where();
  if (jb.valid && !corners_positive) {
    ++r.cells_inverted_corners;
    if (r.cells_invalid++ == 0) r.first_invalid = where() + " (Jacobian positive, corners inverted)";
  }
  if (!jb.proven) ++r.cells_unproven;
  if (sj < r.scaled_jacobian_min) {
    r.scaled_jacobian_min = sj;
    r.scaled_jacobian_worst = where();
  }
  if (jb.valid) r.aspect_ratio_max = std::max(r.aspect_ratio_max, ar);
  if (per_cell) {
    per_cell->valid.push_back(jb.valid && corners_positive ? 1 : 0);
    per_cell->scaled_jacobian.push_back(sj);
    per_cell->aspect_ratio.push_back(ar);
  }
}

// The facets of a 3D surface mesh (boundary blocks, no cells) as its cells: triangles certified
// relative to their flat triangles, quadrilaterals in the plane of their vector area
// (validity.h); the aspect ratio in that plane frame.
template <int Dim>
void assess_surface(const HybridMesh<Dim>& mesh, JacobianCertifier& certifier, QualityReport& r,
                    CellQuality* per_cell) {
  if constexpr (Dim == 3) {
    std::vector<Eigen::Vector3d> nodes;
    std::vector<double> plane, grad;
    for (const CellBlock& b : mesh.boundary) {
      const bool triangle = b.type == CellType::Triangle;
      r.cells_by_type[type_key(b)] += b.size();
      r.cells_total += b.size();
      const LagrangeElement& e = lagrange_element(b.type, b.order);
      nodes.resize(static_cast<std::size_t>(e.size()));
      plane.resize(static_cast<std::size_t>(e.size()) * 2);
      grad.resize(static_cast<std::size_t>(e.size()) * 2);
      for (std::size_t i = 0; i < b.size(); ++i) {
        const NodeId* c = b.cell(i);
        for (int k = 0; k < e.size(); ++k) nodes[static_cast<std::size_t>(k)] = mesh.nodes[c[k]];
        const JacobianBounds jb = triangle ? certify_surface_triangle(certifier, b.order, nodes.data())
                                           : certify_surface_quad(certifier, b.order, nodes.data());
        const double sj = jb.scaled_lower();
        const bool framed = triangle ? surface_triangle_plane_coords(b.order, nodes.data(), plane.data())
                                     : surface_quad_plane_coords(b.order, nodes.data(), plane.data());
        const double ar =
            framed ? aspect_ratio<2>(e, plane.data(), grad.data()) : std::numeric_limits<double>::infinity();
        record_cell(jb, sj, ar, r, per_cell, [&] {
          std::ostringstream w;
          w << "surface " << cell_name(b.type) << ' ' << i << " of boundary block " << (&b - mesh.boundary.data())
            << " at (" << nodes[0][0] << ", " << nodes[0][1] << ", " << nodes[0][2] << ")";
          return w.str();
        });
      }
    }
  } else {
    (void)mesh, (void)certifier, (void)r, (void)per_cell;
  }
}

}  // namespace

std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  std::ostringstream s;
  s << std::setprecision(10) << x;
  return s.str();
}

std::string json_string(const std::string& x) {
  std::string out = "\"";
  for (char ch : x) {
    const auto u = static_cast<unsigned char>(ch);
    if (u < 0x20) {  // control characters may not appear raw in a JSON string (RFC 8259, Sec. 7)
      out += "\\u00";
      out += "0123456789abcdef"[u >> 4];
      out += "0123456789abcdef"[u & 0xf];
      continue;
    }
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}

template <int Dim>
QualityReport assess_quality(const HybridMesh<Dim>& mesh, const MetricField<Dim>* metric, const QualityOptions& options,
                             CellQuality* per_cell) {
  QualityReport r;
  JacobianCertifier certifier(options.validity);
  std::vector<std::unique_ptr<JacobianCertifier>> extra;  // workers 1.. (parallel.h)
  for (unsigned w = 1; w < worker_threads(); ++w) extra.push_back(std::make_unique<JacobianCertifier>(options.validity));
  r.scaled_jacobian_min = std::numeric_limits<double>::infinity();
  if (per_cell) *per_cell = CellQuality{};

  // 1. Cells: certified validity, scaled Jacobian and aspect ratio.
  // A 3D mesh of boundary facets alone (a surface mesh): its triangles and quadrilaterals are the
  // cells, certified in their planes (validity.h).
  r.surface = Dim == 3 && mesh.cells.empty() && !mesh.boundary.empty();
  if (r.surface) assess_surface(mesh, certifier, r, per_cell);
  // The progress: the cells' share of the work, then the edges' (measured: the certification of
  // curved cells costs several times the metric lengths of their edges).
  const double cells_share = metric && !r.surface ? kCellsShareOfWork : 1.0;
  std::size_t cells_all = 0;
  for (const CellBlock& b : mesh.cells) cells_all += b.size();
  std::atomic<std::size_t> certified{0};
  for (const CellBlock& b : mesh.cells) {
    const LagrangeElement& e = lagrange_element(b.type, b.order);
    r.cells_by_type[type_key(b)] += b.size();
    r.cells_total += b.size();
    // Certified on worker threads (modules/base/parallel.h), recorded in order.
    std::vector<JacobianBounds> bounds(b.size());
    std::vector<double> ratios(b.size());
    std::vector<char> corners(b.size(), 1);
    parallel_chunks(b.size(), 256, [&](unsigned w, std::size_t begin, std::size_t end) {
      JacobianCertifier& cert = w == 0 ? certifier : *extra.at(w - 1);
      std::vector<double> xs(static_cast<std::size_t>(e.size()) * Dim), gs(xs.size());
      for (std::size_t i = begin; i < end; ++i) {
        gather_coords(mesh, b, i, xs.data());
        bounds[i] = cert.certify(b.type, b.order, xs.data());
        ratios[i] = aspect_ratio<Dim>(e, xs.data(), gs.data());
        corners[i] = simplex_corners_positive<Dim>(b.type, xs.data()) ? 1 : 0;
      }
      if (options.progress) {
        const std::size_t n = certified.fetch_add(end - begin) + (end - begin);
        options.progress(cells_share * static_cast<double>(n) / static_cast<double>(cells_all),
                         std::to_string(n) + " of " + std::to_string(cells_all) + " cells certified");
      }
    });
    for (std::size_t i = 0; i < b.size(); ++i) {
      const JacobianBounds& jb = bounds[i];
      const double sj = jb.scaled_lower();
      const double ar = ratios[i];
      record_cell(jb, sj, ar, r, per_cell, [&] {
        std::ostringstream w;
        w << cell_name(b.type) << " cell " << i << " of block " << (&b - mesh.cells.data()) << " at (";
        for (int d = 0; d < Dim; ++d) w << (d ? ", " : "") << mesh.nodes[b.cell(i)[0]][d];
        w << ")";
        return w.str();
      }, corners[i] != 0);
    }
  }
  if (r.cells_total == 0) r.scaled_jacobian_min = 0;

  // 2. Metric length of every distinct edge (keyed by its two vertices), and the simplices' share
  // (2D triangles, with their shape in the metric; 3D tetrahedra).
  if (metric) {
    r.has_metric = true;
    std::function<void(std::size_t, std::size_t)> edges_progress;
    if (options.progress)
      edges_progress = [&](std::size_t done, std::size_t total) {
        options.progress(cells_share + (1 - cells_share) * static_cast<double>(done) / static_cast<double>(total),
                         std::to_string(done) + " of " + std::to_string(total) + " edges measured in the metric");
      };
    measure_edges<Dim>(mesh, r.surface ? mesh.boundary : mesh.cells, *metric, options.histogram_bins, r.metric,
                       Dim == 2 ? &r.triangle_metric.edges : r.surface ? nullptr : &r.tetrahedron_edges, edges_progress);
    if constexpr (Dim == 2) {
      TriangleMetricStats& t = r.triangle_metric;
      t.quality_histogram.assign(10, 0);
      t.quality_min = std::numeric_limits<double>::infinity();
      double sum = 0;
      for (const CellBlock& b : mesh.cells) {
        if (b.type != CellType::Triangle) continue;
        for (std::size_t i = 0; i < b.size(); ++i) {
          const NodeId* c = b.cell(i);
          const Eigen::Vector2d p0 = mesh.nodes[c[0]], p1 = mesh.nodes[c[1]], p2 = mesh.nodes[c[2]];
          const Eigen::Matrix2d m = metric->evaluate((p0 + p1 + p2) / 3).matrix();
          const Eigen::Vector2d e0 = p1 - p0, e1 = p2 - p1, e2 = p0 - p2;
          const double area = 0.5 * (e0.x() * (-e2).y() - e0.y() * (-e2).x()) * std::sqrt(m.determinant());
          const double l2 = e0.dot(m * e0) + e1.dot(m * e1) + e2.dot(m * e2);
          const double q = l2 > 0 ? std::max(0.0, 4 * std::sqrt(3.0) * area / l2) : 0.0;
          ++t.triangles;
          sum += q;
          t.quality_min = std::min(t.quality_min, q);
          t.quality_histogram[static_cast<std::size_t>(std::min(9.0, std::floor(10 * q)))]++;
        }
      }
      if (t.triangles)
        t.quality_mean = sum / static_cast<double>(t.triangles);
      else
        t.quality_min = 0;
    }
  }

  // 3. Conformity.
  r.conformity = check_conformity(mesh);
  return r;
}

namespace {

// The report's extra keys as a tree: "a.b.c" -> {"a": {"b": {"c": value}}}, groups and keys in
// the order they were first added.
struct JsonTree {
  std::string name;                // the key in its parent
  std::string value;               // leaf
  std::vector<JsonTree> children;  // (not pairs holding a JsonTree: Clang rejects the incomplete pair)
  JsonTree& child(const std::string& k) {
    for (JsonTree& c : children)
      if (c.name == k) return c;
    children.push_back(JsonTree{k, {}, {}});
    return children.back();
  }
  void insert(const std::string& key, const std::string& v) {
    const auto dot = key.find('.');
    if (dot == std::string::npos) {
      child(key).value = v;
    } else {
      child(key.substr(0, dot)).insert(key.substr(dot + 1), v);
    }
  }
  std::string text() const {
    if (children.empty()) return value;
    std::string out = "{";
    for (std::size_t k = 0; k < children.size(); ++k)
      out += (k ? ", " : "") + json_string(children[k].name) + ": " + children[k].text();
    return out + "}";
  }
};

}  // namespace

std::string report_json(const QualityReport& r) {
  std::ostringstream s;
  s << "{\n  \"name\": " << json_string(r.name) << ",\n";
  s << "  \"ok\": " << (r.ok() && r.run_failures.empty() ? "true" : "false") << ",\n";
  if (r.exit_code >= 0) {
    s << "  \"exit_code\": " << r.exit_code << ",\n  \"failures\": [";
    for (std::size_t i = 0; i < r.run_failures.size(); ++i) s << (i ? ", " : "") << json_string(r.run_failures[i]);
    s << "],\n";
  }
  s << "  \"cells\": {\n    \"total\": " << r.cells_total << ",\n    \"surface\": " << (r.surface ? "true" : "false")
    << ",\n    \"by_type\": {";
  bool first = true;
  for (const auto& [k, n] : r.cells_by_type) {
    s << (first ? "" : ", ") << json_string(k) << ": " << n;
    first = false;
  }
  s << "},\n    \"invalid\": " << r.cells_invalid << ",\n    \"inverted_corners\": " << r.cells_inverted_corners
    << ",\n    \"unproven\": " << r.cells_unproven
    << ",\n    \"first_invalid\": " << json_string(r.first_invalid) << "\n  },\n";
  s << "  \"scaled_jacobian\": {\"min\": " << json_number(r.scaled_jacobian_min)
    << ", \"worst\": " << json_string(r.scaled_jacobian_worst) << "},\n";
  s << "  \"aspect_ratio\": {\"max\": " << json_number(r.aspect_ratio_max) << "},\n";
  if (r.has_metric) {
    const EdgeLengthStats& m = r.metric;
    s << "  \"metric\": {\n    \"edges\": " << m.count << ",\n    \"unit_fraction\": " << json_number(m.unit_fraction)
      << ",\n    \"min\": " << json_number(m.min) << ",\n    \"max\": " << json_number(m.max)
      << ",\n    \"max_at\": " << json_string(m.max_at)
      << ",\n    \"mean\": " << json_number(m.mean) << ",\n    \"histogram\": {\"bin_edges\": [";
    for (std::size_t k = 0; k < m.bin_edges.size(); ++k) s << (k ? ", " : "") << json_number(m.bin_edges[k]);
    s << "], \"counts\": [";
    for (std::size_t k = 0; k < m.histogram.size(); ++k) s << (k ? ", " : "") << m.histogram[k];
    s << "]}";
    const EdgeLengthStats& te = r.tetrahedron_edges;
    if (te.count)
      s << ",\n    \"tetrahedra\": {\"edges\": " << te.count << ", \"unit_fraction\": " << json_number(te.unit_fraction)
        << ", \"edge_min\": " << json_number(te.min) << ", \"edge_max\": " << json_number(te.max)
        << ", \"edge_mean\": " << json_number(te.mean) << "}";
    const TriangleMetricStats& t = r.triangle_metric;
    if (t.triangles) {
      s << ",\n    \"triangles\": {\"count\": " << t.triangles << ", \"edges\": " << t.edges.count
        << ", \"unit_fraction\": " << json_number(t.edges.unit_fraction)
        << ", \"edge_min\": " << json_number(t.edges.min) << ", \"edge_max\": " << json_number(t.edges.max)
        << ", \"edge_max_at\": " << json_string(t.edges.max_at)
        << ", \"edge_mean\": " << json_number(t.edges.mean) << ", \"edge_histogram_counts\": [";
      for (std::size_t k = 0; k < t.edges.histogram.size(); ++k) s << (k ? ", " : "") << t.edges.histogram[k];
      s << "], \"quality_min\": " << json_number(t.quality_min) << ", \"quality_mean\": " << json_number(t.quality_mean)
        << ", \"quality_histogram\": {\"bin_edges\": [0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1], "
           "\"counts\": [";
      for (std::size_t k = 0; k < t.quality_histogram.size(); ++k) s << (k ? ", " : "") << t.quality_histogram[k];
      s << "]}}";
    }
    s << "\n  },\n";
  }
  const ConformityReport& c = r.conformity;
  s << "  \"conformity\": {\"ok\": " << (c.ok ? "true" : "false") << ", \"interior_facets\": " << c.interior_facets
    << ", \"boundary_facets\": " << c.boundary_facets << ", \"open_facets\": " << c.open_facets
    << ", \"overshared_facets\": " << c.overshared_facets << ", \"node_mismatches\": " << c.node_mismatches
    << ", \"order_transitions\": " << c.order_transitions
    << ", \"orientation_mismatches\": " << c.orientation_mismatches << ", \"stray_boundary\": " << c.stray_boundary
    << ", \"first_problem\": " << json_string(c.first_problem) << "},\n";
  // Extra sections: dotted keys nest, "a.b.c" under "a" then "b" (groups in name order).
  JsonTree tree;
  for (const auto& [k, v] : r.extra) tree.insert(k, v);
  for (const JsonTree& group : tree.children) s << "  " << json_string(group.name) << ": " << group.text() << ",\n";
  s << "  \"timings_s\": {";
  for (std::size_t k = 0; k < r.timings_s.size(); ++k)
    s << (k ? ", " : "") << json_string(r.timings_s[k].first) << ": " << json_number(r.timings_s[k].second);
  s << "}\n}\n";
  return s.str();
}

std::string report_summary(const QualityReport& r) {
  std::ostringstream s;
  s << std::setprecision(4);
  if (r.cells_total == 0) {
    s << r.name << ": no cells (a surface mesh alone)\n  conformity: "
      << (r.conformity.ok ? "ok" : "FAILED: " + r.conformity.first_problem) << '\n';
    return s.str();
  }
  s << r.name << ": " << r.cells_total << (r.surface ? " surface facets (" : " cells (");
  bool first = true;
  for (const auto& [k, n] : r.cells_by_type) {
    s << (first ? "" : ", ") << n << ' ' << k;
    first = false;
  }
  s << ")\n  invalid cells: " << r.cells_invalid;
  if (r.cells_unproven) s << " (" << r.cells_unproven << " undecided at the depth limit)";
  if (r.cells_inverted_corners)
    s << " (" << r.cells_inverted_corners << " with a positive Jacobian but inverted corners)";
  s << "\n  min scaled Jacobian: " << r.scaled_jacobian_min << "   max aspect ratio: " << r.aspect_ratio_max << '\n';
  if (r.has_metric)
    s << "  metric edge lengths: " << r.metric.count << " edges, " << 100.0 * r.metric.unit_fraction
      << "% in [1/sqrt2, sqrt2], min " << r.metric.min << ", max " << r.metric.max << '\n';
  if (r.has_metric && r.tetrahedron_edges.count)
    s << "  tetrahedra in the metric: " << r.tetrahedron_edges.count << " edges, " << 100.0 * r.tetrahedron_edges.unit_fraction
      << "% unit, min " << r.tetrahedron_edges.min << ", max " << r.tetrahedron_edges.max << '\n';
  if (r.has_metric && r.triangle_metric.triangles)
    s << "  triangles in the metric: " << 100.0 * r.triangle_metric.edges.unit_fraction
      << "% of their edges unit, shape quality min " << r.triangle_metric.quality_min << ", mean "
      << r.triangle_metric.quality_mean << '\n';
  s << "  conformity: " << (r.conformity.ok ? "ok" : "FAILED: " + r.conformity.first_problem) << '\n';
  if (!r.ok())
    s << "  MESH FAILED: " << r.cells_invalid << " invalid cells"
      << (r.first_invalid.empty() ? "" : " (first: " + r.first_invalid + ")")
      << (r.conformity.ok ? "" : ", not conforming") << '\n';
  return s.str();
}

template QualityReport assess_quality(const HybridMesh<2>&, const MetricField<2>*, const QualityOptions&, CellQuality*);
template QualityReport assess_quality(const HybridMesh<3>&, const MetricField<3>*, const QualityOptions&, CellQuality*);

}  // namespace mesh
}  // namespace plaf
