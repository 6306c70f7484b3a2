// The peer for `snell bench sort`: NVIDIA's own CUB radix sort (DeviceRadixSort
// with double buffers, its fastest path) on the same sizes, key widths and
// 32-bit values, timed with CUDA events, median of the same run count.
// Built and run on the NVIDIA machine only: bench/run_sort_on_device.sh.
#include <cub/cub.cuh>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#define CUDA_CHECK(x)                                                                          \
  do {                                                                                         \
    cudaError_t e = (x);                                                                       \
    if (e != cudaSuccess) {                                                                    \
      std::fprintf(stderr, "%s failed: %s (%s:%d)\n", #x, cudaGetErrorString(e), __FILE__, __LINE__); \
      std::exit(1);                                                                            \
    }                                                                                          \
  } while (0)

struct Row {
  uint64_t pairs;
  int bits;
  double median, min, max;
  bool correct;
};

template <typename Key>
Row measure(uint64_t n, int runs, int warmup) {
  std::mt19937_64 random(n * 131 + sizeof(Key));
  std::vector<Key> keys(n);
  for (Key& k : keys) k = static_cast<Key>(random());
  std::vector<uint32_t> values(n);
  for (uint64_t i = 0; i < n; ++i) values[i] = static_cast<uint32_t>(i);

  Key *pristineKeys, *k0, *k1;
  uint32_t *pristineValues, *v0, *v1;
  CUDA_CHECK(cudaMalloc(&pristineKeys, n * sizeof(Key)));
  CUDA_CHECK(cudaMalloc(&k0, n * sizeof(Key)));
  CUDA_CHECK(cudaMalloc(&k1, n * sizeof(Key)));
  CUDA_CHECK(cudaMalloc(&pristineValues, n * 4));
  CUDA_CHECK(cudaMalloc(&v0, n * 4));
  CUDA_CHECK(cudaMalloc(&v1, n * 4));
  CUDA_CHECK(cudaMemcpy(pristineKeys, keys.data(), n * sizeof(Key), cudaMemcpyHostToDevice));
  CUDA_CHECK(cudaMemcpy(pristineValues, values.data(), n * 4, cudaMemcpyHostToDevice));

  size_t tempBytes = 0;
  cub::DoubleBuffer<Key> dk(k0, k1);
  cub::DoubleBuffer<uint32_t> dv(v0, v1);
  CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, tempBytes, dk, dv, static_cast<int>(n)));
  void* temp;
  CUDA_CHECK(cudaMalloc(&temp, tempBytes));
  // As snell's bench: warm-up runs, then timed runs back to back with no host
  // synchronisation between them, each restoring the unsorted input first.
  std::vector<cudaEvent_t> start(runs), stop(runs);
  for (int r = 0; r < runs; ++r) {
    CUDA_CHECK(cudaEventCreate(&start[r]));
    CUDA_CHECK(cudaEventCreate(&stop[r]));
  }
  // Warm up for at least 250 ms, as snell's bench does, so both meet the same clocks.
  auto warmStart = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - warmStart < std::chrono::milliseconds(250)) {
    for (int r = 0; r < warmup; ++r) {
      CUDA_CHECK(cudaMemcpyAsync(k0, pristineKeys, n * sizeof(Key), cudaMemcpyDeviceToDevice));
      CUDA_CHECK(cudaMemcpyAsync(v0, pristineValues, n * 4, cudaMemcpyDeviceToDevice));
      dk = cub::DoubleBuffer<Key>(k0, k1);
      dv = cub::DoubleBuffer<uint32_t>(v0, v1);
      CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp, tempBytes, dk, dv, static_cast<int>(n)));
    }
    CUDA_CHECK(cudaDeviceSynchronize());
  }
  for (int r = 0; r < warmup + runs; ++r) {
    CUDA_CHECK(cudaMemcpyAsync(k0, pristineKeys, n * sizeof(Key), cudaMemcpyDeviceToDevice));
    CUDA_CHECK(cudaMemcpyAsync(v0, pristineValues, n * 4, cudaMemcpyDeviceToDevice));
    dk = cub::DoubleBuffer<Key>(k0, k1);
    dv = cub::DoubleBuffer<uint32_t>(v0, v1);
    if (r >= warmup) CUDA_CHECK(cudaEventRecord(start[r - warmup]));
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp, tempBytes, dk, dv, static_cast<int>(n)));
    if (r >= warmup) CUDA_CHECK(cudaEventRecord(stop[r - warmup]));
    if (r == warmup - 1) CUDA_CHECK(cudaDeviceSynchronize());
  }
  CUDA_CHECK(cudaDeviceSynchronize());
  std::vector<double> times;
  for (int r = 0; r < runs; ++r) {
    float ms = 0;
    CUDA_CHECK(cudaEventElapsedTime(&ms, start[r], stop[r]));
    times.push_back(ms);
    cudaEventDestroy(start[r]);
    cudaEventDestroy(stop[r]);
  }
  std::vector<Key> gotKeys(n);
  std::vector<uint32_t> gotValues(n);
  CUDA_CHECK(cudaMemcpy(gotKeys.data(), dk.Current(), n * sizeof(Key), cudaMemcpyDeviceToHost));
  CUDA_CHECK(cudaMemcpy(gotValues.data(), dv.Current(), n * 4, cudaMemcpyDeviceToHost));
  std::vector<std::pair<Key, uint32_t>> expected(n);
  for (uint64_t i = 0; i < n; ++i) expected[i] = {keys[i], values[i]};
  std::sort(expected.begin(), expected.end());
  bool correct = true;
  for (uint64_t i = 0; i < n && correct; ++i) correct = gotKeys[i] == expected[i].first && gotValues[i] == expected[i].second;
  cudaFree(temp);
  cudaFree(pristineKeys);
  cudaFree(k0);
  cudaFree(k1);
  cudaFree(pristineValues);
  cudaFree(v0);
  cudaFree(v1);
  std::sort(times.begin(), times.end());
  return {n, int(sizeof(Key) * 8), times[times.size() / 2], times.front(), times.back(), correct};
}

int main(int argc, char** argv) {
  int minLog = 16, maxLog = 24, runs = 20, warmup = 10;
  std::string json;
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string a = argv[i];
    if (a == "--min-log") minLog = std::atoi(argv[i + 1]);
    else if (a == "--max-log") maxLog = std::atoi(argv[i + 1]);
    else if (a == "--runs") runs = std::atoi(argv[i + 1]);
    else if (a == "--json") json = argv[i + 1];
  }
  cudaDeviceProp prop;
  CUDA_CHECK(cudaGetDeviceProperties(&prop, 0));
  int driver = 0;
  CUDA_CHECK(cudaDriverGetVersion(&driver));
  std::printf("CUB %d.%d.%d on %s (CUDA driver %d)\n", CUB_MAJOR_VERSION, CUB_MINOR_VERSION, CUB_SUBMINOR_VERSION,
              prop.name, driver);
  std::vector<Row> rows;
  for (int bits : {32, 64}) {
    for (int log = minLog; log <= maxLog; ++log) {
      Row r = bits == 32 ? measure<uint32_t>(1ull << log, runs, warmup) : measure<uint64_t>(1ull << log, runs, warmup);
      std::printf("%12llu %3d %10.4f ms %9.3f Gpairs/s %s\n", (unsigned long long)r.pairs, r.bits, r.median,
                  r.pairs / (r.median * 1e6), r.correct ? "ok" : "WRONG");
      rows.push_back(r);
    }
  }
  if (!json.empty()) {
    FILE* f = std::fopen(json.c_str(), "w");
    std::fprintf(f, "{\n  \"benchmark\": \"sort\",\n  \"implementation\": \"CUB %d.%d.%d DeviceRadixSort::SortPairs (DoubleBuffer)\",\n",
                 CUB_MAJOR_VERSION, CUB_MINOR_VERSION, CUB_SUBMINOR_VERSION);
    std::fprintf(f, "  \"device\": \"%s\",\n  \"cuda_driver\": %d,\n  \"runs\": %d,\n  \"results\": [\n", prop.name, driver, runs);
    for (size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      std::fprintf(f, "    {\"pairs\": %llu, \"key_bits\": %d, \"median_ms\": %.6f, \"min_ms\": %.6f, \"max_ms\": %.6f, \"gpairs_per_s\": %.6f, \"correct\": %s}%s\n",
                   (unsigned long long)r.pairs, r.bits, r.median, r.min, r.max, r.pairs / (r.median * 1e6),
                   r.correct ? "true" : "false", i + 1 < rows.size() ? "," : "");
    }
    std::fprintf(f, "  ]\n}\n");
    std::fclose(f);
  }
  return 0;
}
