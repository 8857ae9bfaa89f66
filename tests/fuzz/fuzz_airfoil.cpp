// SPDX-License-Identifier: MIT
// libFuzzer harness: airfoil / body contour files (modules/io/airfoil_io.h, read_body_contour,
// which also runs the simple-loop check). The whole input is the contour file.
#include "modules/io/airfoil_io.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = plaf_fuzz::write_input("contour.dat", data, size);
  plaf_fuzz::expect_plaf_errors_only([&] { (void)plaf::read_body_contour(path); });
  return 0;
}
