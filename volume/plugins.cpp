// SPDX-License-Identifier: MIT
#include "volume/plugins.h"

#include "modules/base/error.h"
#include "modules/pipeline/run_state.h"
#include "modules/pipeline/stages.h"
#include "volume/advancing_front_2d.h"

namespace plaf::volume {

void register_plugins() {
  static const bool once = [] {
    stage_registry<2>(StageKind::Fill)
        .add("advancing_front", [](const ConfigNode& section) -> Stage<2> {
          AdvancingFrontParams p;
          p.max_triangles = static_cast<std::size_t>(section.get_int("max_triangles", 20000000, 1, 2000000000));
          return [p](RunState<2>& s, StageReport& rep) {
            if (!s.layers) throw MesherError("fill: no front to fill from");
            AdvancingFrontResult fill = advancing_front_fill(s.layers->fill_front, *s.metric, p);
            const AdvancingFrontStats& f = fill.stats;
            rep.add("steps", f.steps);
            rep.add("new_points", f.new_points);
            rep.add("merges", f.merges);
            rep.add("delaunay_apexes", f.delaunay_apexes);
            rep.add("max_front", f.max_front);
            rep.line("fill: " + std::to_string(f.steps) + " steps, " + std::to_string(f.new_points) + " new points, " +
                     std::to_string(f.merges) + " merges, " + std::to_string(f.delaunay_apexes) +
                     " Delaunay fallbacks, largest front " + std::to_string(f.max_front) + " edges");
            s.fill = static_cast<FillResult<2>&&>(std::move(fill));
          };
        });
    return true;
  }();
  (void)once;
}

}  // namespace plaf::volume
