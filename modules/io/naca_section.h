// SPDX-License-Identifier: MIT
// NACA 4- and 5-digit sections generated from their formulas, so that a run needs no published
// coordinate file for them (Abbott & von Doenhoff, *Theory of Wing Sections*, sec. 6.4; Ladson
// et al., NASA TM-4741):
// - thickness  y_t = t/0.2 (0.2969 sqrt(x) - 0.1260 x - 0.3516 x^2 + 0.2843 x^3 + a4 x^4), with
//   a4 = -0.1015 (the standard, blunt trailing edge of thickness 0.00252 t/0.12) or -0.1036 (sharp:
//   y_t(1) = 0);
// - 4-digit MPTT camber: m = M/100 at p = P/10, two parabolas
//   y_c = m/p^2 (2 p x - x^2) (x < p),  m/(1-p)^2 (1 - 2p + 2 p x - x^2) (x >= p);
// - 5-digit LPQTT camber: design lift 0.15 L, maximum camber at P/20, Q = 0 simple, 1 reflex;
//   simple: y_c = k1/6 (x^3 - 3 r x^2 + r^2 (3 - r) x) (x < r),  k1 r^3/6 (1 - x) (x >= r);
//   reflex: y_c = k1/6 ((x - r)^3 - k21 (1 - r)^3 x - r^3 x + r^3) (x < r),
//           k1/6 (k21 (x - r)^3 - k21 (1 - r)^3 x - r^3 x + r^3) (x >= r),
//   with r, k1 (and k21 = k2/k1) from the standard tables for a design lift of 0.3, k1 scaled by
//   the design lift over 0.3;
// - the thickness laid off normal to the camber line; cosine spacing x = (1 - cos theta)/2 with
//   `intervals` equal steps of theta per surface, the leading edge x = 0 a point of both.
// The points are in Selig order (TE -> upper -> LE -> lower -> TE) and become a BodyContour
// (airfoil_io.h) exactly as a file's would: a sharp section has one trailing-edge corner, a blunt
// one a closing segment between two.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "modules/io/airfoil_io.h"

namespace plaf {
inline namespace io {

struct NacaSection {
  std::string digits = "0012";  // 4 or 5 digits
  bool sharp = true;            // closed trailing edge (a4 = -0.1036) or the standard blunt one
  int intervals = 100;          // cosine-spaced intervals per surface
};

// Throws InputError naming the designation when it is not a NACA 4- or 5-digit section plaf can
// generate (wrong length, a non-digit, a 4-digit camber without its position, a 5-digit mean line
// outside the tables, zero thickness).
void check_naca(const NacaSection& s);

// The points in Selig order, chord 1 from (0, 0) to (1, 0).
std::vector<Eigen::Vector2d> naca_points(const NacaSection& s);

// "NACA 0012 (sharp trailing edge)": the name messages and reports use for the section.
std::string naca_name(const NacaSection& s);

// The section as a contour (contour_from_points).
BodyContour naca_contour(const NacaSection& s);

}  // namespace io
}  // namespace plaf
