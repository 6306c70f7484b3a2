// The command line and file formats as a pipeline relies on them: exit codes,
// errors that name the option, --quiet, JSON that parses whatever the names
// hold, PNGs compressed like zlib would, EXRs a compositor reads.
#include "assets.h"
#include "command_run.h"

#include "io/json.h"
#include "io/version.h"
#include "scene/gltf_writer.h"
#include "scene/png.h"
#include "scene/procedural_eye.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

// Standard output alone: lavapipe writes its own warning to standard error.
CommandRun snellStdout(const std::string& arguments) {
  return runCommand(std::string(SNELL_BINARY) + " " + arguments + " 2>/dev/null");
}

// A fresh folder per test, removed with it.
struct TempFolder {
  fs::path path;
  explicit TempFolder(const std::string& name) : path(test::scratchDir("cli-" + name)) {}
  ~TempFolder() { fs::remove_all(path); }
  std::string operator/(const std::string& file) const { return (path / file).string(); }
};

io::Json readJson(const std::string& path) {
  std::ifstream in(path);
  return io::Json::parse(in);  // throws on invalid JSON
}

void expectHead(const io::Json& j, const std::string& kind) {
  EXPECT_EQ(j.at("schema"), "snell." + kind + "/1");
  EXPECT_EQ(j.at("snell_version"), io::version());
  EXPECT_FALSE(j.at("command_line").get<std::string>().empty());
  EXPECT_FALSE(j.at("device").at("name").get<std::string>().empty()) << j.dump(2);
  EXPECT_FALSE(j.at("device").at("driver").get<std::string>().empty());
}

// ---- exit codes and usage ---------------------------------------------------

struct BadOption {
  const char* arguments;
  const char* option;  // the message must name it
};

class BadOptionValue : public ::testing::TestWithParam<BadOption> {};

TEST_P(BadOptionValue, ExitsTwoNamingTheOptionAndTheSubcommandsHelp) {
  CommandRun run = snell(GetParam().arguments);
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_NE(run.output.find(GetParam().option), std::string::npos) << run.output;
  std::string command = std::string(GetParam().arguments).substr(0, std::string(GetParam().arguments).find(" -"));
  EXPECT_NE(run.output.find("Run 'snell " + command + " --help'"), std::string::npos) << run.output;
}

INSTANTIATE_TEST_SUITE_P(
    CommandLine, BadOptionValue,
    ::testing::Values(BadOption{"render --eye -o /tmp/snell_never.png --size 0x5", "--size"},
                      BadOption{"render --eye -o /tmp/snell_never.png --size big", "--size"},
                      BadOption{"render --eye -o /tmp/snell_never.png --max-interfaces 5000", "--max-interfaces"},
                      BadOption{"render --eye -o /tmp/snell_never.png --fov abc", "--fov"},
                      BadOption{"render --eye -o /tmp/snell_never.png --method bogus", "--method"},
                      BadOption{"render --eye -o /tmp/snell_never.png --frames 1:4 --time 2", "--time"},
                      BadOption{"render --eye -o /tmp/snell_never.txt", "--output"},
                      BadOption{"render --eye -o /tmp/snell_never.png --aov depth", "--aov"},
                      BadOption{"render --eye -o /tmp/snell_never.exr --aov colour", "--aov"},
                      BadOption{"render --eye -o /tmp/snell_never.png --nonsense", "--nonsense"},
                      BadOption{"eye -o /tmp/snell_never.glb --resolution many", "--resolution"},
                      BadOption{"eye -o /tmp/snell_never.obj", "--output"},
                      BadOption{"info --texture-budget 0 scene.glb", "--texture-budget"},
                      BadOption{"bench frame --frames lots", "--frames"}));

TEST(CommandLine, AnOptionTakesItsValueAfterAnEqualsSign) {
  TempFolder dir("equals");
  CommandRun run = snell("render --eye --size=32x24 --output=" + shellQuoted(dir / "eye.png"));
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_TRUE(fs::exists(dir / "eye.png"));
}

TEST(CommandLine, QuietPrintsNothingOnSuccess) {
  TempFolder dir("quiet");
  CommandRun run = snellStdout("render --eye --size 32x24 --quiet -o " + shellQuoted(dir / "eye.png"));
  EXPECT_EQ(run.exitCode, 0);
  EXPECT_EQ(run.output, "");
  EXPECT_TRUE(fs::exists(dir / "eye.png"));
  // Before the subcommand, and with frames whose progress would otherwise print.
  run = runCommand(std::string(SNELL_BINARY) + " -q render --eye --size 16x12 --frames 1:3 -o " +
                   shellQuoted(dir / "f.#.png") + " 2>&1 | grep -v -i lavapipe");
  EXPECT_EQ(run.output, "");
  EXPECT_TRUE(fs::exists(dir / "f.3.png"));
}

TEST(CommandLine, QuietKeepsTheJsonAskedForOnStandardOutput) {
  CommandRun run = snellStdout("--quiet info --devices --json -");
  EXPECT_EQ(run.exitCode, 0);
  io::Json j = io::Json::parse(run.output);  // the JSON alone: no table, no notes
  expectHead(j, "info");
}

TEST(CommandLine, HelpListsTheExitCodesAndExitsZero) {
  for (const char* command : {"--help", "render --help", "bench frame --help", "eye --help"}) {
    CommandRun run = snell(command);
    EXPECT_EQ(run.exitCode, 0) << command << run.output;
    EXPECT_NE(run.output.find("2 bad command line"), std::string::npos) << command << run.output;
  }
}

TEST(CommandLine, NoCommandIsAUsageError) {
  EXPECT_EQ(snell("").exitCode, 2);
  EXPECT_EQ(snell("paint").exitCode, 2);
}

TEST(CommandLine, ProgressOnARedirectedStreamIsPlainLinesWithTimeLeft) {
  TempFolder dir("progress");
  CommandRun run = snell("render --eye --size 16x12 --frames 1:3 -o " + shellQuoted(dir / "f.#.png"));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_EQ(run.output.find('\r'), std::string::npos) << "no carriage returns in a log";
  EXPECT_NE(run.output.find("1/3 frames"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("left"), std::string::npos) << run.output;
}

// Every command that opens a Vulkan device exits 1 when the validation layer
// speaks; SNELL_FAULT=validation-message makes it speak once, at creation.
class ValidationMessage : public ::testing::TestWithParam<const char*> {};

TEST_P(ValidationMessage, MakesTheCommandExitOne) {
  TempFolder dir("validation");
  std::string arguments = std::regex_replace(GetParam(), std::regex("DIR"), dir.path.string());
  CommandRun run = runCommand("SNELL_VALIDATION=1 SNELL_FAULT=validation-message " + std::string(SNELL_BINARY) + " " +
                              arguments);
  EXPECT_EQ(run.exitCode, 1) << arguments << "\n" << run.output;
  EXPECT_NE(run.output.find("validation"), std::string::npos) << run.output;
}

INSTANTIATE_TEST_SUITE_P(CommandLine, ValidationMessage,
                         ::testing::Values("render --eye --size 16x12 -o DIR/a.png",
                                           "bake --eye --size 16x12 -o DIR/a.png",
                                           "export-web --eye --size 16x12 -o DIR/web",
                                           "bench sort --min-log 10 --max-log 10 --runs 10 --warmup 1 --keys 32",
                                           "bench frame --eye-resolution 16 --frames 2 --size 32x24"));

// ---- JSON ------------------------------------------------------------------------

// A scene whose file, mesh and material names hold a quote, a backslash and non-ASCII.
std::string awkwardScene(const TempFolder& dir) {
  scene::Scene eye = scene::makeEye();
  for (scene::Shape& s : eye.shapes) s.name = "eye \"shape\" \\ " + s.name + " ünïcødé";
  for (scene::Material& m : eye.materials) m.name = "mat \"" + m.name + "\" \\ ø";
  std::string path = dir / "my \"eye\" \\ é.glb";
  scene::saveGltf(eye, path);
  return path;
}


struct JsonCommand {
  const char* kind;
  const char* arguments;  // SCENE and OUT are replaced
};

class JsonOutput : public ::testing::TestWithParam<JsonCommand> {};

TEST_P(JsonOutput, ParsesWithAwkwardNamesAndCarriesVersionAndDevice) {
  TempFolder dir(std::string("json_") + GetParam().kind);
  std::string scene = awkwardScene(dir), out = dir / "out \"q\" \\ ü.json";
  std::string arguments = GetParam().arguments;
  auto replace = [&](const std::string& word, const std::string& path) {
    if (size_t at = arguments.find(word); at != std::string::npos) arguments.replace(at, word.size(), shellQuoted(path));
  };
  replace("SCENE", scene);
  replace("OUT", out);
  CommandRun run = snell(arguments);
  ASSERT_EQ(run.exitCode, 0) << arguments << "\n" << run.output;
  io::Json j = readJson(out);
  expectHead(j, GetParam().kind);
  EXPECT_NE(j.at("command_line").get<std::string>().find("ü.json"), std::string::npos) << j.at("command_line");
  if (std::string(GetParam().arguments).find("SCENE") != std::string::npos) {
    EXPECT_NE(j.dump().find("my \\\"eye\\\" \\\\ é.glb"), std::string::npos) << "the scene's name, whole: " << j.dump(2);
  }
}

INSTANTIATE_TEST_SUITE_P(
    CommandLine, JsonOutput,
    ::testing::Values(JsonCommand{"info", "info SCENE --json OUT"}, JsonCommand{"info", "info --devices --json OUT"},
                      JsonCommand{"bench-frame", "bench frame SCENE --frames 2 --size 32x24 --json OUT"},
                      JsonCommand{"bench-bvh", "bench bvh SCENE --json OUT"},
                      JsonCommand{"bench-methods", "bench methods SCENE --size 32x24 --frames 1 --json OUT"},
                      JsonCommand{"bench-sort", "bench sort --min-log 10 --max-log 10 --runs 10 --warmup 1 --keys 32 --json OUT"}),
    [](const ::testing::TestParamInfo<JsonCommand>& info) {
      std::string name = std::string(info.param.kind) + "_" + std::to_string(info.index);
      for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
      return name;
    });

// `bench scale --compact-trees` measures the trees RendererOptions::compactTrees
// makes: 40 bytes a triangle, without the exact child boxes the default keeps.
TEST(BenchScale, CompactTreesAreMeasuredWithoutTheirExactChildBoxes) {
  TempFolder dir("bench_scale");
  auto bytesPerTriangle = [&](const std::string& name, const std::string& flags) {
    std::string out = dir / (name + ".json");
    CommandRun run = snell("bench scale --triangles 10000 --crowds 0 --refined 0 --runs 1 --sah-limit 0 " + flags +
                           " --json " + shellQuoted(out));
    EXPECT_EQ(run.exitCode, 0) << run.output;
    io::Json j = readJson(out);
    EXPECT_EQ(j.at("compact_trees").get<bool>(), !flags.empty());
    return j.at("spheres").at(0).at("tree_bytes_per_triangle").get<double>();
  };
  double compact = bytesPerTriangle("compact", "--compact-trees"), exact = bytesPerTriangle("exact", "");
  EXPECT_NEAR(compact, 40.0, 0.1);
  EXPECT_GT(exact, compact + 40.0);
}

// A subdivision cage whose faces carry three materials is one shape split in
// parts that share its refined vertices: one refine pass a frame, not three.
TEST(BenchScale, ACageOfSeveralMaterialsIsRefinedOnceAFrame) {
  TempFolder dir("bench_scale_materials");
  std::string out = dir / "scale.json";
  CommandRun run = snell("bench scale --triangles 0 --crowds 0 --refined 10000 --refined-materials 3 --frames 2 --json " +
                         shellQuoted(out));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  io::Json row = readJson(out).at("subdivision").at(0);
  EXPECT_EQ(row.at("materials").get<int>(), 3);
  EXPECT_EQ(row.at("refine_passes_per_frame").get<double>(), 1.0);
  EXPECT_GT(row.at("refit_ms").get<double>(), 0.0);
}

// What "refit ms" after a refine times: the refined surface's trees refit
// (two triangles a refined vertex), and none rebuilt while the cage waves.
TEST(BenchScale, ARefinedCageMovedEveryFrameIsRefitNotRebuilt) {
  TempFolder dir("bench_scale_refit");
  std::string out = dir / "scale.json";
  CommandRun run = snell("bench scale --triangles 0 --crowds 0 --refined 10000 --frames 3 --json " + shellQuoted(out));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  io::Json row = readJson(out).at("subdivision").at(0);
  EXPECT_EQ(row.at("trees_built").get<int>(), 0);
  EXPECT_EQ(row.at("trees_refit").get<int>(), 3) << "one tree, each timed frame";
  EXPECT_NEAR(row.at("triangles").get<double>(), 2.0 * row.at("refined_vertices").get<double>(),
              0.05 * row.at("refined_vertices").get<double>());
}

TEST(JsonWriter, DeviceNamesWithQuotesAndNonAsciiComeOutAsValidJson) {
  vk::DeviceFacts facts;
  facts.name = "GPU \"fast\" \\ Größe \x01";
  facts.driverName = "drv\tname";
  io::Json j = io::reportHead("test", &facts);
  io::Json back = io::Json::parse(io::jsonText(j));
  EXPECT_EQ(back.at("device").at("name"), facts.name);
  EXPECT_EQ(back.at("device").at("driver"), facts.driverName);
}

TEST(JsonWriter, InvalidUtf8IsReplacedNotThrown) {
  io::Json j = io::reportHead("test", nullptr);
  j["name"] = std::string("bad \xff\xfe bytes");
  io::Json back = io::Json::parse(io::jsonText(j));
  EXPECT_NE(back.at("name").get<std::string>().find("bytes"), std::string::npos);
}

// ---- image files ---------------------------------------------------------------

// What zlib at level 6 makes of the PNG's pixels, unfiltered: the bar a PNG encoder should not be twice above.
size_t zlibLevel6Bytes(const std::vector<uint8_t>& rows) {
  uLongf bytes = compressBound(uLong(rows.size()));
  std::vector<Bytef> out(bytes);
  EXPECT_EQ(compress2(out.data(), &bytes, rows.data(), uLong(rows.size()), 6), Z_OK);
  return size_t(bytes);
}

TEST(PngFiles, ARenderedFrameIsWithinTwiceWhatZlibLevel6Gives) {
  TempFolder dir("png");
  ASSERT_EQ(snell("render --eye --size 320x240 -o " + shellQuoted(dir / "eye.png")).exitCode, 0);
  OIIO::ImageBuf image(dir / "eye.png");
  ASSERT_TRUE(image.read(0, 0, true, OIIO::TypeDesc::UINT8));
  const OIIO::ImageSpec& spec = image.spec();
  std::vector<uint8_t> pixels(size_t(spec.width) * spec.height * size_t(spec.nchannels));
  ASSERT_TRUE(image.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, pixels.data()));
  std::vector<uint8_t> rows;  // a filter byte (none) before each row, as PNG stores them
  size_t rowBytes = size_t(spec.width) * size_t(spec.nchannels);
  for (int y = 0; y < spec.height; ++y) {
    rows.push_back(0);
    rows.insert(rows.end(), pixels.begin() + std::ptrdiff_t(y * rowBytes), pixels.begin() + std::ptrdiff_t((y + 1) * rowBytes));
  }
  size_t file = fs::file_size(dir / "eye.png"), zlib = zlibLevel6Bytes(rows);
  EXPECT_LE(file, 2 * zlib) << "PNG " << file << " bytes, zlib level 6 " << zlib;
}

// An image's bytes (big-endian samples, as PNG stores them) whose rows each
// favour one PNG filter: noise, then zeros (none), a ramp (sub), a copy of
// the noise above (up), and rows built from the average and Paeth predictors
// of the noise above them. Odd sizes, so no row is a round number of words.
std::vector<uint8_t> filterExercise(uint32_t w, uint32_t h, uint32_t pixelBytes) {
  const uint32_t rowBytes = w * pixelBytes;
  std::vector<uint8_t> bytes(size_t(rowBytes) * h);
  uint32_t noise = 12345u;
  for (uint32_t y = 0; y < h; ++y) {
    uint8_t* row = &bytes[size_t(y) * rowBytes];
    const uint8_t* above = y ? row - rowBytes : nullptr;
    for (uint32_t i = 0; i < rowBytes; ++i) {
      int left = i >= pixelBytes ? row[i - pixelBytes] : 0, up = above ? above[i] : 0;
      int upLeft = above && i >= pixelBytes ? above[i - pixelBytes] : 0;
      int p = left + up - upLeft, pa = std::abs(p - left), pb = std::abs(p - up), pc = std::abs(p - upLeft);
      noise = noise * 1664525u + 1013904223u;
      switch (y % 8) {
        case 1: row[i] = 0; break;
        case 2: row[i] = uint8_t(i * 3); break;
        case 4: row[i] = uint8_t(up); break;
        case 5: row[i] = uint8_t((left + up) / 2); break;
        case 7: row[i] = uint8_t(pa <= pb && pa <= pc ? left : pb <= pc ? up : upLeft); break;
        default: row[i] = uint8_t(noise >> 24);
      }
    }
  }
  return bytes;
}

std::vector<uint16_t> bigEndianSamples(const std::vector<uint8_t>& bytes) {
  std::vector<uint16_t> samples(bytes.size() / 2);
  for (size_t i = 0; i < samples.size(); ++i) samples[i] = uint16_t(bytes[2 * i] << 8 | bytes[2 * i + 1]);
  return samples;
}

// A PNG's samples as OpenImageIO reads them, alpha left as stored (not premultiplied).
template <typename Sample>
std::vector<Sample> readBack(const std::string& path, OIIO::TypeDesc type) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  OIIO::ImageBuf back(path, 0, 0, nullptr, &config);
  EXPECT_TRUE(back.read(0, 0, true, type)) << back.geterror();
  const OIIO::ImageSpec& spec = back.spec();
  std::vector<Sample> pixels(size_t(spec.width) * spec.height * size_t(spec.nchannels));
  EXPECT_TRUE(back.get_pixels(OIIO::ROI::All(), type, pixels.data()));
  return pixels;
}

// The filter type byte of each row of a PNG file (one IDAT chunk or more).
std::set<int> rowFilters(const std::vector<uint8_t>& png, uint32_t rowBytes, uint32_t height) {
  std::vector<uint8_t> idat;
  for (size_t at = 8; at + 12 <= png.size();) {
    uint32_t length = uint32_t(png[at]) << 24 | uint32_t(png[at + 1]) << 16 | uint32_t(png[at + 2]) << 8 | png[at + 3];
    if (std::string(png.begin() + std::ptrdiff_t(at + 4), png.begin() + std::ptrdiff_t(at + 8)) == "IDAT") {
      idat.insert(idat.end(), png.begin() + std::ptrdiff_t(at + 8), png.begin() + std::ptrdiff_t(at + 8 + length));
    }
    at += 12 + length;
  }
  std::vector<uint8_t> rows(size_t(height) * (rowBytes + 1));
  uLongf size = uLongf(rows.size());
  EXPECT_EQ(uncompress(rows.data(), &size, idat.data(), uLong(idat.size())), Z_OK);
  std::set<int> filters;
  for (uint32_t y = 0; y < height; ++y) filters.insert(rows[size_t(y) * (rowBytes + 1)]);
  return filters;
}

TEST(PngFiles, EveryFilterRoundTripsExactlyThroughAnotherDecoder) {
  TempFolder dir("png-filters");
  const uint32_t w = 67, h = 41;
  std::vector<uint8_t> rgba8 = filterExercise(w, h, 4);
  std::vector<uint16_t> rgba16 = bigEndianSamples(filterExercise(w, h, 8));
  std::vector<uint8_t> png8 = scene::encodePng(w, h, rgba8), png16 = scene::encodePng16(w, h, rgba16);
  std::ofstream(dir / "8.png", std::ios::binary).write(reinterpret_cast<const char*>(png8.data()), std::streamsize(png8.size()));
  std::ofstream(dir / "16.png", std::ios::binary).write(reinterpret_cast<const char*>(png16.data()), std::streamsize(png16.size()));
  EXPECT_EQ(rowFilters(png8, w * 4, h), (std::set<int>{0, 1, 2, 3, 4})) << "the rows should use every filter";
  EXPECT_EQ(rowFilters(png16, w * 8, h), (std::set<int>{0, 1, 2, 3, 4})) << "the rows should use every filter";
  EXPECT_EQ(readBack<uint8_t>(dir / "8.png", OIIO::TypeDesc::UINT8), rgba8);
  EXPECT_EQ(readBack<uint16_t>(dir / "16.png", OIIO::TypeDesc::UINT16), rgba16);
}

TEST(PngFiles, ALargeImageDeflatedInBandsIsOneValidStreamThatRoundTripsExactly) {
  TempFolder dir("png-bands");
  const uint32_t w = 2053, h = 613;  // 5 MB filtered: several bands at 8 and at 16 bits
  std::vector<uint8_t> rgba8 = filterExercise(w, h, 4);
  std::vector<uint16_t> rgba16 = bigEndianSamples(filterExercise(w / 2, h, 8));
  std::vector<uint8_t> png8 = scene::encodePng(w, h, rgba8), png16 = scene::encodePng16(w / 2, h, rgba16);
  // zlib's own inflate checks the stream's Adler-32, which a wrong join of the bands would break.
  EXPECT_EQ(rowFilters(png8, w * 4, h).size(), 5u);
  EXPECT_EQ(rowFilters(png16, (w / 2) * 8, h).size(), 5u);
  std::ofstream(dir / "8.png", std::ios::binary).write(reinterpret_cast<const char*>(png8.data()), std::streamsize(png8.size()));
  std::ofstream(dir / "16.png", std::ios::binary).write(reinterpret_cast<const char*>(png16.data()), std::streamsize(png16.size()));
  EXPECT_EQ(readBack<uint8_t>(dir / "8.png", OIIO::TypeDesc::UINT8), rgba8);
  EXPECT_EQ(readBack<uint16_t>(dir / "16.png", OIIO::TypeDesc::UINT16), rgba16);
}

TEST(PngFiles, SixteenBitMapsAreDeflatedToo) {
  const uint32_t w = 256, h = 128;
  std::vector<uint16_t> rgba(size_t(w) * h * 4);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      uint16_t* p = &rgba[(size_t(y) * w + x) * 4];
      p[0] = uint16_t(x * 256), p[1] = uint16_t(y * 512), p[2] = 0, p[3] = 65535;
    }
  }
  std::vector<uint8_t> png = scene::encodePng16(w, h, rgba);
  std::vector<uint8_t> rows;
  for (uint32_t y = 0; y < h; ++y) {
    rows.push_back(0);
    for (size_t i = size_t(y) * w * 4; i < size_t(y + 1) * w * 4; ++i) rows.push_back(uint8_t(rgba[i] >> 8)), rows.push_back(uint8_t(rgba[i]));
  }
  EXPECT_LE(png.size(), 2 * zlibLevel6Bytes(rows)) << png.size();
  TempFolder dir("png16");
  std::ofstream(dir / "map.png", std::ios::binary).write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
  OIIO::ImageBuf back(dir / "map.png");
  ASSERT_TRUE(back.read(0, 0, true, OIIO::TypeDesc::UINT16));
  uint16_t pixel[4];
  back.get_pixels(OIIO::ROI(100, 101, 50, 51, 0, 1, 0, 4), OIIO::TypeDesc::UINT16, pixel);
  EXPECT_EQ(pixel[0], uint16_t(100 * 256));
  EXPECT_EQ(pixel[1], uint16_t(50 * 512));
}

TEST(ExrFiles, AovLayersRoundTripThroughOpenImageIOWithNamedChannelsAndMetadata) {
  TempFolder dir("exr");
  std::string path = dir / "eye.exr";
  CommandRun run = snell("render --eye --size 64x48 --time 0.5 --aov depth,normal,instance,primitive,interfaces,cost -o " +
                         shellQuoted(path));
  ASSERT_EQ(run.exitCode, 0) << run.output;
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in) << OIIO::geterror();
  const OIIO::ImageSpec& spec = in->spec();
  // EXR keeps channels sorted by name; colour comes first as OpenImageIO reads them.
  std::vector<std::string> want = {"R", "G", "B", "A", "cost.nodes", "depth.Z", "instance.id", "interfaces.count",
                                   "normal.X", "normal.Y", "normal.Z", "primitive.id"};
  ASSERT_EQ(spec.channelnames, want);
  auto channel = [&](const std::string& name) {
    return int(std::find(spec.channelnames.begin(), spec.channelnames.end(), name) - spec.channelnames.begin());
  };
  EXPECT_EQ(spec.channelformat(0), OIIO::TypeDesc::HALF);
  EXPECT_EQ(spec.channelformat(channel("depth.Z")), OIIO::TypeDesc::HALF);
  EXPECT_EQ(spec.channelformat(channel("instance.id")), OIIO::TypeDesc::UINT) << "ids stay exact";
  EXPECT_EQ(spec.get_string_attribute("snell:version"), io::version());
  EXPECT_NE(spec.get_string_attribute("snell:camera"), "");
  EXPECT_NE(spec.get_string_attribute("snell:device"), "");
  EXPECT_FLOAT_EQ(spec.get_float_attribute("snell:time"), 0.5f);
  EXPECT_NE(spec.find_attribute("worldToCamera"), nullptr);

  const size_t pixels = size_t(spec.width) * spec.height;
  auto read = [&](const std::string& name, OIIO::TypeDesc type, void* data) {
    int c = channel(name);
    EXPECT_TRUE(in->read_image(0, 0, c, c + 1, type, data)) << name << in->geterror();
  };
  std::vector<float> alpha(pixels), depth(pixels), nx(pixels), ny(pixels), nz(pixels);
  std::vector<uint32_t> instance(pixels), interfaces(pixels), cost(pixels);
  read("A", OIIO::TypeDesc::FLOAT, alpha.data());
  read("depth.Z", OIIO::TypeDesc::FLOAT, depth.data());
  read("normal.X", OIIO::TypeDesc::FLOAT, nx.data());
  read("normal.Y", OIIO::TypeDesc::FLOAT, ny.data());
  read("normal.Z", OIIO::TypeDesc::FLOAT, nz.data());
  read("instance.id", OIIO::TypeDesc::UINT, instance.data());
  read("interfaces.count", OIIO::TypeDesc::UINT, interfaces.data());
  read("cost.nodes", OIIO::TypeDesc::UINT, cost.data());
  size_t covered = 0, crossedGlass = 0;
  for (size_t i = 0; i < pixels; ++i) {
    ASSERT_TRUE(alpha[i] == 0.0f || alpha[i] == 1.0f) << "coverage of one ray per pixel";
    if (alpha[i] == 1.0f) {
      ++covered;
      EXPECT_GT(depth[i], 0.0f);
      EXPECT_NEAR(nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i], 1.0f, 1e-2f) << "a unit normal";
      EXPECT_NE(instance[i], 0xffffffffu);
      if (interfaces[i] > 0) ++crossedGlass;
    } else {
      EXPECT_EQ(instance[i], 0xffffffffu) << "a miss has no instance";
      EXPECT_TRUE(std::isinf(depth[i]));
    }
    EXPECT_GT(cost[i], 0u) << "every ray visits the top of the tree";
  }
  EXPECT_GT(covered, 0u);
  EXPECT_LT(covered, pixels) << "the eye does not fill the frame";
  EXPECT_GT(crossedGlass, 0u) << "the cornea is crossed somewhere";
}

TEST(ExrFiles, FloatPixelsOnRequest) {
  TempFolder dir("exr_float");
  ASSERT_EQ(snell("render --eye --size 16x12 --float --aov depth -o " + shellQuoted(dir / "eye.exr")).exitCode, 0);
  auto in = OIIO::ImageInput::open(dir / "eye.exr");
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().channelformat(0), OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(in->spec().channelformat(4), OIIO::TypeDesc::FLOAT);
}

TEST(ExrFiles, TheReferenceWritesTheSameLayersButCost) {
  TempFolder dir("exr_reference");
  ASSERT_EQ(snell("render --eye --size 16x12 --reference --aov depth,instance -o " + shellQuoted(dir / "eye.exr")).exitCode, 0);
  auto in = OIIO::ImageInput::open(dir / "eye.exr");
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().channelnames.size(), 6u);
  EXPECT_EQ(in->spec().get_string_attribute("snell:method"), "reference");
  EXPECT_EQ(snell("render --eye --size 16x12 --reference --aov cost -o " + shellQuoted(dir / "no.exr")).exitCode, 2);
}

// ---- glTF --------------------------------------------------------------------------

TEST(EyeCommand, TheExtensionChoosesGlbOrGltfWithItsBin) {
  TempFolder dir("eye_formats");
  ASSERT_EQ(snell("eye --resolution 16 -o " + shellQuoted(dir / "eye.gltf")).exitCode, 0);
  ASSERT_EQ(snell("eye --resolution 16 -o " + shellQuoted(dir / "eye.glb")).exitCode, 0);
  io::Json gltf = readJson(dir / "eye.gltf");  // JSON, not a binary under a .gltf name
  EXPECT_EQ(gltf.at("buffers").at(0).at("uri"), "eye.bin");
  EXPECT_TRUE(fs::exists(dir / "eye.bin"));
  std::ifstream glb(dir / "eye.glb", std::ios::binary);
  char magic[4] = {};
  glb.read(magic, 4);
  EXPECT_EQ(std::string(magic, 4), "glTF");
  // Both load and describe the same eye.
  CommandRun a = snell("info " + shellQuoted(dir / "eye.gltf")), b = snell("info " + shellQuoted(dir / "eye.glb"));
  EXPECT_EQ(a.exitCode, 0) << a.output;
  EXPECT_EQ(b.exitCode, 0) << b.output;
}

}  // namespace
}  // namespace snell::test
