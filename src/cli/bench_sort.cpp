// `snell bench sort`: pairs per second of the GPU radix sort, from GPU
// timestamps, median of many runs after warm-up; every size is also checked
// against std::sort so a fast wrong sort never makes the table.
#include "cli/commands.h"
#include "io/image_file.h"
#include "io/json.h"

#include "render/radix_sort.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace snell::cli {

namespace {

struct Options {
  unsigned minLog = 16;
  unsigned maxLog = 24;
  unsigned runs = 20;
  unsigned warmup = 10;
  std::vector<unsigned> keyBits = {32, 64};
  std::string json;
  bool breakdown = false;
  bool pipelineStats = false;
  render::RadixSortTuning tuning;
};

struct Row {
  uint64_t pairs;
  unsigned keyBits;
  double medianMs, minMs, maxMs;
  bool correct;
  uint32_t workgroup = 0, keysPerThread = 0;
};

template <typename Key>
Row measure(vk::Context& context, render::RadixSort& sort, uint64_t count, const Options& o) {
  std::mt19937_64 random(count * 131 + sizeof(Key));
  std::vector<Key> keys(count);
  for (Key& k : keys) k = static_cast<Key>(random());
  std::vector<uint32_t> values(count);
  std::iota(values.begin(), values.end(), 0u);

  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  vk::Buffer pristineKeys(context, {count * sizeof(Key), usage, vk::MemoryDomain::Device, "bench pristine keys"});
  vk::Buffer pristineValues(context, {count * 4, usage, vk::MemoryDomain::Device, "bench pristine values"});
  vk::Buffer workKeys(context, {count * sizeof(Key), usage, vk::MemoryDomain::Device, "bench keys"});
  vk::Buffer workValues(context, {count * 4, usage, vk::MemoryDomain::Device, "bench values"});
  vk::upload(context, pristineKeys, keys.data(), count * sizeof(Key));
  vk::upload(context, pristineValues, values.data(), count * 4);
  render::RadixSort::Scratch scratch = sort.makeScratch(count);

  vk::Commands commands(context, "bench sort");
  // Every run sorts the same unsorted input (sorted input would flatter the
  // scatter). Runs go back to back in one submission, so the GPU never idles
  // between them and its clocks settle during the warm-up submission.
  auto recordRuns = [&](unsigned runs, bool timed) {
    commands.begin();
    for (unsigned run = 0; run < runs; ++run) {
      commands.copyBuffer(pristineKeys, workKeys, count * sizeof(Key));
      commands.copyBuffer(pristineValues, workValues, count * 4);
      commands.transferToCompute();
      if (timed) commands.beginPass("sort");
      sort.record(commands, workKeys, workValues, count, scratch);
      if (timed) commands.endPass();
      commands.computeToTransfer();
    }
    commands.submitAndWait();
  };
  // Warm up for a fixed time, not a count: after the host-side check of the
  // previous size the GPU has idled and lowered its clocks, and a few small
  // sorts take milliseconds, far too little for them to come back.
  auto warmStart = std::chrono::steady_clock::now();
  do {
    recordRuns(o.warmup, false);
  } while (std::chrono::steady_clock::now() - warmStart < std::chrono::milliseconds(250));
  recordRuns(o.runs, true);
  std::vector<double> times;
  for (const vk::PassTime& t : commands.passTimes()) times.push_back(t.milliseconds);
  if (times.size() != o.runs) throw std::runtime_error("this device's queue has no timestamps; cannot time the sort");

  if (o.breakdown) {
    // Separate runs: per-step timestamps add gaps the headline figure must not
    // carry. Each sort stamps 3 steps per pass; a submission holds 128 stamps.
    std::map<std::string, std::vector<double>> steps;
    sort.setStepTiming(true);
    unsigned stepsPerSort = 3 * ((static_cast<unsigned>(sizeof(Key)) * 8 + 7) / 8);
    unsigned batch = std::max(1u, 128 / stepsPerSort);
    for (unsigned done = 0; done < o.runs; done += batch) {
      recordRuns(batch, false);  // the sort stamps its own steps
      const std::vector<vk::PassTime>& stamps = commands.passTimes();
      for (size_t first = 0; first + stepsPerSort <= stamps.size(); first += stepsPerSort) {
        std::map<std::string, double> sums;
        for (size_t i = first; i < first + stepsPerSort; ++i) sums[stamps[i].name] += stamps[i].milliseconds;
        for (auto& [name, ms] : sums) steps[name].push_back(ms);
      }
    }
    sort.setStepTiming(false);
    std::printf("%12s", "  steps:");
    for (auto& [name, ms] : steps) {
      std::sort(ms.begin(), ms.end());
      std::printf("  %s %.4f ms", name.c_str(), ms[ms.size() / 2]);
    }
    std::printf("  (medians, all passes)\n");
  }

  std::vector<Key> gotKeys(count);
  std::vector<uint32_t> gotValues(count);
  vk::download(context, workKeys, gotKeys.data(), count * sizeof(Key));
  vk::download(context, workValues, gotValues.data(), count * 4);
  // Values are the original positions, so the stable order is (key, value) order.
  std::vector<std::pair<Key, uint32_t>> expected(count);
  for (uint64_t i = 0; i < count; ++i) expected[i] = {keys[i], values[i]};
  std::sort(expected.begin(), expected.end());
  bool correct = true;
  for (uint64_t i = 0; i < count && correct; ++i) {
    correct = gotKeys[i] == expected[i].first && gotValues[i] == expected[i].second;
  }

  std::sort(times.begin(), times.end());
  return {count, static_cast<unsigned>(sizeof(Key) * 8), times[times.size() / 2], times.front(), times.back(), correct};
}

int runSort(const Options& o) {
  if (!o.json.empty()) io::checkWritable(o.json);
  vk::ContextDesc desc = io::contextDescFromEnvironment();
  desc.pipelineStatistics = o.pipelineStats;
  auto context = vk::Context::create(desc);
  const vk::DeviceFacts& device = context->facts();
  std::printf("device: %s (%s %s), Vulkan %s\n", device.name.c_str(), device.driverName.c_str(),
              device.driverInfo.c_str(), vk::versionString(device.apiVersion).c_str());

  std::vector<Row> rows;
  bool allCorrect = true;
  std::printf("%12s %5s %11s %11s %11s %13s %8s\n", "pairs", "bits", "median ms", "min ms", "max ms", "Gpairs/s", "correct");
  for (unsigned bits : o.keyBits) {
    render::RadixSort sort(*context, bits == 64 ? render::KeyWidth::Bits64 : render::KeyWidth::Bits32, o.tuning);
    std::printf("%u-bit keys: workgroup %u x %u keys\n", bits, sort.workgroupSize(), sort.keysPerThread());
    if (o.pipelineStats) {
      for (const std::string& line : sort.statistics()) std::printf("  %s\n", line.c_str());
    }
    for (unsigned log = o.minLog; log <= o.maxLog; ++log) {
      uint64_t count = uint64_t(1) << log;
      if (count > sort.maxCount()) {
        std::printf("%12llu %5u   skipped: above this device's %llu-pair limit\n", (unsigned long long)count, bits,
                    (unsigned long long)sort.maxCount());
        continue;
      }
      Row row = bits == 64 ? measure<uint64_t>(*context, sort, count, o) : measure<uint32_t>(*context, sort, count, o);
      allCorrect = allCorrect && row.correct;
      row.workgroup = sort.workgroupSize();
      row.keysPerThread = sort.keysPerThread();
      std::printf("%12llu %5u %11.4f %11.4f %11.4f %13.3f %8s\n", (unsigned long long)row.pairs, row.keyBits, row.medianMs,
                  row.minMs, row.maxMs, static_cast<double>(row.pairs) / (row.medianMs * 1e6), row.correct ? "yes" : "NO");
      std::fflush(stdout);
      rows.push_back(row);
    }
  }

  if (!o.json.empty()) {
    io::Json j = io::reportHead("bench-sort", &device);
    j["benchmark"] = "sort";
    j["runs"] = o.runs;
    j["warmup"] = o.warmup;
    io::Json results = io::Json::array();
    for (const Row& r : rows) {
      results.push_back(io::Json{{"pairs", r.pairs},
                                 {"key_bits", r.keyBits},
                                 {"median_ms", r.medianMs},
                                 {"min_ms", r.minMs},
                                 {"max_ms", r.maxMs},
                                 {"gpairs_per_s", static_cast<double>(r.pairs) / (r.medianMs * 1e6)},
                                 {"correct", r.correct},
                                 {"workgroup_size", r.workgroup},
                                 {"keys_per_thread", r.keysPerThread}});
    }
    j["results"] = std::move(results);
    io::writeJson(o.json, j);
    std::printf("wrote %s\n", o.json.c_str());
  }
  int validation = validationExitCode(*context);
  if (!allCorrect) {
    std::fprintf(stderr, "snell: error: the GPU sort disagreed with std::sort (rows marked NO)\n");
    return kExitFailure;
  }
  return validation;
}

}  // namespace

void addBenchSort(CLI::App& bench, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub = bench.add_subcommand("sort", "GPU radix sort: pairs per second, each size checked against std::sort");
  describe(*sub,
      "Sorts random key-value pairs (32-bit values) on the GPU and prints pairs per\n"
      "second from GPU timestamps: the median over --runs back-to-back runs, after\n"
      "at least 250 ms of warm-up runs.\n"
      "Each size is checked against std::sort before it is reported.");
  sub->footer(kHelpFooter);
  sub->add_option("--min-log", o->minLog, "smallest size, 2^N pairs (default 16)")
      ->type_name("N")
      ->check(CLI::Range(0u, 30u));
  sub->add_option("--max-log", o->maxLog, "largest size, 2^N pairs (default 24, at most 30)")
      ->type_name("N")
      ->check(CLI::Range(0u, 30u));
  sub->add_option("--runs", o->runs, "timed runs per size, 10 to 100 (default 20)")
      ->type_name("N")
      ->check(CLI::Range(10u, 100u));
  sub->add_option("--warmup", o->warmup,
                  "untimed runs per warm-up submission, repeated for at\nleast 250 ms (default 10)")
      ->type_name("N");
  sub->add_option_function<std::string>(
         "--keys",
         [o](const std::string& keys) {
           o->keyBits = keys == "32" ? std::vector<unsigned>{32} :
                        keys == "64" ? std::vector<unsigned>{64} :
                                       std::vector<unsigned>{32, 64};
         },
         "key width (default both)")
      ->type_name("32|64|both")
      ->check(CLI::IsMember({"32", "64", "both"}));
  sub->add_option("--json", o->json, "also write the results as JSON")->type_name("FILE");
  sub->add_flag("--breakdown", o->breakdown, "also time each step (histogram, scan, scatter) separately");
  sub->add_flag("--pipeline-stats", o->pipelineStats,
                "print the driver's statistics of each program (registers, spills)");
  sub->add_option("--workgroup", o->tuning.workgroupSize, "override the workgroup size (tuning)")->type_name("N");
  sub->add_option("--keys-per-thread", o->tuning.keysPerThread, "override keys per invocation (tuning)")
      ->type_name("N");
  sub->callback([o, &run] {
    if (o->minLog > o->maxLog) throw UsageError{"bench sort: need --min-log <= --max-log"};
    run = [o] { return runSort(*o); };
  });
}

}  // namespace snell::cli
