// The model-set container: round trip, every header and directory bit under the CRC, and each
// structural fault refused with a message naming it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "tables/aspect_file.hpp"
#include "tables/feature_db_format.hpp"
#include "tables/model_set.hpp"
#include "tables/shape_views_file.hpp"
#include "tables/table_file.hpp"
#include "tests/support/aligned_blob.hpp"
#include "tools/tablegen/model_set_writer.hpp"

namespace sh {
namespace {

using testing::AlignedBlob;

constexpr uint32_t kHash = static_cast<uint32_t>(SectionKind::kHash3d);
constexpr uint32_t kAspects = static_cast<uint32_t>(SectionKind::kAspects2d);

ModelSetInput TableInput(uint32_t kind = kHash) {
  return {kind, static_cast<const uint8_t*>(DefaultTableBlob()), DefaultTableBlobSize()};
}
ModelSetInput AspectInput(uint32_t kind = kAspects) {
  return {kind, static_cast<const uint8_t*>(DefaultAspectBlob()), DefaultAspectBlobSize()};
}

// A small stand-in payload of a known kind: the common blob header and a pattern (the container
// checks the header, the CRC and the placement; the kind's own view the rest).
std::vector<uint8_t> FakeBlob(SectionKind kind, uint16_t version, size_t size) {
  std::vector<uint8_t> bytes(size);
  for (size_t i = 0; i < size; ++i) bytes[i] = uint8_t(i * 7 + 3);
  SectionBlobPrefix prefix{};
  std::memcpy(prefix.magic, FindSectionKind(uint32_t(kind))->magic, sizeof(prefix.magic));
  prefix.format_version = version;
  prefix.total_size = size;
  std::memcpy(bytes.data(), &prefix, sizeof(prefix));
  return bytes;
}

std::vector<uint8_t> Build(const std::vector<ModelSetInput>& sections) {
  Result<std::vector<uint8_t>> blob = BuildModelSet(sections);
  EXPECT_TRUE(blob.ok()) << blob.status().message();
  return blob.ok() ? *blob : std::vector<uint8_t>();
}

ModelSetHeader* Header(std::vector<uint8_t>& bytes) {
  return reinterpret_cast<ModelSetHeader*>(bytes.data());
}
ModelSetSection* Directory(std::vector<uint8_t>& bytes) {
  return reinterpret_cast<ModelSetSection*>(bytes.data() + sizeof(ModelSetHeader));
}
// After a deliberate change: the whole-blob CRC made to match, so the structural check is what
// has to catch it.
void Reseal(std::vector<uint8_t>& bytes) {
  Header(bytes)->blob_crc32 = ModelSetCrc32(bytes.data(), bytes.size());
}

std::string OpenError(const std::vector<uint8_t>& bytes) {
  AlignedBlob blob(bytes);
  Result<ModelSetView> set = ModelSetView::Open(blob.data, blob.size);
  return set.ok() ? std::string("opened") : std::string(set.status().message());
}

TEST(ModelSet, RoundTripGivesEachViewItsBlobByteForByte) {
  AlignedBlob blob(Build({TableInput(), AspectInput()}));
  Result<ModelSetView> set = ModelSetView::Open(blob.data, blob.size);
  ASSERT_TRUE(set.ok()) << set.status().message();
  ASSERT_EQ(set->section_count(), 2u);
  const Result<BlobSpan> hash = set->FindSection(SectionKind::kHash3d);
  const Result<BlobSpan> aspects = set->FindSection(SectionKind::kAspects2d);
  ASSERT_TRUE(hash.ok() && aspects.ok());
  EXPECT_EQ(reinterpret_cast<uintptr_t>(hash->data) % kModelSetAlignment, 0u);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(aspects->data) % kModelSetAlignment, 0u);
  ASSERT_EQ(hash->size, DefaultTableBlobSize());
  EXPECT_EQ(std::memcmp(hash->data, DefaultTableBlob(), hash->size), 0);
  ASSERT_EQ(aspects->size, DefaultAspectBlobSize());
  EXPECT_EQ(std::memcmp(aspects->data, DefaultAspectBlob(), aspects->size), 0);
  EXPECT_EQ(set->section(0).kind_version, kTableFormatVersion);
  EXPECT_EQ(set->section(1).kind_version, kAspectFormatVersion);

  // The kinds' own views open on the sections exactly as on the bare blobs.
  Result<TableView> table = TableView::Open(hash->data, hash->size);
  Result<TableView> bare = OpenDefaultTable();
  ASSERT_TRUE(table.ok() && bare.ok());
  EXPECT_EQ(table->model_count(), bare->model_count());
  EXPECT_EQ(table->point_entry_count(), bare->point_entry_count());
  Result<AspectTableView> aspect = AspectTableView::Open(aspects->data, aspects->size);
  ASSERT_TRUE(aspect.ok()) << aspect.status().message();
  EXPECT_EQ(aspect->aspect_count(), OpenDefaultAspectTable()->aspect_count());

  const Result<BlobSpan> views = set->FindSection(SectionKind::kShapeViews);
  ASSERT_FALSE(views.ok());
  EXPECT_EQ(views.status().code(), StatusCode::kNotFound);
  EXPECT_NE(std::string(views.status().message()).find("no SHAPE_VIEWS section"),
            std::string::npos);
  const Result<uint32_t> kinds = BlobKinds(blob.data, blob.size);
  ASSERT_TRUE(kinds.ok());
  EXPECT_EQ(*kinds, KindBit(SectionKind::kHash3d) | KindBit(SectionKind::kAspects2d));
}

TEST(ModelSet, BareBlobsStillReadAsTheirKind) {
  const Result<BlobSpan> bare =
      SectionOrBareBlob(DefaultTableBlob(), DefaultTableBlobSize(), SectionKind::kHash3d);
  ASSERT_TRUE(bare.ok());
  EXPECT_EQ(bare->data, DefaultTableBlob());
  EXPECT_EQ(bare->size, DefaultTableBlobSize());
  const Result<uint32_t> kinds = BlobKinds(DefaultAspectBlob(), DefaultAspectBlobSize());
  ASSERT_TRUE(kinds.ok());
  EXPECT_EQ(*kinds, KindBit(SectionKind::kAspects2d));
}

TEST(ModelSet, EveryBitOfTheHeaderAndDirectoryIsChecked) {
  // A flipped bit anywhere before the first payload (header, directory, padding) is refused:
  // never read as another, valid set.
  const std::vector<uint8_t> table = FakeBlob(SectionKind::kHash3d, kTableFormatVersion, 1000);
  const std::vector<uint8_t> views = FakeBlob(SectionKind::kShapeViews, 1, 300);
  const std::vector<uint8_t> bytes =
      Build({{kHash, table.data(), table.size()},
             {uint32_t(SectionKind::kShapeViews), views.data(), views.size()}});
  AlignedBlob blob(bytes);
  const size_t first_payload =
      reinterpret_cast<const ModelSetSection*>(bytes.data() + sizeof(ModelSetHeader))->offset;
  int opened = 0;
  for (size_t bit = 0; bit < first_payload * 8; ++bit) {
    blob.data[bit / 8] ^= uint8_t(1u << (bit % 8));
    if (ModelSetView::Open(blob.data, blob.size).ok()) ++opened;
    blob.data[bit / 8] ^= uint8_t(1u << (bit % 8));
  }
  EXPECT_EQ(opened, 0);
  EXPECT_TRUE(ModelSetView::Open(blob.data, blob.size).ok());

  // Beyond the CRC: each directory field is range-checked, so a changed entry with a matching
  // whole-blob CRC is refused, or gives the same hash tables, or none (a kind turned into one
  // this build does not know is skipped): never other tables.
  int opened_different = 0, refused = 0;
  for (size_t bit = sizeof(ModelSetHeader) * 8; bit < first_payload * 8; ++bit) {
    std::vector<uint8_t> changed = bytes;
    changed[bit / 8] ^= uint8_t(1u << (bit % 8));
    Reseal(changed);
    AlignedBlob flipped(changed);
    Result<ModelSetView> set = ModelSetView::Open(flipped.data, flipped.size);
    if (!set.ok()) {
      ++refused;
      continue;
    }
    const Result<BlobSpan> hash = set->FindSection(SectionKind::kHash3d);
    const bool same = hash.ok() ? hash->size == table.size() &&
                                      std::memcmp(hash->data, table.data(), hash->size) == 0
                                : hash.status().code() == StatusCode::kNotFound;
    if (!same) ++opened_different;
  }
  EXPECT_EQ(opened_different, 0);
  EXPECT_GT(refused, 400);
}

TEST(ModelSet, RefusesTruncatedSets) {
  std::vector<uint8_t> bytes = Build({TableInput(), AspectInput()});
  EXPECT_NE(OpenError(std::vector<uint8_t>(bytes.begin(), bytes.begin() + 40)).find("truncated"),
            std::string::npos);
  std::vector<uint8_t> cut(bytes.begin(), bytes.end() - 100);
  EXPECT_NE(OpenError(cut).find("truncated or padded"), std::string::npos);
  // The header agrees with the shorter file: the last section now ends past the blob.
  Header(cut)->total_size = cut.size();
  Reseal(cut);
  EXPECT_NE(OpenError(cut).find("section 1 (ASPECTS_2D) ends past the blob"), std::string::npos)
      << OpenError(cut);
}

TEST(ModelSet, RefusesOverlappingMisalignedAndDuplicateSections) {
  const std::vector<uint8_t> bytes = Build({TableInput(), AspectInput()});
  // Section 1 pointing into section 0 (an unknown kind over the same payload, so that every
  // other check of the entry passes).
  std::vector<uint8_t> overlap = bytes;
  Directory(overlap)[1] = Directory(overlap)[0];
  Directory(overlap)[1].kind = 77;
  Reseal(overlap);
  EXPECT_NE(OpenError(overlap).find("section 1 (unknown) overlaps section 0 (HASH3D)"),
            std::string::npos)
      << OpenError(overlap);

  std::vector<uint8_t> misaligned = bytes;
  Directory(misaligned)[1].offset += 8;
  Reseal(misaligned);
  EXPECT_NE(OpenError(misaligned).find("section 1 (ASPECTS_2D) is misaligned"), std::string::npos);

  std::vector<uint8_t> into_directory = bytes;
  Directory(into_directory)[0].offset = 0;
  Reseal(into_directory);
  EXPECT_NE(OpenError(into_directory).find("overlaps the header or the directory"),
            std::string::npos);

  // Two sections of one kind (an unknown kind, so that only the duplicate is wrong).
  std::vector<uint8_t> twice = Build({TableInput(77), AspectInput(78)});
  Directory(twice)[1].kind = 77;
  Reseal(twice);
  EXPECT_NE(OpenError(twice).find("sections 0 and 1 both hold kind 77"), std::string::npos)
      << OpenError(twice);

  // A section whose payload is another kind's blob.
  std::vector<uint8_t> swapped = bytes;
  Directory(swapped)[0].kind = kAspects;
  Directory(swapped)[1].kind = kHash;
  Reseal(swapped);
  EXPECT_NE(OpenError(swapped).find("does not hold a ASPECTS_2D blob"), std::string::npos);
}

TEST(ModelSet, RefusesBadHeaderFieldsAndSectionCrcs) {
  const std::vector<uint8_t> bytes = Build({TableInput(), AspectInput()});
  std::vector<uint8_t> version = bytes;
  Header(version)->format_version = 2;
  Reseal(version);
  EXPECT_NE(OpenError(version).find("version 2"), std::string::npos);
  std::vector<uint8_t> none = bytes;
  Header(none)->section_count = 0;
  Reseal(none);
  EXPECT_NE(OpenError(none).find("0 sections"), std::string::npos);
  std::vector<uint8_t> many = bytes;
  Header(many)->section_count = 1000000;
  Reseal(many);
  EXPECT_NE(OpenError(many).find("1000000 sections"), std::string::npos);
  std::vector<uint8_t> payload = bytes;
  payload[Directory(payload)[0].offset + 1000] ^= 0x10;
  Reseal(payload);
  EXPECT_NE(OpenError(payload).find("section 0 (HASH3D) CRC-32"), std::string::npos);
  std::vector<uint8_t> damaged = bytes;
  damaged[damaged.size() / 2] ^= 0x01;
  EXPECT_NE(OpenError(damaged).find("CRC-32"), std::string::npos);
}

TEST(ModelSet, UnknownKindsAreSkippedAndTheWriterRefusesBadInput) {
  AlignedBlob blob(Build({AspectInput(1234), TableInput()}));
  Result<ModelSetView> set = ModelSetView::Open(blob.data, blob.size);
  ASSERT_TRUE(set.ok()) << set.status().message();
  EXPECT_STREQ(SectionKindName(set->section(0).kind), "unknown");
  EXPECT_TRUE(set->FindSection(SectionKind::kHash3d).ok());

  EXPECT_FALSE(BuildModelSet({}).ok());
  const Result<std::vector<uint8_t>> twice = BuildModelSet({TableInput(), TableInput()});
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(std::string(twice.status().message()).find("both HASH3D"), std::string::npos);
  const Result<std::vector<uint8_t>> wrong = BuildModelSet({TableInput(kAspects)});
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(std::string(wrong.status().message()).find("not a ASPECTS_2D blob"), std::string::npos);
}

TEST(ModelSet, TheMagicsAreThoseOfTheKindsOwnFormats) {
  EXPECT_EQ(std::memcmp(FindSectionKind(kHash)->magic, kTableMagic, 8), 0);
  EXPECT_EQ(std::memcmp(FindSectionKind(kAspects)->magic, kAspectMagic, 8), 0);
  EXPECT_EQ(
      std::memcmp(FindSectionKind(uint32_t(SectionKind::kShapeViews))->magic, kShapeViewsMagic, 8),
      0);
  EXPECT_EQ(std::memcmp(FindSectionKind(uint32_t(SectionKind::kTextureFeatures))->magic,
                        kFeatureDbMagic, 8),
            0);
}

TEST(ModelSet, MappedViewsOpenTheirSectionOfAFile) {
  const std::vector<uint8_t> bytes = Build({TableInput(), AspectInput()});
  char path[] = "/tmp/model_set_testXXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(write(fd, bytes.data(), bytes.size()), ssize_t(bytes.size()));
  close(fd);
  MappedTable table;
  ASSERT_TRUE(table.Open(path).ok());
  EXPECT_EQ(table.size(), DefaultTableBlobSize());
  EXPECT_EQ(table.view().model_count(), OpenDefaultTable()->model_count());
  MappedAspectTable aspects;
  EXPECT_TRUE(aspects.Open(path).ok());
  MappedShapeViews views;
  const Status s = views.Open(path);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(std::string(s.message()).find("no SHAPE_VIEWS section"), std::string::npos);
  EXPECT_NE(std::string(s.message()).find(path), std::string::npos);
  std::remove(path);
}

}  // namespace
}  // namespace sh
