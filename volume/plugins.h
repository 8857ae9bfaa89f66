// SPDX-License-Identifier: MIT
// The fill stage's plugins (modules/pipeline/stages.h), registered by register_plugins():
// `advancing_front` (2D: the metric advancing front, advancing_front_2d.h, then its metric
// optimisation, optimize_2d.h) and `tetgen` (3D: TetGen's tetrahedra between the layers' outer
// front and a farfield sphere or box, the symmetry planes' regions meshed, hybrid_fill3d.h; it
// needs a layers section, whose front it closes linear where a closing layer is valid; the
// tetrahedra on a triangle still curved are curved, fill.curved_front_triangles; the layers'
// insides are holes). Their keys, types, defaults and descriptions: `plaf keys fill`
// (docs/config.md; the lines in apps/key_notes.cpp).
// TetGen's sizes: its m with, at each front node, the mean length of its front edges and, at the
// farfield, fill.farfield.h; TetGen grades between them. The farfield is tagged `farfield` (kind
// farfield); the layers' outer front becomes interior (its order-Q nodes shared by the
// tetrahedra, assemble_hybrid_3d). With symmetry planes (axis-aligned) the farfield must be a
// box; its size along a plane's axis is then the bodies' side of the plane (or the slab between
// two).
#pragma once

namespace plaf::volume {

void register_plugins();

}  // namespace plaf::volume
