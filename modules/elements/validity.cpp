// SPDX-License-Identifier: MIT
// Implements certified validity of curved Lagrange cells from A. Johnen, J.-F. Remacle and
// C. Geuzaine, "Geometrical validity of curvilinear finite elements", J. Comput. Phys. 233 (2013).
//
// det J is sampled at the equispaced points of its polynomial space and mapped to Bernstein
// coefficients by the inverse of the Bernstein matrix at those points. The coefficients bound
// det J from below and above (convex hull property), and the samples are values of det J, so
//   min coefficient <= min det J <= min sample,   max sample <= max det J <= max coefficient.
// A sub-cell is an affine image of the reference cell. The cell itself is sampled; a sub-cell's
// coefficients come from its parent's by the fixed subdivision matrix of its child map (Johnen et
// al.'s adaptive subdivision): the parent's Bernstein polynomial evaluated at the child's points
// (E_k, whose rows give the child's samples, i.e. values of det J) and mapped back by the inverse
// Bernstein matrix (M_k = A^-1 E_k, a de Casteljau step: stochastic, so rounding does not grow
// with the depth). Child maps are block diagonal (simplex part x segment part), so both factors
// of the tensor space subdivide separately: C_child = Ma_k C Mb_k^T. No basis function is
// evaluated below the root, which makes a subdivision a few small matrix products. Refinement is best-first: only the sub-cell holding the lowest (highest)
// coefficient can raise (lower) the global bound, so it is the only one split.
#include "modules/elements/validity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <string>

#include "modules/base/error.h"
#include "modules/elements/mapping.h"
#include "modules/geometry/predicates.h"

namespace plaf {
inline namespace elements {
namespace {

// Gradient entries of the largest element, the order-4 prism (75 nodes x 3).
constexpr int max_grad_size = (max_order + 1) * (max_order + 1) * (max_order + 2) / 2 * 3;

// Sub-cells one certify call may examine. Together with max_depth it bounds the work on
// pathological cells (det J touching zero along a whole face); hitting it counts as depth
// exhaustion: an undecided sign is reported as proven = false.
constexpr int max_subcells = 4096;

constexpr double inf = std::numeric_limits<double>::infinity();

// det J at xi; dphi is scratch for the element's gradients. Coordinates are taken relative to
// node 0 (the gradients sum to zero), so a cell far from the origin loses no digits to
// cancellation.
double det_at(const LagrangeElement& e, const double* coords, const double* xi, double* dphi) {
  switch (e.dim()) {
    case 1: {
      e.eval_grad(xi, dphi);
      const int n = e.size();
      double j = 0;
      for (int k = 1; k < n; ++k) j += (coords[k] - coords[0]) * dphi[k];
      return j;
    }
    case 2:
      return mapping_jacobian<2>(e, coords, xi, dphi).determinant();
    default:
      return mapping_jacobian<3>(e, coords, xi, dphi).determinant();
  }
}

// The space of det J is a tensor product A (x) B of Bernstein spaces on simplices: A is the
// triangle/tetrahedron (or the u segment of a quadrilateral), B the segment along the second
// tensor direction (quadrilateral v, prism w), or trivial (dimension 0) for simplices.
struct Degrees {
  int dim_a, deg_a, dim_b, deg_b;
};

Degrees det_degrees(CellType type, int q) {
  switch (type) {
    case CellType::Triangle:
      return {2, 2 * (q - 1), 0, 0};
    case CellType::Quadrilateral:
      return {1, 2 * q - 1, 1, 2 * q - 1};
    case CellType::Tetrahedron:
      return {3, 3 * (q - 1), 0, 0};
    case CellType::Prism:
      return {2, 3 * q - 2, 1, 3 * q - 1};
    case CellType::Line:
      break;
  }
  return {1, q - 1, 0, 0};
}

long double factorial(int n) {
  long double f = 1;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

long double power(long double x, int n) {
  long double p = 1;
  for (int i = 0; i < n; ++i) p *= x;
  return p;
}

// Bernstein polynomials of degree n on the dim-simplex: B_a = n!/(a_0! ... a_d!) prod l_i^a_i,
// with barycentric l_0 = 1 - sum x, l_i = x_i. Dimension 0 is the constant 1.
struct Factor {
  std::vector<std::array<double, 3>> points;  // equispaced points, one per basis function
  std::vector<std::array<long double, 3>> x;  // the same points in long double
  Eigen::MatrixXd inverse;                    // coefficients = inverse * samples at points
  Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic> inverse_l;
};

// Multi-indices of the Bernstein basis of degree n on the dim-simplex, in the Factor's order.
std::vector<std::array<int, 3>> bernstein_indices(int dim, int n) {
  std::vector<std::array<int, 3>> alpha;
  for (int k = 0; k <= (dim > 2 ? n : 0); ++k)
    for (int j = 0; j <= (dim > 1 ? n - k : 0); ++j)
      for (int i = 0; i <= (dim > 0 ? n - j - k : 0); ++i) alpha.push_back({i, j, k});
  return alpha;
}

// b(p, c) = Bernstein polynomial c of degree n on the dim-simplex at point x[p], in long double.
using MatrixL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
MatrixL bernstein_matrix(int dim, int n, const std::vector<std::array<long double, 3>>& x) {
  const std::vector<std::array<int, 3>> alpha = bernstein_indices(dim, n);
  MatrixL b(static_cast<Eigen::Index>(x.size()), static_cast<Eigen::Index>(alpha.size()));
  for (std::size_t p = 0; p < x.size(); ++p)
    for (std::size_t c = 0; c < alpha.size(); ++c) {
      long double l0 = 1;
      int a0 = n;
      long double v = 1;
      for (int d = 0; d < dim; ++d) {
        l0 -= x[p][static_cast<std::size_t>(d)];
        a0 -= alpha[c][static_cast<std::size_t>(d)];
        v *= power(x[p][static_cast<std::size_t>(d)], alpha[c][static_cast<std::size_t>(d)]) /
             factorial(alpha[c][static_cast<std::size_t>(d)]);
      }
      b(static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(c)) = v * power(l0, a0) * factorial(n) / factorial(a0);
    }
  return b;
}

Factor make_factor(int dim, int n) {
  const std::vector<std::array<int, 3>> alpha = bernstein_indices(dim, n);
  const int size = static_cast<int>(alpha.size());

  Factor f;
  std::vector<std::array<long double, 3>> x(alpha.size(), {0, 0, 0});
  // Degree 0 has one basis function and any point will do: take the centroid.
  for (int p = 0; p < size; ++p)
    for (int d = 0; d < dim; ++d) x[p][d] = n > 0 ? static_cast<long double>(alpha[p][d]) / n : 1.0L / (dim + 1);
  for (const auto& xp : x)
    f.points.push_back({static_cast<double>(xp[0]), static_cast<double>(xp[1]), static_cast<double>(xp[2])});
  f.x = x;

  // Build and invert in long double (at most 220 x 220, the Q = 4 tetrahedron), so the inverse
  // is accurate to a few ulps. Its infinity norm still amplifies rounding in the samples: it
  // reaches ~5e3 per factor at Q = 4, so coefficients of a Q = 4 prism carry noise of ~1e-8
  // times max |det J|; a positive min_lower below that is a rounding-level certificate.
  f.inverse_l = bernstein_matrix(dim, n, x).partialPivLu().inverse();
  f.inverse = f.inverse_l.cast<double>();
  return f;
}

// An affine sub-cell x = origin + map * xi of the reference cell (2D cells leave z at 0).
struct Affine {
  Eigen::Vector3d origin;
  Eigen::Matrix3d map;
};

Affine simplex_affine(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                      const Eigen::Vector3d& v3) {
  Eigen::Matrix3d m;
  m << v1 - v0, v2 - v0, v3 - v0;
  return {v0, m};
}

// Triangle split into 4 at edge midpoints (the middle one reversed, which is harmless: det J is
// sampled from the original map, not from the composition).
std::vector<Affine> triangle_children() {
  const Eigen::Vector3d p0(0, 0, 0), p1(1, 0, 0), p2(0, 1, 0), ez(0, 0, 1);
  const Eigen::Vector3d m01 = (p0 + p1) / 2, m02 = (p0 + p2) / 2, m12 = (p1 + p2) / 2;
  return {simplex_affine(p0, m01, m02, p0 + ez), simplex_affine(m01, p1, m12, m01 + ez),
          simplex_affine(m02, m12, p2, m02 + ez), simplex_affine(m12, m02, m01, m12 + ez)};
}

// Tetrahedron split into 8: four corner tetrahedra and the inner octahedron cut into four around
// its diagonal m01-m23.
std::vector<Affine> tet_children() {
  const Eigen::Vector3d p0(0, 0, 0), p1(1, 0, 0), p2(0, 1, 0), p3(0, 0, 1);
  const Eigen::Vector3d m01 = (p0 + p1) / 2, m02 = (p0 + p2) / 2, m03 = (p0 + p3) / 2;
  const Eigen::Vector3d m12 = (p1 + p2) / 2, m13 = (p1 + p3) / 2, m23 = (p2 + p3) / 2;
  return {simplex_affine(p0, m01, m02, m03),  simplex_affine(m01, p1, m12, m13),  simplex_affine(m02, m12, p2, m23),
          simplex_affine(m03, m13, m23, p3),  simplex_affine(m01, m23, m02, m12), simplex_affine(m01, m23, m12, m13),
          simplex_affine(m01, m23, m13, m03), simplex_affine(m01, m23, m03, m02)};
}

std::vector<Affine> quad_children() {
  std::vector<Affine> out;
  const Eigen::Matrix3d half = Eigen::Vector3d(0.5, 0.5, 1.0).asDiagonal();
  for (double v : {0.0, 0.5})
    for (double u : {0.0, 0.5}) out.push_back({Eigen::Vector3d(u, v, 0), half});
  return out;
}

// Prism split into 8: the four triangle children times the two halves along w.
std::vector<Affine> prism_children() {
  std::vector<Affine> out;
  for (double w : {0.0, 0.5})
    for (Affine a : triangle_children()) {
      a.origin.z() = w;
      a.map(2, 2) = 0.5;
      out.push_back(a);
    }
  return out;
}

const std::vector<Affine>& children(CellType type) {
  static const std::vector<Affine> tri = triangle_children(), quad = quad_children(), tet = tet_children(),
                                   prism = prism_children(), none;
  switch (type) {
    case CellType::Triangle:
      return tri;
    case CellType::Quadrilateral:
      return quad;
    case CellType::Tetrahedron:
      return tet;
    case CellType::Prism:
      return prism;
    case CellType::Line:
      break;
  }
  return none;
}

struct SubCell {
  int depth;
  double coef_min, coef_max;  // extreme Bernstein coefficients of det J on this sub-cell
};

struct Range {
  double lo, hi;
};

// Bernstein transform and scratch of one (type, order), built on first use.
struct Space {
  bool ready = false;
  Factor a, b;
  std::vector<Eigen::Vector3d> points;   // reference sample points, index ia * nb + ib
  std::vector<double> root_gradients;    // basis gradients at every point of the whole cell
  Eigen::MatrixXd samples, half, coefs;  // na x nb scratch
  // Per child map k: its samples from the parent's coefficients (Ea, Eb) and its coefficients
  // (Ma = A^-1 Ea, Mb = B^-1 Eb), per factor.
  std::vector<Eigen::MatrixXd> ea, eb, ma, mb;
};

// The subdivision matrices of one factor (dim, degree n) for the child map y = origin + map x
// restricted to the factor's coordinates [first, first + dim).
void factor_child(const Factor& f, int dim, int n, int first, const Affine& kid, Eigen::MatrixXd& e,
                  Eigen::MatrixXd& m) {
  std::vector<std::array<long double, 3>> y(f.x.size(), {0, 0, 0});
  for (std::size_t p = 0; p < f.x.size(); ++p)
    for (int r = 0; r < dim; ++r) {
      long double v = kid.origin[first + r];
      for (int c = 0; c < dim; ++c) v += static_cast<long double>(kid.map(first + r, first + c)) * f.x[p][static_cast<std::size_t>(c)];
      y[p][static_cast<std::size_t>(r)] = v;
    }
  const MatrixL el = bernstein_matrix(dim, n, y);
  e = el.cast<double>();
  m = (f.inverse_l * el).cast<double>();
}

}  // namespace

namespace {

// The Bernstein transforms, built once per (dimension, degree) for the whole process (the
// order-4 tetrahedron's takes ~0.08 s); certifiers copy them.
const Factor& shared_factor(int dim, int n) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, Factor> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find({dim, n});
  if (it == cache.end()) it = cache.emplace(std::make_pair(dim, n), make_factor(dim, n)).first;
  return it->second;
}

}  // namespace

struct JacobianCertifier::Impl {
  ValidityOptions options;
  std::array<std::array<Space, max_order + 1>, 5> spaces;
  std::vector<SubCell> leaves;
  std::vector<Eigen::MatrixXd> leaf_coefs;  // per leaf: its Bernstein coefficients (na x nb)
  Eigen::MatrixXd parent_coefs;

  Space& space(CellType type, int order) {
    Space& s = spaces[static_cast<int>(type)][order];
    if (s.ready) return s;
    const Degrees g = det_degrees(type, order);
    s.a = shared_factor(g.dim_a, g.deg_a);
    s.b = shared_factor(g.dim_b, g.deg_b);
    for (const auto& pa : s.a.points)
      for (const auto& pb : s.b.points) {
        Eigen::Vector3d xi(pa[0], pa[1], pa[2]);
        if (g.dim_b > 0) xi[g.dim_a] = pb[0];  // B's one coordinate follows A's
        s.points.push_back(xi);
      }
    const auto na = static_cast<Eigen::Index>(s.a.points.size()), nb = static_cast<Eigen::Index>(s.b.points.size());
    // The whole cell is sampled at the same points for every cell: keep its basis gradients.
    const LagrangeElement& e = lagrange_element(type, order);
    const std::size_t per_point = static_cast<std::size_t>(e.size() * e.dim());
    s.root_gradients.resize(s.points.size() * per_point);
    for (std::size_t k = 0; k < s.points.size(); ++k)
      e.eval_grad(s.points[k].data(), s.root_gradients.data() + k * per_point);
    s.samples.resize(na, nb);
    s.half.resize(na, nb);
    s.coefs.resize(na, nb);
    for (const Affine& kid : children(type)) {
      // Child maps are block diagonal: the simplex coordinates [0, dim_a), the segment dim_a.
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          if ((r < g.dim_a) != (c < g.dim_a) && kid.map(r, c) != 0)
            throw MesherError("validity: a child map mixes the factors of the Bernstein space");
      s.ea.emplace_back();
      s.ma.emplace_back();
      s.eb.emplace_back();
      s.mb.emplace_back();
      factor_child(s.a, g.dim_a, g.deg_a, 0, kid, s.ea.back(), s.ma.back());
      factor_child(s.b, g.dim_b, g.deg_b, g.dim_a, kid, s.eb.back(), s.mb.back());
    }
    s.ready = true;
    return s;
  }

  // Samples det J on the whole cell, stores its coefficients in `coefs` and their range in c,
  // and returns the sample range.
  Range evaluate_root(const LagrangeElement& e, const double* coords, Space& s, SubCell& c, Eigen::MatrixXd& coefs) {
    Range r{inf, -inf};
    const Eigen::Index nb = s.samples.cols();
    const std::size_t per_point = static_cast<std::size_t>(e.size() * e.dim());
    for (Eigen::Index ia = 0; ia < s.samples.rows(); ++ia)
      for (Eigen::Index ib = 0; ib < nb; ++ib) {
        const auto k = static_cast<std::size_t>(ia * nb + ib);
        const double v =
            e.dim() == 2
                ? mapping_jacobian_from_gradients<2>(e.size(), coords, s.root_gradients.data() + k * per_point).determinant()
                : mapping_jacobian_from_gradients<3>(e.size(), coords, s.root_gradients.data() + k * per_point).determinant();
        s.samples(ia, ib) = v;
        r.lo = std::min(r.lo, v);
        r.hi = std::max(r.hi, v);
      }
    // C = A^-1 S B^-T, the tensor form of the inverse Bernstein matrix. Coefficient-wise
    // (lazy) products: the matrices are at most 28 x 28, where Eigen's blocked GEMM spends more
    // on packing than on arithmetic (measured: a quarter of a 3D layer run).
    s.half.noalias() = s.a.inverse.lazyProduct(s.samples);
    coefs.noalias() = s.half.lazyProduct(s.b.inverse.transpose());
    c.coef_min = coefs.minCoeff();
    c.coef_max = coefs.maxCoeff();
    return r;
  }

  // Child k of a sub-cell with coefficients `parent`: its coefficients and range, and the range
  // of its samples (values of det J at its points).
  Range subdivide(Space& s, const Eigen::MatrixXd& parent, std::size_t k, SubCell& c, Eigen::MatrixXd& coefs) {
    s.half.noalias() = s.ea[k].lazyProduct(parent);
    s.samples.noalias() = s.half.lazyProduct(s.eb[k].transpose());
    s.half.noalias() = s.ma[k].lazyProduct(parent);
    coefs.noalias() = s.half.lazyProduct(s.mb[k].transpose());
    c.coef_min = coefs.minCoeff();
    c.coef_max = coefs.maxCoeff();
    return {s.samples.minCoeff(), s.samples.maxCoeff()};
  }
};

// The scaled bounds bracket min det J / max det J for every (min, max) allowed by the four bounds.
// For a valid cell they are min_lower / max_upper and min_upper / max_lower; with a negative
// minimum the denominators swap so the bracket stays sign-consistent.
double JacobianBounds::scaled_lower() const {
  // Without a proven positive det J the ratio is no quality measure: rank the cell below all.
  if (max_lower <= 0) return -inf;
  // min/max >= min_lower/max_upper holds for min_lower >= 0; for a negative minimum the
  // smallest possible max gives the most negative ratio.
  return min_lower >= 0 ? min_lower / max_upper : min_lower / max_lower;
}

double JacobianBounds::scaled_upper() const {
  if (max_lower <= 0) return -inf;
  return min_upper >= 0 ? min_upper / max_lower : min_upper / max_upper;
}

JacobianCertifier::JacobianCertifier(ValidityOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->leaves.reserve(256);
}

JacobianCertifier::~JacobianCertifier() = default;

JacobianBounds JacobianCertifier::certify(CellType type, int order, const double* coords) {
  check_order(order);
  if (ref_dim(type) < 2)
    throw InputError(std::string("validity: a ") + cell_name(type) + " has no volume Jacobian to certify");
  const LagrangeElement& e = lagrange_element(type, order);
  for (int i = 0; i < e.size() * e.dim(); ++i)
    if (!std::isfinite(coords[i]))
      throw InputError(std::string("validity: node ") + std::to_string(i / e.dim()) + " of an order-" +
                       std::to_string(order) + " " + cell_name(type) + " has a non-finite coordinate");

  Impl& m = *impl_;
  Space& s = m.space(type, order);
  const int num_kids = static_cast<int>(children(type).size());
  std::vector<SubCell>& leaves = m.leaves;
  std::vector<Eigen::MatrixXd>& coefs = m.leaf_coefs;
  leaves.clear();
  leaves.push_back({0, 0, 0});
  if (coefs.empty()) coefs.emplace_back();
  Range seen = m.evaluate_root(e, coords, s, leaves[0], coefs[0]);

  JacobianBounds r;
  bool min_frozen = false, max_frozen = false;  // the bound's sub-cell is at the depth limit
  while (true) {
    std::size_t lo = 0, hi = 0;
    for (std::size_t i = 1; i < leaves.size(); ++i) {
      if (leaves[i].coef_min < leaves[lo].coef_min) lo = i;
      if (leaves[i].coef_max > leaves[hi].coef_max) hi = i;
    }
    r.min_lower = leaves[lo].coef_min;
    r.max_upper = leaves[hi].coef_max;
    r.min_upper = seen.lo;
    r.max_lower = seen.hi;
    r.proven = r.min_lower > 0 || r.min_upper <= 0;
    // Relative to the largest |det J| bound, so the test is scale-free (max_upper for valid cells).
    const double tol_abs = m.options.rel_tol * std::max(std::abs(r.max_upper), std::abs(r.min_lower));
    const bool min_open = !min_frozen && r.min_upper - r.min_lower > tol_abs;
    const bool max_open = !max_frozen && r.max_upper - r.max_lower > tol_abs;
    std::size_t pick = 0;
    if (!r.proven || min_open)
      pick = lo;
    else if (max_open)
      pick = hi;
    else
      break;
    if (leaves[pick].depth >= m.options.max_depth || r.subdivisions + num_kids > max_subcells) {
      if (!r.proven) break;
      (min_open ? min_frozen : max_frozen) = true;
      continue;
    }
    const int depth = leaves[pick].depth + 1;
    m.parent_coefs = coefs[pick];
    for (int k = 0; k < num_kids; ++k) {
      std::size_t slot = pick;
      if (k == 0) {
        leaves[pick] = {depth, 0, 0};
      } else {
        slot = leaves.size();
        leaves.push_back({depth, 0, 0});
        if (coefs.size() < leaves.size()) coefs.emplace_back();
      }
      const Range got = m.subdivide(s, m.parent_coefs, static_cast<std::size_t>(k), leaves[slot], coefs[slot]);
      seen.lo = std::min(seen.lo, got.lo);
      seen.hi = std::max(seen.hi, got.hi);
    }
    r.subdivisions += num_kids;
  }
  r.valid = r.proven && r.min_lower > 0;
  return r;
}

bool surface_triangle_plane_coords(int order, const Eigen::Vector3d* nodes, double* coords2d) {
  const int n = num_nodes(CellType::Triangle, order);
  const Eigen::Vector3d a = nodes[0];
  const Eigen::Vector3d e0 = nodes[1] - a, e1 = nodes[2] - a;
  const Eigen::Vector3d normal = e0.cross(e1);
  const double len0 = e0.norm();
  // Zero area to round-off: |e0 x e1| against the product of the edge lengths.
  constexpr double degenerate_sine = 1e-14;
  const double area2 = normal.norm();
  if (!std::isfinite(area2) || !(area2 > degenerate_sine * len0 * e1.norm())) return false;
  const Eigen::Vector3d x_axis = e0 / len0;
  const Eigen::Vector3d y_axis = normal.cross(e0).normalized();  // in the plane, toward vertex 2
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d d = nodes[k] - a;
    coords2d[2 * k] = d.dot(x_axis);
    coords2d[2 * k + 1] = d.dot(y_axis);
  }
  return true;
}

JacobianBounds certify_surface_triangle(JacobianCertifier& certifier, int order, const Eigen::Vector3d* nodes) {
  check_order(order);
  const int n = num_nodes(CellType::Triangle, order);
  for (int k = 0; k < n; ++k)
    if (!nodes[k].allFinite())
      throw InputError("validity: node " + std::to_string(k) + " of an order-" + std::to_string(order) +
                       " surface triangle has a non-finite coordinate");
  std::array<double, 2 * 15> coords{};  // the order-4 triangle has 15 nodes
  static_assert(2 * ((max_order + 1) * (max_order + 2) / 2) <= 2 * 15);
  if (!surface_triangle_plane_coords(order, nodes, coords.data())) {
    JacobianBounds degenerate;
    degenerate.proven = true;
    return degenerate;
  }
  return certifier.certify(CellType::Triangle, order, coords.data());
}

bool surface_quad_plane_coords(int order, const Eigen::Vector3d* nodes, double* coords2d) {
  const int n = num_nodes(CellType::Quadrilateral, order);
  const Eigen::Vector3d a = nodes[0];
  const Eigen::Vector3d d0 = nodes[2] - a, d1 = nodes[3] - nodes[1];
  const Eigen::Vector3d normal = d0.cross(d1);  // twice the vector area of the vertex quadrilateral
  constexpr double degenerate_sine = 1e-14;
  const double area2 = normal.norm();
  if (!std::isfinite(area2) || !(area2 > degenerate_sine * d0.norm() * d1.norm())) return false;
  const Eigen::Vector3d unit_normal = normal / area2;
  // Edge 0-1 in the plane; for a quadrilateral folded so far that edge 0-1 is along the normal,
  // the diagonal 0-2 (never along it: the normal is orthogonal to it).
  Eigen::Vector3d x_axis = nodes[1] - a;
  x_axis -= x_axis.dot(unit_normal) * unit_normal;
  if (!(x_axis.norm() > degenerate_sine * d0.norm())) x_axis = d0;
  x_axis.normalize();
  const Eigen::Vector3d y_axis = unit_normal.cross(x_axis);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d d = nodes[k] - a;
    coords2d[2 * k] = d.dot(x_axis);
    coords2d[2 * k + 1] = d.dot(y_axis);
  }
  return true;
}

JacobianBounds certify_surface_quad(JacobianCertifier& certifier, int order, const Eigen::Vector3d* nodes) {
  check_order(order);
  const int n = num_nodes(CellType::Quadrilateral, order);
  for (int k = 0; k < n; ++k)
    if (!nodes[k].allFinite())
      throw InputError("validity: node " + std::to_string(k) + " of an order-" + std::to_string(order) +
                       " surface quadrilateral has a non-finite coordinate");
  std::array<double, 2 * (max_order + 1) * (max_order + 1)> coords{};
  if (!surface_quad_plane_coords(order, nodes, coords.data())) {
    JacobianBounds degenerate;
    degenerate.proven = true;
    return degenerate;
  }
  return certifier.certify(CellType::Quadrilateral, order, coords.data());
}

double jacobian_determinant(CellType type, int order, const double* coords, const double* xi) {
  const LagrangeElement& e = lagrange_element(type, order);
  std::array<double, max_grad_size> dphi{};
  return det_at(e, coords, xi, dphi.data());
}

template <int Dim>
bool simplex_corners_positive(CellType type, const double* xs) {
  if constexpr (Dim == 2) {
    if (type != CellType::Triangle) return true;
    const Eigen::Vector2d a(xs[0], xs[1]), b(xs[2], xs[3]), c(xs[4], xs[5]);
    return sign_orient2d(a, b, c) > 0;
  } else {
    if (type != CellType::Tetrahedron) return true;
    const Eigen::Vector3d a(xs[0], xs[1], xs[2]), b(xs[3], xs[4], xs[5]), c(xs[6], xs[7], xs[8]), d(xs[9], xs[10], xs[11]);
    return positive_tet(a, b, c, d);
  }
}
template bool simplex_corners_positive<2>(CellType, const double*);
template bool simplex_corners_positive<3>(CellType, const double*);

}  // namespace elements
}  // namespace plaf
