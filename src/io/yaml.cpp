// YAML for job templates (see yaml.h).
#include "io/yaml.h"

namespace snell::io {

namespace {

std::string yamlScalar(const Json& value) {
  if (!value.is_string()) return value.dump();
  std::string quoted = "'";
  for (char c : value.get<std::string>()) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

void emitYaml(const Json& node, const std::string& indent, std::string& out) {
  if (node.is_object()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      const Json& value = it.value();
      out += indent + it.key() + ":";
      if (value.is_object() && !value.empty()) {
        out += "\n";
        emitYaml(value, indent + "  ", out);
      } else if (value.is_array() && !value.empty()) {
        out += "\n";
        emitYaml(value, indent, out);
      } else {
        out += " " + (value.is_structured() ? std::string(value.is_array() ? "[]" : "{}") : yamlScalar(value)) + "\n";
      }
    }
  } else if (node.is_array()) {
    for (const Json& item : node) {
      if (item.is_structured() && !item.empty()) {
        std::string inner;
        emitYaml(item, indent + "  ", inner);
        out += indent + "- " + inner.substr(indent.size() + 2);
      } else {
        out += indent + "- " + (item.is_structured() ? std::string(item.is_array() ? "[]" : "{}") : yamlScalar(item)) + "\n";
      }
    }
  }
}

}  // namespace

std::string yamlText(const Json& json) {
  std::string out;
  emitYaml(json, "", out);
  return out;
}

}  // namespace snell::io
