// Inputs that are not regular files, or larger than their bound: refused at once by name, never
// waited on and never read whole (docs/limits.md, Input files).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hal/sim/image_files.hpp"
#include "hal/sim/textured_model_files.hpp"
#include "tables/input_file.hpp"
#include "tables/model_files.hpp"
#include "tables/table_file.hpp"
#include "tests/support/temp_dir.hpp"

namespace sh {
namespace {

using hal::ImageInfo;
using hal::PixelFormat;
using hal::ReadImageFile;
using testing::TempDir;

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

bool Contains(const Status& s, const std::string& fragment) {
  return std::string(s.message()).find(fragment) != std::string::npos;
}

// A FIFO without a writer: opening it for reading would block for ever.
std::string MakeFifo(const TempDir& dir, const std::string& name) {
  std::string path = dir.Sub(name);
  EXPECT_EQ(mkfifo(path.c_str(), 0600), 0);
  return path;
}

std::string CopyModels(const TempDir& dir) {
  std::string models = dir.Mkdir("models");
  for (const char* name : {"cube.obj", "wedge.obj", "models.txt"}) {
    std::filesystem::copy_file(std::string("models/") + name, models + "/" + name);
  }
  WriteText(models + "/models.txt", "cube\nwedge\n");
  return models;
}

TEST(InputLimits, EachSpecialFileIsRefusedByItsType) {
  TempDir dir("input_limits");
  const std::string fifo = MakeFifo(dir, "fifo");
  char buffer[64];
  size_t n = 0;
  const auto start = std::chrono::steady_clock::now();
  Status s = ReadInputFile(fifo.c_str(), "calibration", buffer, sizeof(buffer), &n);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  EXPECT_EQ(std::string(s.message()), "calibration '" + fifo + "' is a FIFO, not a regular file");
  s = ReadInputFile("/dev/zero", "OBJ", buffer, sizeof(buffer), &n);
  EXPECT_EQ(std::string(s.message()), "OBJ '/dev/zero' is a character device, not a regular file");
  s = ReadInputFile(dir.path().c_str(), "table", buffer, sizeof(buffer), &n);
  EXPECT_TRUE(Contains(s, "is a directory, not a regular file")) << s.message();
  s = ReadInputFile(dir.Sub("missing").c_str(), "table", buffer, sizeof(buffer), &n);
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_TRUE(Contains(s, "No such file")) << s.message();
}

TEST(InputLimits, ASparseFileBeyondTheBoundIsRefusedFromItsSize) {
  TempDir dir("input_limits");
  const std::string big = dir.Sub("big.obj");
  const int fd = open(big.c_str(), O_WRONLY | O_CREAT, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(ftruncate(fd, off_t{3} << 30), 0);  // 3 GiB of holes: no disk, no memory
  close(fd);
  std::string text;
  Status s = ReadInputFile(big, "OBJ", size_t(kMaxObjFileBytes), &text);
  EXPECT_EQ(s.code(), StatusCode::kOutOfRange);
  EXPECT_TRUE(Contains(s, "is 3221225472 bytes, larger than the 1048576-byte limit"))
      << s.message();
  EXPECT_LT(text.capacity(), size_t(kMaxObjFileBytes));
  MappedFile mapped;
  s = mapped.Open(big.c_str(), "table file");
  EXPECT_TRUE(Contains(s, "larger than the 268435456-byte limit")) << s.message();
}

TEST(InputLimits, ProcFilesThatReportNoSizeAreReadToTheirEnd) {
  std::string text;
  const Status s = ReadInputFile(std::string("/proc/self/status"), "file", 1 << 16, &text);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_NE(text.find("Name:"), std::string::npos);
}

TEST(InputLimits, BlobFilesRefuseSpecialFiles) {
  TempDir dir("input_limits");
  const std::string fifo = MakeFifo(dir, "tables.bin");
  MappedFile mapped;
  Status s = mapped.Open(fifo.c_str(), "table file");
  EXPECT_TRUE(Contains(s, "is a FIFO, not a regular file")) << s.message();
  s = mapped.Open(dir.path().c_str(), "table file");
  EXPECT_TRUE(Contains(s, "is a directory, not a regular file")) << s.message();
  s = mapped.Open("/dev/zero", "table file");
  EXPECT_TRUE(Contains(s, "is a character device")) << s.message();
  const Result<uint32_t> kinds = FileBlobKinds(fifo.c_str());
  EXPECT_FALSE(kinds.ok());
}

TEST(InputLimits, ModelFoldersRefuseSpecialFiles) {
  TempDir dir("input_limits");
  const std::string models = CopyModels(dir);
  std::vector<Model> loaded;
  ASSERT_TRUE(LoadModelFolder(models, &loaded).ok());

  std::filesystem::remove(models + "/cube.obj");
  ASSERT_EQ(symlink("/dev/zero", (models + "/cube.obj").c_str()), 0);
  Status s = LoadModelFolder(models, &loaded);
  EXPECT_TRUE(Contains(s, "cube.obj' is a character device, not a regular file")) << s.message();

  std::filesystem::remove(models + "/cube.obj");
  MakeFifo(dir, "models/cube.obj");
  s = LoadModelFolder(models, &loaded);
  EXPECT_TRUE(Contains(s, "cube.obj' is a FIFO")) << s.message();

  std::filesystem::remove(models + "/models.txt");
  MakeFifo(dir, "models/models.txt");
  s = LoadModelFolder(models, &loaded);
  EXPECT_TRUE(Contains(s, "model list '" + models + "/models.txt' is a FIFO")) << s.message();
}

TEST(InputLimits, MaterialsAndTexturesRefuseSpecialFiles) {
  TempDir dir("input_limits");
  const std::string folder = dir.Mkdir("printed");
  std::filesystem::copy("models/textured", folder, std::filesystem::copy_options::recursive);
  std::vector<std::string> objs;
  for (const auto& e : std::filesystem::directory_iterator(folder)) {
    if (e.path().extension() == ".obj") objs.push_back(e.path().string());
  }
  ASSERT_FALSE(objs.empty());
  // The first carton's MTL becomes a FIFO.
  std::string obj_text;
  ASSERT_TRUE(ReadInputFile(objs[0], "OBJ", 1 << 20, &obj_text).ok());
  const size_t at = obj_text.find("mtllib ");
  ASSERT_NE(at, std::string::npos);
  const std::string mtl = obj_text.substr(at + 7, obj_text.find('\n', at) - at - 7);
  std::filesystem::remove(folder + "/" + mtl);
  ASSERT_EQ(mkfifo((folder + "/" + mtl).c_str(), 0600), 0);
  Result<TexturedModel> model = LoadTexturedModelFile(objs[0]);
  ASSERT_FALSE(model.ok());
  EXPECT_TRUE(Contains(model.status(), "is a FIFO, not a regular file"))
      << model.status().message();
}

TEST(InputLimits, ImagesRefuseSpecialFiles) {
  TempDir dir("input_limits");
  const std::string fifo = MakeFifo(dir, "left.png");
  std::vector<uint8_t> pixels(64);
  Result<ImageInfo> info = ReadImageFile(fifo.c_str(), PixelFormat::kGray8, pixels.data(), 64);
  ASSERT_FALSE(info.ok());
  EXPECT_TRUE(Contains(info.status(), "is a FIFO, not a regular file")) << info.status().message();
  info = ReadImageFile("/dev/zero", PixelFormat::kGray8, pixels.data(), 64);
  ASSERT_FALSE(info.ok());
  EXPECT_TRUE(Contains(info.status(), "is a character device")) << info.status().message();
}

}  // namespace
}  // namespace sh
