// The script reader: checks every line before the viewer starts, so a typo
// fails at once instead of halfway through a test.
#include "script.h"

#include <charconv>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace snell::viewer {

namespace {

enum class Arg { Number, Switch, Camera, Text };

const std::map<std::string, std::vector<Arg>>& grammar() {
  static const std::map<std::string, std::vector<Arg>> actions = {
      {"resize", {Arg::Number, Arg::Number}}, {"orbit", {Arg::Number, Arg::Number}},
      {"pan", {Arg::Number, Arg::Number}},    {"dolly", {Arg::Number}},
      {"filmpan", {Arg::Number, Arg::Number}}, {"filmzoom", {Arg::Number}},
      {"filmreset", {}},                      {"frame", {}},
      {"camera", {Arg::Camera}},              {"play", {}},
      {"pause", {}},                          {"scrub", {Arg::Number}},
      {"loop", {Arg::Switch}},                {"refraction", {Arg::Switch}},
      {"wireframe", {Arg::Switch}},           {"heatmap", {Arg::Switch}},
      {"gate", {Arg::Switch}},                {"split", {Arg::Switch}},
      {"ui", {Arg::Switch}},                  {"minimise", {}},
      {"restore", {}},                        {"load", {Arg::Text}},
      {"method", {Arg::Text}},                {"screenshot", {}},
      {"quit", {}}};
  return actions;
}

bool isNumber(const std::string& s) {
  std::istringstream in(s);
  double v;
  return (in >> v) && in.eof();
}

}  // namespace

std::vector<ScriptAction> loadScript(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the script");
  std::vector<ScriptAction> script;
  std::string text;
  int lineNumber = 0;
  while (std::getline(in, text)) {
    ++lineNumber;
    size_t hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    std::istringstream words(text);
    std::string frame;
    if (!(words >> frame)) continue;  // blank or comment
    auto fail = [&](const std::string& why) {
      throw std::runtime_error(path + ":" + std::to_string(lineNumber) + ": " + why);
    };
    ScriptAction a;
    a.line = lineNumber;
    auto [end, error] = std::from_chars(frame.data(), frame.data() + frame.size(), a.frame);
    if (error != std::errc() || end != frame.data() + frame.size()) fail("expected a frame number, got '" + frame + "'");
    if (!(words >> a.action)) fail("frame " + frame + " has no action");
    auto rule = grammar().find(a.action);
    if (rule == grammar().end()) fail("unknown action '" + a.action + "'");
    std::string arg;
    while (words >> arg) a.args.push_back(arg);
    if (a.args.size() != rule->second.size()) {
      fail("'" + a.action + "' takes " + std::to_string(rule->second.size()) + " argument(s), got " +
           std::to_string(a.args.size()));
    }
    for (size_t i = 0; i < a.args.size(); ++i) {
      const std::string& v = a.args[i];
      switch (rule->second[i]) {
        case Arg::Number:
          if (!isNumber(v)) fail("'" + a.action + "' expects a number, got '" + v + "'");
          break;
        case Arg::Switch:
          if (v != "on" && v != "off") fail("'" + a.action + "' expects on or off, got '" + v + "'");
          break;
        case Arg::Camera:
          if (v != "orbit" && !isNumber(v)) fail("'camera' expects a camera index or 'orbit', got '" + v + "'");
          break;
        case Arg::Text:
          break;
      }
    }
    if (!script.empty() && a.frame < script.back().frame) fail("frames must not go backwards");
    script.push_back(std::move(a));
  }
  return script;
}

}  // namespace snell::viewer
