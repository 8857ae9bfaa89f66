// SPDX-License-Identifier: MIT
// libFuzzer harness: surface files (surface3d/read_surface.h, read_surface_file, which picks the
// format by extension). The first input byte picks the extension, byte % 6:
//   0 .stl (ASCII or binary)  1 .obj  2 .off  3 .ply  4 .fmt (Plot3D)  5 .p3d (Plot3D, via
//   read_plot3d directly)
// and the rest of the input is the file.
#include <array>

#include "surface3d/read_surface.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static constexpr std::array<const char*, 6> names = {"surface.stl", "surface.obj", "surface.off",
                                                       "surface.ply", "surface.fmt", "surface.p3d"};
  const std::size_t format = data[0] % names.size();
  const auto path = plaf_fuzz::write_input(names[format], data + 1, size - 1);
  plaf_fuzz::expect_plaf_errors_only([&] {
    if (format == 5)
      (void)plaf::read_plot3d(path);
    else
      (void)plaf::read_surface_file(path);
  });
  return 0;
}
