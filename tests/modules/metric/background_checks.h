// SPDX-License-Identifier: MIT
// What the 2D and 3D background-metric suites (background_metric_test.cpp,
// background_metric_3d_test.cpp) share: point location against brute force, meshes read alike,
// fixture editing, the InputError a reader throws in its "path:line: reason" form, and the
// truncation and corruption sweep over good files. Header-only.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/metric/background_metric.h"
#include "tests/test_support.h"

namespace plaf::test {

// Where brute force puts the points (the largest smallest barycentric coordinate over all
// simplices): on a facet up to round-off, inside, outside.
struct LocateCounts {
  int on_facets = 0, inside = 0, outside = 0;
};

// field.locate agrees with brute force at every point: a point inside or on a facet up to
// round-off is found, a point clearly outside is not, and a simplex found holds the point up to
// a relative tolerance.
template <int Dim>
void check_locate(const BackgroundMetricField<Dim>& field,
                  const std::vector<typename BackgroundMesh<Dim>::Point>& points, LocateCounts& counts) {
  const auto num_simplices = static_cast<int>(field.mesh().simplices.size());
  for (const auto& x : points) {
    double best = -std::numeric_limits<double>::infinity();
    for (int s = 0; s < num_simplices; ++s) best = std::max(best, field.barycentric(s, x).minCoeff());
    const int s = field.locate(x);
    INFO("x = ", x.transpose(), ", best = ", best, ", located = ", s);
    if (best >= -1e-13) CHECK(s >= 0);
    if (best < -1e-9) CHECK(s == -1);
    if (s >= 0) CHECK(field.barycentric(s, x).minCoeff() >= -1e-9);
    if (std::abs(best) < 1e-12)
      ++counts.on_facets;
    else if (best > 0)
      ++counts.inside;
    else
      ++counts.outside;
  }
}

// Every mesh read equals `mesh` bit for bit (nodes, simplices, metrics), and the fields of all
// evaluate alike at the points, by both means.
template <int Dim>
void check_read_alike(const BackgroundMesh<Dim>& mesh, const std::vector<BackgroundMesh<Dim>>& read,
                      const std::vector<typename BackgroundMesh<Dim>::Point>& points) {
  for (const BackgroundMesh<Dim>& r : read) {
    REQUIRE(r.nodes.size() == mesh.nodes.size());
    REQUIRE(r.simplices == mesh.simplices);
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
      CHECK(r.nodes[i] == mesh.nodes[i]);
      CHECK(r.metrics[i].matrix() == mesh.metrics[i].matrix());
    }
  }
  for (MetricMean mean : {MetricMean::LogEuclidean, MetricMean::AffineInvariant}) {
    const BackgroundMetricField<Dim> reference(mesh, mean);
    std::vector<std::unique_ptr<BackgroundMetricField<Dim>>> fields;  // the field is neither copied nor moved
    for (const BackgroundMesh<Dim>& r : read) fields.push_back(std::make_unique<BackgroundMetricField<Dim>>(r, mean));
    for (const auto& x : points) {
      const auto expected = reference.evaluate(x).matrix();
      for (const auto& field : fields) CHECK(field->evaluate(x).matrix() == expected);
    }
  }
}

// s with its first `from` replaced by `to` (the fixture must hold `from`).
inline std::string replace(std::string s, const std::string& from, const std::string& to) {
  const std::size_t at = s.find(from);
  REQUIRE_MESSAGE(at != std::string::npos, "test fixture lacks: ", from);
  return s.replace(at, from.size(), to);
}

// The InputError message of read(), or "" if it throws none.
inline std::string input_error(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// read() throws an InputError "named:line: ..." holding fragment.
inline void check_input_error(const std::function<void()>& read, const std::filesystem::path& named, int line,
                              const std::string& fragment) {
  const std::string message = input_error(read);
  REQUIRE_MESSAGE(!message.empty(), "no InputError");
  CHECK_MESSAGE(message.find(fragment) != std::string::npos, message);
  CHECK_MESSAGE(message.rfind(named.string() + ":" + std::to_string(line) + ": ", 0) == 0, message);
}

// A file a reader reads: its good text, where the sweep writes the bad ones, the reader, and how
// long a prefix must be to be complete (shorter prefixes must be refused).
struct FuzzedFile {
  std::string good;
  std::filesystem::path target;
  std::function<void()> read;
  std::size_t complete;
};

// Every truncation before `complete` throws InputError, and 200 random corruptions of 1 to 4
// bytes each parse or throw InputError (any other exception fails the test case).
inline void check_truncations_and_corruptions(const std::vector<FuzzedFile>& files, unsigned seed) {
  auto refused = [](const std::function<void()>& read) {
    try {
      read();
      return 0;
    } catch (const InputError&) {
      return 1;
    }
  };
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  for (const FuzzedFile& f : files) {
    INFO(f.target.string());
    int rejected = 0, prefixes = 0;
    for (std::size_t n = 0; n < f.complete; ++n, ++prefixes) {
      write_text(f.target, f.good.substr(0, n));
      rejected += refused(f.read);
    }
    CHECK(rejected == prefixes);
    std::uniform_int_distribution<std::size_t> pos(0, f.good.size() - 1);
    for (int trial = 0; trial < 200; ++trial) {
      std::string text = f.good;
      for (int k = 0; k < 1 + trial % 4; ++k) text[pos(rng)] = static_cast<char>(byte(rng));
      write_text(f.target, text);
      refused(f.read);
    }
  }
}

// The sweep over good.msh and the pair good.mesh / good.sol in dir, read by read_msh(path) and
// read_meshb(mesh, sol): every prefix that stops before the final $EndNodeData or End is
// incomplete.
inline void check_background_files_fuzz(
    const TempDir& dir, const std::function<void(const std::filesystem::path&)>& read_msh,
    const std::function<void(const std::filesystem::path&, const std::filesystem::path&)>& read_meshb) {
  const std::filesystem::path msh = dir / "bad.msh", mesh = dir / "bad.mesh", sol = dir / "bad.sol";
  const std::string msh_text = read_text(dir / "good.msh"), mesh_text = read_text(dir / "good.mesh"),
                    sol_text = read_text(dir / "good.sol");
  check_truncations_and_corruptions(
      {{msh_text, msh, [&] { read_msh(msh); }, msh_text.size() - 1},
       {mesh_text, mesh, [&] { read_meshb(mesh, dir / "good.sol"); }, mesh_text.rfind("End") + 3},
       {sol_text, sol, [&] { read_meshb(dir / "good.mesh", sol); }, sol_text.rfind("End") + 3}},
      13);
}

}  // namespace plaf::test
