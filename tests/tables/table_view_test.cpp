#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "tables/model_files.hpp"
#include "tables/table_view.hpp"
#include "tests/support/aligned_blob.hpp"
#include "tools/tablegen/table_builder.hpp"

namespace sh {
namespace {

using testing::AlignedBlob;

std::vector<uint8_t> BuildReferenceBlob(HashFunction hf = HashFunction::kLinePointMidway) {
  std::vector<Model> models;
  EXPECT_TRUE(LoadModelFolder("models", &models).ok());
  TableBuildOptions options;
  options.hash_function = hf;
  auto blob = BuildTableBlob(models, options);
  EXPECT_TRUE(blob.ok());
  return *blob;
}

TEST(TableView, OpensWhatTheBuilderWrote) {
  AlignedBlob blob(BuildReferenceBlob());
  auto view = TableView::Open(blob.data, blob.size);
  ASSERT_TRUE(view.ok()) << view.status().message();
  EXPECT_EQ(view->hash_function(), HashFunction::kLinePointMidway);
  EXPECT_EQ(view->model_count(), 6u);
  EXPECT_EQ(view->point_entry_count(), 3136u);
  EXPECT_EQ(view->line_entry_count(), 4832u);
  EXPECT_EQ(view->FindModel("star"), 3);
  EXPECT_EQ(view->model(3).n_symmetries, 10);
  // Every entry sits in the bin its coordinates fall into.
  const GridGeometry& g = view->point_grid();
  for (uint32_t bin = 0; bin < g.bin_count(); ++bin) {
    for (const PointEntry& e : view->point_bin(bin)) {
      const float coords[3] = {e.x / 64.0f, e.y / 64.0f, e.z / 64.0f};
      uint32_t idx[3];
      for (int a = 0; a < 3; ++a)
        idx[a] = uint32_t(std::floor((coords[a] - g.min_mm[a]) / g.bin_mm));
      EXPECT_EQ((idx[2] * g.dims[1] + idx[1]) * g.dims[0] + idx[0], bin);
    }
  }
  // Entry counts per basis add up to the stored normalisers.
  std::vector<uint32_t> points(view->basis_count()), lines(view->basis_count());
  for (uint32_t i = 0; i < view->point_entry_count(); ++i) ++points[view->point_entries()[i].basis];
  for (uint32_t i = 0; i < view->line_entry_count(); ++i) ++lines[view->line_entries()[i].basis];
  for (uint32_t b = 0; b < view->basis_count(); ++b) {
    EXPECT_EQ(points[b], view->basis(b).n_point_entries);
    EXPECT_EQ(lines[b], view->basis(b).n_line_entries);
  }
}

std::string OpenError(const std::vector<uint8_t>& bytes, size_t size) {
  AlignedBlob blob(bytes);
  auto view = TableView::Open(blob.data, size);
  return view.ok() ? std::string("opened") : std::string(view.status().message());
}

TEST(TableView, RefusesTruncatedBlobs) {
  const std::vector<uint8_t> bytes = BuildReferenceBlob();
  EXPECT_NE(OpenError(bytes, 100).find("truncated"), std::string::npos);
  EXPECT_NE(OpenError(bytes, bytes.size() - 1).find("truncated"), std::string::npos);
}

TEST(TableView, RefusesCorruptedPayload) {
  std::vector<uint8_t> bytes = BuildReferenceBlob();
  bytes[bytes.size() / 2] ^= 0x40;
  EXPECT_NE(OpenError(bytes, bytes.size()).find("CRC-32"), std::string::npos);
}

TEST(TableView, EveryBitOfTheHeaderIsUnderTheCrc) {
  // A flipped bit anywhere in the header (hash function, grids, limits, section offsets, the CRC
  // itself) must be refused, never read as a different but valid table.
  const std::vector<uint8_t> bytes = BuildReferenceBlob();
  AlignedBlob blob(bytes);
  int opened = 0;
  for (size_t bit = 0; bit < sizeof(TableHeader) * 8; ++bit) {
    blob.data[bit / 8] ^= uint8_t(1u << (bit % 8));
    if (TableView::Open(blob.data, blob.size).ok()) ++opened;
    blob.data[bit / 8] ^= uint8_t(1u << (bit % 8));
  }
  EXPECT_EQ(opened, 0);
  EXPECT_TRUE(TableView::Open(blob.data, blob.size).ok());
}

TEST(TableView, RefusesNonFiniteLimitsEvenWithAMatchingCrc) {
  std::vector<uint8_t> bytes = BuildReferenceBlob();
  auto* h = reinterpret_cast<TableHeader*>(bytes.data());
  h->max_point_line_mm = std::nanf("");
  h->blob_crc32 = TableBlobCrc32(bytes.data(), bytes.size());
  EXPECT_NE(OpenError(bytes, bytes.size()).find("basis limits"), std::string::npos);
}

TEST(TableView, RefusesWrongMagicAndVersion) {
  std::vector<uint8_t> bytes = BuildReferenceBlob();
  std::vector<uint8_t> wrong_magic = bytes;
  wrong_magic[0] = 'X';
  EXPECT_NE(OpenError(wrong_magic, bytes.size()).find("magic"), std::string::npos);
  std::vector<uint8_t> wrong_version = bytes;
  reinterpret_cast<TableHeader*>(wrong_version.data())->format_version = 99;
  EXPECT_NE(OpenError(wrong_version, bytes.size()).find("version 99"), std::string::npos);
}

TEST(TableView, ModelNamesInErrorsAreEscaped) {
  // A damaged model record whose CRC was made to match: the name carries terminal control
  // bytes, the counts are out of range.
  std::vector<uint8_t> bytes = BuildReferenceBlob();
  auto* h = reinterpret_cast<TableHeader*>(bytes.data());
  auto* model = reinterpret_cast<Model*>(bytes.data() + h->models.offset);
  std::memcpy(model->name, "cu\x1b[2Jbe\xff", 10);
  model->n_symmetries = 0;
  h->blob_crc32 = TableBlobCrc32(bytes.data(), bytes.size());
  const std::string message = OpenError(bytes, bytes.size());
  EXPECT_NE(message.find("model 'cu\\x1B[2Jbe\\xFF' counts out of range"), std::string::npos)
      << message;
}

TEST(TableView, RefusesMisalignedMemory) {
  const std::vector<uint8_t> bytes = BuildReferenceBlob();
  std::vector<uint8_t> storage(bytes.size() + 16);
  uint8_t* aligned = storage.data() + (8 - reinterpret_cast<uintptr_t>(storage.data()) % 8) % 8;
  std::memcpy(aligned + 4, bytes.data(), bytes.size());
  auto view = TableView::Open(aligned + 4, bytes.size());
  ASSERT_FALSE(view.ok());
  EXPECT_NE(std::string(view.status().message()).find("aligned"), std::string::npos);
}

}  // namespace
}  // namespace sh
