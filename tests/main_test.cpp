// SPDX-License-Identifier: MIT
// The test runner: every library's stage plugins are registered first, as the plaf driver does,
// so configurations parse in the suites as they do in a run. A listener prints the skip marker of
// a case that asked for it and did not fail (tests/published_data.h).
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <iostream>

#include "layers/plugins.h"
#include "modules/pipeline/stages.h"
#include "surface3d/plugins.h"
#include "tests/published_data.h"
#include "volume/plugins.h"

namespace {

struct SkipListener : doctest::IReporter {
  explicit SkipListener(const doctest::ContextOptions&) {}
  void report_query(const doctest::QueryData&) override {}
  void test_run_start() override {}
  void test_run_end(const doctest::TestRunStats&) override {}
  void test_case_start(const doctest::TestCaseData&) override { plaf::test::skip_request().clear(); }
  void test_case_reenter(const doctest::TestCaseData&) override {}
  void test_case_end(const doctest::CurrentTestCaseStats& st) override {
    if (!plaf::test::skip_request().empty() && st.testCaseSuccess)
      std::cout << plaf::test::kSkipMarker << ' ' << plaf::test::skip_request() << std::endl;
    plaf::test::skip_request().clear();
  }
  void test_case_exception(const doctest::TestCaseException&) override {}
  void subcase_start(const doctest::SubcaseSignature&) override {}
  void subcase_end() override {}
  void log_assert(const doctest::AssertData&) override {}
  void log_message(const doctest::MessageData&) override {}
  void test_case_skipped(const doctest::TestCaseData&) override {}
};

}  // namespace

DOCTEST_REGISTER_LISTENER("plaf_skip", 1, SkipListener);

int main(int argc, char** argv) {
  plaf::register_core_plugins();
  plaf::register_surface3d_plugins();
  plaf::layers::register_plugins();
  plaf::volume::register_plugins();
  return doctest::Context(argc, argv).run();
}
