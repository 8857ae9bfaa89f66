// SPDX-License-Identifier: MIT
// The 3D front specifics of the prismatic layers (K. J. Fidkowski's PLAF, Sec. II.E): curved
// prisms of order Q grown layer by layer from the wall triangles of a CurvedFront<3>. The heights,
// attenuation, certify-and-shrink, stop rules, closing layer and the per-layer table are the
// dimension-generic core (layer_core.h); this file adds what is particular to surfaces:
//  1. parts: the connected sets of wall triangles; each keeps its topology from layer to layer
//     (one new node per front node, vertex or high-order), so a layer is one column of Q nodes per
//     front node and one prism per front triangle (three tetrahedra in a first layer with fans);
//  2. normals at every front node (normals_3d.h): the reference normal carried by the front on
//     the first layer at smooth nodes; otherwise the angle-weighted average of the normals of the
//     front's linear sub-triangles around the node (the 2D panel average), and at ridges and
//     corners the normal that sees every face, stretched at concave ones (the 3D concave merge);
//     after the first layer, with smooth_normals (the 3D default, plugins.cpp), the smooth
//     nodes' normals are relaxed toward their neighbours' (two Jacobi passes, halfway each, kept
//     in their symmetry planes and seeing every face around at cos 75 degrees or as well as
//     before): the columns bend with their neighbours instead of converging at concave bends and
//     beside fans (the published AMReX airfoil slab, h0 1e-5 L, q2: 100 % coverage, not 84.2 %);
//  3. symmetry planes: the front's rim (edges used by one triangle) must lie on planes (fitted per
//     connected rim, to 1e-6 of its size); the normals of rim nodes are projected into the plane
//     and their new nodes put on it, so the prisms' side faces there lie on the plane; they are
//     tagged with the rim's tag (kind Symmetry) as quadrilateral boundary facets of order Q;
//  4. the high-order nodes of a new top triangle grow along their normals, leaning at most 0.1 rad
//     from the blend of the triangle's vertex directions (all the way to it next to a convex
//     ridge or corner with a merged normal; a fan's directions and a concave merge's keep
//     theirs), so the pull below (at the paper's f_atten, 0.2) outruns the bend; they are
//     attenuated toward the linear interpolation of
//     its vertex tops (Fig. 5) by at most f_atten times their height; before that pull a node
//     stands off the straight top (its vertex tops' chord plus the base's offset from its chord)
//     by at most the narrowest altitude of its faces over 2 Q^2 (the lean cap: on the sliver
//     strips a fan leaves along a curved ridge the lean turned the curved edges past the
//     sliver's corner); a straight base edge or
//     triangle grows a straight top, and so does every triangle touching a concave node (as next
//     to a 2D concave corner); the column nodes are uniform along base -> top, so every prism is
//     linear along its height;
//  5. collisions: the new front's linear sub-triangles (of triangles and quadrilaterals) may
//     cross neither another part's front nor themselves (exact triangle-triangle tests on
//     AABB-tree candidates, sub-triangles sharing a node skipped, and pairs of faces the layer
//     left in place, every column under them stopped: no stop mends those), nor fold onto
//     themselves along an edge (under kFoldMinDeg on the fill's side) or flatten a chord into a
//     cap (over 180 - kFoldMinDeg), across the limit or to half the base's (front_collisions_3d.h:
//     the fill's tetrahedra there are slivers); heights are halved on the
//     nodes of the failing faces' old faces and their neighbours (a height's scale applies to
//     the vertices, which the high-order nodes then interpolate: a ring of shrunk faces raises no
//     bump on the faces around it);
//  6. fans (first layer; Aubry & Loehner's ridge and corner fans, Sec. II.E leaving them open): a
//     wall edge whose faces meet convexly at more than corner_angle_deg is a fan edge; fan edges
//     chain between corners (3+ fan edges at a node), symmetry planes, closed loops and, with
//     fan_fades (off by default), fades; without it a chain ending elsewhere keeps the merged
//     normal. A fade is a chain's end elsewhere (its ridge fades out, as a trailing edge into a
//     rounded tip): the node keeps its merged normal; toward it the fan narrows by at most
//     fan_angle_deg per edge (its two wedge directions turned toward their bisector) and keeps
//     as many kites as edges to the fade (the arc's 2 k sectors kept, the outer ones closed onto
//     the wedge directions); a sector closed at one end of an edge is two tetrahedra (the closed
//     end's node, the other node and the sector's two tops there; the closed end's node, its top
//     and those two), nodes nearer the fade ranking first in the cut so every quadrilateral
//     there is cut from its closed end; the zone's columns keep their directions in later
//     layers, as a corner's. A chain of one edge that fades keeps the merged normal, and so does
//     a fan edge whose fan opens by under 5 degrees at an end that does not fade or does not
//     turn about it, its arc's axis more than 60 degrees off the edge. Each wedge
//     of faces between fan edges grows along its own normal; between the two wedges of a fan edge
//     k sectors (at most fan_angle_deg each, one k per chain) are the 2D fan's kites (Fig. 4,
//     grow_layers_2d.h): normals n_s dividing the angle equally, the kite (node, P_s, X_s,
//     P_s+1) with P_s one height along n_s and X_s where the perpendiculars at P_s and P_s+1
//     meet; extruded along the ridge each kite is split along node-X_s into two prisms, and its
//     outer edges P_s X_s, X_s P_s+1 sweep quadrilaterals (cut into triangles, below). So the
//     cross section of a ridge
//     fan is the 2D fan, and an extruded section grows the 2D layers at mid-span
//     (tests/layers/extrusion_match_test.cpp). At a corner a flat patch of triangles from the
//     corner's merged normal to every kite edge of its arcs gives tetrahedra (node + patch
//     triangle). Every fan cell is straight-sided. The whole first layer of such a part is
//     tetrahedra: every prism (over a wall triangle, or a kite half) is cut into three by
//     Dompierre et al.'s rule (each quadrilateral face along the diagonal through its vertex of
//     smallest rank: old nodes by local id, then the tops by direction), which cuts a face that
//     two cells share alike and never closes a cycle on a prism; the kites' quadrilaterals join
//     the new front as the two triangles their tetrahedra cut them into. So the front is all
//     triangles after the first layer and every later layer is prisms (a prism layer ending on a
//     quadrilateral could meet neither the next layer's cut nor a tetrahedral fill without
//     pyramids, and a tetrahedral first layer is the one place the cut can start: its bottom is
//     the wall's triangles). Why not prisms at the wall and only the last layer cut (issue 31's
//     proposal): with prisms and tetrahedra alone, a quadrilateral face is shared by two prisms
//     or lies on the boundary, and a prism beside a cut quadrilateral must be cut whole (all
//     three of its quadrilaterals). A kite prism's top is a quadrilateral, so the cell above it is
//     a prism extruded along the ridge again, whose top is one too, up to the outer front; and
//     cutting any layer above cuts its bottom quadrilaterals, so the cut runs down the fan's
//     column to the first layer and along it through every prism. Prisms at the wall therefore
//     need pyramids: on the outer front's quadrilaterals (the fill's side), or in the layer where
//     the fan's columns turn to triangles. A corner's columns keep their
//     direction (radial from the corner) while every face around sees it within 80 degrees;
//     a ridge fan's nodes take the faces' average afterwards, as 2D's do. Fan heights: the
//     smallest metric height over the node's normals (wedge directions, kite normals, a
//     corner's centre; 2D takes the two sides, the same where the metric's normal at the ridge
//     is one side's).
//  7. local stops (layer_core.h, step 3): where a cell cannot be valid even at 1/16 of the
//     metric's height, the vertices of its old face stop (their columns end there, and so do the
//     high-order nodes between stopped vertices); the part's layers from then on are tetrahedra
//     (each prism cut by the rule of step 6, the cut's tetrahedron holding both ends of a stopped
//     column left out), because a prism over a face with a stopped vertex is a pyramid and a
//     prism's quadrilateral can meet only a prism's or be cut alike on both sides. A cell's
//     nodes off the two fronts lift the base's curved triangle by the column heights of the
//     cell's corners, affine over the cell (a stopped column's height is 0), shared by every
//     cell and symmetry facet with the same corners and weights: the cell is the base's triangle
//     sheared up the layer, valid over a regular base at any order and at a stopped column,
//     where the prism's own map collapses (and its lattice, cut into tetrahedra, inverted at Q3
//     wherever the heights varied over a face). Every face of such a layer grows a top from
//     the vertex tops' lift plus the base's offset from its chord, attenuated by at most 0.05 of
//     the height (the paper's 0.2 inverted cut cells at Q3: the pull grows with the level and is
//     of degree Q + 1 in a cut cell); the front straightens slowly until the heights outgrow its
//     sag (a closing layer straightens the rest). The vertices beside a column stopped in an
//     earlier layer (any stop: a failure's, the proximity rule's, isotropic_stop's) grow half
//     their height, so the front slopes into the stop rather than rising beside it as a wall
//     whose cut cells fail (on the published 717 wing they did, and each failure stopped more
//     columns); beyond that ring a vertex's stack rises at most half its distance along the front
//     above an earlier stop's (it grows a quarter height where it stands that high), so the slope
//     holds when the layers grow as tall as the faces are wide. In every layer without fans a
//     column grows at most twice the height of a growing neighbour (the shrinks' rings and the
//     rules above are the only jumps): no cell spans a ring shrunk to the floor and a full one.
//     Elsewhere the part's other columns grow on to the stop rule. A cusp (no direction sees
//     every face around a node) grows along the most normal direction (normals_3d.h) and, where
//     its cells cannot be valid, stops there too: no run ends on a cusp.
//  8. the proximity rule (layer_core.h, step 1; SurfaceFronts::stop_point_room): a ray along
//     each vertex column's front normal to the first wall triangle facing it (its own face's
//     neighbours skipped) and one back to its own wall give the gap (the distance back at most
//     twice the column's stack: a ray grazing a convex ridge meets the body's far side); the allowance, share x the
//     gap x cos/(1 + cos), is graded over the front's edges (at most half the distance more);
//     where the front is concave, a layer may take at most half the distance to its nearest
//     focus (where two neighbouring columns, along the front's angle-weighted normals, meet),
//     graded in the same way (layer_core.h, graded_room, shared with the 2D loops).
//  9. isotropic_stop: node (the 3D default, layers/plugins.cpp): a column whose front point has
//     an isotropic metric stops there, as a local stop does (its layers from then on are
//     tetrahedra around it), having reached its stop rule: the wall law's anisotropy has ended,
//     its boundary layer is complete.
#pragma once

#include "layers/layer_core.h"
#include "modules/mesh/curved_front.h"
#include "modules/metric/metric.h"

namespace plaf::layers {

// Grows layers from the wall triangles of `front` (tags of kind Wall). The result's mesh holds the
// prisms (cells[0]) and the tetrahedra of first layers with fans (cells[1]), the wall triangles
// as tagged boundary facets and the symmetry facets (quadrilaterals of prisms, triangles of
// tetrahedra); its outer front is the last layer's top (triangles, tags as the wall's), its
// fill_front the outer front's linear triangles (tag "layers_outer") followed by the non-wall
// triangles of the front. counts gives the classes of the first layer's front nodes
// (normals_3d.h), the concave merges and the fans (ridge_fans.edges, ridge_fans.sectors,
// corner_fans).
LayerResult<3> grow_layers(const CurvedFront<3>& front, const MetricField<3>& metric, const LayerParams& params);

}  // namespace plaf::layers
