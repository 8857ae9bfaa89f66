// SPDX-License-Identifier: MIT
// Contiguous chunks of an index range on worker threads: the certification of every cell of a
// layer and of the quality stage (one JacobianCertifier per worker). Results are written by
// index, so they do not depend on the number of workers.
//
// Workers: the CPUs the process may use (at most 16), or PLAF_THREADS when set (1: all on the caller's
// thread). A range of one chunk runs on the caller's thread alone.
#pragma once

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace plaf {
inline namespace base {

inline unsigned worker_threads() {
  if (const char* env = std::getenv("PLAF_THREADS")) {
    const long n = std::strtol(env, nullptr, 10);
    if (n >= 1) return static_cast<unsigned>(std::min(n, 256L));
  }
  // The CPUs this process may run on (a container's or taskset's limit), else the hardware's.
  cpu_set_t set;
  CPU_ZERO(&set);
  const int allowed = sched_getaffinity(0, sizeof(set), &set) == 0 ? CPU_COUNT(&set) : 0;
  const unsigned n = allowed > 0 ? static_cast<unsigned>(allowed) : std::thread::hardware_concurrency();
  return std::clamp(n, 1u, 16u);
}

// fn(worker, begin, end) for contiguous chunks of `chunk` indices covering [0, n), handed out in
// order to whichever worker is free (cells of curved first layers cost more than linear ones:
// fixed shares would leave one worker with the expensive ones); worker in [0, workers). An
// exception stops the handing out; once all workers have finished, the one thrown by the
// lowest chunk is rethrown (the error a single thread would have met first, whatever the
// timing). If a thread cannot be started, the started ones finish and the rest runs here.
template <class Fn>
void parallel_chunks(std::size_t n, std::size_t chunk, Fn&& fn) {
  chunk = std::max<std::size_t>(1, chunk);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  const unsigned workers = static_cast<unsigned>(std::min<std::size_t>(worker_threads(), chunks));
  if (workers <= 1) {
    if (n > 0) fn(0u, std::size_t{0}, n);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::vector<std::exception_ptr> errors(workers);
  std::vector<std::size_t> error_chunk(workers, chunks);
  auto work = [&](unsigned w) {
    std::size_t k = 0;
    try {
      for (k = next++; k < chunks; k = next++) fn(w, k * chunk, std::min(n, (k + 1) * chunk));
    } catch (...) {
      errors[w] = std::current_exception();
      error_chunk[w] = k;
      next = chunks;  // the others stop at their next chunk
    }
  };
  std::vector<std::thread> threads;
  unsigned started = 1;
  try {
    for (; started < workers; ++started) threads.emplace_back(work, started);
  } catch (const std::system_error&) {
    // (no more threads: the caller's thread works along)
  }
  work(0);
  for (std::thread& t : threads) t.join();
  unsigned first = workers;
  for (unsigned w = 0; w < workers; ++w)
    if (errors[w] && (first == workers || error_chunk[w] < error_chunk[first])) first = w;
  if (first < workers) std::rethrow_exception(errors[first]);
}

}  // namespace base
}  // namespace plaf
