// SPDX-License-Identifier: MIT
// Implements the loose quadtree of the 2D advancing front (loose_quadtree.h).
#include "volume/loose_quadtree.h"

#include <algorithm>
#include <cmath>

namespace plaf::volume {

Box segment_box(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return {std::min(a.x(), b.x()), std::min(a.y(), b.y()), std::max(a.x(), b.x()), std::max(a.y(), b.y())};
}

LooseQuadtree::LooseQuadtree(const Box& domain) {
  const double half = 0.5 * std::max(domain.x1 - domain.x0, domain.y1 - domain.y0) * 1.01 + 1e-300;
  cells_.push_back({0.5 * (domain.x0 + domain.x1), 0.5 * (domain.y0 + domain.y1), half, {-1, -1, -1, -1}, {}});
}

void LooseQuadtree::insert(int id, const Box& b) {
  if (static_cast<std::size_t>(id) >= where_.size()) {
    where_.resize(2 * static_cast<std::size_t>(id) + 16, {-1, -1});
    boxes_.resize(where_.size());
  }
  boxes_[id] = b;
  const double ext = std::max(b.x1 - b.x0, b.y1 - b.y0);
  const double cx = 0.5 * (b.x0 + b.x1), cy = 0.5 * (b.y0 + b.y1);
  int c = 0;
  const Cell& root = cells_[0];
  const bool inside = std::abs(cx - root.cx) <= root.half && std::abs(cy - root.cy) <= root.half;
  for (int depth = 0; inside && depth < 60; ++depth) {
    const double h = 0.5 * cells_[c].half;
    if (ext > h) break;
    const int q = (cx >= cells_[c].cx ? 1 : 0) + (cy >= cells_[c].cy ? 2 : 0);
    if (cells_[c].child[q] < 0) {
      const Cell child{cells_[c].cx + (q & 1 ? h : -h), cells_[c].cy + (q & 2 ? h : -h), h, {-1, -1, -1, -1}, {}};
      cells_[c].child[q] = static_cast<int>(cells_.size());
      cells_.push_back(child);
    }
    c = cells_[c].child[q];
  }
  where_[id] = {c, static_cast<int>(cells_[c].items.size())};
  cells_[c].items.push_back(id);
}

void LooseQuadtree::remove(int id) {
  if (static_cast<std::size_t>(id) >= where_.size() || where_[id].first < 0) return;
  auto [c, slot] = where_[id];
  std::vector<int>& items = cells_[c].items;
  items[slot] = items.back();
  where_[items[slot]].second = slot;
  items.pop_back();
  where_[id] = {-1, -1};
}

}  // namespace plaf::volume
