// SPDX-License-Identifier: MIT
// The front of the 2D advancing front (advancing_front_2d.h) as a set of occurrences, and the
// mesh it leaves behind. Internal to volume/.
//
// An occurrence is one appearance of a node on a front loop, with its previous and next
// occurrence; it stands for the front edge from its node to the next one. A node appears more
// than once where fronts touch after a merge (a pinch); the free angle of each occurrence is the
// counter-clockwise sector from its next edge to its previous edge. Every change of the front is
// one operation, advance(o, c): the triangle (a, b, c) on the front edge a -> b of occurrence o,
// with c a new point or an existing front node; a -> b becomes a -> c -> b, and zero-area spikes
// (x -> y -> x) are removed, which is how loops close, merge and split.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "volume/advancing_front_2d.h"
#include "volume/loose_quadtree.h"

namespace plaf::volume {

// M^(1/2) and M^(-1/2) of a node's metric: the map to the space where the metric is Euclidean.
struct NodeMetric {
  Eigen::Matrix2d f;
  Eigen::Matrix2d f_inv;
};

NodeMetric node_metric(const Metric<2>& m);

double cross(const Eigen::Vector2d& u, const Eigen::Vector2d& w);

// Is the direction q - v strictly inside the counter-clockwise sector from n - v to p - v?
// (Exact predicates; a straight angle is the half plane, n and p on one ray the full turn but
// that ray.)
bool in_sector(const Eigen::Vector2d& v, const Eigen::Vector2d& n, const Eigen::Vector2d& p, const Eigen::Vector2d& q);

// A triangle's third corner: an existing front node (occ >= 0) or a new point.
struct Apex {
  NodeId node = -1;
  int occ = -1;
  Eigen::Vector2d point;
};

class OccurrenceFront {
 public:
  // The occurrences of front's loops, its node ids kept. Throws MesherError when a node id is out
  // of range or not finite, there are no loops, a loop has fewer than 3 nodes, a node appears
  // twice, the loops enclose no region, cross or touch, or a loop's orientation does not match
  // its nesting.
  OccurrenceFront(const LinearFront<2>& front, const MetricField<2>& metric);

  const MetricField<2>& metric() const { return metric_; }
  const Eigen::Vector2d& pt(NodeId v) const { return nodes_[v]; }
  const Eigen::Vector2d& opt(int o) const { return nodes_[occ_[o].node]; }
  NodeId nd(int o) const { return occ_[o].node; }
  int next(int o) const { return occ_[o].next; }
  int prev(int o) const { return occ_[o].prev; }
  bool alive(int o) const { return occ_[o].alive; }
  int num_occurrences() const { return static_cast<int>(occ_.size()); }
  std::size_t num_triangles() const { return triangles_.size(); }
  // The largest extent of the front's bounding box.
  double root_extent() const { return root_extent_; }

  // The metric of node v, evaluated once.
  const NodeMetric& nm(NodeId v) const;

  // Calls f(o) for every live occurrence o whose edge o -> next(o) has a box meeting b.
  template <class F>
  void edges_near(const Box& b, F&& f) const {
    index_.query(b, std::forward<F>(f));
  }
  // The occurrence of node v whose free angle contains the direction to q, or -1.
  int occurrence_towards(NodeId v, const Eigen::Vector2d& q) const;
  // Front nodes near x (within `radius` in the metric m), nearest first, but a and b.
  std::vector<std::pair<double, NodeId>> nodes_near(const Eigen::Vector2d& x, double radius, const NodeMetric& m,
                                                    NodeId a, NodeId b) const;

  // Emits (a, b, c) on the front edge o: a -> b and updates the front. Returns the occurrences
  // whose angle changed (some may have died).
  const std::vector<int>& advance(int o, const Apex& c);

  // The mesh so far (nodes and triangles) with the counts new_points and max_front.
  AdvancingFrontResult take_result();

 private:
  struct Occ {
    NodeId node;
    int prev, next;
    int same;  // the next occurrence of the same node, -1 at the end
    bool alive;
  };

  NodeId add_node(const Eigen::Vector2d& p);
  int add_occ(NodeId v, int prev, int next);
  void kill(int o);
  void reindex(int o);
  void remove_spikes(int x);
  void build(const LinearFront<2>& front);
  void check_crossings() const;
  void check_nesting(const LinearFront<2>& front) const;

  const MetricField<2>& metric_;
  LooseQuadtree index_;
  double root_extent_ = 0;
  std::vector<Eigen::Vector2d> nodes_;
  std::vector<std::array<NodeId, 3>> triangles_;
  mutable std::vector<NodeMetric> metrics_;
  mutable std::vector<std::uint8_t> has_metric_;
  std::vector<int> head_;  // first occurrence of each node, -1 if none
  std::vector<Occ> occ_;
  std::size_t front_edges_ = 0;
  std::size_t new_points_ = 0;
  std::size_t max_front_ = 0;
  std::vector<int> touched_;
};

}  // namespace plaf::volume
