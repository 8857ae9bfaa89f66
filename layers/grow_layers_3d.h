// SPDX-License-Identifier: MIT
// The 3D front specifics of the prismatic layers (K. J. Fidkowski's PLAF, Sec. II.E): curved
// prisms of order Q grown layer by layer from the wall triangles of a CurvedFront<3>. The heights,
// attenuation, certify-and-shrink, stop rules, closing layer and the per-layer table are the
// dimension-generic core (layer_core.h); this file adds what is particular to surfaces:
//  1. parts: the connected sets of wall triangles; each keeps its topology from layer to layer
//     (one new node per front node, vertex or high-order), so a layer is one column of Q nodes per
//     front node and one prism per front triangle;
//  2. normals at every front node (normals_3d.h): the reference normal carried by the front on
//     the first layer at smooth nodes; otherwise the angle-weighted average of the normals of the
//     front's linear sub-triangles around the node (the 2D panel average), and at ridges and
//     corners the normal that sees every face, stretched at concave ones (the 3D concave merge);
//  3. symmetry planes: the front's rim (edges used by one triangle) must lie on planes (fitted per
//     connected rim, to 1e-6 of its size); the normals of rim nodes are projected into the plane
//     and their new nodes put on it, so the prisms' side faces there lie on the plane; they are
//     tagged with the rim's tag (kind Symmetry) as quadrilateral boundary facets of order Q;
//  4. the high-order nodes of a new top triangle are attenuated toward the linear interpolation of
//     its vertex tops (Fig. 5) by at most f_atten times their height; a straight base edge or
//     triangle grows a straight top, and so does every triangle touching a concave node (as next
//     to a 2D concave corner); the column nodes are uniform along base -> top, so every prism is
//     linear along its height;
//  5. collisions: the new front's linear sub-triangles may cross neither another part's front nor
//     themselves (exact triangle-triangle tests on AABB-tree candidates, sub-triangles sharing a
//     node skipped); heights are halved on the failing triangles and their neighbours.
// Not yet: fans of extra normals at convex ridges and corners (convex features get the merged
// normal), and isotropic_stop: node (stopped nodes would need pyramids or tetrahedra; the plugin
// refuses it in 3D).
#pragma once

#include "layers/layer_core.h"
#include "modules/mesh/curved_front.h"
#include "modules/metric/metric.h"

namespace plaf::layers {

// Grows layers from the wall triangles of `front` (tags of kind Wall). The result's mesh holds the
// prisms, the wall triangles as tagged boundary facets and the symmetry quadrilaterals; its outer
// front is the last layer's top (tags as the wall's), its fill_front the outer front's linear
// triangles (tag "layers_outer") followed by the non-wall triangles of the front. counts gives
// the classes of the first layer's front nodes (normals_3d.h) and the concave merges.
LayerResult<3> grow_layers(const CurvedFront<3>& front, const MetricField<3>& metric, const LayerParams& params);

}  // namespace plaf::layers
