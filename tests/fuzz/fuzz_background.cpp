// SPDX-License-Identifier: MIT
// libFuzzer harness: background metric meshes (modules/metric/background_metric.h,
// read_background_msh and read_background_meshb, 2D and 3D). The first input byte picks the
// reader, byte % 4:
//   0 read_background_msh<2>   1 read_background_msh<3>   (the rest is the .msh file)
//   2 read_background_meshb<2> 3 read_background_meshb<3> (the rest is the .mesh file, a NUL
//     byte, then the .sol file; without a NUL the .sol file is empty)
// A mesh that reads is then made into a BackgroundMetricField (check_background_mesh, the
// point-location tree) and evaluated at its first node, as the metric stage does with it.
#include <algorithm>

#include "modules/metric/background_metric.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

template <int Dim>
void use(plaf::BackgroundMesh<Dim> mesh) {
  if (mesh.nodes.empty()) return;
  const auto x = mesh.nodes.front();
  const plaf::BackgroundMetricField<Dim> field(std::move(mesh), plaf::MetricMean::LogEuclidean);
  (void)field.evaluate(x);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const int mode = data[0] % 4;
  const std::uint8_t* body = data + 1;
  const std::size_t n = size - 1;
  plaf_fuzz::expect_plaf_errors_only([&] {
    if (mode < 2) {
      const auto path = plaf_fuzz::write_input("background.msh", body, n);
      if (mode == 0)
        use<2>(plaf::read_background_msh<2>(path));
      else
        use<3>(plaf::read_background_msh<3>(path));
      return;
    }
    const std::uint8_t* nul = std::find(body, body + n, std::uint8_t{0});
    const std::size_t mesh_size = static_cast<std::size_t>(nul - body);
    const std::size_t sol_offset = nul == body + n ? n : mesh_size + 1;
    const auto mesh = plaf_fuzz::write_input("background.mesh", body, mesh_size);
    const auto sol = plaf_fuzz::write_input("background.sol", body + sol_offset, n - sol_offset);
    if (mode == 2)
      use<2>(plaf::read_background_meshb<2>(mesh, sol));
    else
      use<3>(plaf::read_background_meshb<3>(mesh, sol));
  });
  return 0;
}
