// SPDX-License-Identifier: MIT
// NACA 4- and 5-digit sections from their formulas (naca_section.h).
#include "modules/io/naca_section.h"

#include <algorithm>
#include <cmath>

#include "modules/base/error.h"

namespace plaf {
inline namespace io {

namespace {

// The 5-digit mean lines for a design lift coefficient of 0.3 (Abbott & von Doenhoff; NASA
// TM-4741): r (the end of the cubic), k1, and for the reflexed lines k2/k1.
struct MeanLine5 {
  double r, k1, k21;
};
constexpr MeanLine5 kSimple[5] = {
    {0.0580, 361.400, 0}, {0.1260, 51.640, 0}, {0.2025, 15.957, 0}, {0.2900, 6.643, 0}, {0.3910, 3.230, 0}};
constexpr MeanLine5 kReflex[5] = {
    {0, 0, 0}, {0.1300, 51.990, 0.000764}, {0.2170, 15.793, 0.00677}, {0.3180, 6.520, 0.0303}, {0.4410, 3.191, 0.1355}};

int digit(const std::string& s, std::size_t i) { return s[i] - '0'; }

struct Camber {
  double y, slope;
};

// The camber line and its slope at x.
Camber camber(const NacaSection& s, double x) {
  const std::string& d = s.digits;
  if (d.size() == 4) {
    const double m = digit(d, 0) / 100.0, p = digit(d, 1) / 10.0;
    if (m == 0) return {0, 0};
    if (x < p) return {m / (p * p) * (2 * p * x - x * x), 2 * m / (p * p) * (p - x)};
    const double q = (1 - p) * (1 - p);
    return {m / q * (1 - 2 * p + 2 * p * x - x * x), 2 * m / q * (p - x)};
  }
  const int lift = digit(d, 0), pos = digit(d, 1);
  const bool reflex = digit(d, 2) == 1;
  const MeanLine5 ml = (reflex ? kReflex : kSimple)[pos - 1];
  const double k1 = ml.k1 * (0.15 * lift) / 0.3, r = ml.r, r3 = r * r * r;
  if (!reflex) {
    if (x < r) return {k1 / 6 * (x * x * x - 3 * r * x * x + r * r * (3 - r) * x), k1 / 6 * (3 * x * x - 6 * r * x + r * r * (3 - r))};
    return {k1 * r3 / 6 * (1 - x), -k1 * r3 / 6};
  }
  const double k21 = ml.k21, c = k21 * std::pow(1 - r, 3) + r3;
  if (x < r) return {k1 / 6 * (std::pow(x - r, 3) - c * x + r3), k1 / 6 * (3 * (x - r) * (x - r) - c)};
  return {k1 / 6 * (k21 * std::pow(x - r, 3) - c * x + r3), k1 / 6 * (3 * k21 * (x - r) * (x - r) - c)};
}

double half_thickness(const NacaSection& s, double x) {
  const std::string& d = s.digits;
  const double t = (digit(d, d.size() - 2) * 10 + digit(d, d.size() - 1)) / 100.0;
  const double a4 = s.sharp ? -0.1036 : -0.1015;
  const double y = t / 0.2 * (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x + a4 * x * x * x * x);
  return std::max(y, 0.0);  // the sharp law's y(1) is 0 up to rounding: never negative
}

}  // namespace

void check_naca(const NacaSection& s) {
  const std::string& d = s.digits;
  const std::string what = "NACA '" + d + "'";
  if (d.size() != 4 && d.size() != 5)
    throw InputError(what + ": a NACA section has 4 digits (MPTT, e.g. 2412) or 5 (LPQTT, e.g. 23012)");
  for (char c : d)
    if (c < '0' || c > '9') throw InputError(what + ": '" + std::string(1, c) + "' is not a digit");
  if (digit(d, d.size() - 2) * 10 + digit(d, d.size() - 1) == 0)
    throw InputError(what + ": the thickness (the last two digits) must not be 0");
  if (d.size() == 4 && (digit(d, 0) == 0) != (digit(d, 1) == 0))
    throw InputError(what + ": a 4-digit section has both a camber (1st digit) and its position (2nd) or neither");
  if (d.size() == 5) {
    if (digit(d, 0) == 0) throw InputError(what + ": the design lift (1st digit) of a 5-digit section must not be 0");
    if (digit(d, 2) > 1) throw InputError(what + ": the 3rd digit of a 5-digit section is 0 (simple) or 1 (reflex)");
    const int pos = digit(d, 1);
    if (pos < 1 || pos > 5 || (digit(d, 2) == 1 && pos == 1))
      throw InputError(what + ": the mean line " + d.substr(0, 3) +
                       " is not in the 5-digit tables (210-250, reflexed 221-251)");
  }
  if (s.intervals < 4 || s.intervals > 100000)
    throw InputError(what + ": " + std::to_string(s.intervals) + " intervals per surface; give 4 to 100000");
}

std::vector<Eigen::Vector2d> naca_points(const NacaSection& s) {
  check_naca(s);
  const int n = s.intervals;
  // A point of the upper (+1) or lower (-1) surface at theta = pi k / n.
  const auto point = [&](int k, int side) {
    const double x = k == n ? 1.0 : (1 - std::cos(M_PI * k / n)) / 2;
    const Camber c = camber(s, x);
    const double yt = half_thickness(s, x), a = std::atan(c.slope);
    return Eigen::Vector2d(x - side * yt * std::sin(a), c.y + side * yt * std::cos(a));
  };
  std::vector<Eigen::Vector2d> pts;
  for (int k = n; k >= 1; --k) pts.push_back(point(k, +1));
  pts.push_back(Eigen::Vector2d(0, 0));
  for (int k = 1; k <= n; ++k) pts.push_back(point(k, -1));
  if (s.sharp) pts.back() = pts.front();  // one trailing-edge point, bit for bit
  return pts;
}

std::string naca_name(const NacaSection& s) {
  return "NACA " + s.digits + (s.sharp ? " (sharp trailing edge)" : " (blunt trailing edge)");
}

BodyContour naca_contour(const NacaSection& s) { return contour_from_points(naca_points(s), naca_name(s)); }

}  // namespace io
}  // namespace plaf
