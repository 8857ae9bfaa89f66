// SPDX-License-Identifier: MIT
#include "modules/mesh/layer_mesh.h"

#include <algorithm>

namespace plaf {
inline namespace mesh {

std::vector<StopRegion> stop_regions(const LayerCoverage& coverage, double radius) {
  std::vector<const LayerCoverage::Site*> sites;
  for (const LayerCoverage::Site& s : coverage.sites) sites.push_back(&s);
  std::stable_sort(sites.begin(), sites.end(), [](const auto* a, const auto* b) { return a->measure > b->measure; });
  std::vector<StopRegion> regions;
  for (const LayerCoverage::Site* s : sites) {
    auto near = [&](const StopRegion& r) {
      double d2 = 0;
      for (std::size_t i = 0; i < 3; ++i) d2 += (r.point[i] - s->point[i]) * (r.point[i] - s->point[i]);
      return d2 <= radius * radius;
    };
    auto it = std::find_if(regions.begin(), regions.end(), near);
    if (it == regions.end()) {
      StopRegion r;
      r.point = s->point;
      r.first_layer = r.last_layer = s->layer;
      regions.push_back(r);
      it = regions.end() - 1;
    }
    it->measure += s->measure;
    it->first_layer = std::min(it->first_layer, s->layer);
    it->last_layer = std::max(it->last_layer, s->layer);
    ++it->groups;
    (s->crossing ? it->crossing : it->invalid) = true;
  }
  std::stable_sort(regions.begin(), regions.end(), [](const StopRegion& a, const StopRegion& b) { return a.measure > b.measure; });
  return regions;
}

LinearLoop linear_loop(const CurvedFront<2>& front, const FrontLoop& l, bool layered, int source_loop) {
  LinearLoop out{l.tag, l.kind, layered, source_loop, {}};
  for (std::size_t e = 0; e < l.size(); ++e) out.nodes.push_back(front.element(l, e)[0]);
  return out;
}

LayerResult<2> unlayered(const CurvedFront<2>& front) {
  LayerResult<2> r;
  r.mesh.nodes = front.nodes;
  r.outer = front;
  r.fill_front.nodes = front.nodes;
  for (std::size_t k = 0; k < front.loops.size(); ++k)
    r.fill_front.loops.push_back(linear_loop(front, front.loops[k], false, static_cast<int>(k)));
  return r;
}

}  // namespace mesh
}  // namespace plaf
