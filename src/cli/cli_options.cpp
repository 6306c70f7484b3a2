// Option parsing and the device choice shared by `snell` and `snell-view`.
#include "cli/cli.h"

#include "render/renderer.h"
#include "scene/procedural_eye.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <charconv>
#include <cstdlib>

#include <unistd.h>

namespace snell::cli {

vk::ContextDesc contextDescFromEnvironment() {
  vk::ContextDesc desc;
  const char* validation = std::getenv("SNELL_VALIDATION");
  desc.validation = validation && std::string(validation) == "1";
  desc.synchronizationValidation = desc.validation;  // as the tests' own context has it
  return desc;
}

uint64_t hostResidentBytes() {
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  if (!statm) return 0;
  unsigned long long size = 0, resident = 0;
  int read = std::fscanf(statm, "%llu %llu", &size, &resident);
  std::fclose(statm);
  return read == 2 ? uint64_t(resident) * uint64_t(::sysconf(_SC_PAGESIZE)) : 0;
}

unsigned long long parseCount(const std::string& option, const std::string& value) {
  unsigned long long result = 0;
  auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), result);
  if (value.empty() || error != std::errc() || end != value.data() + value.size()) {
    throw UsageError{option + " expects a whole number, got '" + value + "'"};
  }
  return result;
}

void parseSize(const std::string& option, const std::string& value, uint32_t& width, uint32_t& height) {
  size_t x = value.find('x');
  if (x == std::string::npos) throw UsageError{option + " expects WxH, e.g. 640x480, got '" + value + "'"};
  unsigned long long w = parseCount(option, value.substr(0, x)), h = parseCount(option, value.substr(x + 1));
  if (w == 0 || h == 0 || w > 65536 || h > 65536) {
    throw UsageError{option + " " + value + " is out of range (1x1 to 65536x65536)"};
  }
  width = uint32_t(w);
  height = uint32_t(h);
}

uint64_t parseTextureBudget(const std::string& option, const std::string& value) {
  unsigned long long mib = parseCount(option, value);
  if (mib == 0 || mib > (1ull << 20)) throw UsageError{option + " " + value + " is out of range (1 to 1048576 MiB)"};
  return uint64_t(mib) << 20;
}

std::vector<double> parseNumbers(const std::string& option, const std::string& value, size_t count) {
  std::vector<double> numbers;
  std::stringstream in(value);
  std::string part;
  while (std::getline(in, part, ',')) {
    char* end = nullptr;
    double v = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !std::isfinite(v)) break;
    numbers.push_back(v);
  }
  if (numbers.size() != count || std::count(value.begin(), value.end(), ',') != long(count - 1)) {
    throw UsageError{option + " expects " + std::to_string(count) + " comma-separated numbers, got '" + value + "'"};
  }
  return numbers;
}

bool ShotOptions::take(const std::string& command, const Args& args, size_t& i) {
  const std::string& a = args[i];
  if (a == "--eye") {
    eye = true;
    return true;
  }
  if (!a.empty() && a[0] != '-') {
    if (!input.empty()) throw UsageError{command + ": more than one scene given ('" + input + "', '" + a + "')"};
    input = a;
    return true;
  }
  static const char* const kWithValue[] = {"--size", "--camera", "--look-at", "--fov", "--time", "--max-interfaces",
                                           "--background", "--scene", "--ignore-extension", "--texture-budget"};
  if (std::find(std::begin(kWithValue), std::end(kWithValue), a) == std::end(kWithValue)) return false;
  if (i + 1 >= args.size()) throw UsageError{command + ": " + a + " needs a value"};
  const std::string& v = args[++i];
  if (a == "--size") {
    parseSize(a, v, width, height);
  } else if (a == "--camera") {
    view.camera = int(parseCount(a, v));
  } else if (a == "--look-at") {
    std::vector<double> n = parseNumbers(a, v, 6);
    view.lookAt = scene::LookAt{{n[0], n[1], n[2]}, {n[3], n[4], n[5]}, {0.0, 1.0, 0.0}};
  } else if (a == "--fov") {
    double deg = parseNumbers(a, v, 1)[0];
    if (!(deg > 0.0 && deg < 180.0)) throw UsageError{"--fov must be between 0 and 180 degrees, got " + v};
    view.yfov = deg * 3.14159265358979 / 180.0;
  } else if (a == "--time") {
    time = parseNumbers(a, v, 1)[0];
  } else if (a == "--max-interfaces") {
    maxInterfaces = uint32_t(std::min<unsigned long long>(parseCount(a, v), 1024));
  } else if (a == "--background") {
    std::vector<double> n = parseNumbers(a, v, 3);
    background = glm::vec3(glm::dvec3(n[0], n[1], n[2]));
  } else if (a == "--scene") {
    load.scene = v;
  } else if (a == "--ignore-extension") {
    load.ignoredExtensions.push_back(v);
  } else {
    load.textureBudget = parseTextureBudget(a, v);
  }
  return true;
}

void ShotOptions::require(const std::string& command) const {
  if (input.empty() && !eye) throw UsageError{command + ": give a scene file (or --eye)"};
  if (!input.empty() && eye) throw UsageError{command + ": give a scene file or --eye, not both"};
}

scene::Scene ShotOptions::loadScene() const {
  scene::Scene scene = eye ? scene::makeEye() : scene::loadGltf(input, load);
  if (eye) scene.source = "procedural eye";
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "snell: note: %s\n", w.c_str());
  return scene;
}

scene::View ShotOptions::resolveView(const std::string& command, const scene::Scene& scene,
                                     const scene::Pose& pose) const {
  try {
    return scene::resolveView(scene, pose, view);
  } catch (const std::invalid_argument& e) {
    throw UsageError{command + ": " + e.what()};
  }
}

std::unique_ptr<vk::Context> ShotOptions::openContext(const std::string& command) const {
  std::unique_ptr<vk::Context> context = vk::Context::create(contextDescFromEnvironment());
  try {
    render::checkImageSize(*context, width, height);
  } catch (const std::invalid_argument& e) {
    throw UsageError{command + ": " + e.what()};
  }
  return context;
}

uint32_t findTexturedMaterial(const std::string& command, const scene::Scene& scene, const std::string& wanted) {
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    if (scene.materials[i].name != wanted && std::to_string(i) != wanted) continue;
    if (!scene.materials[i].baseColorTexture.present()) {
      throw UsageError{command + ": --material " + wanted + " has no base colour texture for the UVs to address"};
    }
    return uint32_t(i);
  }
  throw UsageError{command + ": --material " + wanted + ": the scene has no such material (" +
                   std::to_string(scene.materials.size()) + " materials)"};
}

int validationExitCode(const vk::Context& context) {
  if (context.validationMessageCount() == 0) return 0;
  std::fprintf(stderr, "snell: the validation layer reported %llu message(s)\n",
               static_cast<unsigned long long>(context.validationMessageCount()));
  return 1;
}

std::string xmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string jsonEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  return out;
}

}  // namespace snell::cli
