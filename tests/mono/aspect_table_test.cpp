// The aspect table blob: what the builder stores, and the validating reader refusing
// truncated, corrupt and foreign blobs with a message.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>

#include "recog/base/crc32.hpp"
#include "tables/aspect_view.hpp"
#include "tests/mono/mono_fixtures.hpp"
#include "tools/tablegen/aspect_builder.hpp"

namespace sh {
namespace {

using testing::ReferenceModel;

std::vector<uint8_t> SmallBlob(AspectBuildOptions options = {}) {
  options.initial_spacing_deg = 30.0f;
  options.refine = false;
  Result<std::vector<uint8_t>> blob =
      BuildAspectBlob({ReferenceModel("cube"), ReferenceModel("wedge")}, options);
  EXPECT_TRUE(blob.ok()) << blob.status().message();
  return blob.ok() ? *blob : std::vector<uint8_t>{};
}

// The blob in 8-byte aligned memory.
struct Aligned {
  std::vector<uint64_t> words;
  size_t size;
  explicit Aligned(const std::vector<uint8_t>& bytes)
      : words((bytes.size() + 7) / 8), size(bytes.size()) {
    std::memcpy(words.data(), bytes.data(), bytes.size());
  }
  uint8_t* bytes() { return reinterpret_cast<uint8_t*>(words.data()); }
  AspectHeader& header() { return *reinterpret_cast<AspectHeader*>(words.data()); }
  void FixCrc() {
    header().blob_crc32 = BlobCrc32(bytes(), size, offsetof(AspectHeader, blob_crc32));
  }
  Status Open() { return AspectTableView::Open(words.data(), size).status(); }
};

TEST(AspectTable, BuilderStoresWhatItReports) {
  AspectBuildReport report;
  Result<std::vector<uint8_t>> blob = BuildAspectBlob(
      {ReferenceModel("cube"), ReferenceModel("wedge")}, AspectBuildOptions{}, &report);
  ASSERT_TRUE(blob.ok()) << blob.status().message();
  Aligned a(*blob);
  Result<AspectTableView> view = AspectTableView::Open(a.words.data(), a.size);
  ASSERT_TRUE(view.ok()) << view.status().message();
  EXPECT_EQ(view->model_count(), 2u);
  EXPECT_EQ(view->aspect_count(), report.aspects);
  EXPECT_EQ(view->basis_count(), report.bases);
  EXPECT_EQ(view->point_entry_count(), report.point_entries);
  EXPECT_EQ(view->line_entry_count(), report.line_entries);
  ASSERT_EQ(report.per_model.size(), 2u);
  EXPECT_EQ(report.per_model[0].model, "cube");
  // Every aspect's bases follow it, every basis's entries name it.
  uint32_t points = 0, lines = 0;
  for (uint32_t b = 0; b < view->basis_count(); ++b) {
    const AspectBasis& basis = view->basis(b);
    const AspectRecord& aspect = view->aspect(basis.aspect);
    EXPECT_GE(b, aspect.first_basis);
    EXPECT_LT(b, aspect.first_basis + aspect.n_bases);
    points += basis.n_point_entries;
    lines += basis.n_line_entries;
  }
  EXPECT_EQ(points, view->point_entry_count());
  EXPECT_EQ(lines, view->line_entry_count());
}

TEST(AspectTable, EveryCornerPairStoresMoreThanEdgePairs) {
  AspectBuildOptions edges;
  edges.refine = false;
  AspectBuildOptions all = edges;
  all.edge_bases_only = false;
  AspectBuildReport edges_report, all_report;
  auto models = std::vector<Model>{ReferenceModel("cube")};
  ASSERT_TRUE(BuildAspectBlob(models, edges, &edges_report).ok());
  ASSERT_TRUE(BuildAspectBlob(models, all, &all_report).ok());
  EXPECT_EQ(edges_report.aspects, all_report.aspects);
  EXPECT_GT(all_report.bases, edges_report.bases);
  EXPECT_GT(all_report.point_entries, edges_report.point_entries);
}

TEST(AspectTable, AffineBasesUseThreeCorners) {
  AspectBuildOptions affine;
  affine.kind = AspectBasisKind::kAffine;
  const std::vector<uint8_t> blob = SmallBlob(affine);
  Aligned a(blob);
  Result<AspectTableView> view = AspectTableView::Open(a.words.data(), a.size);
  ASSERT_TRUE(view.ok()) << view.status().message();
  EXPECT_EQ(view->basis_kind(), AspectBasisKind::kAffine);
  ASSERT_GT(view->basis_count(), 0u);
  for (uint32_t b = 0; b < view->basis_count(); ++b) {
    const AspectBasis& basis = view->basis(b);
    EXPECT_NE(basis.corners[0], basis.corners[1]);
    EXPECT_NE(basis.corners[1], basis.corners[2]);
    EXPECT_NE(basis.corners[0], basis.corners[2]);
  }
}

TEST(AspectTable, RefinementAddsViewsWhereTestViewsFail) {
  // A coarse grid with a strict test: failing test views add aspects of the next level.
  AspectBuildOptions o;
  o.initial_spacing_deg = 30.0f;
  o.max_levels = 1;
  o.test_vote_fraction = 0.45f;
  o.test_pass_fraction = 0.7f;
  o.test_sigma_point_px = o.test_sigma_line_px = 4.0f;
  AspectBuildReport report;
  ASSERT_TRUE(BuildAspectBlob({ReferenceModel("cube")}, o, &report).ok());
  ASSERT_EQ(report.per_model.size(), 1u);
  EXPECT_GT(report.per_model[0].failed_test_views, 0u);
  EXPECT_GT(report.per_model[0].aspects_per_level[1], 0u);
  EXPECT_EQ(report.per_model[0].aspects,
            report.per_model[0].aspects_per_level[0] + report.per_model[0].aspects_per_level[1]);
}

TEST(AspectTable, EveryHeaderBitFlipIsRefused) {
  const std::vector<uint8_t> blob = SmallBlob();
  for (size_t bit = 0; bit < sizeof(AspectHeader) * 8; ++bit) {
    Aligned a(blob);
    a.bytes()[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(a.Open().ok()) << "bit " << bit;
  }
}

TEST(AspectTable, ReservedHeaderBitsMustBeZero) {
  const std::vector<uint8_t> blob = SmallBlob();
  const size_t build = offsetof(AspectHeader, build);
  for (size_t offset :
       {offsetof(AspectHeader, reserved0), build + offsetof(AspectBuildParams, reserved),
        build + offsetof(AspectBuildParams, flags)}) {
    Aligned a(blob);
    a.bytes()[offset] |= 0x80;
    a.FixCrc();
    const Status s = a.Open();
    EXPECT_NE(std::string(s.message()).find("reserved"), std::string::npos) << s.message();
  }
}

TEST(AspectTable, ReaderRefusesDamagedBlobs) {
  const std::vector<uint8_t> blob = SmallBlob();
  {
    Aligned a(blob);
    EXPECT_TRUE(a.Open().ok());
  }
  {
    Aligned a(blob);
    a.bytes()[0] = 'X';
    EXPECT_EQ(a.Open().code(), StatusCode::kInvalidArgument);
  }
  {
    Aligned a(blob);
    a.size -= 64;
    EXPECT_EQ(a.Open().code(), StatusCode::kDataLoss);
  }
  {
    Aligned a(blob);
    a.bytes()[a.size - 1] ^= 0x5a;  // payload changed, CRC not: corrupt
    const Status s = a.Open();
    EXPECT_EQ(s.code(), StatusCode::kDataLoss);
    EXPECT_NE(std::strstr(s.message(), "CRC"), nullptr) << s.message();
  }
  {
    Aligned a(blob);
    a.header().format_version = 99;
    EXPECT_EQ(a.Open().code(), StatusCode::kInvalidArgument);
  }
  {
    // A point entry naming a basis past the end, with the CRC made right: the structural
    // checks behind the CRC catch it.
    Aligned a(blob);
    auto* entries =
        reinterpret_cast<AspectPointEntry*>(a.bytes() + a.header().point_entries.offset);
    entries[0].basis = a.header().n_bases;
    a.FixCrc();
    EXPECT_EQ(a.Open().code(), StatusCode::kDataLoss);
  }
  {
    Aligned a(blob);
    a.header().n_bases = kMaxAspectBases + 1;
    a.FixCrc();
    EXPECT_EQ(a.Open().code(), StatusCode::kOutOfRange);
  }
  {
    Aligned a(blob);
    a.header().size_slices = 0;
    a.FixCrc();
    EXPECT_EQ(a.Open().code(), StatusCode::kDataLoss);
  }
  EXPECT_EQ(AspectTableView::Open(nullptr, 100).status().code(), StatusCode::kInvalidArgument);
}

TEST(AspectTable, BuilderRefusesBadOptions) {
  AspectBuildOptions o;
  o.initial_spacing_deg = 0.5f;
  const Status s = BuildAspectBlob({ReferenceModel("cube")}, o).status();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_STREQ(s.message(),
               "aspect table: initial spacing (--spacing, degrees) is 0.5, outside 2..90");
  o = AspectBuildOptions{};
  o.size_slices = 0;
  EXPECT_STREQ(BuildAspectBlob({ReferenceModel("cube")}, o).status().message(),
               "aspect table: size slices (--slices D,S: S) is 0, outside 1..64")
      << "the option is named";
  EXPECT_EQ(BuildAspectBlob({}, AspectBuildOptions{}).status().code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh
