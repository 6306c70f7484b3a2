// Option parsing and the device choice shared by `snell` and `snell-view`.
#include "cli/cli.h"

#include <algorithm>
#include <charconv>
#include <cstdlib>

namespace snell::cli {

vk::ContextDesc contextDescFromEnvironment() {
  vk::ContextDesc desc;
  const char* validation = std::getenv("SNELL_VALIDATION");
  desc.validation = validation && std::string(validation) == "1";
  desc.synchronizationValidation = desc.validation;  // as the tests' own context has it
  return desc;
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
