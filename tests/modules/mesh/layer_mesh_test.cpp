// SPDX-License-Identifier: MIT
#include "modules/mesh/layer_mesh.h"

#include <doctest/doctest.h>

namespace plaf {
namespace {

LayerCoverage::Site site(double x, double measure, int layer, bool crossing) {
  LayerCoverage::Site s;
  s.point = {x, 0, 0};
  s.measure = measure;
  s.layer = layer;
  s.crossing = crossing;
  return s;
}

TEST_CASE("stop regions: sites within the radius of a region's largest site join it, largest region first") {
  LayerCoverage c;
  c.sites = {site(10, 0.5, 2, false), site(0.01, 1, 5, true), site(0, 2, 3, false), site(0.04, 0.25, 9, false),
             site(10.2, 4, 7, true)};
  const std::vector<StopRegion> r = stop_regions(c, 0.05);
  // The site at 10.2 (largest) starts a region that the one at 10 does not reach (0.2 > 0.05);
  // the one at 0 (next) gathers 0.01 and 0.04.
  REQUIRE(r.size() == 3);
  CHECK(r[0].point[0] == 10.2);
  CHECK(r[0].measure == 4);
  CHECK(r[0].groups == 1);
  CHECK(r[0].crossing);
  CHECK_FALSE(r[0].invalid);
  CHECK(r[1].point[0] == 0);
  CHECK(r[1].measure == doctest::Approx(3.25));
  CHECK(r[1].groups == 3);
  CHECK(r[1].first_layer == 3);
  CHECK(r[1].last_layer == 9);
  CHECK(r[1].invalid);
  CHECK(r[1].crossing);
  CHECK(r[2].point[0] == 10);
  CHECK(r[2].measure == 0.5);
  CHECK(stop_regions(LayerCoverage{}, 1).empty());
}

}  // namespace
}  // namespace plaf
