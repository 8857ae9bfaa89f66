// SPDX-License-Identifier: MIT
// libFuzzer harness: Gmsh MSH 4.1 ASCII meshes (modules/io/msh_io.h, read_msh41). The whole
// input is the .msh file.
#include "modules/io/msh_io.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = plaf_fuzz::write_input("mesh.msh", data, size);
  plaf_fuzz::expect_plaf_errors_only([&] { (void)plaf::read_msh41(path); });
  return 0;
}
