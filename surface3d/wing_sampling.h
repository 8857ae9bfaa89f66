// SPDX-License-Identifier: MIT
// Internal to the analytic wing (analytic.h): the samples of the wing section's contour that the
// initial triangulation's side grid runs through.
//
// The contour is sampled at spacing min(h, 30 degrees of turning x radius of curvature): the
// initial triangles are about h, but their chords never cut across a leading edge much smaller
// than h (a chord turning more would leave the wing's faces facing away from the surface they
// approximate). A floor of 12 samples around the section keeps coarse h (of the order of the
// chord) from collapsing a thin section's surface into single chords.
#pragma once

#include <vector>

#include "surface3d/rounded_cap.h"
#include "surface3d/wing_reference.h"

namespace plaf::analytic_detail {

// Contour samples of a wing section, in loop order (unwrapped increasing parameters).
struct ContourSamples {
  std::vector<double> t;
  std::vector<int> corner_index;  // sample index of each loop corner (in loop_.corners() order)
  // Rounded ends only: stations s_j and the sample index of each station on both arcs.
  std::vector<double> stations;
  std::vector<int> arc1, arc2;
};

// Flat and symmetry ends: each corner-to-corner run sampled on its own.
ContourSamples sample_by_corners(const WingReference& w, double h);

// Rounded ends: samples at shared chord stations of both arcs of `cap`, then the blunt base.
ContourSamples sample_by_stations(const WingReference& w, const RoundedCap& cap, double h);

}  // namespace plaf::analytic_detail
