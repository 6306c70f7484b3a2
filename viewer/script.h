// Scripted input for tests and demos (--script FILE): one action per line,
// "<frame> <action> [arguments]", run when the viewer reaches that frame.
// The actions call the same handlers as the mouse and keyboard.
//
//   resize W H        orbit DX DY       pan DX DY        dolly STEPS
//   filmpan DX DY     filmzoom STEPS    filmreset        frame
//   camera N|orbit    play | pause      scrub SECONDS    loop on|off
//   refraction on|off wireframe on|off  heatmap on|off   gate on|off
//   split on|off      ui on|off         minimise         restore
//   load PATH         method NAME       screenshot       quit
//
// screenshot does what the screenshot key (F12) does: the frame as shown, to
// snell-view-YYYYMMDD-HHMMSS.png in the current folder.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace snell::viewer {

struct ScriptAction {
  uint64_t frame = 0;
  std::string action;
  std::vector<std::string> args;
  int line = 0;  ///< in the script file, for messages
};

/// Reads a script; throws std::runtime_error naming the file and line of the
/// first unknown action or malformed argument.
std::vector<ScriptAction> loadScript(const std::string& path);

}  // namespace snell::viewer
