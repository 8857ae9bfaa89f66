// SPDX-License-Identifier: MIT
#include "modules/mesh/layer_mesh.h"

namespace plaf {
inline namespace mesh {

LinearLoop linear_loop(const CurvedFront<2>& front, const FrontLoop& l, bool layered, int source_loop) {
  LinearLoop out{l.tag, l.kind, layered, source_loop, {}};
  for (std::size_t e = 0; e < l.size(); ++e) out.nodes.push_back(front.element(l, e)[0]);
  return out;
}

LayerResult<2> unlayered(const CurvedFront<2>& front) {
  LayerResult<2> r;
  r.mesh.nodes = front.nodes;
  r.outer = front;
  r.fill_front.nodes = front.nodes;
  for (std::size_t k = 0; k < front.loops.size(); ++k)
    r.fill_front.loops.push_back(linear_loop(front, front.loops[k], false, static_cast<int>(k)));
  return r;
}

}  // namespace mesh
}  // namespace plaf
