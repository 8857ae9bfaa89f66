// SPDX-License-Identifier: MIT
// libFuzzer harness: YAML run configurations (modules/pipeline/run_config.h, load_run_config,
// and modules/pipeline/config.h, ConfigNode::load_string). The whole input is the YAML text.
//
// Validation only: load_run_config parses and checks every section through the registered stage
// plugins but reads no file the config names (contours, surfaces and background meshes are read
// when the stages run, which this harness never does); file keys resolve relative to the
// temporary directory and are never opened.
//
// Plugins: every stage's, as the plaf CLI registers them.
#include "layers/plugins.h"
#include "modules/pipeline/config.h"
#include "modules/pipeline/run_config.h"
#include "modules/pipeline/stages.h"
#include "surface3d/plugins.h"
#include "tests/fuzz/fuzz_support.h"
#include "volume/plugins.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  plaf::register_core_plugins();
  plaf::register_surface3d_plugins();
  plaf::layers::register_plugins();
  plaf::volume::register_plugins();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = plaf_fuzz::write_input("fuzz_run.yaml", data, size);
  plaf_fuzz::expect_plaf_errors_only([&] { (void)plaf::load_run_config(path); });
  plaf_fuzz::expect_plaf_errors_only([&] {
    const std::string text(reinterpret_cast<const char*>(data), size);
    (void)plaf::ConfigNode::load_string(text, "fuzz_string.yaml");
  });
  return 0;
}
