// SPDX-License-Identifier: MIT
// OutputSet (modules/io/output_set.h): a run's files as one set. A writer that fails half-way
// (the set destroyed before commit, as when an exception unwinds the run) leaves none of the files
// it staged and replaces none of an earlier run's; commit moves them in together.
#include <doctest/doctest.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "modules/io/atomic_file.h"
#include "modules/io/output_set.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using plaf::test::read_text;
using plaf::test::TempDir;
using plaf::test::write_text;

namespace {

void stage(const plaf::OutputSet& set, const std::string& suffix, const std::string& text) {
  plaf::AtomicFile f(set.staged_base().string() + suffix);
  f.write(text);
  f.commit();
}

}  // namespace

TEST_CASE("output set: a writer failing half-way leaves none of the set's files and keeps an earlier run's") {
  const TempDir d("output_set");
  const fs::path out = d / "out";
  fs::create_directories(out);
  write_text(out / "case.msh", "the earlier run's mesh\n");
  try {
    plaf::OutputSet set(out, "case");
    stage(set, ".msh", "the new mesh\n");
    stage(set, ".vtu", "the new vtu\n");
    throw std::runtime_error("the third writer fails");
  } catch (const std::runtime_error&) {
  }
  CHECK(read_text(out / "case.msh") == "the earlier run's mesh\n");
  CHECK(plaf::test::count_files(out) == 1);
  for (const auto& e : fs::directory_iterator(out)) CHECK(e.path().filename() == "case.msh");  // no staging folder left
  {
    plaf::OutputSet set(out, "case");
    stage(set, ".msh", "the new mesh\n");
    stage(set, ".vtu", "the new vtu\n");
    set.commit();
  }
  CHECK(read_text(out / "case.msh") == "the new mesh\n");
  CHECK(read_text(out / "case.vtu") == "the new vtu\n");
  CHECK(plaf::test::count_files(out) == 2);
}
