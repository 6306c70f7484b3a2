// `snell bench stress`: the numerical stability grid (src/stress), GPU against
// the CPU double-precision reference, as a table and as JSON.
#include "cli/cli.h"
#include "cli/image_file.h"
#include "stress/stress.h"

#include <sstream>
#include <cstdio>
#include <fstream>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell bench stress [--json FILE] [--size WxH] [--rays N] [--huge]

Renders every case of the stability grid on the GPU and with the CPU
double-precision reference and compares them: the eye far from the origin
and at extreme scales, grazing views, cornea IORs from 0.75 to 4, total
internal reflection, rays aimed exactly at shared edges and vertices of
closed meshes, thin slabs down to 1e-5, degenerate and non-finite triangles,
a deformation squashed to 1% and turned inside out, odd image sizes, and
every optics feature (Fresnel, sky, volume, dispersion, IOR texture, nested
media) alone and together.

  --size WxH   image cases' size (default 96x72)
  --rays N     aimed-ray cases trace N x N rays (default 1024: about 10^6)
  --huge       add a 10^7-triangle case
  --json FILE  write the rows as a JSON array
  --only TEXT  run only the cases whose name contains TEXT
  --verbose    print the first pixels or rays of each case that differ or leak

Columns: max and mean channel error against the reference (sRGB, 1/255),
pixels more than 1/255 off, NaN pixels, leaks (aimed rays that slipped
between triangles or never left a closed mesh), self-hits (more crossings
than the reference), rays that hit the traversal's step cap, triangles the
GPU dropped as non-finite, and |R+T-1|: the reference's largest energy
error at any boundary (T from the Fresnel amplitudes, not 1 - R). Exits 1
when any case leaks, self-hits or NaNs, or an energy error passes 1e-6.
)";

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  return out + "\"";
}

}  // namespace

int runBenchStress(const Args& args) {
  stress::GridOptions options;
  options.aimedRaysSide = 1024;
  std::string json, only;
  bool verbose = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (a == "--huge" || a == "--verbose") {
      (a == "--huge" ? options.huge : verbose) = true;
      continue;
    }
    if (a != "--json" && a != "--size" && a != "--rays" && a != "--only") throw UsageError{"bench stress: unknown option " + a};
    if (i + 1 >= args.size()) throw UsageError{"bench stress: " + a + " needs a value"};
    const std::string& value = args[++i];
    if (a == "--json") checkWritable(json = value);
    else if (a == "--only") only = value;
    else if (a == "--rays") options.aimedRaysSide = uint32_t(parseCount(a, value));
    else parseSize(a, value, options.imageWidth, options.imageHeight);
  }
  auto context = vk::Context::create(contextDescFromEnvironment());
  std::printf("device: %s\n", context->facts().name.c_str());
  std::printf("%-58s %8s %6s %7s %7s %5s %6s %6s %6s %7s %7s %8s\n", "case", "pixels", "max", "mean", ">1/255", "NaN",
              "leaks", "self", "caps", "dropped", "seconds", "|R+T-1|");
  std::vector<stress::Result> results;
  bool bad = false;
  for (const stress::Case& c : stress::grid(options)) {
    if (!only.empty() && c.name.find(only) == std::string::npos) continue;
    stress::Result r = stress::run(*context, c);
    if (!r.error.empty()) {
      std::printf("%-58.58s error: %s\n", r.name.c_str(), r.error.c_str());
    } else {
      std::printf("%-58.58s %8llu %6d %7.3f %7llu %5llu %6llu %6llu %6llu %7llu %7.1f %8.1e\n", r.name.c_str(),
                  (unsigned long long)r.pixels, r.maxError, r.meanError, (unsigned long long)r.overOne,
                  (unsigned long long)r.nanCount, (unsigned long long)r.leakCount, (unsigned long long)r.selfHitCount,
                  (unsigned long long)r.capHits, (unsigned long long)r.dropped, r.seconds, r.energyError);
    }
    if (verbose && !r.firstProblems.empty()) std::fputs(r.firstProblems.c_str(), stdout);
    std::fflush(stdout);
    bad = bad || r.nanCount || r.leakCount || r.selfHitCount || r.energyError > 1e-6;
    results.push_back(r);
  }
  if (!json.empty()) {
    {
      std::ostringstream out;
      out << "[\n";
      for (size_t i = 0; i < results.size(); ++i) {
        const stress::Result& r = results[i];
        out << "  {\"case\": " << jsonString(r.name) << ", \"group\": " << jsonString(r.group)
            << ", \"device\": " << jsonString(context->facts().name) << ", \"pixels\": " << r.pixels
            << ", \"max_error\": " << r.maxError << ", \"mean_error\": " << r.meanError
            << ", \"over_one\": " << r.overOne << ", \"nan_count\": " << r.nanCount
            << ", \"leak_count\": " << r.leakCount << ", \"self_hit_count\": " << r.selfHitCount
            << ", \"cap_hits\": " << r.capHits << ", \"energy_error\": " << r.energyError << ", \"dropped_triangles\": " << r.dropped
            << ", \"error\": " << jsonString(r.error) << ", \"seconds\": " << r.seconds << "}"
            << (i + 1 < results.size() ? "," : "") << "\n";
      }
      out << "]\n";
      writeTextFile(json, out.str());
    }
  }
  return bad ? 1 : 0;
}

}  // namespace snell::cli
