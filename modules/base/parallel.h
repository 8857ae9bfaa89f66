// SPDX-License-Identifier: MIT
// Contiguous chunks of an index range on worker threads: the certification of every cell of a
// layer and of the quality stage (one JacobianCertifier per worker). Results are written by
// index, so they do not depend on the number of workers.
//
// Workers: the hardware threads (at most 16), or PLAF_THREADS when set (1: all on the caller's
// thread). A range of one chunk runs on the caller's thread alone.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <thread>
#include <vector>

namespace plaf {
inline namespace base {

inline unsigned worker_threads() {
  if (const char* env = std::getenv("PLAF_THREADS")) {
    const long n = std::strtol(env, nullptr, 10);
    if (n >= 1) return static_cast<unsigned>(std::min(n, 256L));
  }
  return std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
}

// fn(worker, begin, end) for contiguous chunks of `chunk` indices covering [0, n), handed out in
// order to whichever worker is free (cells of curved first layers cost more than linear ones:
// fixed shares would leave one worker with the expensive ones); worker in [0, workers). The first
// exception a worker throws is rethrown here after all have finished.
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
  std::vector<std::thread> threads;
  std::vector<std::exception_ptr> errors(workers);
  for (unsigned w = 0; w < workers; ++w)
    threads.emplace_back([&, w] {
      try {
        for (std::size_t k = next++; k < chunks; k = next++) fn(w, k * chunk, std::min(n, (k + 1) * chunk));
      } catch (...) {
        errors[w] = std::current_exception();
        next = chunks;  // the others stop at their next chunk
      }
    });
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace base
}  // namespace plaf
