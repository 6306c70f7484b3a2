// `snell bench scale`: how the bottom-level update scales with triangles, on
// UV spheres of 1e4 to 1e7 triangles: build and refit times (GPU timestamps,
// medians), their rates, tree memory per triangle and the build's SAH cost
// against a CPU binned-SAH tree.
#include "cli/cli.h"

#include "ref/sah_bvh.h"
#include "render/bvh.h"
#include "vk/commands.h"
#include "vk/upload_arena.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell bench scale [options]

Builds and refits the bottom-level tree of UV spheres of increasing size on
the GPU and reports, per size, the median GPU time of a build (boxes, Morton
codes, sort, H-PLOC) and of a refit, in milliseconds and millions of
triangles per second, the tree's memory per triangle (nodes and per-tree
records; the build's scratch separately) and, up to --sah-limit triangles,
its SAH cost against a CPU binned-SAH tree of the same triangles.

options:
  --triangles N,N,...  sphere sizes (default 10000,100000,1000000,10000000)
  --runs N             timed builds and refits per size (default 10, after one warm-up)
  --restructure N      rounds of treelet restructuring after each build (default 0)
  --sah-limit N        price the tree against binned SAH up to this size (default 1000000)
  --json FILE          write the results as JSON too
)";

struct Mesh {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
};

// A UV sphere of about `triangles` triangles: rings x 2 rings quads, two triangles each.
Mesh uvSphere(uint64_t triangles) {
  uint32_t rings = std::max<uint32_t>(2, static_cast<uint32_t>(std::lround(std::sqrt(double(triangles) / 4.0))));
  uint32_t segments = 2 * rings;
  Mesh m;
  m.positions.reserve(size_t(rings + 1) * (segments + 1) * 3);
  for (uint32_t r = 0; r <= rings; ++r) {
    double theta = M_PI * r / rings;
    for (uint32_t s = 0; s <= segments; ++s) {
      double phi = 2.0 * M_PI * s / segments;
      m.positions.insert(m.positions.end(), {float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                                             float(std::sin(theta) * std::sin(phi))});
    }
  }
  for (uint32_t r = 0; r < rings; ++r) {
    for (uint32_t s = 0; s < segments; ++s) {
      uint32_t a = r * (segments + 1) + s, b = a + 1, c = a + segments + 1, d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  }
  return m;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

struct Row {
  uint64_t triangles = 0;
  double buildMs = 0, refitMs = 0, bytesPerTriangle = 0, scratchPerTriangle = 0, sahRatio = 0;
};

std::vector<uint64_t> parseList(const std::string& option, const std::string& value) {
  std::vector<uint64_t> out;
  std::stringstream in(value);
  std::string item;
  while (std::getline(in, item, ',')) {
    double v = 0;
    try {
      v = std::stod(item);
    } catch (const std::exception&) {
      throw UsageError{"bench scale: " + option + " takes numbers separated by commas, not '" + item + "'"};
    }
    if (!(v >= 2 && v <= 1e9)) throw UsageError{"bench scale: " + option + " sizes must be within 2 and 1e9"};
    out.push_back(static_cast<uint64_t>(v));
  }
  if (out.empty()) throw UsageError{"bench scale: " + option + " needs at least one size"};
  return out;
}

}  // namespace

int runBenchScale(const Args& args) {
  std::vector<uint64_t> sizes = {10000, 100000, 1000000, 10000000};
  uint32_t runs = 10, restructure = 0;
  uint64_t sahLimit = 1000000;
  std::string json;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (i + 1 >= args.size()) throw UsageError{"bench scale: " + a + " needs a value (or is unknown)"};
    const std::string& v = args[++i];
    if (a == "--triangles") sizes = parseList(a, v);
    else if (a == "--runs") runs = std::max<uint32_t>(1, uint32_t(parseCount(a, v)));
    else if (a == "--restructure") restructure = uint32_t(parseCount(a, v));
    else if (a == "--sah-limit") sahLimit = parseCount(a, v);
    else if (a == "--json") json = v;
    else throw UsageError{"bench scale: unknown option " + a};
  }
  auto context = vk::Context::create(contextDescFromEnvironment());
  std::printf("device: %s\n", context->facts().name.c_str());
  render::BvhBuilder builder(*context);
  vk::UploadArena arena(*context, "bench scale uploads");
  std::vector<Row> rows;
  std::printf("%12s %10s %10s %10s %10s %10s %10s %10s\n", "triangles", "build ms", "Mtri/s", "refit ms", "Mtri/s",
              "B/tri", "scratch", "SAH/binned");
  for (uint64_t target : sizes) {
    Mesh mesh = uvSphere(target);
    uint32_t triangles = static_cast<uint32_t>(mesh.indices.size() / 3);
    auto buffer = [&](const void* data, size_t bytes, const char* name) {
      vk::Buffer b(*context, {bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                              vk::MemoryDomain::Device, name});
      vk::upload(*context, b, data, bytes);
      return b;
    };
    vk::Buffer positions = buffer(mesh.positions.data(), mesh.positions.size() * 4, "sphere positions");
    vk::Buffer indices = buffer(mesh.indices.data(), mesh.indices.size() * 4, "sphere indices");
    render::Bvh bvh = builder.makeBvh({triangles}, render::BvhLeaves::Triangles, "sphere");
    render::BvhInputs inputs{&positions, &indices, nullptr, nullptr};
    vk::Commands commands(*context, "bench scale");
    std::vector<double> build, refit;
    for (uint32_t run = 0; run <= runs; ++run) {
      commands.begin();
      arena.reset();
      commands.beginPass("build");
      builder.recordBuild(commands, bvh, inputs, {}, arena, restructure);
      commands.endPass();
      commands.beginPass("refit");
      builder.recordRefit(commands, bvh, inputs, {}, arena);
      commands.endPass();
      commands.submitAndWait();
      if (run == 0) continue;  // warm-up
      for (const vk::PassTime& p : commands.passTimes()) (p.name == "build" ? build : refit).push_back(p.milliseconds);
    }
    Row row;
    row.triangles = triangles;
    row.buildMs = median(build);
    row.refitMs = median(refit);
    row.bytesPerTriangle = double(bvh.treeBytes()) / triangles;
    row.scratchPerTriangle = double(builder.scratchBytes()) / triangles;
    if (triangles <= sahLimit) {
      render::BvhSnapshot snapshot = builder.download(bvh);
      render::BvhSnapshot::TreeBoxes tree = snapshot.treeBoxes(0);
      std::vector<ref::Aabb> boxes(triangles);
      for (uint32_t t = 0; t < triangles; ++t) {
        for (int k = 0; k < 3; ++k) {
          const float* p = &mesh.positions[3 * size_t(mesh.indices[3 * size_t(t) + size_t(k)])];
          boxes[t].extend(glm::dvec3(p[0], p[1], p[2]));
        }
      }
      row.sahRatio = ref::sahCost(tree.internal, tree.leaves) / ref::binnedSahCost(boxes);
    }
    rows.push_back(row);
    std::printf("%12llu %10.3f %10.1f %10.4f %10.1f %10.1f %10.1f %10s\n", static_cast<unsigned long long>(triangles),
                row.buildMs, triangles / row.buildMs / 1e3, row.refitMs, triangles / row.refitMs / 1e3,
                row.bytesPerTriangle, row.scratchPerTriangle,
                row.sahRatio > 0 ? std::to_string(row.sahRatio).substr(0, 5).c_str() : "-");
    std::fflush(stdout);
    builder.releaseScratch();
  }
  if (!json.empty()) {
    std::ofstream out(json);
    out << "{\n  \"device\": \"" << context->facts().name << "\",\n  \"restructure_rounds\": " << restructure
        << ",\n  \"runs\": " << runs << ",\n  \"spheres\": [\n";
    for (size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      out << "    {\"triangles\": " << r.triangles << ", \"build_ms\": " << r.buildMs << ", \"refit_ms\": " << r.refitMs
          << ", \"build_mtris_per_s\": " << double(r.triangles) / r.buildMs / 1e3
          << ", \"refit_mtris_per_s\": " << double(r.triangles) / r.refitMs / 1e3 << ", \"tree_bytes_per_triangle\": "
          << r.bytesPerTriangle << ", \"scratch_bytes_per_triangle\": " << r.scratchPerTriangle
          << ", \"sah_over_binned\": " << r.sahRatio << "}" << (i + 1 < rows.size() ? "," : "") << "\n";
    }
    out << "  ]\n}\n";
    if (!out) throw std::runtime_error(json + ": could not write");
  }
  return 0;
}

}  // namespace snell::cli
