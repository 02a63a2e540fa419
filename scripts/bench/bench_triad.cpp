// Memory bandwidth (not a test): the STREAM triad a = b + s c on arrays far larger than the
// L3, at the given thread counts; the ceiling the solver's roofline (docs/solver.md, "Costs")
// measures each phase against.
//   bench_triad [--mib N] [--threads 1,2] [--repeats R]
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  size_t mib = 256;  // per array
  int repeats = 10;
  std::vector<int> threads{1, 2};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--mib" && i + 1 < argc) {
      mib = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg == "--repeats" && i + 1 < argc) {
      repeats = std::atoi(argv[++i]);
    } else if (arg == "--threads" && i + 1 < argc) {
      threads.clear();
      std::stringstream list(argv[++i]);
      for (std::string item; std::getline(list, item, ',');) threads.push_back(std::atoi(item.c_str()));
    } else {
      std::fprintf(stderr, "usage: bench_triad [--mib N] [--threads 1,2] [--repeats R]\n");
      return 2;
    }
  }
  const size_t n = mib * 1024 * 1024 / sizeof(double);
  std::vector<double> a(n), b(n), c(n);
  for (int t : threads) {
    omp_set_num_threads(t);
    // First touch by the threads that use the pages (NUMA placement, as STREAM does).
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; ++i) a[i] = 0, b[i] = 1, c[i] = 2;
    double best = 1e30;
    for (int r = 0; r < repeats; ++r) {
      const auto start = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static)
      for (size_t i = 0; i < n; ++i) a[i] = b[i] + 3.0 * c[i];
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    // STREAM counts 3 arrays moved (2 read, 1 written), not the write-allocate read.
    std::printf("threads %d: triad %.1f GB/s (best of %d, 3 x %zu MiB)\n", t, 3.0 * n * sizeof(double) / best / 1e9,
                repeats, mib);
  }
  return a[n / 2] == 7 ? 0 : 1;
}
