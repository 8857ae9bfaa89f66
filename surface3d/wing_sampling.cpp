// SPDX-License-Identifier: MIT
// Contour samples of the analytic wing's section (see wing_sampling.h): graded by a cumulative
// table of length x max(1 / h, curvature / 30 degrees), inverted at equal steps.
#include "surface3d/wing_sampling.h"

#include <algorithm>
#include <cmath>

namespace plaf::analytic_detail {

using Eigen::Vector2d;

namespace {

constexpr double kTurn = M_PI / 6;
constexpr int kMinSamples = 12;

// Inverts a cumulative table: the abscissa (linear in the table) where `cum` reaches `target`.
double invert_table(const std::vector<double>& x, const std::vector<double>& cum, double target) {
  const auto it = std::upper_bound(cum.begin(), cum.end(), target);
  const int m = std::clamp(static_cast<int>(it - cum.begin()) - 1, 0, static_cast<int>(cum.size()) - 2);
  const double w = cum[m + 1] > cum[m] ? std::clamp((target - cum[m]) / (cum[m + 1] - cum[m]), 0.0, 1.0) : 0.0;
  return x[m] + w * (x[m + 1] - x[m]);
}

// Samples t0 < ... < t_{n-1} in [t0, t1) of one corner-to-corner run (at least min_n).
std::vector<double> graded_samples(const SplineLoop& loop, double t0, double t1, double h, int min_n) {
  const int fine = 32 * std::max(1, static_cast<int>(std::ceil(t1 - t0)));
  std::vector<double> ts(fine + 1), cum(fine + 1, 0.0);
  Vector2d prev = loop.point(t0);
  for (int k = 0; k <= fine; ++k) {
    ts[k] = t0 + (t1 - t0) * k / fine;
    if (k == 0) continue;
    const Vector2d q = loop.point(ts[k]);
    const double kappa = std::abs(loop.curvature(0.5 * (ts[k - 1] + ts[k])));
    cum[k] = cum[k - 1] + (q - prev).norm() * std::max(1 / h, kappa / kTurn);
    prev = q;
  }
  const int n = std::max(min_n, static_cast<int>(std::lround(cum[fine])));
  std::vector<double> out = {t0};
  for (int q = 1; q < n; ++q) out.push_back(invert_table(ts, cum, cum[fine] * q / n));
  return out;
}

// Stations s_0 = 0 < ... < s_J = 1 of the cap, graded as in graded_samples on the mean of both
// arcs' lengths and curvatures.
std::vector<double> graded_stations(const WingReference& w, const RoundedCap& cap, double h) {
  const SplineLoop& loop = w.loop();
  constexpr int kFine = 2048;
  std::vector<double> sigma(kFine + 1), cum(kFine + 1, 0.0);
  Vector2d prev1 = loop.point(w.t_le()), prev2 = prev1;
  for (int m = 0; m <= kFine; ++m) {
    sigma[m] = static_cast<double>(m) / kFine;
    if (m == 0) continue;
    const double s = sigma[m];
    const Vector2d p1 = loop.point(cap.station_t(0, s).first), p2 = loop.point(cap.station_t(1, s).first);
    const double mid = 0.5 * (sigma[m - 1] + s);
    const double kappa = std::max(std::abs(loop.curvature(cap.station_t(0, mid).first)),
                                  std::abs(loop.curvature(cap.station_t(1, mid).first)));
    cum[m] = cum[m - 1] + 0.5 * ((p1 - prev1).norm() + (p2 - prev2).norm()) * std::max(1 / h, kappa / kTurn);
    prev1 = p1;
    prev2 = p2;
  }
  const int J = std::max(kMinSamples / 2, static_cast<int>(std::lround(cum[kFine])));
  std::vector<double> stations(J + 1);
  for (int j = 0; j <= J; ++j) stations[j] = std::clamp(invert_table(sigma, cum, cum[kFine] * j / J), 0.0, 1.0);
  stations[0] = 0;
  stations[J] = 1;
  return stations;
}

}  // namespace

ContourSamples sample_by_corners(const WingReference& w, double h) {
  const SplineLoop& loop = w.loop();
  ContourSamples out;
  const std::vector<double>& corners = w.corner_t();
  const double P = loop.period();
  std::vector<double> starts = corners;
  if (starts.empty()) starts.push_back(0.0);
  const int nc = static_cast<int>(starts.size());
  for (int m = 0; m < nc; ++m) {
    const double t0 = starts[m], t1 = m + 1 < nc ? starts[m + 1] : starts[0] + P;
    if (!corners.empty()) out.corner_index.push_back(static_cast<int>(out.t.size()));
    const int min_n =
        std::max(nc == 1 ? 3 : 1, static_cast<int>(std::lround(kMinSamples * loop.arc_length(t0, t1) / loop.length())));
    for (double t : graded_samples(loop, t0, t1, h, min_n)) out.t.push_back(t);
  }
  return out;
}

ContourSamples sample_by_stations(const WingReference& w, const RoundedCap& cap, double h) {
  const SplineLoop& loop = w.loop();
  ContourSamples out;
  out.stations = graded_stations(w, cap, h);
  const int J = static_cast<int>(out.stations.size()) - 1;
  const double P = loop.period();
  // Arc 1 forward from the leading edge to t_a, then the blunt base, then arc 2 back towards
  // the leading edge.
  out.t.push_back(w.t_le());
  for (int j = 1; j <= J; ++j) out.t.push_back(cap.station_t(0, out.stations[j]).first);
  out.arc1.resize(J + 1);
  out.arc2.resize(J + 1);
  for (int j = 0; j <= J; ++j) out.arc1[j] = j;
  out.t[J] = w.t_a();
  int te2 = J;
  if (!w.sharp()) {
    const double tb = w.t_b() + P;  // the base runs from t_a to t_b + P
    const double len = loop.arc_length(w.t_a(), tb);
    const int nb = std::max(1, static_cast<int>(std::lround(len / h)));
    for (int q = 1; q < nb; ++q) out.t.push_back(w.t_a() + (tb - w.t_a()) * q / nb);
    out.t.push_back(tb);
    te2 = static_cast<int>(out.t.size()) - 1;
  }
  out.arc2[0] = 0;
  out.arc2[J] = te2;
  for (int j = J - 1; j >= 1; --j) {
    out.arc2[j] = static_cast<int>(out.t.size());
    out.t.push_back(cap.station_t(1, out.stations[j]).first + P);
  }
  // Corner samples, in the loop's corner order.
  for (double c : w.corner_t()) {
    int best = 0;
    for (int i = 0; i < static_cast<int>(out.t.size()); ++i) {
      const double d = std::abs(std::remainder(out.t[i] - c, P));
      if (d < std::abs(std::remainder(out.t[best] - c, P))) best = i;
    }
    out.corner_index.push_back(best);
  }
  return out;
}

}  // namespace plaf::analytic_detail
