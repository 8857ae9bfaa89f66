// SPDX-License-Identifier: MIT
#include "modules/mesh/quality.h"

#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "modules/mesh/annulus.h"
#include "tests/modules/mesh/structured_mesh.h"

using namespace plaf;

namespace {

// Independent cells collected into one mesh and assessed once (certifier set-up per (type,
// order) dominates: about 0.1 s for Q = 4 tetrahedra). add() returns the cell's number.
template <int Dim>
struct CellSet {
  using Point = Eigen::Matrix<double, Dim, 1>;
  HybridMesh<Dim> mesh;
  std::vector<std::pair<CellType, std::size_t>> where;  // (type, index in its block), order q
  int q;
  CellQuality pc;
  QualityReport report;

  explicit CellSet(int order) : q(order) {}
  // A cell of (type, q) whose node with reference coordinates r sits at map(r).
  template <class Map>
  std::size_t add(CellType t, Map map) {
    const LagrangeElement& e = lagrange_element(t, q);
    CellBlock& b = mesh.block(t, q);
    where.push_back({t, b.size()});
    for (int i = 0; i < e.size(); ++i) {
      const auto r = e.ref_node(i);
      b.connectivity.push_back(static_cast<NodeId>(mesh.nodes.size()));
      mesh.nodes.push_back(map(Eigen::Vector3d(r[0], r[1], r[2])));
    }
    return where.size() - 1;
  }
  // The affine cell x = a r + shift.
  std::size_t add_affine(CellType t, const Eigen::Matrix<double, Dim, Dim>& a, const Point& shift = Point::Zero()) {
    return add(t, [&](const Eigen::Vector3d& r) -> Point { return a * r.head<Dim>() + shift; });
  }
  void assess() { report = assess_quality<Dim>(mesh, nullptr, QualityOptions{}, &pc); }
  // Position of cell k in the per-cell arrays (blocks in mesh order).
  std::size_t flat(std::size_t k) const {
    std::size_t offset = 0;
    for (const CellBlock& b : mesh.cells) {
      if (b.type == where[k].first) return offset + where[k].second;
      offset += b.size();
    }
    return offset;
  }
  double aspect_ratio(std::size_t k) const { return pc.aspect_ratio.at(flat(k)); }
  bool valid(std::size_t k) const { return pc.valid.at(flat(k)) != 0; }
};

template <int Dim>
QualityReport assess(const HybridMesh<Dim>& m, CellQuality* pc = nullptr, const MetricField<Dim>* metric = nullptr,
                     QualityOptions options = {}) {
  return assess_quality<Dim>(m, metric, options, pc);
}

// A strict reader of the JSON grammar (RFC 8259) that flattens the document into dotted paths:
// scalars (strings decoded, other values as written) and the set of object/array paths. Throws
// std::runtime_error on any syntax error, raw control character in a string, or duplicate key.
class FlatJson {
 public:
  explicit FlatJson(const std::string& text) : s_(text) {
    value("");
    ws();
    if (i_ != s_.size()) fail("text after the document");
  }
  std::map<std::string, std::string> scalars;
  std::set<std::string> containers;
  bool has(const std::string& path) const { return scalars.count(path) || containers.count(path); }
  double number(const std::string& path) const { return std::stod(scalars.at(path)); }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("JSON: " + why + " at offset " + std::to_string(i_));
  }
  void ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\n' || s_[i_] == '\t' || s_[i_] == '\r')) ++i_;
  }
  char peek() {
    ws();
    if (i_ >= s_.size()) fail("unexpected end");
    return s_[i_];
  }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++i_;
  }
  static std::string join(const std::string& a, const std::string& b) { return a.empty() ? b : a + "." + b; }
  void value(const std::string& path) {
    const char c = peek();
    if (c == '{' || c == '[') {
      if (!containers.insert(path).second) fail("duplicate key " + path);
      ++i_;
      const char close = c == '{' ? '}' : ']';
      if (peek() == close) {
        ++i_;
        return;
      }
      for (int k = 0;; ++k) {
        std::string key = std::to_string(k);
        if (c == '{') {
          key = string();
          expect(':');
        }
        value(join(path, key));
        if (peek() == ',') {
          ++i_;
          continue;
        }
        expect(close);
        return;
      }
    }
    std::string text;
    if (c == '"') {
      text = string();
    } else {
      const std::size_t start = i_;
      while (i_ < s_.size() && std::string("+-.0123456789eEtruefalsn").find(s_[i_]) != std::string::npos) ++i_;
      text = s_.substr(start, i_ - start);
      if (text != "true" && text != "false" && text != "null" && !is_number(text)) fail("bad literal '" + text + "'");
    }
    if (!scalars.emplace(path, text).second) fail("duplicate key " + path);
  }
  // -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?
  static bool is_number(const std::string& t) {
    std::size_t k = 0;
    auto digits = [&] {
      const std::size_t from = k;
      while (k < t.size() && std::isdigit(static_cast<unsigned char>(t[k]))) ++k;
      return k > from;
    };
    if (k < t.size() && t[k] == '-') ++k;
    if (k < t.size() && t[k] == '0')
      ++k;
    else if (!digits())
      return false;
    if (k < t.size() && t[k] == '.' && !(++k, digits())) return false;
    if (k < t.size() && (t[k] == 'e' || t[k] == 'E')) {
      ++k;
      if (k < t.size() && (t[k] == '+' || t[k] == '-')) ++k;
      if (!digits()) return false;
    }
    return k == t.size();
  }
  std::string string() {
    expect('"');
    std::string out;
    for (;;) {
      if (i_ >= s_.size()) fail("unterminated string");
      const char c = s_[i_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) fail("raw control character in a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (i_ >= s_.size()) fail("unterminated escape");
      const char e = s_[i_++];
      switch (e) {
        case '"':
        case '\\':
        case '/':
          out += e;
          break;
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'n':
          out += '\n';
          break;
        case 'r':
          out += '\r';
          break;
        case 't':
          out += '\t';
          break;
        case 'u': {
          if (i_ + 4 > s_.size()) fail("short \\u escape");
          const unsigned long code = std::stoul(s_.substr(i_, 4), nullptr, 16);
          if (code >= 0x80) fail("non-ASCII \\u escape (not needed here)");
          out += static_cast<char>(code);
          i_ += 4;
          break;
        }
        default:
          fail("bad escape");
      }
    }
  }
  std::string s_;
  std::size_t i_ = 0;
};

}  // namespace

TEST_CASE("quality: aspect ratio of an affine w x h rectangle is max(w, h) / min(w, h)") {
  // J = diag(w, h) and W = I for the quadrilateral (quality.h), so J W^-1 has singular values w, h.
  const double ratios[] = {1.0, 2.0, 10.0, 1e2, 1e3, 1e4, 0.5, 1e-4};
  for (int q = 1; q <= max_order; ++q) {
    CellSet<2> set(q);
    const double h = 0.3;
    for (const double ratio : ratios)
      set.add_affine(CellType::Quadrilateral, Eigen::Vector2d(ratio * h, h).asDiagonal());
    set.assess();
    for (std::size_t k = 0; k < std::size(ratios); ++k) {
      INFO("Q=", q, " w/h=", ratios[k]);
      CHECK(set.aspect_ratio(k) == doctest::Approx(std::max(ratios[k], 1 / ratios[k])).epsilon(1e-12));
    }
    CHECK(set.report.aspect_ratio_max == doctest::Approx(1e4).epsilon(1e-12));
  }
}

TEST_CASE(
    "quality: regular cells have aspect ratio 1, reference simplices sqrt 3 and 2, prisms of height H max(H, 1/H)") {
  // Regular cells placed independently of W's own coordinates: an equilateral triangle on the
  // unit circle (counter-clockwise), a regular tetrahedron on alternate corners of a cube (edge
  // sqrt 2, positively oriented), a unit square. An affine map that takes a regular simplex onto
  // a regular simplex scales all edge vectors by one factor, hence is a similarity: ratio 1.
  const auto on_circle = [](double deg) {
    const double a = deg * std::numbers::pi / 180;
    return Eigen::Vector2d(std::cos(a), std::sin(a));
  };
  const Eigen::Vector2d p0 = on_circle(90), p1 = on_circle(210), p2 = on_circle(330);
  Eigen::Matrix2d tri;
  tri << p1 - p0, p2 - p0;
  Eigen::Matrix3d tet;
  tet << Eigen::Vector3d(1, 0, 1), Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0, 1, 1);
  REQUIRE(tet.determinant() > 0);
  const double sqrt3 = std::sqrt(3.0);
  for (int q = 1; q <= max_order; ++q) {
    INFO("Q=", q);
    CellSet<2> set2(q);
    CellSet<3> set3(q);
    std::vector<std::pair<std::size_t, double>> want2, want3;
    want2.push_back({set2.add_affine(CellType::Triangle, tri), 1.0});
    want2.push_back({set2.add_affine(CellType::Quadrilateral, Eigen::Matrix2d::Identity()), 1.0});
    want3.push_back({set3.add_affine(CellType::Tetrahedron, tet), 1.0});
    // Reference simplices (J = I): the aspect ratio is that of W, whose Gram matrix W^T W has 1
    // on the diagonal and 1/2 off it (unit edges at 60 degrees). Triangle: eigenvalues 3/2 and
    // 1/2, ratio sqrt(3/2 / 1/2) = sqrt 3. Tetrahedron: 2 and 1/2 (twice), ratio sqrt 4 = 2. The
    // reference prism is the reference triangle times a unit height, so also sqrt 3.
    want2.push_back({set2.add_affine(CellType::Triangle, Eigen::Matrix2d::Identity()), sqrt3});
    want3.push_back({set3.add_affine(CellType::Tetrahedron, Eigen::Matrix3d::Identity()), 2.0});
    want3.push_back({set3.add_affine(CellType::Prism, Eigen::Matrix3d::Identity()), sqrt3});
    // Equilateral base of side 1 and height H: J = W diag(1, 1, H), so J W^-1 = diag(I, H) (W is
    // block diagonal) with singular values 1, 1, H.
    // Height 1e-5: a boundary-layer prism whose height is 1e-5 of its base, aspect ratio 1e5.
    for (const double height : {1.0, 3.0, 0.01, 1e4, 1e-5}) {
      Eigen::Matrix3d prism = Eigen::Matrix3d::Zero();
      prism.topLeftCorner<2, 2>() = tri / sqrt3;  // circumradius 1: side sqrt 3
      prism(2, 2) = height;
      want3.push_back({set3.add_affine(CellType::Prism, prism), std::max(height, 1 / height)});
    }
    set2.assess();
    set3.assess();
    for (const auto& [k, ar] : want2) CHECK(set2.aspect_ratio(k) == doctest::Approx(ar).epsilon(1e-12));
    for (const auto& [k, ar] : want3) CHECK(set3.aspect_ratio(k) == doctest::Approx(ar).epsilon(1e-12));
  }
}

TEST_CASE("quality: aspect ratio and validity are invariant under rotation, translation and scale 1e-8 .. 1e8") {
  // Skewed, curved cells (a quadratic bend of the reference cell), then x -> s R x + s t.
  const auto bent = [](const Eigen::Vector3d& r) {
    return Eigen::Vector3d(r[0] + 0.3 * r[1] + 0.05 * r[1] * r[1], 0.8 * r[1] - 0.06 * r[0] * r[0] + 0.1 * r[2],
                           0.9 * r[2] + 0.04 * r[0] * r[1]);
  };
  const Eigen::Matrix2d r2 = Eigen::Rotation2Dd(0.7).toRotationMatrix();
  const Eigen::Matrix3d r3 = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const double scales[] = {1e-8, 1e-4, 1e4, 1e8};
  for (int q = 1; q <= max_order; ++q) {
    CellSet<2> set2(q);
    CellSet<3> set3(q);
    // Cells 0 and 1 unmoved; then, per scale, the same two cells moved.
    const auto add_all = [&](double s, bool moved) {
      const auto map2 = [&](const Eigen::Vector3d& r) {
        const Eigen::Vector2d x = bent(r).head<2>();
        return Eigen::Vector2d(moved ? Eigen::Vector2d(s * (r2 * x + Eigen::Vector2d(10, -7))) : x);
      };
      const auto map3 = [&](const Eigen::Vector3d& r) {
        return Eigen::Vector3d(moved ? Eigen::Vector3d(s * (r3 * bent(r) + Eigen::Vector3d(10, -7, 3))) : bent(r));
      };
      set2.add(CellType::Triangle, map2);
      set2.add(CellType::Quadrilateral, map2);
      set3.add(CellType::Tetrahedron, map3);
      set3.add(CellType::Prism, map3);
    };
    add_all(1, false);
    for (const double s : scales) add_all(s, true);
    set2.assess();
    set3.assess();
    CHECK(set2.report.cells_invalid == 0);
    CHECK(set3.report.cells_invalid == 0);
    for (std::size_t k = 2; k < set2.where.size(); ++k) {
      INFO("Q=", q, " scale=", scales[k / 2 - 1], " cell ", k);
      CHECK(set2.aspect_ratio(k) == doctest::Approx(set2.aspect_ratio(k % 2)).epsilon(1e-9));
      CHECK(set3.aspect_ratio(k) == doctest::Approx(set3.aspect_ratio(k % 2)).epsilon(1e-9));
    }
  }
}

TEST_CASE("quality: cells_by_type and cells_total count every block, a quad/triangle mix conforms") {
  for (int q = 1; q <= max_order; ++q) {
    INFO("Q=", q);
    // Columns 0..k-1 quadrilaterals, k..nx-1 split squares, on one node lattice.
    const int nx = 5, ny = 3, k = 2;
    plaf::test::StructuredMesh<2> s({nx, ny, 0}, q);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        if (i < k)
          s.add_cell(CellType::Quadrilateral, {i, j, 0}, {{i + 1, j, 0}, {i, j + 1, 0}});
        else
          plaf::test::add_split_square(s, i, j);
    s.tag_box_boundary();
    const QualityReport r = assess(s.mesh);
    const std::string qs = "_Q" + std::to_string(q);
    CHECK(r.cells_by_type.size() == 2);
    CHECK(r.cells_by_type.at("quadrilateral" + qs) == std::size_t{k * ny});
    CHECK(r.cells_by_type.at("triangle" + qs) == std::size_t{2 * (nx - k) * ny});
    CHECK(r.cells_total == std::size_t{k * ny + 2 * (nx - k) * ny});
    CHECK(r.cells_invalid == 0);
    CHECK(r.conformity.ok);
    CHECK(r.ok());
    // Straight cells: det J is constant, scaled Jacobian 1.
    CHECK(r.scaled_jacobian_min == doctest::Approx(1).epsilon(1e-9));

    const auto prisms = plaf::test::prism_block(2, 3, 2, q);
    const QualityReport p = assess(prisms.mesh);
    CHECK(p.cells_by_type.size() == 1);
    CHECK(p.cells_by_type.at("prism" + qs) == std::size_t{2 * 2 * 3 * 2});
    CHECK(p.cells_total == std::size_t{2 * 2 * 3 * 2});
    CHECK(p.ok());
    const QualityReport t = assess(plaf::test::kuhn_tets(1, 2, 1, q).mesh);
    CHECK(t.cells_by_type.at("tetrahedron" + qs) == std::size_t{6 * 2});
    CHECK(t.ok());
  }
}

TEST_CASE("quality: one mirrored cell is the one invalid cell, the report fails and the flags mark it") {
  for (int q = 1; q <= max_order; ++q)
    for (const CellType t : {CellType::Quadrilateral, CellType::Triangle, CellType::Prism}) {
      INFO(std::string(cell_name(t)), " Q=", q);
      // Cell `mirrored` has its two first reference axes swapped: the same nodes and facets,
      // det J < 0 everywhere.
      const std::size_t mirrored = 4;
      std::size_t index = 0;
      CellQuality pc;
      QualityReport r;
      const auto axes = [&](plaf::test::Corner a, plaf::test::Corner b, plaf::test::Corner c) {
        std::vector<plaf::test::Corner> out{a, b};
        if (t == CellType::Prism) out.push_back(c);
        if (index++ == mirrored) std::swap(out[0], out[1]);
        return out;
      };
      if (t == CellType::Prism) {
        plaf::test::StructuredMesh<3> s({3, 2, 1}, q);
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 3; ++i) {
            s.add_cell(t, {i, j, 0}, axes({i + 1, j, 0}, {i + 1, j + 1, 0}, {i, j, 1}));
            s.add_cell(t, {i, j, 0}, axes({i + 1, j + 1, 0}, {i, j + 1, 0}, {i, j, 1}));
          }
        s.tag_box_boundary();
        r = assess(s.mesh, &pc);
      } else {
        plaf::test::StructuredMesh<2> s({3, 2, 0}, q);
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 3; ++i)
            if (t == CellType::Quadrilateral) {
              s.add_cell(t, {i, j, 0}, axes({i + 1, j, 0}, {i, j + 1, 0}, {}));
            } else {
              s.add_cell(t, {i, j, 0}, axes({i + 1, j, 0}, {i + 1, j + 1, 0}, {}));
              s.add_cell(t, {i, j, 0}, axes({i + 1, j + 1, 0}, {i, j + 1, 0}, {}));
            }
        s.tag_box_boundary();
        r = assess(s.mesh, &pc);
      }
      CHECK(r.cells_invalid == 1);
      CHECK_FALSE(r.ok());
      // Mirroring keeps every facet's nodes, but the mirrored cell now lies on the same side of
      // the facets it shares as its neighbours: a fold.
      CHECK(r.conformity.node_mismatches == 0);
      CHECK(r.conformity.orientation_mismatches > 0);
      REQUIRE(pc.valid.size() == r.cells_total);
      REQUIRE(pc.scaled_jacobian.size() == r.cells_total);
      REQUIRE(pc.aspect_ratio.size() == r.cells_total);
      for (std::size_t k = 0; k < pc.valid.size(); ++k) CHECK(pc.valid[k] == (k == mirrored ? 0 : 1));
      CHECK(r.scaled_jacobian_min < 0);
      CHECK(pc.scaled_jacobian[mirrored] == r.scaled_jacobian_min);
      CHECK(report_summary(r).find("invalid cells: 1") != std::string::npos);
      CHECK(report_summary(r).find("MESH FAILED") != std::string::npos);
    }
}

TEST_CASE("quality: metric edge lengths on a uniform grid: unit fraction, min/max and histogram") {
  // nx x ny squares of side h have nx (ny + 1) + ny (nx + 1) distinct axis edges, and the
  // triangle split adds nx ny diagonals of length h sqrt 2. With the isotropic metric of size
  // m the lengths are h/m and sqrt 2 h/m; "unit" is [1/sqrt 2, sqrt 2] (quality.h).
  const int nx = 4, ny = 3;
  const std::size_t axis = nx * (ny + 1) + ny * (nx + 1), diagonal = nx * ny;
  const double h = 0.37;
  QualityOptions options;
  // Bins of log2 L over [-3, 3]: with 10 bins of width 0.6, log2 0.5 = -1 lies inside bin 3
  // ([-1.2, -0.6)), log2 1.25 = 0.32 inside bin 5 and log2(1.25 sqrt 2) = 0.82 inside bin 6
  // ([0.6, 1.2)): no length sits on a bin edge.
  options.histogram_bins = 10;
  const auto sum = [](const std::vector<std::size_t>& v) {
    return std::accumulate(v.begin(), v.end(), std::size_t{0});
  };
  for (int q = 1; q <= max_order; ++q) {
    INFO("Q=", q);
    const auto quads = plaf::test::quad_grid(nx, ny, q, h);
    const auto triangles = plaf::test::triangle_grid(nx, ny, q, h);

    // Metric size h: every axis edge has length 1.
    const UniformMetricField<2> size_h(Metric<2>::isotropic(h));
    QualityReport r = assess(quads.mesh, nullptr, &size_h, options);
    CHECK(r.has_metric);
    CHECK(r.metric.count == axis);
    CHECK(r.metric.unit_fraction == 1.0);
    CHECK(r.metric.min == doctest::Approx(1).epsilon(1e-12));
    CHECK(r.metric.max == doctest::Approx(1).epsilon(1e-12));
    CHECK(r.metric.mean == doctest::Approx(1).epsilon(1e-12));
    CHECK(sum(r.metric.histogram) == r.metric.count);
    CHECK(r.metric.bin_edges.size() == r.metric.histogram.size() + 1);

    // Metric size 2h: every edge 0.5, none unit, all in bin 3.
    const UniformMetricField<2> size_2h(Metric<2>::isotropic(2 * h));
    r = assess(quads.mesh, nullptr, &size_2h, options);
    CHECK(r.metric.count == axis);
    CHECK(r.metric.unit_fraction == 0.0);
    CHECK(r.metric.min == doctest::Approx(0.5).epsilon(1e-12));
    CHECK(r.metric.max == doctest::Approx(0.5).epsilon(1e-12));
    CHECK(r.metric.histogram[3] == axis);
    CHECK(sum(r.metric.histogram) == axis);

    // Triangles, size 0.8 h: axis edges 1.25 (unit), diagonals 1.25 sqrt 2 = 1.77 (too long).
    const UniformMetricField<2> size_08h(Metric<2>::isotropic(0.8 * h));
    r = assess(triangles.mesh, nullptr, &size_08h, options);
    CHECK(r.metric.count == axis + diagonal);
    CHECK(r.metric.unit_fraction == doctest::Approx(static_cast<double>(axis) / static_cast<double>(axis + diagonal)));
    CHECK(r.metric.min == doctest::Approx(1.25).epsilon(1e-12));
    CHECK(r.metric.max == doctest::Approx(1.25 * std::sqrt(2.0)).epsilon(1e-12));
    CHECK(r.metric.histogram[5] == axis);
    CHECK(r.metric.histogram[6] == diagonal);
    CHECK(sum(r.metric.histogram) == axis + diagonal);

    // Triangles, size 1.2 h: 0.83 and 1.18, all unit.
    const UniformMetricField<2> size_12h(Metric<2>::isotropic(1.2 * h));
    r = assess(triangles.mesh, nullptr, &size_12h, options);
    CHECK(r.metric.unit_fraction == 1.0);

    // Prisms on unit cubes, size 1.1: axis edges 0.91 and diagonals 1.29, all unit. The edges
    // of 2 x 1 squares: 7 axis edges and 2 diagonals in each of 2 planes, and 6 vertical ones.
    const UniformMetricField<3> size_11(Metric<3>::isotropic(1.1));
    const QualityReport p = assess(plaf::test::prism_block(2, 1, 1, q).mesh, nullptr, &size_11, options);
    CHECK(p.metric.count == 2 * (7 + 2) + 6);
    CHECK(p.metric.unit_fraction == 1.0);
    CHECK(sum(p.metric.histogram) == p.metric.count);
  }
  CHECK_FALSE(assess(plaf::test::quad_grid(1, 1, 1).mesh).has_metric);
}

TEST_CASE("quality: the annulus mesh has min scaled Jacobian r_in / r_out of its innermost ring") {
  // A cell of the annulus is the image of [0,1]^2 under x = r(u) (cos t(v), sin t(v)) with
  // r = r0 + u dr and t = t0 + v dt, so det J = dr dt r(u) and min/max det J = r0 / (r0 + dr).
  // A triangle is that map composed with an affine map of the reference triangle (constant
  // factor in det J) and spans the whole ring, so the same ratio holds for it.
  // Q = 1: a quadrilateral is an isosceles trapezoid whose bilinear det J is linear in u and
  // proportional to the chord at radius r: exactly r0 / (r0 + dr) again. Straight triangles
  // have constant det J: ratio 1.
  // Q >= 2: the order-Q interpolant's derivatives differ from the polar map's by O(dt^Q); we
  // allow dt^Q (constant 1; 0.027, 0.0045, 7.5e-4 for Q = 2, 3, 4) plus the certifier's rel_tol.
  // Counts (annulus.h: rounded metric lengths): radial lround(1 / 0.25) = 4, so dr = 0.25 and the
  // innermost ring gives 1 / 1.25 = 0.8; around lround(2 pi 1.5 / 0.25) = lround(37.7) = 38.
  AnnulusParams params;  // r in [1, 2], full circle
  const UniformMetricField<2> metric(Metric<2>::isotropic(0.25));
  const int n_r = 4, n_t = 38;
  const double dt = 2 * std::numbers::pi / n_t;
  QualityOptions options;
  options.validity.rel_tol = 1e-4;
  for (int q = 1; q <= max_order; ++q)
    for (const bool triangles : {false, true}) {
      params.triangles = triangles;
      INFO("Q=", q, std::string(triangles ? " triangles" : " quadrilaterals"));
      const HybridMesh<2> mesh = mesh_annulus(params, q, metric);
      REQUIRE(mesh.num_cells() == std::size_t{n_r * n_t} * (triangles ? 2 : 1));
      CellQuality pc;
      const QualityReport r = assess_quality<2>(mesh, &metric, options, &pc);
      CHECK(r.ok());
      const bool straight_triangles = triangles && q == 1;
      const double tol = q == 1 ? 1e-12 : std::pow(dt, q) + options.validity.rel_tol;
      const auto close = [&](double got, double want) { return std::abs(got / want - 1) <= tol; };
      CHECK_MESSAGE(close(r.scaled_jacobian_min, straight_triangles ? 1.0 : 0.8), r.scaled_jacobian_min);
      // Each cell against its own ring: r_in / r_out from its vertices.
      const CellBlock& b = mesh.cells[0];
      for (std::size_t i = 0; i < b.size(); ++i) {
        double r_in = 1e300, r_out = 0;
        for (int v = 0; v < num_vertices(b.type); ++v) {
          const double rv = mesh.nodes[static_cast<std::size_t>(b.cell(i)[v])].norm();
          r_in = std::min(r_in, rv);
          r_out = std::max(r_out, rv);
        }
        CHECK_MESSAGE(close(pc.scaled_jacobian[i], straight_triangles ? 1.0 : r_in / r_out), pc.scaled_jacobian[i]);
      }
    }
}

TEST_CASE("quality: a collapsed (zero-length) edge is measured as 0 and binned lowest, its cell is invalid") {
  // The unit square with vertex 2 moved onto vertex 1: edge 1-2 has length 0 and det J vanishes
  // at vertex 1, so validity cannot be proven.
  HybridMesh<2> m;
  m.nodes = {{0, 0}, {1, 0}, {1, 0}, {0, 1}};
  m.block(CellType::Quadrilateral, 1).connectivity = {0, 1, 2, 3};
  const UniformMetricField<2> metric(Metric<2>::isotropic(1.0));
  const QualityReport r = assess(m, nullptr, &metric);
  CHECK(r.cells_invalid == 1);
  CHECK(r.metric.count == 4);
  CHECK(r.metric.min == 0.0);
  CHECK(r.metric.histogram.front() >= 1);
  CHECK(std::accumulate(r.metric.histogram.begin(), r.metric.histogram.end(), std::size_t{0}) == 4);
  CHECK_NOTHROW(FlatJson(report_json(r)));
}

TEST_CASE("quality: report_json is valid JSON with the documented keys and the report's values") {
  auto s = plaf::test::quad_grid(3, 2, 2, 0.5);
  const UniformMetricField<2> metric(Metric<2>::isotropic(0.5));
  QualityReport r = assess(s.mesh, nullptr, &metric);
  // Names may hold any character; JSON needs quotes, backslashes and control characters escaped.
  r.name = "case \"a\\b\"\n\ttab";
  r.timings_s = {{"fill", 0.25}, {"quality", 1.5e-3}};
  r.extra = {{"layers.count", "3"}, {"layers.min_height_abs", "1.5e-05"}};
  const std::string text = report_json(r);
  FlatJson j(text);
  for (const char* key : {"cells", "scaled_jacobian", "aspect_ratio", "metric", "timings_s", "conformity", "layers"})
    CHECK_MESSAGE(j.containers.count(key), key);
  for (const char* key : {"cells.total", "cells.invalid", "scaled_jacobian.min", "aspect_ratio.max",
                          "metric.unit_fraction", "metric.edges", "name", "ok", "conformity.ok"})
    CHECK_MESSAGE(j.scalars.count(key), key);
  CHECK(j.containers.count("cells.by_type"));
  CHECK(j.scalars.at("name") == r.name);
  CHECK(j.scalars.at("ok") == "true");
  CHECK(j.number("cells.total") == 6);
  CHECK(j.number("cells.by_type.quadrilateral_Q2") == 6);
  CHECK(j.number("cells.invalid") == 0);
  CHECK(j.number("scaled_jacobian.min") == doctest::Approx(r.scaled_jacobian_min));
  CHECK(j.number("aspect_ratio.max") == doctest::Approx(1));
  CHECK(j.number("metric.unit_fraction") == 1);
  CHECK(j.number("metric.edges") == static_cast<double>(r.metric.count));
  CHECK(j.number("timings_s.fill") == 0.25);
  CHECK(j.number("timings_s.quality") == 1.5e-3);
  CHECK(j.number("layers.count") == 3);
  CHECK(j.number("conformity.interior_facets") == static_cast<double>(r.conformity.interior_facets));
  for (std::size_t k = 0; k < r.metric.histogram.size(); ++k)
    CHECK(j.number("metric.histogram.counts." + std::to_string(k)) == static_cast<double>(r.metric.histogram[k]));

  // Without a metric there is no metric section; an unproven -inf scaled Jacobian is null.
  QualityReport bare;
  bare.scaled_jacobian_min = -std::numeric_limits<double>::infinity();
  bare.cells_invalid = 1;
  const FlatJson b(report_json(bare));
  CHECK_FALSE(b.has("metric"));
  CHECK(b.scalars.at("scaled_jacobian.min") == "null");
  CHECK(b.scalars.at("ok") == "false");

  // The reader itself rejects what it should (so the checks above can fail).
  CHECK_THROWS(FlatJson("{\"a\": 1"));
  CHECK_THROWS(FlatJson("{\"a\": 1, \"a\": 2}"));
  CHECK_THROWS(FlatJson("{\"a\": \"x\ny\"}"));
  CHECK_THROWS(FlatJson("{\"a\": 01}"));
  CHECK_THROWS(FlatJson("{\"a\": nan}"));
}

TEST_CASE("quality: report_summary names counts, conformity and failure") {
  const auto s = plaf::test::triangle_grid(2, 2, 3);
  QualityReport r = assess(s.mesh);
  r.name = "grid";
  std::string text = report_summary(r);
  CHECK(text.find("grid: 8 cells (8 triangle_Q3)") != std::string::npos);
  CHECK(text.find("invalid cells: 0") != std::string::npos);
  CHECK(text.find("conformity: ok") != std::string::npos);
  CHECK(text.find("FAILED") == std::string::npos);

  auto open = s;
  open.mesh.boundary.pop_back();  // one side untagged: its facets are open
  r = assess(open.mesh);
  CHECK_FALSE(r.ok());
  text = report_summary(r);
  CHECK(text.find("conformity: FAILED: " + r.conformity.first_problem) != std::string::npos);
  CHECK(text.find("not conforming") != std::string::npos);
}

TEST_CASE("quality: the triangles' metric section counts their edges once and their metric shape") {
  // An equilateral triangle of side 0.1 beside a unit-square-ish quad sharing its base: in the
  // isotropic metric h = 0.1 the triangle is metric-equilateral (q = 1) with three unit edges;
  // the quad's three other edges (length 1 = 10 units) count in the whole mesh only.
  HybridMesh<2> m;
  m.nodes = {{0, 0}, {0.1, 0}, {0.05, 0.1 * std::sqrt(3.0) / 2}, {0.1, -1}, {0, -1}};
  m.block(CellType::Triangle, 1).connectivity = {0, 1, 2};
  m.block(CellType::Quadrilateral, 1).connectivity = {4, 3, 1, 0};
  const UniformMetricField<2> metric(Metric<2>::isotropic(0.1));
  const QualityReport r = assess_quality<2>(m, &metric, QualityOptions{});
  CHECK(r.metric.count == 6);
  CHECK(r.triangle_metric.triangles == 1);
  CHECK(r.triangle_metric.edges.count == 3);
  CHECK(r.triangle_metric.edges.unit_fraction == doctest::Approx(1.0));
  CHECK(r.metric.unit_fraction == doctest::Approx(4.0 / 6.0));  // the two sides of length 1 are 10 units
  CHECK(r.triangle_metric.quality_min == doctest::Approx(1.0));
  CHECK(r.triangle_metric.quality_histogram[9] == 1);
  // Stretched 4x along x in the metric's eyes: q = 4 sqrt3 A / sum l^2 drops.
  const UniformMetricField<2> stretched(
      Metric<2>::from_directions(Eigen::Matrix2d::Identity(), Eigen::Vector2d(0.025, 0.1)));
  CHECK(assess_quality<2>(m, &stretched, QualityOptions{}).triangle_metric.quality_min < 0.6);
}

TEST_CASE("quality: a 3D surface mesh is assessed through its triangles, certified against their flat triangles") {
  // Two order-2 triangles of the unit square lifted onto z = x y (a saddle), rim open.
  HybridMesh<3> m;
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{
           {0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0}, {1, 0.5}, {0.5, 1}, {0, 0.5}, {0.5, 0.5}})
    m.nodes.push_back({x, y, x * y});
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  m.boundary_block(CellType::Triangle, 2, wall).connectivity = {0, 1, 2, 4, 5, 8, 0, 2, 3, 8, 6, 7};
  CellQuality pc;
  QualityReport r = assess_quality<3>(m, nullptr, QualityOptions{}, &pc);
  CHECK(r.surface);
  CHECK(r.cells_total == 2);
  CHECK(r.cells_by_type.at("triangle_Q2") == 2);
  CHECK(r.cells_invalid == 0);
  // The lifted diagonal's middle node lies 0.25 below the flat triangle's midpoint, partly
  // sideways in the tilted plane: valid, not straight.
  CHECK(r.scaled_jacobian_min > 0.4);
  CHECK(r.scaled_jacobian_min < 0.99);
  CHECK(r.aspect_ratio_max >= 1);
  CHECK(pc.valid == std::vector<std::uint8_t>{1, 1});
  // The open rim is a hole until a curves block lists it.
  CHECK_FALSE(r.conformity.ok);
  CHECK(r.conformity.open_facets == 4);
  const int symmetry = m.add_tag("symmetry", BoundaryKind::Symmetry);
  m.curve_block(2, symmetry).connectivity = {0, 1, 4, 1, 2, 5, 2, 3, 6, 3, 0, 7};
  r = assess_quality<3>(m, nullptr, QualityOptions{});
  CHECK(r.ok());
  CHECK(r.conformity.boundary_facets == 4);
  CHECK(report_summary(r).find("2 surface facets (2 triangle_Q2)") != std::string::npos);
  CHECK(report_json(r).find("\"surface\": true") != std::string::npos);

  // With a metric: the metric lengths of the 5 distinct edges (unit metric: their lengths).
  const UniformMetricField<3> unit(Metric<3>::isotropic(1.0));
  r = assess_quality<3>(m, &unit, QualityOptions{});
  CHECK(r.has_metric);
  CHECK(r.metric.count == 5);
  CHECK(r.metric.min == doctest::Approx(1).epsilon(1e-9));  // the straight sides y = 0, x = 0
  // The lifted diagonal (t, t, t^2) (exact at order 2): integral of sqrt(2 + 4 t^2) over [0, 1].
  const double diagonal = std::sqrt(1.5) + 0.5 * std::log(1 + std::sqrt(1.5)) - 0.5 * std::log(std::sqrt(0.5));
  CHECK(r.metric.max == doctest::Approx(diagonal).epsilon(1e-6));

  // A middle node moved along its edge past the edge's 3/4 point folds the first triangle.
  m.nodes[4] = {0.9, 0, 0};
  r = assess_quality<3>(m, nullptr, QualityOptions{}, &pc);
  CHECK(r.cells_invalid == 1);
  CHECK_FALSE(r.ok());
  CHECK(r.first_invalid.rfind("surface triangle 0 of boundary block 0 at (0, 0, 0)", 0) == 0);
  CHECK(pc.valid == std::vector<std::uint8_t>{0, 1});
  CHECK(r.scaled_jacobian_min < 0);
}

TEST_CASE("quality: surface quadrilaterals (prism sides on a symmetry plane) are certified in their plane") {
  // Order-Q quadrilaterals x = a + u e0 + v e1 (+ a bend): a 2 x 1 rectangle in the tilted
  // plane spanned by e0, e1, the same rectangle bent out of its plane along its normal, and one
  // whose edge 0-1 folds back on itself in the plane (the map's u-derivative along e0 is
  // 1 - 2.4 u). Next to them, a triangle: both kinds are the report's cells.
  const Eigen::Vector3d a(0.3, -1, 2), e0 = 2 * Eigen::Vector3d(1, 0.2, 0.1).normalized();
  const Eigen::Vector3d e1 = e0.cross(Eigen::Vector3d(0, 0, 1)).cross(e0).normalized();
  const Eigen::Vector3d normal = e0.cross(e1).normalized();
  for (int q = 2; q <= max_order; ++q) {
    INFO("Q=", q);
    HybridMesh<3> m;
    const int symmetry = m.add_tag("symmetry", BoundaryKind::Symmetry);
    const auto add_quad = [&](auto bump) {
      CellBlock& b = m.boundary_block(CellType::Quadrilateral, q, symmetry);
      const LagrangeElement& e = lagrange_element(CellType::Quadrilateral, q);
      for (int i = 0; i < e.size(); ++i) {
        const auto r = e.ref_node(i);
        b.connectivity.push_back(static_cast<NodeId>(m.nodes.size()));
        m.nodes.push_back(a + r[0] * e0 + r[1] * e1 + bump(r[0], r[1]));
      }
    };
    add_quad([](double, double) { return Eigen::Vector3d::Zero(); });
    add_quad([&](double u, double v) { return Eigen::Vector3d(0.4 * u * (1 - u) * v * normal); });
    add_quad([&](double u, double) { return Eigen::Vector3d(-1.2 * u * u * e0); });
    CellBlock& t = m.boundary_block(CellType::Triangle, 1, symmetry);
    for (const Eigen::Vector3d& x : {a, Eigen::Vector3d(a + e0), Eigen::Vector3d(a + e1)}) {
      t.connectivity.push_back(static_cast<NodeId>(m.nodes.size()));
      m.nodes.push_back(x);
    }
    CellQuality pc;
    const QualityReport r = assess_quality<3>(m, nullptr, QualityOptions{}, &pc);
    CHECK(r.surface);
    CHECK(r.cells_total == 4);
    CHECK(r.cells_by_type.at("quadrilateral_Q" + std::to_string(q)) == 3);
    CHECK(r.cells_by_type.at("triangle_Q1") == 1);
    CHECK(pc.valid == std::vector<std::uint8_t>{1, 1, 0, 1});
    CHECK(r.cells_invalid == 1);
    CHECK(r.first_invalid.rfind("surface quadrilateral 2 of boundary block 0 at (", 0) == 0);
    // Flat and bent along the normal: the same map in the plane, scaled Jacobian 1 and aspect
    // ratio 2 (the rectangle's sides).
    for (std::size_t k : {0, 1}) {
      CHECK(pc.scaled_jacobian[k] == doctest::Approx(1).epsilon(1e-9));
      CHECK(pc.aspect_ratio[k] == doctest::Approx(2).epsilon(1e-9));
    }
    CHECK(pc.scaled_jacobian[2] < 0);
  }
}

TEST_CASE("quality: 2D and volume meshes are not marked surface") {
  const auto s = plaf::test::triangle_grid(2, 2, 2);
  CHECK_FALSE(assess_quality<2>(s.mesh, nullptr, QualityOptions{}).surface);
  const auto t = plaf::test::kuhn_tets(1, 1, 1, 1);
  const QualityReport r = assess_quality<3>(t.mesh, nullptr, QualityOptions{});
  CHECK_FALSE(r.surface);
  CHECK(r.cells_total == 6);
}

TEST_CASE("quality: simplex corners are positive, inverted or flat by the exact predicates, other cells pass") {
  // Corners as gather_coords lays them out (the first Dim + 1 nodes of a simplex).
  const double tri[] = {0, 0, 1, 0, 0, 1};
  const double tri_cw[] = {0, 0, 0, 1, 1, 0};
  const double tri_flat[] = {0, 0, 1, 1, 3, 3};
  CHECK(simplex_corners_positive<2>(CellType::Triangle, tri));
  CHECK_FALSE(simplex_corners_positive<2>(CellType::Triangle, tri_cw));
  CHECK_FALSE(simplex_corners_positive<2>(CellType::Triangle, tri_flat));
  CHECK(simplex_corners_positive<2>(CellType::Quadrilateral, tri_cw));  // not a simplex
  const double tet[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double tet_mirrored[] = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
  // Exactly flat but not axis-aligned, far from the origin: four corners on x + y + z = 3e8 + 4
  // (every coordinate exact in doubles), where a determinant in doubles is not reliably 0.
  const double o = 1e8;
  const double tet_flat[] = {o + 1, o + 1, o + 2, o + 3, o + 0.5, o + 0.5, o + 0.25, o + 2.5, o + 1.25, o + 2, o + 2, o + 0};
  CHECK(simplex_corners_positive<3>(CellType::Tetrahedron, tet));
  CHECK_FALSE(simplex_corners_positive<3>(CellType::Tetrahedron, tet_mirrored));
  CHECK_FALSE(simplex_corners_positive<3>(CellType::Tetrahedron, tet_flat));
  CHECK(simplex_corners_positive<3>(CellType::Prism, tet_mirrored));  // not a simplex
}
