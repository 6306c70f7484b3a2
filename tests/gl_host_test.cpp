// examples/gl_host as a user runs it, under Xvfb with Mesa's OpenGL: snell's
// image, imported into OpenGL through shared memory, composited over the
// host's own backdrop.
#include "assets.h"
#include "io/image_file.h"
#include "command_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

// The backdrop examples/gl_host draws at window row `y` (0 at the top), as GL writes it: no sRGB encoding.
std::array<int, 3> backdrop(uint32_t y, uint32_t height) {
  const float bottom[3] = {0.1f, 0.15f, 0.45f}, top[3] = {0.95f, 0.55f, 0.1f};
  float t = (float(height - 1 - y) + 0.5f) / float(height);
  std::array<int, 3> c;
  for (int k = 0; k < 3; ++k) c[size_t(k)] = int(std::lround(255.0f * (bottom[k] + (top[k] - bottom[k]) * t)));
  return c;
}

TEST(GlHost, ItsScreenshotIsTheViewportRenderOverItsOwnBackdrop) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) {
    FAIL() << "xvfb-run is not installed (Debian 12: apt-get install xvfb xauth; scripts/bootstrap test does)";
  }
  fs::path dir = scratchDir("gl-host");
  std::string eye = (dir / "eye.glb").string(), shot = (dir / "gl.ppm").string(), render = (dir / "render.png").string();
  CommandRun made = runCommand(std::string(SNELL_BINARY) + " eye -o " + shellQuoted(eye));
  ASSERT_EQ(made.exitCode, 0) << made.output;
  // Twelve frames from 0 to 0.5 s: the host's image follows the animation to its last frame.
  CommandRun run = runCommand("xvfb-run -a -s '-screen 0 640x480x24' " + std::string(SNELL_GL_HOST_BINARY) + " " +
                              shellQuoted(eye) + " --size 160x120 --frames 12 --time 0.5 --screenshot " + shellQuoted(shot));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("hand-over:"), std::string::npos) << run.output;
  CommandRun reference = runCommand(std::string(SNELL_BINARY) + " render " + shellQuoted(eye) +
                                    " --viewport --time 0.5 --size 160x120 -o " + shellQuoted(render));
  ASSERT_EQ(reference.exitCode, 0) << reference.output;

  io::Rgb8Image got = io::readRgb8(shot), expected = io::readRgb8(render);
  ASSERT_EQ(got.width, expected.width);
  ASSERT_EQ(got.height, expected.height);
  // Where snell drew nothing (its background), the host's backdrop shows;
  // everywhere else snell's pixel, to the rounding of the blit's sRGB encoding.
  const uint8_t* background = expected.rgb.data();  // the corner: no eye there
  size_t host = 0, snell = 0, wrong = 0;
  int worst = 0;
  for (uint32_t y = 0; y < got.height; ++y) {
    for (uint32_t x = 0; x < got.width; ++x) {
      size_t i = 3 * (size_t(y) * got.width + x);
      int fromSnell = 0, fromHost = 0;
      std::array<int, 3> b = backdrop(y, got.height);
      for (int c = 0; c < 3; ++c) {
        fromSnell = std::max(fromSnell, std::abs(int(got.rgb[i + size_t(c)]) - int(expected.rgb[i + size_t(c)])));
        fromHost = std::max(fromHost, std::abs(int(got.rgb[i + size_t(c)]) - b[size_t(c)]));
      }
      bool snellBackground = std::equal(background, background + 3, &expected.rgb[i]);
      if (snellBackground && fromHost <= 1) {
        ++host;
      } else if (fromSnell <= 1) {
        ++snell, worst = std::max(worst, fromSnell);
      } else {
        ++wrong;
      }
    }
  }
  EXPECT_EQ(wrong, 0u) << "pixels neither snell's nor the backdrop's";
  EXPECT_GT(host, 5000u) << "the backdrop should show around the eye";
  EXPECT_GT(snell, 5000u) << "the eye should cover much of the window";
  std::printf("gl_host 160x120: %zu backdrop pixels, %zu of snell's (worst difference %d/255), %zu wrong\n", host,
              snell, worst, wrong);
}

}  // namespace
}  // namespace snell::test
