// SPDX-License-Identifier: MIT
// The range of coordinates every reader accepts (airfoil contours, surface files, MSH and .mesh
// meshes): beyond it, bounding boxes, squared distances and the sizes of a mesh lose their
// meaning in double precision (1e12 leaves 1e-4 of resolution; (1e12)^2 is far from overflow,
// while coordinates near 1e308 overflow a bounding box's extent to inf).
#pragma once

namespace plaf {
inline namespace base {

inline constexpr double kMaxCoordinate = 1e12;

}  // namespace base
}  // namespace plaf
