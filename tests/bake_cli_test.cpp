// `snell bake` and `snell export-web` as a user runs them, and the exported
// page in a real browser: Debian's Chromium, headless, on software GL.
#include "assets.h"
#include "command_run.h"

#include "bake/map_file.h"
#include "bake/refraction_bake.h"
#include "io/image_compare.h"
#include "io/image_file.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(BakeCommand, WritesEachEncodingAndSaysWhatTheGlassLandsOn) {
  fs::path dir = scratchDir("snell_bake_cli");
  for (const char* args : {"--encoding rg16 -o map16.png", "-o map.exr", "-o map8.png"}) {
    CommandRun bake = runCommand("cd " + shellQuoted(dir.string()) + " && " + SNELL_BINARY + " bake --eye --size 64x48 " + args);
    ASSERT_EQ(bake.exitCode, 0) << args << "\n" << bake.output;
    EXPECT_NE(bake.output.find("land on material 'iris'"), std::string::npos) << bake.output;
  }
  EXPECT_TRUE(fs::exists(dir / "map16.png"));
  EXPECT_TRUE(fs::exists(dir / "map.exr"));
  EXPECT_TRUE(fs::exists(dir / "map8.png"));
  fs::remove_all(dir);
}

TEST(BakeCommand, AnEncodingItsExtensionCannotHoldIsAUsageErrorAndWritesNothing) {
  fs::path dir = scratchDir("snell_bake_wrong_extension");
  CommandRun run = snell("bake --eye --encoding rg16 -o " + shellQuoted((dir / "map.exr").string()));
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_NE(run.output.find("rg16"), std::string::npos) << run.output;
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(BakeCommand, AMaterialWithoutATextureIsAUsageError) {
  CommandRun run = snell("bake --eye --material cornea -o /tmp/snell_never_written.png");
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_NE(run.output.find("cornea"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists("/tmp/snell_never_written.png"));
}

TEST(RenderCommand, BakeTimeWithoutTheRefractionMapMethodIsAUsageError) {
  CommandRun run = snell("render --eye --bake-time 1 -o /tmp/snell_never_written.png");
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_FALSE(fs::exists("/tmp/snell_never_written.png"));
}

// ------------------------------------------------------------------ the page in Chromium

const char* chromium() {
  const char* configured = std::getenv("SNELL_CHROMIUM");
  return configured ? configured : "/usr/bin/chromium";
}

std::string chromiumCommand(const fs::path& page, const std::string& action) {
  // SwiftShader is Chromium's own software GL: the same pixels on every machine, GPU or not.
  // Headless Chromium's own throwaway profile: with --user-data-dir the
  // screenshot came back without the WebGL canvas (Chromium 156).
  return std::string(chromium()) +
         " --headless --no-sandbox --disable-gpu-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader"
         " --hide-scrollbars --force-device-scale-factor=1 " + action + " " +
         shellQuoted("file://" + page.string());
}

io::Rgb8Image screenshot(const fs::path& page, uint32_t width, uint32_t height) {
  fs::path shot = page.parent_path() / "screenshot.png";
  CommandRun run = runCommand(chromiumCommand(page, "--screenshot=" + shellQuoted(shot.string()) + " --window-size=" +
                                                        std::to_string(width) + "," + std::to_string(height)));
  if (!fs::exists(shot)) throw std::runtime_error("chromium wrote no screenshot:\n" + run.output);
  return io::readRgb8(shot.string());
}

// The page against the render (io/image_compare.h), over the glass pixels
// whose path lands on the map's texture and over the whole image.
struct PageMatch {
  io::ImageDifference glass, image;
};

PageMatch match(const io::Rgb8Image& page, const io::Rgb8Image& render, const bake::DecodedMap& map) {
  std::vector<bool> lands(map.coverage.size());
  for (size_t i = 0; i < lands.size(); ++i) lands[i] = map.coverage[i] == bake::Coverage::Lands;
  return {io::compareImages(page, render, &lands), io::compareImages(page, render)};
}

// The exported page, opened from the file system by headless Chromium, shows
// what `snell render --method refraction-map` draws of the same view: its
// shader decodes the sky8 map as the seed does. The same page with the
// seed's tile lines broken fails the same comparison, so this test can fail.
TEST(ExportWebCommand, ThePageInChromiumDrawsWhatTheRefractionMapMethodRenders) {
  ASSERT_TRUE(fs::exists(chromium())) << chromium() << " is missing: 'scripts/bootstrap test' installs Debian's chromium";
  const uint32_t width = 160, height = 120;
  fs::path dir = scratchDir("snell_export_web");
  fs::path site = dir / "site";
  CommandRun exported = snell("export-web --eye --size 160x120 -o " + shellQuoted(site.string()));
  ASSERT_EQ(exported.exitCode, 0) << exported.output;
  std::smatch bytes;
  ASSERT_TRUE(std::regex_search(exported.output, bytes, std::regex("the page loads ([0-9]+) bytes"))) << exported.output;
  for (const char* file : {"index.html", "snell-web.js", "images.js", "map.png", "behind-0.png", "diffuse.png", "weight.png"}) {
    EXPECT_TRUE(fs::exists(site / file)) << file;
  }
  CommandRun rendered = snell("render --eye --size 160x120 --method refraction-map -o " +
                              shellQuoted((dir / "render.png").string()));
  ASSERT_EQ(rendered.exitCode, 0) << rendered.output;
  io::Rgb8Image render = io::readRgb8((dir / "render.png").string());
  bake::Encoding encoding = bake::Encoding::Exr;
  bake::MapPixels mapPixels = bake::readMapFile((site / "map.png").string(), encoding);
  bake::DecodedMap map = bake::decodeMap(mapPixels, encoding);
  ASSERT_EQ(encoding, bake::Encoding::Sky8);

  io::Rgb8Image page = screenshot(site / "index.html", width, height);
  ASSERT_EQ(page.width, width);
  ASSERT_EQ(page.height, height);
  // The same layers and mips, read by the browser's sampler in 8-bit sRGB: within 1/255.
  PageMatch m = match(page, render, map);
  std::printf("the page: %llu of %llu glass pixels and %llu of %llu pixels within 1/255 of the render\n",
              (unsigned long long)(m.glass.pixels - m.glass.over1), (unsigned long long)m.glass.pixels,
              (unsigned long long)(m.image.pixels - m.image.over1), (unsigned long long)m.image.pixels);
  ASSERT_GT(m.glass.pixels, 1000u);
  EXPECT_LE(m.glass.share(m.glass.over1), 0.005);
  EXPECT_LE(m.image.share(m.image.over1), 0.001);

  // The page times itself: navigation to its first frame.
  CommandRun dom = runCommand(chromiumCommand(site / "index.html", "--dump-dom"));
  std::smatch ms;
  ASSERT_TRUE(std::regex_search(dom.output, ms, std::regex("data-first-frame-ms=\"([0-9.]+)\""))) << dom.output;
  std::smatch status;
  std::regex_search(dom.output, status, std::regex("first frame [^<]*"));
  std::printf("%s (headless Chromium, SwiftShader); the page loads %s bytes\n", status.str().c_str(),
              bytes[1].str().c_str());

  // A broken decoder: the blue byte's tile of u read as 0.
  fs::path broken = dir / "broken";
  fs::create_directories(broken);
  for (const auto& entry : fs::directory_iterator(site)) {
    if (entry.is_regular_file()) fs::copy_file(entry.path(), broken / entry.path().filename());
  }
  std::string script = readText(broken / "snell-web.js");
  const std::string tileLine = "u += floor(normal.b * 16.0) * 16.0;";
  ASSERT_NE(script.find(tileLine), std::string::npos) << "the seed's decoder line is in the page";
  script.replace(script.find(tileLine), tileLine.size(), "u += 0.0;");
  std::ofstream(broken / "snell-web.js", std::ios::binary) << script;
  PageMatch b = match(screenshot(broken / "index.html", width, height), render, map);
  std::printf("with the broken decoder: %llu of %llu glass pixels within 1/255\n",
              (unsigned long long)(b.glass.pixels - b.glass.over1), (unsigned long long)b.glass.pixels);
  EXPECT_GT(b.glass.share(b.glass.over1), 0.5) << "the comparison notices a wrongly decoded map";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace snell::test
