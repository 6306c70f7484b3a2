#include "io/json.h"

#include "io/image_file.h"
#include "io/version.h"

#include <algorithm>
#include <ctime>
#include <vector>

namespace snell::io {

namespace {

std::vector<std::string>& recordedWords() {
  static std::vector<std::string> words;
  return words;
}

}  // namespace

std::string shellQuoted(const std::string& word) {
  if (!word.empty() && word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./=:,+@%") ==
                           std::string::npos) {
    return word;
  }
  std::string quoted = "'";
  for (char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

void recordCommandLine(int argc, const char* const* argv) {
  recordedWords().assign(argv, argv + argc);
}

std::string commandLine() {
  std::string line;
  for (const std::string& w : recordedWords()) line += (line.empty() ? "" : " ") + shellQuoted(w);
  return line;
}

Json deviceJson(const vk::DeviceFacts& device) {
  char api[32];
  std::snprintf(api, sizeof api, "%u.%u.%u", VK_API_VERSION_MAJOR(device.apiVersion),
                VK_API_VERSION_MINOR(device.apiVersion), VK_API_VERSION_PATCH(device.apiVersion));
  return Json{{"name", device.name},
              {"index", device.index},
              {"driver", device.driverName},
              {"driver_info", device.driverInfo},
              {"vulkan", api},
              {"device_local_bytes", device.deviceLocalBytes},
              {"subgroup_size", device.subgroupSize},
              {"uuid", device.uuid},
              {"pci_bus", device.pciBus.empty() ? Json() : Json(device.pciBus)}};
}

Json reportHead(const std::string& kind, const vk::DeviceFacts* device) {
  std::time_t now = std::time(nullptr);
  char created[32];
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(created, sizeof created, "%Y-%m-%dT%H:%M:%SZ", &utc);
  Json head{{"schema", "snell." + kind + "/1"},
            {"snell_version", version()},
            {"created", created},
            {"command_line", commandLine()}};
  if (device) head["device"] = deviceJson(*device);
  return head;
}

std::string jsonText(const Json& json) {
  return json.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

void writeJson(const std::string& path, const Json& json) { writeTextFile(path, jsonText(json)); }

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace snell::io
