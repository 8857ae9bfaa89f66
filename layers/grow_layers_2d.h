// SPDX-License-Identifier: MIT
// The 2D front specifics of the prismatic layers of K. J. Fidkowski's PLAF, Sec. II.A-B, Fig. 4
// and 5: curved quadrilaterals of order Q grown layer by layer from the wall loops of a curved
// front. The heights, attenuation, certify-and-shrink, stop rules and the per-layer table are the
// dimension-generic core (layer_core.h); this file adds what is particular to loops:
//  1. normals at every node, linear and high-order: the reference normal carried by the front on
//     the first layer (CurvedFront::normals), the average of the adjacent panel normals afterwards
//     (Sec. II.B);
//  2. corners by the turning angle at linear nodes: on the first layer (the wall's corners; a
//     later front's convex vertex, e.g. a kite's outer vertex, grows along its averaged normal,
//     as in 3D, so fans do not multiply layer after layer) a right turn (convex) beyond the
//     threshold gets a fan of extra normals dividing the corner angle, each pair of adjacent normals
//     bounding one element whose outer edges come from intersecting perpendiculars at the normal
//     end points, high-order nodes uniform in the bilinear quad (Fig. 4); a left turn (concave)
//     gets one merged normal (grow_layers_2d.cpp says why), and a regular neighbour whose top
//     would land within a quarter height of the corner's, or past it, shares the corner's top:
//     the element between them becomes a triangle and leaves the front (no near-duplicate
//     nodes, no folded quadrilateral where the layer is as tall as the corner's elements);
//  3. the high-order nodes of an element are uniform along its normals; a straight element, and
//     any element next to a concave corner, grows a straight top;
//  4. transition triangles join the elements of stopped nodes (isotropic_stop: node) to their
//     moving neighbours;
//  5. the collision test: the new front may cross neither another loop's front nor itself
//     (front_crossings_2d.h), and no new element may turn back along its chord where its base
//     did not (a straight-topped closing layer could not cover it); the heights are shrunk around
//     such elements;
//  6. at order 1, where no high-order node carries the wall's curvature, an element counts as
//     curved (its attenuation need is sag / h) until its chord's sag is at most f_atten times the
//     layer height, so stop_when_linear does not hand the fill a front whose chords miss the
//     curve the metric is measured from by more than the sizes there.
// The guarantee (with close_linear, layer_core.h): every accepted front can be closed, each
// closing cell's top rising until it is certified, so the fill starts from a linear front; where
// a closing layer still fails (a cell invalid at every height), the layers are grown again from
// the wall with at most half as many, down to one (grow_layers).
#pragma once

#include <vector>

#include "layers/layer_core.h"
#include "modules/mesh/curved_front.h"
#include "modules/metric/metric.h"

namespace plaf::layers {

// Curvature attenuation of one new 2D front element (Fig. 5): moves the interior top nodes
// tops[1..Q-1] toward their linear positions a + (k/Q)(b - a) by at most f_atten * heights[k]
// (layer_core.h's attenuate). Returns the largest needed move over its height among the clipped
// nodes (0 when none was clipped, i.e. the element is now linear).
double attenuate(std::vector<Eigen::Vector2d>& tops, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                 const std::vector<double>& heights, double f_atten);

// Grows layers from the wall loops of `front` (loops of kind Wall). The result's mesh holds the
// quadrilaterals (and transition triangles) with the wall loops as tagged boundary lines; its
// fill_front lists the grown loops' outer fronts, then the front's other loops (farfield, ...) by
// their vertices.
LayerResult<2> grow_layers(const CurvedFront<2>& front, const MetricField<2>& metric, const LayerParams& params);

}  // namespace plaf::layers
