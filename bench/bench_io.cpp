// SPDX-License-Identifier: MIT
// The writers' own cost, apart from meshing: reads one mesh (MSH 4.1/2.2 or CGNS) and writes it in
// every format and encoding, best of three, into a folder (give a RAM folder such as /dev/shm to
// time the writers rather than the disk), then reads each file back with plaf's reader where
// there is one. Run by hand (bench/bench_write.py calls it after meshing the case once):
//   bench_io MESH DIR
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

#include "modules/base/error.h"
#include "modules/io/cgns_io.h"
#include "modules/io/msh_io.h"
#include "modules/io/vtu_writer.h"

namespace fs = std::filesystem;
using namespace plaf;

namespace {

double best_of_3(const std::function<void()>& f) {
  double best = 1e300;
  for (int i = 0; i < 3; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

template <int Dim>
void run(const HybridMesh<Dim>& mesh, const fs::path& dir) {
  struct Case {
    const char* label;
    const char* file;
    std::function<void(const fs::path&)> write;
    bool readable;
  };
  const Case cases[] = {
      {"msh 4.1 ASCII", "a.msh", [&](const fs::path& p) { write_msh41(mesh, p, MshEncoding::ascii); }, true},
      {"msh 4.1 binary", "b.msh", [&](const fs::path& p) { write_msh41(mesh, p, MshEncoding::binary); }, true},
      {"msh 2.2 ASCII", "a22.msh", [&](const fs::path& p) { write_msh22(mesh, p, MshEncoding::ascii); }, true},
      {"msh 2.2 binary", "b22.msh", [&](const fs::path& p) { write_msh22(mesh, p, MshEncoding::binary); }, true},
      {"vtu ASCII", "a.vtu", [&](const fs::path& p) { write_vtu(mesh, p, {}, VtuEncoding::ascii); }, false},
      {"vtu binary (zlib)", "b.vtu", [&](const fs::path& p) { write_vtu(mesh, p, {}, VtuEncoding::binary); }, false},
      {"cgns (HDF5)", "c.cgns", [&](const fs::path& p) { write_cgns(mesh, p); }, true},
  };
  std::printf("| format | MB | write s | MB/s | read s |\n| --- | --- | --- | --- | --- |\n");
  for (const Case& c : cases) {
    const fs::path p = dir / c.file;
    const double w = best_of_3([&] { c.write(p); });
    const double mb = static_cast<double>(fs::file_size(p)) / 1e6;
    double r = -1;
    if (c.readable) r = best_of_3([&] { fs::path(p).extension() == ".cgns" ? (void)read_cgns(p) : (void)read_msh41(p); });
    std::printf("| %s | %.1f | %.3f | %.0f | %s |\n", c.label, mb, w, mb / w, r < 0 ? "-" : std::to_string(r).c_str());
    std::fflush(stdout);
    fs::remove(p);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bench_io MESH DIR\n");
    return 1;
  }
  try {
    const fs::path in = argv[1];
    const MshMesh m = in.extension() == ".cgns" ? read_cgns(in) : read_msh41(in);
    fs::create_directories(argv[2]);
    std::printf("%s: %zu nodes, %zu cells\n", argv[1], m.dim == 2 ? m.mesh2.nodes.size() : m.mesh3.nodes.size(),
                m.dim == 2 ? m.mesh2.num_cells() : m.mesh3.num_cells());
    if (m.dim == 2)
      run(m.mesh2, argv[2]);
    else
      run(m.mesh3, argv[2]);
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_io: %s\n", e.what());
    return 1;
  }
  return 0;
}
