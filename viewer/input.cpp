// The viewer's input: keys (layout-aware: letters by what the layout prints,
// held arrows keep stepping), the mouse and wheel moving the active viewport's
// camera or film back, files dropped on the window, and the scripted input of
// --script, which calls the same handlers. The help text that lists the
// bindings lives here too, beside them.
#include "viewer_state.h"

#include "render/method.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace snell::viewer {

const char* const kControlsHelp =
    R"(mouse (Maya):  Alt+left drag tumble, Alt+middle track, Alt+right dolly
trackpad:      left drag tumble, Shift+left track, Ctrl+left or wheel dolly
keys:          F frame, Space play, Left/Right step (held: keep stepping),
               Home start, \ 2D pan/zoom of the film back, Backspace reset
               the film back, R refraction, W wireframe, H heat map,
               G film gate, B bake the refraction map again, 2 two viewports,
               F12 screenshot (snell-view-YYYYMMDD-HHMMSS.png in the current
               folder), Tab overlay, Esc quit
               Letters go by what the keyboard layout prints on the key; 2 and
               \ also by their place on a US keyboard, for layouts that need
               Shift or AltGr for them (German: # beside Enter for \)
drop a .gltf/.glb on the window to open it)";

namespace {

// The character a key's place has on a US keyboard: GLFW's key tokens name
// places (from the scancode), not what the layout prints there.
int usCharacter(int key, bool letters) {
  if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) return '0' + (key - GLFW_KEY_0);
  if (key == GLFW_KEY_BACKSLASH) return '\\';
  if (letters && key >= GLFW_KEY_A && key <= GLFW_KEY_Z) return 'a' + (key - GLFW_KEY_A);
  return 0;
}

// The shortcut character of a printable key: what the user's layout prints
// on it (glfwGetKeyName), so W is wireframe wherever the layout puts W. The
// characters that need Shift or AltGr on some layouts (2 on French, the
// backslash on German) also answer at their US place when the key there
// prints punctuation or a letter outside ASCII (é, #): every shortcut has a key.
// Layouts with no Latin letters fall back to the US places altogether.
// 0: not a printable key (those go by their token: F12, Space, arrows...).
int shortcutCharacter(int key, int scancode) {
  const char* name = glfwGetKeyName(key, scancode);
  if (!name || !name[0]) return usCharacter(key, true);
  auto c = static_cast<unsigned char>(name[0]);
  if (name[1] == '\0' && c < 0x80) {
    if (c >= 'A' && c <= 'Z') return c - 'A' + 'a';
    if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '\\') return c;
    return usCharacter(key, false);  // punctuation: only digits and \ by place
  }
  return usCharacter(key, true);  // not ASCII: é on the French 2 key, Cyrillic letters...
}

// Cursor positions come in window units; viewports are laid out in framebuffer
// pixels, which differ on scaled (HiDPI) displays.
double pixelsPerUnit(GLFWwindow* w) {
  int windowWidth = 0, windowHeight = 0, pixelWidth = 0, pixelHeight = 0;
  glfwGetWindowSize(w, &windowWidth, &windowHeight);
  glfwGetFramebufferSize(w, &pixelWidth, &pixelHeight);
  return windowWidth > 0 && pixelWidth > 0 ? double(pixelWidth) / double(windowWidth) : 1.0;
}

constexpr double kStepSeconds = 1.0 / 24.0;  ///< Left/Right: one film frame

}  // namespace

void Viewer::onKey(GLFWwindow* w, int key, int scancode, int action, int) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (action == GLFW_RELEASE || self->ui_->wantsKeyboard()) return;
  Toggles& t = self->toggles_;
  Viewport& vp = self->viewports_[self->active_];
  // Held arrows repeat (GLFW_REPEAT): scrubbing frame by frame.
  switch (key) {
    case GLFW_KEY_LEFT: self->time_ = std::max(0.0, self->time_ - kStepSeconds); return;
    case GLFW_KEY_RIGHT: self->time_ = std::min(self->duration_, self->time_ + kStepSeconds); return;
    default: break;
  }
  if (action != GLFW_PRESS) return;  // a held toggle toggles once
  switch (key) {
    case GLFW_KEY_SPACE: t.playing = !t.playing; return;
    case GLFW_KEY_TAB: t.ui = !t.ui; return;
    case GLFW_KEY_BACKSPACE: vp.rig.resetFilm(); return;
    case GLFW_KEY_HOME: self->time_ = 0.0; return;
    case GLFW_KEY_F12: self->shotRequested_ = true; return;
    case GLFW_KEY_ESCAPE: self->quit_ = true; return;
    default: break;
  }
  switch (shortcutCharacter(key, scancode)) {
    case 'f': self->frameScene(); break;
    case 'r': t.refraction = !t.refraction; break;
    case 'w': t.wireframe = !t.wireframe && self->context_->caps().fillModeNonSolid; break;
    case 'h': t.heatMap = !t.heatMap; break;
    case 'b': self->rebake_ = true; break;
    case 'g': t.gate = !t.gate; break;
    case '2': t.split = !t.split; break;
    case '\\': t.filmMode = !t.filmMode; break;
    default: break;
  }
}

void Viewer::onMouseButton(GLFWwindow* w, int button, int action, int mods) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (button < 0 || button > 2) return;
  if (action == GLFW_PRESS) {
    if (self->ui_->wantsMouse()) return;
    glfwGetCursorPos(w, &self->lastX_, &self->lastY_);
    double scale = pixelsPerUnit(w);
    self->lastX_ *= scale;
    self->lastY_ *= scale;
    self->viewportAt(self->lastX_, self->lastY_);
    self->buttons_ |= 1 << button;
    self->dragMods_ = mods;
  } else {
    self->buttons_ &= ~(1 << button);
  }
}

// Maya: Alt + left tumbles, Alt + middle tracks, Alt + right dollies. Without
// a middle button or where Alt-drag moves windows: left tumbles, Shift + left
// tracks, Ctrl + left dollies. In film mode (\) left drag pans the film back.
void Viewer::onCursor(GLFWwindow* w, double x, double y) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  double scale = pixelsPerUnit(w);
  x *= scale;
  y *= scale;
  double dx = x - self->lastX_, dy = y - self->lastY_;
  self->lastX_ = x;
  self->lastY_ = y;
  if (!self->buttons_) return;
  Viewport& vp = self->viewports_[self->active_];
  bool left = self->buttons_ & 1, right = self->buttons_ & 2, middle = self->buttons_ & 4;
  int mods = self->dragMods_;
  if (self->toggles_.filmMode && left) {
    vp.rig.panFilm(dx, dy, vp.height);
    return;
  }
  self->leaveSceneCamera(vp);
  if (middle || (left && (mods & GLFW_MOD_SHIFT))) {
    vp.rig.pan(dx, dy, vp.height);
  } else if (right || (left && (mods & GLFW_MOD_CONTROL))) {
    vp.rig.dolly((dx - dy) * 0.05);
  } else if (left) {
    vp.rig.orbit(dx, dy);
  }
}

void Viewer::onScroll(GLFWwindow* w, double, double dy) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (self->ui_->wantsMouse()) return;
  double x = 0, y = 0;
  glfwGetCursorPos(w, &x, &y);
  Viewport& vp = *self->viewportAt(x * pixelsPerUnit(w), y);
  if (self->toggles_.filmMode) {
    vp.rig.zoomFilm(dy);
  } else {
    self->leaveSceneCamera(vp);
    vp.rig.dolly(dy);
  }
}

void Viewer::onDrop(GLFWwindow* w, int count, const char** paths) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (count > 0) self->pendingLoad_ = paths[0];  // loaded between frames, not inside GLFW's callback
}

// The script's actions due by `frame` (script.h lists them), each echoed on
// standard output as "frame N: ACTION ARGS".
void Viewer::applyScript(uint64_t frame) {
  while (nextAction_ < script_.size() && script_[nextAction_].frame <= frame) {
    const ScriptAction& a = script_[nextAction_++];
    auto number = [&](size_t i) { return std::stod(a.args[i]); };
    auto on = [&](size_t i) { return a.args[i] == "on"; };
    Viewport& vp = viewports_[active_];
    std::printf("frame %llu: %s", static_cast<unsigned long long>(frame), a.action.c_str());
    for (const std::string& arg : a.args) std::printf(" %s", arg.c_str());
    std::printf("\n");
    if (a.action == "resize") {
      int w = std::max(1, int(number(0))), h = std::max(1, int(number(1)));
      if (window_) {
        glfwSetWindowSize(window_, w, h);
      } else {
        options_.width = uint32_t(w);
        options_.height = uint32_t(h);
      }
    } else if (a.action == "orbit") {
      leaveSceneCamera(vp);
      vp.rig.orbit(number(0), number(1));
    } else if (a.action == "pan") {
      leaveSceneCamera(vp);
      vp.rig.pan(number(0), number(1), vp.height);
    } else if (a.action == "dolly") {
      leaveSceneCamera(vp);
      vp.rig.dolly(number(0));
    } else if (a.action == "filmpan") {
      vp.rig.panFilm(number(0), number(1), vp.height);
    } else if (a.action == "filmzoom") {
      vp.rig.zoomFilm(number(0));
    } else if (a.action == "filmreset") {
      vp.rig.resetFilm();
    } else if (a.action == "frame") {
      frameScene();
    } else if (a.action == "camera") {
      if (a.args[0] == "orbit") {
        leaveSceneCamera(vp);
      } else if (number(0) >= 0.0 && cameraResolves(int(number(0)))) {
        vp.rig.sceneCamera = int(number(0));
      } else {
        message_ = "script line " + std::to_string(a.line) + ": no camera " + a.args[0] + " placed in the scene";
      }
    } else if (a.action == "play") {
      toggles_.playing = true;
    } else if (a.action == "pause") {
      toggles_.playing = false;
    } else if (a.action == "scrub") {
      time_ = std::clamp(number(0), 0.0, duration_);
    } else if (a.action == "loop") {
      toggles_.loop = on(0);
    } else if (a.action == "refraction") {
      toggles_.refraction = on(0);
    } else if (a.action == "method") {
      std::optional<render::Method> m = a.args.empty() ? std::nullopt : render::methodFromName(a.args[0]);
      if (m) {
        toggles_.method = *m;
      } else {
        message_ = "script line " + std::to_string(a.line) + ": method takes one of " + render::methodNames();
      }
    } else if (a.action == "wireframe") {
      toggles_.wireframe = on(0) && context_->caps().fillModeNonSolid;
    } else if (a.action == "heatmap") {
      toggles_.heatMap = on(0);
    } else if (a.action == "gate") {
      toggles_.gate = on(0);
    } else if (a.action == "split") {
      toggles_.split = on(0);
    } else if (a.action == "ui") {
      toggles_.ui = on(0);
    } else if (a.action == "minimise") {
      if (window_) glfwIconifyWindow(window_);
    } else if (a.action == "restore") {
      if (window_) glfwRestoreWindow(window_);
    } else if (a.action == "load") {
      pendingLoad_ = a.args[0];
    } else if (a.action == "screenshot") {
      shotRequested_ = true;  // as the screenshot key
    } else if (a.action == "quit") {
      quit_ = true;
    }
  }
}

}  // namespace snell::viewer
