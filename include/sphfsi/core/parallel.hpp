// sphfsi: the one place where parallel loops are expressed (OpenMP when available, serial otherwise).
#pragma once

#include <cstddef>

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace sphfsi {

/// Number of threads parallel_for will use.
inline int thread_count() noexcept {
#if defined(_OPENMP)
  return omp_get_max_threads();
#else
  return 1;
#endif
}

/// Set the number of threads (no effect in a serial build).
inline void set_thread_count([[maybe_unused]] int n) noexcept {
#if defined(_OPENMP)
  if (n > 0) omp_set_num_threads(n);
#endif
}

/// Calls body(i) for i in [0, n), in parallel over threads; iterations must be independent.
template <class Body>
void parallel_for(std::size_t n, Body&& body) {
#if defined(_OPENMP)
  const auto count = static_cast<long long>(n);
#pragma omp parallel for schedule(static)
  for (long long i = 0; i < count; ++i) body(static_cast<std::size_t>(i));
#else
  for (std::size_t i = 0; i < n; ++i) body(i);
#endif
}

/// Splits [0, n) into `chunks` contiguous ranges, in index order, and calls body(begin, end, chunk) once per range,
/// the ranges shared out to the threads dynamically (whichever thread is free takes the next range, so cheap ranges
/// or a thread descheduled by other work on the machine do not leave the others waiting). For loops whose iterations
/// also write to a few later indices: each range knows its bounds and can set aside what it would write beyond `end`.
template <class Body>
void parallel_chunks(std::size_t n, std::size_t chunks, Body&& body) {
  if (chunks == 0) chunks = 1;
#if defined(_OPENMP)
  const auto count = static_cast<long long>(chunks);
#pragma omp parallel for schedule(dynamic, 1)
  for (long long c = 0; c < count; ++c) {
    const auto k = static_cast<std::size_t>(c);
    body(n * k / chunks, n * (k + 1) / chunks, k);
  }
#else
  for (std::size_t k = 0; k < chunks; ++k) body(n * k / chunks, n * (k + 1) / chunks, k);
#endif
}

/// Parallel minimum reduction of f(i) over [0, n); returns init when n == 0.
template <class T, class F>
T parallel_min(std::size_t n, T init, F&& f) {
  T result = init;
#if defined(_OPENMP)
  const auto count = static_cast<long long>(n);
#pragma omp parallel for schedule(static) reduction(min : result)
  for (long long i = 0; i < count; ++i) {
    const T v = f(static_cast<std::size_t>(i));
    result = v < result ? v : result;
  }
#else
  for (std::size_t i = 0; i < n; ++i) {
    const T v = f(i);
    result = v < result ? v : result;
  }
#endif
  return result;
}

/// Parallel maximum reduction of f(i) over [0, n).
template <class T, class F>
T parallel_max(std::size_t n, T init, F&& f) {
  T result = init;
#if defined(_OPENMP)
  const auto count = static_cast<long long>(n);
#pragma omp parallel for schedule(static) reduction(max : result)
  for (long long i = 0; i < count; ++i) {
    const T v = f(static_cast<std::size_t>(i));
    result = v > result ? v : result;
  }
#else
  for (std::size_t i = 0; i < n; ++i) {
    const T v = f(i);
    result = v > result ? v : result;
  }
#endif
  return result;
}

}  // namespace sphfsi
