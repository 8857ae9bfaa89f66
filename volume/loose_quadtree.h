// SPDX-License-Identifier: MIT
// The search structure of the 2D advancing front (advancing_front_2d.h): a loose quadtree of
// axis-aligned boxes (the front edges' boxes), updated as the front moves. An item lives in the
// deepest cell whose half-size is at least its extent and which contains its centre; a cell's
// loose box (twice its size) then contains the item. Items of any size mix well: an item is found
// by visiting O(depth) cells plus those near the query. Internal to volume/.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace plaf::volume {

struct Box {
  double x0, y0, x1, y1;
  bool intersects(const Box& o) const { return x0 <= o.x1 && o.x0 <= x1 && y0 <= o.y1 && o.y0 <= y1; }
};

Box segment_box(const Eigen::Vector2d& a, const Eigen::Vector2d& b);

class LooseQuadtree {
 public:
  // The root cell covers the domain (items outside it are kept at the root).
  explicit LooseQuadtree(const Box& domain);

  // Ids are small non-negative integers (the storage grows to the largest).
  void insert(int id, const Box& b);
  // Does nothing for an id that is not in the tree.
  void remove(int id);

  // Calls f(id) for every item whose box intersects q.
  template <class F>
  void query(const Box& q, F&& f) const {
    stack_.clear();
    stack_.push_back(0);
    while (!stack_.empty()) {
      const int c = stack_.back();
      stack_.pop_back();
      const Cell& cell = cells_[c];
      // The root holds items outside its box too: never skip it.
      if (c != 0) {
        const double l = 2 * cell.half;
        if (!Box{cell.cx - l, cell.cy - l, cell.cx + l, cell.cy + l}.intersects(q)) continue;
      }
      for (int id : cell.items)
        if (boxes_[id].intersects(q)) f(id);
      for (int ch : cell.child)
        if (ch >= 0) stack_.push_back(ch);
    }
  }

 private:
  struct Cell {
    double cx, cy, half;
    std::array<int, 4> child;
    std::vector<int> items;
  };
  std::vector<Cell> cells_;
  std::vector<Box> boxes_;
  std::vector<std::pair<int, int>> where_;  // id -> (cell, slot); cell -1: absent
  mutable std::vector<int> stack_;
};

}  // namespace plaf::volume
