// SPDX-License-Identifier: MIT
// The 2D layers' collision test (front_crossings_2d.h).
#include "layers/front_crossings_2d.h"

#include <algorithm>

#include "modules/geometry/predicates.h"

namespace plaf::layers {

void append_polyline(const FrontLoop& l, const std::vector<Eigen::Vector2d>& x, int q, bool mine,
                     std::vector<FrontSegment>& out) {
  std::size_t index = 0;
  for (std::size_t e = 0; e < l.size(); ++e) {
    const NodeId* el = l.elements.data() + e * static_cast<std::size_t>(q + 1);
    NodeId prev = el[0];
    for (int k = 1; k <= q; ++k) {
      const NodeId next = k < q ? el[1 + k] : el[1];
      out.push_back({x[prev], x[next], e, index++, mine});
      prev = next;
    }
  }
}

std::vector<std::size_t> front_crossings(std::vector<FrontSegment> segs, std::size_t mine_count) {
  std::sort(segs.begin(), segs.end(), [](const FrontSegment& a, const FrontSegment& b) {
    return std::min(a.a.x(), a.b.x()) < std::min(b.a.x(), b.b.x());
  });
  std::vector<std::size_t> hits;
  std::vector<const FrontSegment*> active;
  for (const FrontSegment& s : segs) {
    const double x0 = std::min(s.a.x(), s.b.x());
    std::erase_if(active, [&](const FrontSegment* t) { return std::max(t->a.x(), t->b.x()) < x0; });
    for (const FrontSegment* t : active) {
      if (!s.mine && !t->mine) continue;
      if (s.mine && t->mine) {
        const std::size_t d = s.index > t->index ? s.index - t->index : t->index - s.index;
        if (d <= 1 || d + 1 >= mine_count) continue;  // neighbours share a node
      }
      if (std::max(s.a.y(), s.b.y()) < std::min(t->a.y(), t->b.y()) ||
          std::max(t->a.y(), t->b.y()) < std::min(s.a.y(), s.b.y()))
        continue;
      if (segments_cross_properly(s.a, s.b, t->a, t->b)) {
        if (s.mine) hits.push_back(s.element);
        if (t->mine) hits.push_back(t->element);
      }
    }
    active.push_back(&s);
  }
  std::sort(hits.begin(), hits.end());
  hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
  return hits;
}

}  // namespace plaf::layers
