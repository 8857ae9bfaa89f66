// SPDX-License-Identifier: MIT
// The fill stage's plugins (modules/pipeline/stages.h), registered by register_plugins():
//   fill:                   the domain between the layers' outer front (or the surface mesh of
//                           bodies without layers) and the farfield, with linear cells
//     type: advancing_front 2D: the metric advancing front (advancing_front_2d.h)   default type
//     max_triangles: <n>    give up (an error) beyond this many triangles   default: 20000000
//     optimize_passes: <0..50>  rounds of metric edge splits, swaps and node smoothing after the front,
//                           the fronts kept (optimize_2d.h; 0: none)        default: 10
//     type: tetgen          3D: TetGen's tetrahedra between the layers' outer front and a
//                           farfield, with the symmetry planes' regions meshed (hybrid_fill3d.h),
//                           the default 3D type; needs a layers section (whose front it closes
//                           linear where a closing layer is valid; the tetrahedra on a triangle
//                           still curved are curved, fill.curved_front_triangles); the layers'
//                           insides are holes
//     max_radius_edge: <0 or >= 1.1>  TetGen's quality bound q (0: off)           default: 1.5
//     max_volume: <>= 0>    TetGen's volume bound a (0: none)                        default: 0
//     farfield:
//       shape: sphere | box                                                          default: sphere
//       radius: <>= 0>      sphere (0: 10 x the layers' bounding-box diagonal)       default: 0
//       size: [a, b, c]     box edge lengths (0: 20 x that diagonal)                 default: [0, 0, 0]
//       center: [x, y, z]   default: the layers' bounding-box centre
//       h: <>= 0>           farfield triangle size (0: the metric's largest size
//                           there, at most a quarter of the radius or half size)     default: 0
//     Sizes: TetGen's m with, at each front node, the mean length of its front edges and, at
//     the farfield, h; TetGen grades between them. Tagged `farfield` (kind farfield); the
//     layers' outer front becomes interior (its order-Q nodes shared by the tetrahedra,
//     assemble_hybrid_3d). With symmetry planes (axis-aligned) the farfield must be a box; its
//     size along a plane's axis is then the bodies' side of the plane (or the slab between two).
#pragma once

namespace plaf::volume {

void register_plugins();

}  // namespace plaf::volume
