// SPDX-License-Identifier: MIT
// The test runner: every library's stage plugins are registered first, as the plaf driver does,
// so configurations parse in the suites as they do in a run.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include "layers/plugins.h"
#include "modules/pipeline/stages.h"
#include "surface3d/plugins.h"
#include "volume/plugins.h"

int main(int argc, char** argv) {
  plaf::register_core_plugins();
  plaf::register_surface3d_plugins();
  plaf::layers::register_plugins();
  plaf::volume::register_plugins();
  return doctest::Context(argc, argv).run();
}
