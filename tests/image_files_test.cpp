// The public API's image files (src/api/image_files.cpp), for hosts without
// an image library of their own (a pip install's snell-usd): snell::writePng
// writes 8-bit sRGB, whole or not at all; snell::readImageFile decodes what
// stb_image reads, as stored, and names the file when it cannot.
#include <snell/snell.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace snell::test {
namespace {

namespace fs = std::filesystem;

// A folder of its own for each test, removed after it.
class ImageFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    folder = fs::temp_directory_path() / ("snell-image-files-" + std::to_string(::getpid()) + "-" + info->name());
    fs::remove_all(folder);
    fs::create_directories(folder);
  }
  void TearDown() override { fs::remove_all(folder); }

  std::vector<std::string> names() const {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(folder)) found.push_back(entry.path().filename().string());
    return found;
  }

  fs::path folder;
};

void writeBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// Linear 0, 0.5 and 1 (sRGB bytes 0, 188 and 255) and an alpha of a quarter (64).
const std::vector<float> kPixels = {0.0f, 0.5f, 1.0f, 0.25f, 1.0f, 1.0f, 1.0f, 1.0f,
                                    0.5f, 0.0f, 0.0f, 1.0f,  0.0f, 0.0f, 0.0f, 0.0f};

TEST_F(ImageFiles, WritePngEncodesLinearAsSrgbBytesAndReadImageFileGivesThemBack) {
  const std::string path = (folder / "two.png").string();
  writePng(path, 2, 2, kPixels.data(), /*alpha=*/true);
  ImageFile image = readImageFile(path);
  EXPECT_EQ(image.width, 2u);
  EXPECT_EQ(image.height, 2u);
  EXPECT_EQ(image.channels, 4u);
  EXPECT_EQ(image.bits, 8u);
  const std::vector<uint8_t> expected = {0, 188, 255, 64, 255, 255, 255, 255, 188, 0, 0, 255, 0, 0, 0, 0};
  EXPECT_EQ(image.data, expected);
}

TEST_F(ImageFiles, WritePngWithoutAlphaIsOpaque) {
  const std::string path = (folder / "opaque.png").string();
  writePng(path, 2, 2, kPixels.data());
  ImageFile image = readImageFile(path);
  ASSERT_EQ(image.data.size(), 16u);
  for (size_t i = 3; i < image.data.size(); i += 4) EXPECT_EQ(image.data[i], 255) << "pixel " << i / 4;
  EXPECT_EQ(image.data[1], 188);
}

TEST_F(ImageFiles, WritePngReplacesAFileWholeAndLeavesNoTemporaryFile) {
  const std::string path = (folder / "frame.png").string();
  writeBytes(path, "an older frame");
  writePng(path, 2, 2, kPixels.data());
  EXPECT_EQ(names(), std::vector<std::string>{"frame.png"});
  EXPECT_EQ(readImageFile(path).width, 2u);
}

TEST_F(ImageFiles, WritePngIntoAMissingFolderThrowsNamingItAndWritesNothing) {
  const std::string path = (folder / "missing" / "frame.png").string();
  try {
    writePng(path, 2, 2, kPixels.data());
    FAIL() << "writing into a missing folder succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": the folder "), std::string::npos) << e.what();
  }
  EXPECT_TRUE(names().empty());
}

TEST_F(ImageFiles, WritePngOfNoPixelsThrowsNamingTheFile) {
  const std::string path = (folder / "empty.png").string();
  EXPECT_THROW(writePng(path, 0, 2, kPixels.data()), Error);
  EXPECT_TRUE(names().empty());
}

TEST_F(ImageFiles, ReadImageFileDecodesRadianceHdrAsFloats) {
  // 2x1 RGBE, flat scanlines: (1, 0.5, 0.25) and (4, 0, 2).
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
  const std::string pixels = {char(128), char(64), char(32), char(129), char(128), char(0), char(64), char(131)};
  const fs::path path = folder / "sky.hdr";
  writeBytes(path, header + pixels);
  ImageFile image = readImageFile(path.string());
  ASSERT_EQ(image.bits, 32u);
  ASSERT_EQ(image.channels, 3u);
  ASSERT_EQ(image.data.size(), 2u * 3u * sizeof(float));
  std::vector<float> values(6);
  std::memcpy(values.data(), image.data.data(), image.data.size());
  const std::vector<float> expected = {1.0f, 0.5f, 0.25f, 4.0f, 0.0f, 2.0f};
  for (size_t i = 0; i < values.size(); ++i) EXPECT_NEAR(values[i], expected[i], 1e-2f * expected[i] + 1e-6f) << i;
}

TEST_F(ImageFiles, ReadImageFileOfAnotherFormatThrowsNamingTheFileAndWhatItReads) {
  const fs::path path = folder / "sky.exr";
  writeBytes(path, std::string("\x76\x2f\x31\x01", 4) + "an EXR's magic number, then nothing stb reads");
  try {
    readImageFile(path.string());
    FAIL() << "an EXR was decoded";
  } catch (const Error& e) {
    const std::string said = e.what();
    EXPECT_EQ(said.rfind(path.string() + ": not an image snell decodes", 0), 0u) << said;
    EXPECT_NE(said.find("it reads PNG, JPEG"), std::string::npos) << said;
  }
}

TEST_F(ImageFiles, ReadImageFileOfAMissingFileThrowsNamingIt) {
  const std::string path = (folder / "gone.png").string();
  try {
    readImageFile(path);
    FAIL() << "a missing file was read";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": no such file");
  }
}

}  // namespace
}  // namespace snell::test
