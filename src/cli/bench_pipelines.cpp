// `snell bench pipelines`: compiles every pipeline the renderer can choose
// (render/pipeline_catalogue.h) on a device and prints what its driver says
// of each: registers, spills, code size, instructions. It allocates nothing
// and submits nothing, so it runs on a null device: AMD's compiler through
// RADV without AMD hardware (--amd). With --baseline it guards the trace's
// registers against a file it wrote before.
#include "cli/commands.h"
#include "io/image_file.h"
#include "io/json.h"
#include "render/pipeline_catalogue.h"
#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/graphics_program.h"
#include "vk/ray_tracing_program.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace snell::cli {

namespace {

struct Options {
  std::string amd;  ///< an AMD family for RADV's null device, or empty
  uint32_t subgroupSize = 0;  ///< lanes every compute pipeline is compiled for; 0: the driver's choice
  std::string only, json, baseline, traceSpirv;
};

// RADV names RDNA2 and older parts by chip (navi21), RDNA3 by its gfx id:
// the gfx ids of the first, as LLVM and AMD's own tools name them.
std::string radvFamily(const std::string& family) {
  static const std::map<std::string, std::string> chips = {
      {"gfx900", "vega10"}, {"gfx906", "vega20"}, {"gfx1010", "navi10"}, {"gfx1011", "navi12"},
      {"gfx1012", "navi14"}, {"gfx1030", "navi21"}, {"gfx1031", "navi22"}, {"gfx1032", "navi23"},
      {"gfx1034", "navi24"}};
  auto found = chips.find(family);
  return found == chips.end() ? family : found->second;
}

// What the table shows of an executable, by the names each driver gives its
// statistics (RADV/ACO, NVIDIA); absent ones stay -1.
struct Summary {
  double registers = -1, scalarRegisters = -1, spills = -1, codeBytes = -1, instructions = -1, waves = -1;
};

Summary summarise(const std::vector<vk::PipelineStatistic>& stats, const std::string& executable) {
  Summary s;
  for (const vk::PipelineStatistic& st : stats) {
    if (st.executable != executable) continue;
    const std::string& n = st.name;
    if (n == "VGPRs" || n == "Register Count") s.registers = st.value;
    else if (n == "SGPRs") s.scalarRegisters = st.value;
    else if (n == "Code size" || n == "Binary Size") s.codeBytes = st.value;
    else if (n == "Instructions") s.instructions = st.value;
    else if (n == "Subgroups per SIMD") s.waves = st.value;
    else if (n.find("Spill") != std::string::npos || n.find("spill") != std::string::npos) {
      s.spills = std::max(s.spills, 0.0) + st.value;
    }
  }
  return s;
}

struct Row {
  render::CataloguedPipeline pipeline;
  double compileSeconds = 0;
  std::vector<vk::PipelineStatistic> statistics;
  std::string error;  ///< the compile's failure, where it failed
};

// RADV's null device for a family: the environment the driver reads when the
// Vulkan loader first starts it, which is after the command line parses.
void chooseAmdNullDevice(const Options& o) {
  std::string icd;
  for (const char* folder : {"/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d"}) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
      std::string name = entry.path().filename().string();
      if (name.rfind("radeon_icd.", 0) == 0 && icd.empty()) icd = entry.path().string();
    }
  }
  if (icd.empty()) {
    throw std::runtime_error("--amd " + o.amd + ": RADV, Mesa's AMD driver, is not installed (no radeon_icd.*.json in "
                             "/usr/share/vulkan/icd.d; Debian: apt install mesa-vulkan-drivers)");
  }
  ::setenv("VK_DRIVER_FILES", icd.c_str(), 1);
  ::setenv("RADV_FORCE_FAMILY", radvFamily(o.amd).c_str(), 1);
}

std::vector<uint32_t> readSpirv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 20 || bytes.size() % 4 != 0) throw std::runtime_error(path + ": not a SPIR-V module (size)");
  std::vector<uint32_t> words(bytes.size() / 4);
  std::memcpy(words.data(), bytes.data(), bytes.size());
  if (words[0] != 0x07230203u) throw std::runtime_error(path + ": not a SPIR-V module (magic number)");
  return words;
}

Row compile(vk::Context& context, const render::CataloguedPipeline& p) {
  Row row{p, 0.0, {}, ""};
  auto start = std::chrono::steady_clock::now();
  try {
    if (p.compute) {
      vk::ComputeProgram program(context, *p.compute);
      program.finishCompile();
      row.compileSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      row.statistics = program.executableStatistics();
    } else if (p.graphics) {
      vk::GraphicsProgram program(context, *p.graphics);
      row.statistics = program.executableStatistics();  // waits for the compile
      row.compileSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    } else if (p.rayTracing) {
      vk::RayTracingProgram program(context, *p.rayTracing);
      row.compileSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      row.statistics = program.executableStatistics();
    }
  } catch (const std::exception& e) {
    row.error = e.what();
  }
  return row;
}

std::string cell(double value) {
  if (value < 0) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.0f", value);
  return text;
}

std::string rowName(const Row& row, const std::string& executable, size_t executables) {
  std::string name = row.pipeline.pass + ": " + row.pipeline.variant;
  return executables > 1 ? name + " (" + executable + ")" : name;
}

std::vector<std::string> executablesOf(const Row& row) {
  std::vector<std::string> names;
  for (const vk::PipelineStatistic& s : row.statistics) {
    if (names.empty() || names.back() != s.executable) names.push_back(s.executable);
  }
  return names;
}

// The statistics the guard holds: registers (AMD's VGPRs, NVIDIA's count)
// and registers spilled, where a compiler that caps its registers (ACO's
// gfx1100 wave64 near 128 VGPRs) puts a rise.
const char* const kGuardedStatistics[] = {"VGPRs", "Spilled VGPRs", "Register Count"};

// The guard: each trace pipeline's registers against the baseline's, for the
// same device and subgroup size. Returns the lines that fail.
std::vector<std::string> checkBaseline(const std::string& path, const vk::Context& context, uint32_t lanes,
                                       const std::vector<Row>& rows) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  io::Json baseline = io::Json::parse(in, nullptr, false);
  if (baseline.is_discarded() || !baseline.contains("pipelines") || !baseline["pipelines"].is_array()) {
    throw std::runtime_error(path + ": not a 'snell bench pipelines --json' file");
  }
  std::string device = baseline.value("/device/name"_json_pointer, std::string());
  uint32_t subgroup = baseline.value("subgroup_size", 0u);
  if (device != context.facts().name || subgroup != lanes) {
    throw std::runtime_error(path + ": the baseline is of " + device + " at " + std::to_string(subgroup) +
                             " lanes; this is " + context.facts().name + " at " + std::to_string(lanes) + " lanes");
  }
  // (variant, executable) -> the guarded statistics it recorded
  std::map<std::string, std::map<std::string, double>> recorded;
  for (const io::Json& p : baseline["pipelines"]) {
    if (p.value("pass", "") != "trace") continue;
    for (const io::Json& e : p.value("executables", io::Json::array())) {
      const io::Json& stats = e.value("statistics", io::Json::object());
      auto& entry = recorded[p.value("variant", "") + "|" + e.value("name", "")];
      for (const char* key : kGuardedStatistics) {
        if (stats.contains(key)) entry[key] = stats[key].get<double>();
      }
    }
  }
  std::vector<std::string> failures;
  for (const Row& row : rows) {
    if (row.pipeline.pass != "trace" || !row.error.empty()) continue;
    for (const std::string& executable : executablesOf(row)) {
      std::string name = rowName(row, executable, 1);
      auto found = recorded.find(row.pipeline.variant + "|" + executable);
      if (found == recorded.end()) {
        failures.push_back(name + ": not in " + path + " (write it again with --json, in a commit that says why)");
        continue;
      }
      for (const vk::PipelineStatistic& st : row.statistics) {
        if (st.executable != executable) continue;
        auto was = found->second.find(st.name);
        if (was == found->second.end() || st.value <= was->second) continue;
        std::string what = st.name == "Spilled VGPRs" ? "spilled VGPRs" : st.name == "Register Count" ? "registers" : st.name;
        failures.push_back(name + ": " + cell(st.value) + " " + what + ", up from " + cell(was->second) + " in " + path);
      }
    }
  }
  return failures;
}

int runPipelines(const Options& o) {
  if (!o.json.empty()) io::checkWritable(o.json);
  if (!o.amd.empty()) chooseAmdNullDevice(o);
  // Every pipeline compiled afresh, its time and statistics the compiler's:
  // the drivers' own disk caches (Mesa's, NVIDIA's) are off for this process.
  ::setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
  ::setenv("__GL_SHADER_DISK_CACHE", "0", 1);
  std::vector<uint32_t> traceSpirv;
  if (!o.traceSpirv.empty()) traceSpirv = readSpirv(o.traceSpirv);

  vk::ContextDesc desc = io::contextDescFromEnvironment();
  desc.compileOnly = true;
  desc.pipelineStatistics = true;
  // The pipelines as the renderer makes them for a user: SNELL_VALIDATION's
  // bounds checks (robust buffer access) change the code a compiler writes
  // (ACO spilled 1 to 32 VGPRs more in the trace on gfx1100 with them).
  desc.robustBufferAccess = false;
  desc.driverAccelerationStructures = desc.driverRayTracing = true;
  auto context = vk::Context::create(desc);
  const vk::DeviceFacts& facts = context->facts();
  std::printf("device: %s, %s %s, subgroups of %u-%u lanes\n", facts.name.c_str(), facts.driverName.c_str(),
              facts.driverInfo.c_str(), facts.minSubgroupSize, facts.maxSubgroupSize);
  bool statistics = context->caps().pipelineStatistics;
  if (!statistics) {
    std::printf("%s reports no pipeline statistics (it lacks VK_KHR_pipeline_executable_properties): each pipeline "
                "is created and timed only%s\n",
                facts.name.c_str(),
                facts.driverId == VK_DRIVER_ID_MESA_LLVMPIPE ? " (llvmpipe generates its code at the first dispatch)"
                                                              : "");
  }

  std::vector<render::CataloguedPipeline> catalogue = render::pipelineCatalogue(*context);
  for (render::CataloguedPipeline& p : catalogue) {
    if (!traceSpirv.empty() && p.pass == "trace" && p.compute && p.compute->name == "trace") p.compute->spirv = traceSpirv;
    if (p.compute && !p.compute->requiredSubgroupSize) p.compute->requiredSubgroupSize = o.subgroupSize;
  }
  if (o.subgroupSize) std::printf("compute pipelines compiled for subgroups of %u lanes\n", o.subgroupSize);
  std::printf("%-66s %5s %5s %6s %7s %6s %5s %8s\n", "pipeline", "regs", "sgprs", "spills", "code B", "instr",
              "waves", "compile");
  std::vector<Row> rows;
  auto started = std::chrono::steady_clock::now();
  for (const render::CataloguedPipeline& p : catalogue) {
    if (!o.only.empty() && (p.pass + ": " + p.variant).find(o.only) == std::string::npos) continue;
    Row row = compile(*context, p);
    if (!row.error.empty()) {
      std::printf("%-66.66s failed: %s\n", (p.pass + ": " + p.variant).c_str(), row.error.c_str());
    } else {
      std::vector<std::string> executables = executablesOf(row);
      if (executables.empty()) executables.push_back("");
      for (const std::string& executable : executables) {
        Summary s = summarise(row.statistics, executable);
        std::printf("%-66.66s %5s %5s %6s %7s %6s %5s %7.2fs\n", rowName(row, executable, executables.size()).c_str(),
                    cell(s.registers).c_str(), cell(s.scalarRegisters).c_str(), cell(s.spills).c_str(),
                    cell(s.codeBytes).c_str(), cell(s.instructions).c_str(), cell(s.waves).c_str(), row.compileSeconds);
      }
    }
    std::fflush(stdout);
    rows.push_back(std::move(row));
  }
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  int failed = 0;
  std::vector<std::string> spilling;
  for (const Row& row : rows) {
    failed += row.error.empty() ? 0 : 1;
    for (const std::string& executable : executablesOf(row)) {
      Summary s = summarise(row.statistics, executable);
      if (s.spills > 0) spilling.push_back(rowName(row, executable, 2) + ": " + cell(s.spills) + " registers spilled");
    }
  }
  std::printf("%zu pipelines compiled in %.1f s, %d failed; ", rows.size() - size_t(failed), total, failed);
  if (!statistics) {
    std::printf("spills unknown\n");
  } else if (spilling.empty()) {
    std::printf("none spills\n");
  } else {
    std::printf("%zu spill:\n", spilling.size());
    for (const std::string& line : spilling) std::printf("  spills: %s\n", line.c_str());
  }

  if (!o.json.empty()) {
    io::Json j = io::reportHead("bench-pipelines", &facts);
    j["subgroup_size"] = o.subgroupSize ? o.subgroupSize : facts.maxSubgroupSize;
    j["statistics"] = statistics;
    if (!o.traceSpirv.empty()) j["trace_spirv"] = o.traceSpirv;
    io::Json list = io::Json::array();
    for (const Row& row : rows) {
      io::Json p{{"pass", row.pipeline.pass}, {"variant", row.pipeline.variant}};
      if (row.pipeline.pass == "trace" && row.pipeline.lanes) {
        p["optics"] = row.pipeline.optics, p["flags"] = row.pipeline.flags, p["lanes"] = row.pipeline.lanes;
        p["surface"] = row.pipeline.surface;
      }
      if (row.pipeline.compute && row.pipeline.compute->requiredSubgroupSize) {
        p["required_subgroup_size"] = row.pipeline.compute->requiredSubgroupSize;
      }
      p["compile_seconds"] = row.compileSeconds;
      if (!row.error.empty()) p["error"] = row.error;
      io::Json executables = io::Json::array();
      for (const std::string& executable : executablesOf(row)) {
        io::Json stats = io::Json::object();
        for (const vk::PipelineStatistic& s : row.statistics) {
          if (s.executable == executable) stats[s.name] = s.value;
        }
        executables.push_back(io::Json{{"name", executable}, {"statistics", std::move(stats)}});
      }
      p["executables"] = std::move(executables);
      list.push_back(std::move(p));
    }
    j["pipelines"] = std::move(list);
    io::writeJson(o.json, j);
  }

  int exit = failed ? kExitFailure : 0;
  if (!o.baseline.empty()) {
    std::vector<std::string> failures = checkBaseline(o.baseline, *context,
                                                     o.subgroupSize ? o.subgroupSize : context->facts().maxSubgroupSize, rows);
    if (failures.empty()) {
      std::printf("registers: every trace pipeline within %s (VGPRs, spilled VGPRs, NVIDIA's register count)\n",
                  o.baseline.c_str());
    } else {
      for (const std::string& line : failures) std::fprintf(stderr, "snell: registers: %s\n", line.c_str());
      exit = kExitFailure;
    }
  }
  int validation = validationExitCode(*context);
  return exit ? exit : validation;
}

}  // namespace

void addBenchPipelines(CLI::App& bench, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub = bench.add_subcommand("pipelines", "every pipeline compiled: the driver's registers, spills, code size");
  describe(*sub,
      "Compiles every pipeline the renderer can choose on the device: the trace's\n"
      "specialisations (each surface feature, the AOVs, the ray list, the masked\n"
      "viewport at 1, 2, 4 and 8 lanes a pixel, every optics feature), the trace's\n"
      "compaction, the tree builds and refits, the sorts and scans, deform, refine,\n"
      "texture mips, the raster's and, where the device has ray tracing pipelines,\n"
      "driver-rt's. Prints what the driver reports of each (VK_KHR_pipeline_\n"
      "executable_properties): registers (AMD's VGPRs, NVIDIA's register count),\n"
      "scalar registers, registers spilled, code size, instructions and waves a\n"
      "SIMD, with the compile time; then the pipelines that spill.\n"
      "\n"
      "Each is compiled afresh (snell's pipeline cache and the drivers' shader\n"
      "caches are off). Nothing is allocated or run, so a null device will do: --amd gfx1100 (RDNA3)\n"
      "or gfx1030 (RDNA2) compiles with AMD's compiler through Mesa's RADV on any\n"
      "machine, no AMD GPU needed (RADV_FORCE_FAMILY). RADV compiles compute in\n"
      "wave64; --subgroup-size 32 asks each pipeline for wave32 (RADV_PERFTEST=\n"
      "cswave32 leaves the shaders that use subgroups at wave64). A driver without\n"
      "statistics (lavapipe) is said to have none.\n"
      "\n"
      "--baseline FILE (a --json file of the same device and subgroup size) fails\n"
      "when a trace pipeline holds more registers or spills more of them than FILE\n"
      "records, naming it and both counts: the tests hold bench/results/\n"
      "pipelines-radv-gfx1100.json and -gfx1030.json (wave64).");
  sub->footer(kHelpFooter);
  sub->add_option("--amd", o->amd,
                  "compile on RADV's null device for an AMD part: gfx1100\n(RDNA3), gfx1030 (RDNA2), or a chip RADV names (navi21)")
      ->type_name("FAMILY");
  sub->add_option("--subgroup-size", o->subgroupSize,
                  "compile every compute pipeline for subgroups of N lanes\n(AMD: 32 for wave32, 64 for wave64), but those the renderer\ncompiles for a size of their own")
      ->type_name("N")
      ->check(CLI::IsMember({1u, 2u, 4u, 8u, 16u, 32u, 64u, 128u}));
  sub->add_option("--only", o->only, "only the pipelines whose name contains TEXT")->type_name("TEXT");
  sub->add_option("--json", o->json, "also write every statistic of every pipeline as JSON")->type_name("FILE");
  sub->add_option("--baseline", o->baseline, "fail when a trace pipeline holds more registers than FILE records")
      ->type_name("FILE");
  sub->add_option("--trace-spirv", o->traceSpirv,
                  "compile the trace's specialisations from FILE, another\nbuild's trace.comp as SPIR-V (for comparisons)")
      ->type_name("FILE");
  sub->callback([o, &run] { run = [o] { return runPipelines(*o); }; });
}

}  // namespace snell::cli
