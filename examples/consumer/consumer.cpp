// SPDX-License-Identifier: MIT
// plaf as a library, from outside the project: curved layers on a circle through the API (the
// airfoils geometry with a circle body, the paper's wall law, the order-3 surface mesh, ten
// layers), every cell certified, the mesh written as MSH 4.1 and read back.
//
//   plaf_consumer [OUT.msh]    exit 0 when the ten layers are valid and the file reads back
#include <iostream>
#include <string>
#include <vector>

#include "layers/grow_layers_2d.h"
#include "modules/base/error.h"
#include "modules/geometry/geometry2d.h"
#include "modules/io/msh_io.h"
#include "modules/mesh/curve_mesh.h"
#include "modules/mesh/quality.h"
#include "modules/metric/wall_metric.h"

int main(int argc, char** argv) {
  try {
    plaf::AirfoilsParams body;
    plaf::BodyParams circle;
    circle.name = "wall";
    circle.circle = true;
    circle.circle_radius = 0.5;
    body.bodies.push_back(circle);
    const plaf::Geometry2D geometry = plaf::build_airfoils_geometry(body);

    plaf::WallLawParams law;
    law.h0 = 1e-3;
    law.growth = 1.2;
    law.h_max = 10;
    law.h_wall_max = 0.1;
    const plaf::WallPowerLawField metric({geometry.loops[0].loop}, law);

    const plaf::CurvedFront<2> front = plaf::mesh_curves(geometry, metric, 3);
    plaf::layers::LayerParams params;
    params.max_layers = 10;
    const plaf::LayerResult<2> layers = plaf::layers::grow_layers(front, metric, params);
    const plaf::QualityReport quality = plaf::assess_quality<2>(layers.mesh, &metric, plaf::QualityOptions{});

    const std::string path = argc > 1 ? argv[1] : "consumer.msh";
    plaf::write_msh41<2>(layers.mesh, path);
    const plaf::MshMesh back = plaf::read_msh41(path);
    std::cout << "plaf_consumer: " << layers.layers.size() << " layers, " << quality.cells_total << " cells, "
              << quality.cells_invalid << " invalid, min scaled Jacobian " << quality.scaled_jacobian_min
              << ", front linear after layer " << layers.linear_after << ", " << path << " read back with "
              << back.mesh2.num_cells() << " cells\n";
    const bool ok = layers.layers.size() == 10 && quality.cells_invalid == 0 && quality.cells_total > 0 &&
                    back.mesh2.num_cells() == quality.cells_total;
    return ok ? 0 : 1;
  } catch (const plaf::Error& e) {
    std::cerr << "plaf_consumer: error: " << e.what() << '\n';
    return 1;
  }
}
