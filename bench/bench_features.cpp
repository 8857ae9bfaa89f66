// SPDX-License-Identifier: MIT
// Time of feature detection (surface3d/features.h; paper Sec. II.E): detect_features (its three
// linear passes: edges, vertices, curves) and feature_curves (walking every curve) on the cube
// made of k x k squares per face (12 k^2 triangles; the default k = 91 gives 99,372), best of a
// few repeats. The unit tests check the same cube's features for correctness; this only times
// them (both passes are O(V + E + F): well under a second at 100k faces).
// Run by hand: bench_features [squares_per_side] [repeats].
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "modules/geometry/tri_surface.h"
#include "surface3d/features.h"
#include "tests/surface3d/test_surfaces.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const int k = argc > 1 ? std::atoi(argv[1]) : 91;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
  if (k < 1 || repeats < 1) {
    std::fprintf(stderr, "usage: bench_features [squares_per_side >= 1] [repeats >= 1]\n");
    return 2;
  }

  // 1. The cube.
  const plaf::TriSurface cube = plaf::surface_from_soup(plaf::test::voxel_soup({{0, 0, 0}}, k));
  std::printf("cube of %d x %d squares per face: %zu faces, %zu vertices\n", k, k, cube.mesh.n_faces(),
              cube.mesh.n_vertices());

  // 2. Best of the repeats, each on a fresh copy (detection writes the surface's properties).
  double detect_s = 1e300, curves_s = 1e300;
  plaf::FeatureReport r;
  std::size_t walked = 0;
  for (int rep = 0; rep < repeats; ++rep) {
    plaf::TriSurface s = cube;
    Clock::time_point t0 = Clock::now();
    r = plaf::detect_features(s, {});
    detect_s = std::min(detect_s, seconds_since(t0));
    t0 = Clock::now();
    const auto curves = plaf::feature_curves(s);
    curves_s = std::min(curves_s, seconds_since(t0));
    walked = 0;
    for (const auto& path : curves) walked += path.size();
  }

  // 3. The timings, and the counts as a sanity check (12 k ridges, 8 corners, 12 curves).
  std::printf("%-16s %9.4f s\n%-16s %9.4f s\n", "detect_features", detect_s, "feature_curves", curves_s);
  std::printf("found %zu convex ridges, %zu convex corners, %zu curves (%zu curve vertices walked)\n", r.ridges_convex,
              r.corners_convex, r.curves, walked);
  return 0;
}
