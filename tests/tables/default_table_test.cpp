#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "tables/model_files.hpp"
#include "tables/table_file.hpp"
#include "tools/tablegen/table_builder.hpp"

namespace sh {
namespace {

TEST(DefaultTable, IsTheHashFn5TableOfTheReferenceModels) {
  auto view = OpenDefaultTable();
  ASSERT_TRUE(view.ok()) << view.status().message();
  EXPECT_EQ(reinterpret_cast<uintptr_t>(DefaultTableBlob()) % 64, 0u);
  EXPECT_EQ(view->hash_function(), HashFunction::kLinePointMidway);
  // Byte-identical to what the builder produces now from the repository's models.
  std::vector<Model> models;
  ASSERT_TRUE(LoadModelFolder("models", &models).ok());
  auto blob = BuildTableBlob(models, TableBuildOptions{});
  ASSERT_TRUE(blob.ok());
  ASSERT_EQ(blob->size(), DefaultTableBlobSize());
  EXPECT_EQ(std::memcmp(blob->data(), DefaultTableBlob(), blob->size()), 0);
}

TEST(MappedTable, MapsAFileAndRefusesBadOnes) {
  std::vector<Model> models;
  ASSERT_TRUE(LoadModelFolder("models", &models).ok());
  auto blob = BuildTableBlob(models, TableBuildOptions{});
  ASSERT_TRUE(blob.ok());
  const std::string path = ::testing::TempDir() + "/tables_hf5.bin";
  FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  std::fwrite(blob->data(), 1, blob->size(), f);
  std::fclose(f);
  MappedTable table;
  ASSERT_TRUE(table.Open(path.c_str()).ok());
  EXPECT_EQ(table.view().line_entry_count(), 4832u);

  // Truncated file: refused, message names the file and the problem.
  f = std::fopen(path.c_str(), "wb");
  std::fwrite(blob->data(), 1, blob->size() / 2, f);
  std::fclose(f);
  MappedTable truncated;
  const Status s = truncated.Open(path.c_str());
  ASSERT_FALSE(s.ok());
  EXPECT_NE(std::string(s.message()).find("truncated"), std::string::npos) << s.message();
  EXPECT_NE(std::string(s.message()).find(path), std::string::npos);

  MappedTable missing;
  EXPECT_EQ(missing.Open("/nonexistent/tables.bin").code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace sh
