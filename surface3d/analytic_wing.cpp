// SPDX-License-Identifier: MIT
// The analytic wing (see analytic.h): an extruded spline loop (wing_reference.h) with flat,
// rounded or symmetry ends, and its initial triangulation. The side is a structured
// (contour x span) grid through the contour samples (wing_sampling.h); flat ends triangulate the
// sampled contour polygon (triangulate_polygon.h); rounded ends are structured rows of half
// circles at shared chord stations of both surfaces (rounded_cap.h). Feature curves are made of
// pieces (spanwise ridge lines, end contour arcs, the half circle closing a blunt base) merged
// where they continue each other smoothly.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "modules/geometry/spline_loop.h"
#include "modules/io/airfoil_io.h"
#include "surface3d/analytic.h"
#include "surface3d/analytic_builder.h"
#include "surface3d/rounded_cap.h"
#include "surface3d/triangulate_polygon.h"
#include "surface3d/wing_reference.h"
#include "surface3d/wing_sampling.h"

namespace plaf {

using analytic_detail::ContourSamples;
using analytic_detail::CurvePiece;
using analytic_detail::MeshBuilder;
using analytic_detail::num;
using analytic_detail::RoundedCap;
using analytic_detail::triangulate_polygon;
using analytic_detail::WingReference;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

// Union-find over curve pieces (pieces that continue each other smoothly form one curve).
struct UnionFind {
  std::vector<int> parent;
  int add() {
    parent.push_back(static_cast<int>(parent.size()));
    return parent.back();
  }
  int find(int i) { return parent[i] == i ? i : parent[i] = find(parent[i]); }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

// The wing's initial triangulation as it is assembled into a MeshBuilder: the side grid
// grid_[i][k] (contour sample i, span station k of n_span_) and the feature-curve pieces with
// their mesh edges, which the union-find merges into curves.
class WingMesh {
 public:
  WingMesh(WingReference& ref, const ContourSamples& cs, double h, MeshBuilder& mb, const std::string& name)
      : ref_(ref),
        loop_(ref.loop()),
        cs_(cs),
        h_(h),
        mb_(mb),
        name_(name),
        n_contour_(static_cast<int>(cs.t.size())),
        n_span_(std::max(1, static_cast<int>(std::lround(ref.span() / h)))),
        n_corners_(static_cast<int>(ref.corner_t().size())) {}

  void add_side();
  void add_span_ridges();
  void add_contour_end(int end);  // flat or symmetry
  void add_rounded_end(int end);
  // Numbers the curves by first appearance, records their pieces in the reference and marks
  // their edges.
  void number_curves();

 private:
  struct PieceEdges {
    CurvePiece piece;
    std::vector<int> vertices;
    EdgeFeature feature;
  };
  int add_piece(const CurvePiece& c, std::vector<int> vs, EdgeFeature f) {
    uf_.add();
    pieces_.push_back({c, std::move(vs), f});
    return static_cast<int>(pieces_.size()) - 1;
  }
  // The cap's rows at the stations, each a half circle from arc 1 to arc 2 (a single point where
  // they meet).
  std::vector<std::vector<int>> add_cap_rows(const RoundedCap& cap, int kz);
  // The triangles between consecutive rows.
  void add_cap_strips(const std::vector<std::vector<int>>& rows);
  // The blunt base under the cap's last row closed by a flat half disc; its half circle
  // continues both trailing-edge ridges.
  void add_blunt_base(int end, const RoundedCap& cap, const std::vector<int>& last);

  WingReference& ref_;
  const SplineLoop& loop_;
  const ContourSamples& cs_;
  double h_;
  MeshBuilder& mb_;
  const std::string& name_;
  int n_contour_, n_span_, n_corners_;  // contour samples, span divisions, section corners
  std::vector<std::vector<int>> grid_;
  UnionFind uf_;
  std::vector<PieceEdges> pieces_;
  std::vector<int> span_piece_;  // per section corner
};

void WingMesh::add_side() {
  const double span = ref_.span();
  grid_.assign(n_contour_, std::vector<int>(n_span_ + 1));
  for (int i = 0; i < n_contour_; ++i) {
    const Vector2d xy = loop_.point(cs_.t[i]);
    for (int k = 0; k <= n_span_; ++k) grid_[i][k] = mb_.add_point(Vector3d(xy.x(), xy.y(), span * k / n_span_));
  }
  // Quads in (contour, span) order, whose normal tangent x e_z is the loop's right normal:
  // inward, since the body loop is clockwise (its left normal points out of the body).
  for (int i = 0; i < n_contour_; ++i)
    for (int k = 0; k < n_span_; ++k)
      mb_.add_quad(grid_[i][k], grid_[(i + 1) % n_contour_][k], grid_[(i + 1) % n_contour_][k + 1], grid_[i][k + 1]);
  mb_.end_patch(true);
}

void WingMesh::add_span_ridges() {
  span_piece_.resize(n_corners_);
  for (int c = 0; c < n_corners_; ++c) {
    std::vector<int> vs;
    for (int k = 0; k <= n_span_; ++k) vs.push_back(grid_[cs_.corner_index[c]][k]);
    CurvePiece p{CurvePiece::Span, ref_.corner_t()[c], 0, 0, ref_.span(), 0};
    span_piece_[c] = add_piece(p, vs, ref_.corner_convex()[c] ? EdgeFeature::ConvexRidge : EdgeFeature::ConcaveRidge);
  }
}

void WingMesh::add_contour_end(int end) {
  const int kz = end == 0 ? 0 : n_span_;
  const double z = end == 0 ? 0.0 : ref_.span();
  const WingEnd type = ref_.end(end);
  const EdgeFeature f = type == WingEnd::Flat ? EdgeFeature::ConvexRidge : EdgeFeature::Boundary;
  if (type == WingEnd::Symmetry) mb_.set_symmetry();
  // The end contour split at the corners.
  std::vector<int> starts = cs_.corner_index;
  std::sort(starts.begin(), starts.end());
  if (starts.empty()) starts.push_back(0);
  for (std::size_t m = 0; m < starts.size(); ++m) {
    const int i0 = starts[m];
    const int i1 = m + 1 < starts.size() ? starts[m + 1] : starts[0] + n_contour_;
    std::vector<int> vs;
    for (int i = i0; i <= i1; ++i) vs.push_back(grid_[i % n_contour_][kz]);
    double t0 = cs_.t[i0], t1 = i1 < n_contour_ ? cs_.t[i1] : cs_.t[i1 - n_contour_] + loop_.period();
    if (t1 <= t0) t1 += loop_.period();
    add_piece({CurvePiece::Contour, t0, t1, z, z, end}, vs, f);
  }
  for (int c = 0; c < n_corners_; ++c) {
    const int v = grid_[cs_.corner_index[c]][kz];
    if (type == WingEnd::Symmetry)
      mb_.mark_corner(v, VertexFeature::BoundaryCorner);
    else
      mb_.mark_corner(v, ref_.corner_convex()[c] ? VertexFeature::ConvexCorner : VertexFeature::SaddleCorner);
  }
  if (type == WingEnd::Flat) {
    std::vector<Vector2d> poly(n_contour_);
    for (int i = 0; i < n_contour_; ++i) poly[i] = mb_.point(grid_[i][kz]).head<2>();
    // Counter-clockwise in (x, y): normal +z, outward at the tip, inward at the root.
    for (const auto& t : triangulate_polygon(poly, name_ + " flat end"))
      mb_.add_triangle(grid_[t[0]][kz], grid_[t[1]][kz], grid_[t[2]][kz]);
    mb_.end_patch(end == 0);
  }
}

void WingMesh::add_rounded_end(int end) {
  const int kz = end == 0 ? 0 : n_span_;
  const RoundedCap& cap = *ref_.cap(end);
  const std::vector<std::vector<int>> rows = add_cap_rows(cap, kz);
  add_cap_strips(rows);
  // Counter-clockwise in (s, theta): normal C_s x C_theta, compared with the outward radial
  // direction at the top of a mid-chord section.
  {
    const RoundedCap::Section sec = cap.section(0.5);
    const Vector3d c_s = sec.dm + sec.dr * sec.e;
    const Vector3d ct = -sec.r * sec.d;
    mb_.end_patch(c_s.cross(ct).dot(sec.e) < 0);
  }
  if (ref_.sharp()) {
    for (int c = 0; c < n_corners_; ++c)
      mb_.mark_corner(grid_[cs_.corner_index[c]][kz],
                      ref_.corner_convex()[c] ? VertexFeature::ConvexCorner : VertexFeature::ConcaveCorner);
  } else {
    add_blunt_base(end, cap, rows.back());
  }
}

std::vector<std::vector<int>> WingMesh::add_cap_rows(const RoundedCap& cap, int kz) {
  const int J = static_cast<int>(cs_.stations.size()) - 1;
  std::vector<std::vector<int>> rows(J + 1);
  for (int j = 0; j <= J; ++j) {
    const RoundedCap::Section sec = cap.section(cs_.stations[j]);
    const int a = grid_[cs_.arc1[j]][kz], b = grid_[cs_.arc2[j]][kz];
    rows[j].push_back(a);
    if (a == b) continue;
    const int n = std::max(2, static_cast<int>(std::lround(M_PI * sec.r / h_)));
    for (int k = 1; k < n; ++k) rows[j].push_back(mb_.add_point(RoundedCap::at(sec, M_PI * k / n)));
    rows[j].push_back(b);
  }
  return rows;
}

void WingMesh::add_cap_strips(const std::vector<std::vector<int>>& rows) {
  for (std::size_t j = 0; j + 1 < rows.size(); ++j) {
    const std::vector<int>& A = rows[j];
    const std::vector<int>& B = rows[j + 1];
    const int na = static_cast<int>(A.size()) - 1, nb = static_cast<int>(B.size()) - 1;
    int ia = 0, ib = 0;
    while (ia < na || ib < nb) {
      // Advance the row whose next point comes first in normalised angle (in (s, theta),
      // A is the left column and B the right one; both triangles below are counter-clockwise).
      const bool step_a = ib == nb || (ia < na && (ia + 1.0) / na <= (ib + 1.0) / nb);
      if (step_a) {
        mb_.add_triangle(A[ia], B[ib], A[ia + 1]);
        ++ia;
      } else {
        mb_.add_triangle(A[ia], B[ib], B[ib + 1]);
        ++ib;
      }
    }
  }
}

void WingMesh::add_blunt_base(int end, const RoundedCap& cap, const std::vector<int>& last) {
  const int kz = end == 0 ? 0 : n_span_;
  const double z = end == 0 ? 0.0 : ref_.span();
  const int J = static_cast<int>(cs_.stations.size()) - 1;
  const int hc = add_piece({CurvePiece::HalfCircle, 0, 0, z, z, end}, last, EdgeFeature::ConvexRidge);
  for (int c = 0; c < n_corners_; ++c) uf_.unite(span_piece_[c], hc);
  const RoundedCap::Section sec = cap.section(1.0);
  std::vector<int> poly_ids = last;
  for (int i = cs_.arc2[J] - 1; i > cs_.arc1[J]; --i) poly_ids.push_back(grid_[i][kz]);
  std::vector<Vector2d> poly;
  for (int v : poly_ids) {
    const Vector3d w = mb_.point(v) - sec.m;
    poly.emplace_back(w.dot(sec.d), w.dot(sec.e));
  }
  // Counter-clockwise in (d, e): normal d x e, against the base's outward normal.
  for (const auto& t : triangulate_polygon(poly, name_ + " rounded end base"))
    mb_.add_triangle(poly_ids[t[0]], poly_ids[t[1]], poly_ids[t[2]]);
  const Vector2d nb = loop_.normal(ref_.t_a() + 0.5);
  mb_.end_patch(sec.d.cross(sec.e).dot(Vector3d(nb.x(), nb.y(), 0)) < 0);
}

void WingMesh::number_curves() {
  std::map<int, int> curve_of_root;
  auto& curves = ref_.curves();
  for (int p = 0; p < static_cast<int>(pieces_.size()); ++p) {
    const int root = uf_.find(p);
    auto it = curve_of_root.find(root);
    if (it == curve_of_root.end()) {
      it = curve_of_root.emplace(root, static_cast<int>(curves.size())).first;
      curves.emplace_back();
    }
    curves[it->second].push_back(pieces_[p].piece);
    mb_.mark_polyline(pieces_[p].vertices, it->second, pieces_[p].feature);
  }
}

// The checks of the parameters that need no file.
void check_params(const WingParams& params, double h, const std::string& name) {
  if (!(params.chord > 0) || !std::isfinite(params.chord))
    throw ConfigError(name + ": chord must be positive, got " + num(params.chord));
  if (!(params.span > 0) || !std::isfinite(params.span))
    throw ConfigError(name + ": span must be positive, got " + num(params.span));
  if (!(params.corner_angle_deg > 0 && params.corner_angle_deg < 180))
    throw ConfigError(name + ": corner_angle_deg must be in (0, 180), got " + num(params.corner_angle_deg));
  analytic_detail::check_h(name, h, std::max(params.chord, params.span));
}

// The section: the contour scaled by the chord, and its corners (those detected at
// corner_angle_deg and the file's trailing-edge corners).
struct Section {
  BodyContour contour;
  std::vector<int> corners;
};

Section read_section(const WingParams& params) {
  Section sec{params.naca ? naca_contour(*params.naca) : read_body_contour(params.file), {}};
  for (Vector2d& p : sec.contour.points) p *= params.chord;
  sec.corners = detect_corners(sec.contour.points, params.corner_angle_deg);
  sec.corners.insert(sec.corners.end(), sec.contour.corners.begin(), sec.contour.corners.end());
  std::sort(sec.corners.begin(), sec.corners.end());
  sec.corners.erase(std::unique(sec.corners.begin(), sec.corners.end()), sec.corners.end());
  return sec;
}

// A rounded end needs a section whose only corners are at the trailing edge, a blunt trailing
// edge's two corners adjacent.
void check_rounded_section(const Section& sec, const WingParams& params, const std::string& name) {
  const BodyContour& contour = sec.contour;
  std::vector<int> te = contour.corners;
  std::sort(te.begin(), te.end());
  for (int c : sec.corners)
    if (!std::binary_search(te.begin(), te.end(), c))
      throw InputError(contour.file + ":" + std::to_string(contour.lines[c]) +
                       ": a rounded wing end needs a section whose only corners are at the trailing edge, but the " +
                       "contour turns by more than " + num(params.corner_angle_deg) + " degrees here");
  const int n = static_cast<int>(contour.points.size());
  if (contour.corners.size() == 2) {
    const int a = contour.corners[0], b = contour.corners[1];
    if (!((b - a) == 1 || (a == 0 && b == n - 1)))
      throw InputError(name + ": the blunt trailing edge corners are not adjacent points");
  }
}

// The rounded cap pairs the two surfaces at equal chord stations: x must increase from the
// leading edge to the trailing edge along both (checked at 64 samples per section point).
void check_monotone_arcs(const WingReference& ref, int n, double chord, const std::string& name) {
  const SplineLoop& loop = ref.loop();
  for (int arc = 0; arc < 2; ++arc) {
    const double t_end = arc == 0 ? ref.t_a() : ref.t_b();
    const int samples = 64 * n;
    double prev = loop.point(ref.t_le()).x();
    for (int k = 1; k <= samples; ++k) {
      const double x = loop.point(ref.t_le() + (t_end - ref.t_le()) * k / samples).x();
      if (x < prev - 1e-9 * chord)
        throw InputError(name + ": a rounded end needs x increasing from the leading edge to the trailing edge on " +
                         "both surfaces of the section");
      prev = std::max(prev, x);
    }
  }
}

// Contour samples, refined until the sampled section polygon is simple (coarse h on thin
// sections could make chords cross).
ContourSamples sample_simple_contour(const WingReference& ref, double h, const std::string& name) {
  ContourSamples cs;
  double h_contour = h;
  for (int attempt = 0;; ++attempt) {
    const RoundedCap* cap = ref.cap(0) ? ref.cap(0) : ref.cap(1);
    cs = cap ? sample_by_stations(ref, *cap, h_contour) : sample_by_corners(ref, h_contour);
    std::vector<Vector2d> poly;
    for (double t : cs.t) poly.push_back(ref.loop().point(t));
    if (analytic_detail::polygon_is_simple(poly)) break;
    if (attempt >= 8) throw MesherError(name + ": could not sample the section contour as a simple polygon");
    h_contour *= 0.5;
  }
  return cs;
}

}  // namespace

AnalyticBody make_wing(const WingParams& params, double h) {
  const std::string name = "wing " + (params.naca ? naca_name(*params.naca) : params.file.string());
  // 1. The parameters and the section.
  check_params(params, h, name);
  const Section sec = read_section(params);
  const std::array<WingEnd, 2> ends = {params.root, params.tip};
  const bool rounded = ends[0] == WingEnd::Rounded || ends[1] == WingEnd::Rounded;
  if (rounded) check_rounded_section(sec, params, name);
  // 2. The reference geometry.
  auto ref = std::make_unique<WingReference>(SplineLoop(sec.contour.points, sec.corners, sec.contour.file), params.span,
                                             ends, sec.contour.corners);
  if (rounded) check_monotone_arcs(*ref, static_cast<int>(sec.contour.points.size()), params.chord, name);
  // 3. The initial triangulation: side, spanwise ridges, ends, then the curves they form.
  const ContourSamples cs = sample_simple_contour(*ref, h, name);
  MeshBuilder mb;
  WingMesh wing(*ref, cs, h, mb, name);
  wing.add_side();
  wing.add_span_ridges();
  for (int end = 0; end < 2; ++end) {
    if (ends[end] == WingEnd::Rounded)
      wing.add_rounded_end(end);
    else
      wing.add_contour_end(end);
  }
  wing.number_curves();
  AnalyticBody body;
  body.initial = mb.build(name);
  body.reference = std::move(ref);
  return body;
}

}  // namespace plaf
