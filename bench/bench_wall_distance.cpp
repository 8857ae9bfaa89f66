// SPDX-License-Identifier: MIT
// Throughput of the wall distance behind the boundary-layer metric (K. J. Fidkowski, *Anisotropic
// Metric-Based Curved Meshing Using Prismatic Layers*, Sec. IV.A, eq. 6): the exact closest point
// on the cubic-spline walls (SplineLoop::closest_point: a bounding-box tree over the pieces, then
// the roots of each candidate piece's quintic) against the naive peer, a brute-force scan over a
// dense polyline of the same walls. Walls: the Eppler 387 and the blunt NACA 0012, its open
// trailing edge closed by a straight segment (data/airfoils). Queries: uniform in a box around
// the bodies, and in a near-wall band.
// Also times WallPowerLawField::evaluate (closest point + sizes + metric) on the same points.
// Run by hand: bench_wall_distance [queries] [brute_force_queries] [polyline_points_per_loop].
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "modules/geometry/geometry2d.h"
#include "modules/metric/wall_metric.h"
#include "modules/pipeline/data_root.h"

namespace {

using Clock = std::chrono::steady_clock;
using Eigen::Vector2d;
using plaf::SplineLoop;
using plaf::WallLawParams;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The walls as one polyline per loop, its vertices on the spline: each corner-to-corner segment
// sampled uniformly in arc length (corners are vertices, so no chord cuts a corner), about
// `points` vertices per loop. Stored as segments a + s e, s in [0, 1], structure of arrays.
struct Polyline {
  std::vector<double> ax, ay, ex, ey, inv_len2;
  double chord_error = 0;  // max distance between the spline and its chords (sampled)

  void add(const SplineLoop& loop, int points) {
    std::vector<double> cuts(loop.corners().begin(), loop.corners().end());
    if (cuts.empty()) cuts.push_back(0.0);
    const double total = loop.length();
    for (std::size_t k = 0; k < cuts.size(); ++k) {
      const double t0 = cuts[k], t1 = k + 1 < cuts.size() ? cuts[k + 1] : cuts[0] + loop.period();
      const double length = loop.arc_length(t0, t1);
      const int n = std::max(1, static_cast<int>(std::lround(points * length / total)));
      double ta = t0;
      for (int i = 1; i <= n; ++i) {
        const double tb = i == n ? t1 : loop.parameter_at(t0, length * i / n);
        const Vector2d a = loop.point(std::fmod(ta, loop.period())), b = loop.point(std::fmod(tb, loop.period()));
        const Vector2d e = b - a;
        ax.push_back(a[0]);
        ay.push_back(a[1]);
        ex.push_back(e[0]);
        ey.push_back(e[1]);
        inv_len2.push_back(1 / e.squaredNorm());
        // Sagitta: the spline between the two vertices against the chord.
        for (int s = 1; s < 8; ++s) {
          const Vector2d x = loop.point(std::fmod(ta + (tb - ta) * s / 8, loop.period()));
          const double f = std::clamp((x - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
          chord_error = std::max(chord_error, (x - a - f * e).norm());
        }
        ta = tb;
      }
    }
  }

  // Brute force: the distance to every segment.
  double distance(const Vector2d& x) const {
    double best = std::numeric_limits<double>::infinity();
    const std::size_t n = ax.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double dx = x[0] - ax[i], dy = x[1] - ay[i];
      const double s = std::clamp((dx * ex[i] + dy * ey[i]) * inv_len2[i], 0.0, 1.0);
      const double rx = dx - s * ex[i], ry = dy - s * ey[i];
      best = std::min(best, rx * rx + ry * ry);
    }
    return std::sqrt(best);
  }
};

double spline_distance(const std::vector<SplineLoop>& walls, const Vector2d& x) {
  double best = std::numeric_limits<double>::infinity();
  for (const SplineLoop& w : walls) best = std::min(best, w.closest_point(x).distance);
  return best;
}

struct Case {
  const char* name;
  std::string file;  // a published contour in the data root (modules/pipeline/data_root.h), or
  std::optional<plaf::NacaSection> naca;  // a generated section
  double corner_angle_deg;  // as in configs/<case>.yaml
  WallLawParams law;        // as in configs/<case>.yaml
};

void run_case(const Case& c, std::size_t queries, std::size_t brute_queries, int polyline_points) {
  // 1. Walls.
  plaf::AirfoilsParams a;
  plaf::BodyParams body;
  body.name = "wall";
  body.naca = c.naca;
  if (!c.naca) {
    const std::optional<std::string> found = plaf::find_data_file(c.file);
    if (!found) {
      std::printf("%s: skipped, %s is in no data root (docs/data.md)\n", c.name, c.file.c_str());
      return;
    }
    body.file = *found;
  }
  a.bodies.push_back(body);
  a.corner_angle_deg = c.corner_angle_deg;
  std::vector<SplineLoop> walls;
  for (const plaf::GeometryLoop& g : plaf::build_airfoils_geometry(a).loops)
    if (g.kind == plaf::BoundaryKind::Wall) walls.push_back(g.loop);
  Vector2d lo = walls[0].points()[0], hi = lo;
  int pieces = 0;
  for (const SplineLoop& w : walls) {
    for (const Vector2d& p : w.points()) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    pieces += w.num_points();
  }
  const double chord = hi[0] - lo[0];
  Polyline poly;
  for (const SplineLoop& w : walls) poly.add(w, polyline_points);
  std::printf("\n== %s: %zu walls, %d spline pieces; polyline of %zu segments, chord error %.3g (%.3g chord)\n", c.name,
              walls.size(), pieces, poly.ax.size(), poly.chord_error, poly.chord_error / chord);

  // 2. Queries: uniform in the bounding box grown by half a chord on every side; and a band
  //    0..1% of the chord off the walls (a random wall point, offset along its normal).
  std::mt19937 rng(387);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Vector2d> box(queries), band(queries);
  std::vector<double> band_offset(queries);
  for (Vector2d& x : box)
    x = lo - Vector2d::Constant(0.5 * chord) +
        Vector2d(u01(rng) * (hi[0] - lo[0] + chord), u01(rng) * (hi[1] - lo[1] + chord));
  for (std::size_t i = 0; i < queries; ++i) {
    const SplineLoop& w =
        walls[std::min(walls.size() - 1, static_cast<std::size_t>(u01(rng) * static_cast<double>(walls.size())))];
    const double t = u01(rng) * w.period();
    band_offset[i] = 0.01 * chord * u01(rng);
    band[i] = w.point(t) + band_offset[i] * w.normal(t);
  }

  const plaf::WallPowerLawField field(walls, c.law);
  for (const auto& [set, points] :
       {std::pair<const char*, const std::vector<Vector2d>*>{"box", &box}, {"band", &band}}) {
    // 3. Exact spline distance, all queries.
    std::vector<double> exact(points->size());
    Clock::time_point t0 = Clock::now();
    for (std::size_t i = 0; i < points->size(); ++i) exact[i] = spline_distance(walls, (*points)[i]);
    const double spline_s = seconds_since(t0);
    const double spline_rate = static_cast<double>(points->size()) / spline_s;

    // 4. Brute force over the polyline, the first brute_queries queries.
    const std::size_t nb = std::min(brute_queries, points->size());
    double max_diff = 0, checksum = 0;
    t0 = Clock::now();
    for (std::size_t i = 0; i < nb; ++i) {
      const double d = poly.distance((*points)[i]);
      checksum += d;
      max_diff = std::max(max_diff, std::abs(d - exact[i]));
    }
    const double brute_s = seconds_since(t0);
    const double brute_rate = static_cast<double>(nb) / brute_s;

    // 5. The whole metric.
    t0 = Clock::now();
    double trace = 0;
    for (const Vector2d& x : *points) trace += field.evaluate(x).matrix().trace();
    const double metric_s = seconds_since(t0);

    std::printf("%-5s spline closest_point   %9zu queries %8.3f s  %11.0f /s\n", set, points->size(), spline_s,
                spline_rate);
    std::printf("%-5s polyline brute force  %9zu queries %8.3f s  %11.0f /s   spline/brute = %.0fx\n", set, nb, brute_s,
                brute_rate, spline_rate / brute_rate);
    std::printf("%-5s max |d_spline - d_polyline| = %.3g (bound: chord error %.3g) %s\n", set, max_diff,
                poly.chord_error, max_diff <= 1.01 * poly.chord_error + 1e-15 ? "ok" : "EXCEEDED");
    if (set == std::string("band")) {
      // The offset point's foot is on the wall, so the distance is at most the offset.
      std::size_t above = 0;
      for (std::size_t i = 0; i < band.size(); ++i) above += exact[i] > band_offset[i] + 1e-12 * chord ? 1 : 0;
      std::printf("band  distances above their offset: %zu of %zu\n", above, band.size());
    }
    std::printf("%-5s WallPowerLawField::evaluate %9zu      %8.3f s  %11.0f /s   (checksums %.6g %.6g)\n", set,
                points->size(), metric_s, static_cast<double>(points->size()) / metric_s, checksum, trace);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const long queries = argc > 1 ? std::atol(argv[1]) : 1000000;
  const long brute_queries = argc > 2 ? std::atol(argv[2]) : 20000;
  const int polyline_points = argc > 3 ? std::atoi(argv[3]) : 20000;
  if (queries < 1 || brute_queries < 1 || polyline_points < 3) {
    std::fprintf(stderr,
                 "usage: bench_wall_distance [queries >= 1] [brute_force_queries >= 1] [points_per_loop >= 3]\n");
    return 2;
  }
  // Wall-law parameters and corner thresholds of configs/e387.yaml and configs/naca0012_blunt.yaml.
  WallLawParams e387;
  e387.h0 = 0.005;
  e387.growth = 1.2;
  e387.h_max = 2.0;
  e387.h_wall_max = 0.04;
  e387.curvature_factor = 0.3;
  e387.h_corner = 0.01;
  WallLawParams blunt = e387;
  blunt.h0 = 0.001;
  blunt.h_corner = 0.005;
  const Case cases[] = {
      {"E387", "airfoils/e387.dat", std::nullopt, 70.0, e387},
      {"NACA 0012, blunt TE (generated)", "", plaf::NacaSection{"0012", false, 100}, 30.0, blunt},
  };
  for (const Case& c : cases)
    run_case(c, static_cast<std::size_t>(queries), static_cast<std::size_t>(brute_queries), polyline_points);
  return 0;
}
