// The feature database: what the builder writes from a printed model, read back through the
// validating view, and every kind of damage refused with a reason.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include "hal/sim/textured_model_files.hpp"
#include "recog/base/crc32.hpp"
#include "recog/texture/descriptor.hpp"
#include "recog/texture/polygon.hpp"
#include "tables/feature_db_view.hpp"
#include "tests/support/aligned_blob.hpp"
#include "tools/tablegen/feature_db_builder.hpp"

namespace sh {
namespace {

// A blob copy whose header can be edited and the CRC recomputed, to reach the structural checks
// behind it.
struct AlignedBlob : testing::AlignedBlob {
  using testing::AlignedBlob::AlignedBlob;
  FeatureDbHeader& header() { return *reinterpret_cast<FeatureDbHeader*>(data); }
  void Reseal() {
    header().blob_crc32 = 0;
    header().blob_crc32 = BlobCrc32(data, size, offsetof(FeatureDbHeader, blob_crc32));
  }
};

// The smallest carton, frontal views only: quick enough for the emulator.
const std::vector<uint8_t>& PillsBlob(FeatureDbBuildReport* report_out = nullptr) {
  static FeatureDbBuildReport report;
  static const std::vector<uint8_t> blob = [] {
    Result<TexturedModel> m = LoadTexturedModelFile("models/textured/pills.obj");
    EXPECT_TRUE(m.ok()) << m.status().message();
    FeatureDbBuildOptions options;
    options.tilts.clear();
    Result<std::vector<uint8_t>> b = BuildFeatureDb({*m}, options, &report);
    EXPECT_TRUE(b.ok()) << b.status().message();
    return b.ok() ? *b : std::vector<uint8_t>{};
  }();
  if (report_out) *report_out = report;
  return blob;
}

TEST(FeatureDb, OpensWhatTheBuilderWroteAndEveryFeatureLiesOnItsFace) {
  FeatureDbBuildReport report;
  AlignedBlob blob(PillsBlob(&report));
  Result<FeatureDbView> view = FeatureDbView::Open(blob.data, blob.size);
  ASSERT_TRUE(view.ok()) << view.status().message();
  EXPECT_EQ(view->model_count(), 1u);
  EXPECT_STREQ(view->model(0).name, "pills");
  EXPECT_EQ(view->FindModel("pills"), 0);
  EXPECT_EQ(view->FindModel("tea"), -1);
  EXPECT_EQ(view->face_count(), 6u);
  EXPECT_EQ(view->view_count(), 6u);  // frontal only
  EXPECT_EQ(view->feature_count(), report.features);
  EXPECT_GT(view->feature_count(), 300u);
  uint32_t per_face = 0;
  for (uint32_t f = 0; f < view->face_count(); ++f) {
    const TexturedFace& face = view->face(f);
    per_face += face.n_features;
    EXPECT_EQ(face.n_corners, 4);
    // Texture at 2 texels per millimetre over the face's extent.
    EXPECT_NEAR(face.texel_width, 2.0f * (face.max_ab_mm[0] - face.min_ab_mm[0]), 1.0f);
    EXPECT_NEAR(face.texel_height, 2.0f * (face.max_ab_mm[1] - face.min_ab_mm[1]), 1.0f);
    const Eigen::Vector3f a(face.axis_a[0], face.axis_a[1], face.axis_a[2]);
    const Eigen::Vector3f b(face.axis_b[0], face.axis_b[1], face.axis_b[2]);
    // a x b is the model face's outward normal.
    const Model& m = view->model(face.model);
    EXPECT_LT((a.cross(b) - m.face_normal(face.model_face)).norm(), 1e-5f);
  }
  EXPECT_EQ(per_face, view->feature_count());
  for (uint32_t i = 0; i < view->feature_count(); ++i) {
    const FeatureRecord& r = view->feature(i);
    const FaceView& v = view->view(r.view);
    const TexturedFace& face = view->face(v.face);
    const Model& m = view->model(face.model);
    const Eigen::Vector3f x(r.model_mm[0], r.model_mm[1], r.model_mm[2]);
    // On the face's plane ...
    EXPECT_NEAR(m.face_normal(face.model_face).dot(x), m.faces[face.model_face].offset_mm, 1e-3f);
    // ... inside its polygon, clear of the edges by the descriptor's window ...
    const Eigen::Vector3f o(face.origin_mm[0], face.origin_mm[1], face.origin_mm[2]);
    const Eigen::Vector2f ab((x - o).dot(Eigen::Vector3f(face.axis_a)),
                             (x - o).dot(Eigen::Vector3f(face.axis_b)));
    Eigen::Vector2f poly[kMaxTexturedFaceCorners];
    for (int k = 0; k < face.n_corners; ++k)
      poly[k] = {face.corners_ab_mm[k][0], face.corners_ab_mm[k][1]};
    EXPECT_GT(texture::InsideDistance(poly, face.n_corners, ab), 0.0f);
    // ... and where its view coordinates say (frontal views: u = ppm * (a - centre)).
    EXPECT_NEAR(r.u_px, view->header().feature_px_per_mm * (ab.x() - v.centre_ab_mm[0]), 0.05f);
    EXPECT_NEAR(r.v_px, -view->header().feature_px_per_mm * (ab.y() - v.centre_ab_mm[1]), 0.05f);
  }
  // The stored extraction settings are the builder's.
  const texture::TextureFeatureConfig c = texture::ExtractionConfig(view->header().extraction);
  const texture::TextureFeatureConfig d;
  EXPECT_EQ(c.levels, d.levels);
  EXPECT_FLOAT_EQ(c.integration_sigma_px, d.integration_sigma_px);
  EXPECT_FLOAT_EQ(c.min_response, d.min_response);
  EXPECT_EQ(c.orientation.max_orientations, d.orientation.max_orientations);
}

TEST(FeatureDb, TiltedViewsAddFeaturesOfTheSameFaces) {
  Result<TexturedModel> m = LoadTexturedModelFile("models/textured/pills.obj");
  ASSERT_TRUE(m.ok());
  FeatureDbBuildOptions options;  // frontal + 4 tilts
  FeatureDbBuildReport tilted;
  ASSERT_TRUE(BuildFeatureDb({*m}, options, &tilted).ok());
  FeatureDbBuildReport frontal;
  PillsBlob(&frontal);
  EXPECT_EQ(tilted.views, 6u * 5u);
  EXPECT_GT(tilted.features, 3 * frontal.features);
}

// The views hold the face in a margin, so that a small face has features at the coarse levels
// and near its edges, as the face has in a scene (where it is part of a larger image): the pills
// carton's 25 mm sides are 100 px at 4 px/mm, too small for the coarsest levels on their own.
TEST(FeatureDb, EveryFaceHasFeaturesOnEveryLevelUpToTheWindowFromItsEdges) {
  const FeatureDbBuildOptions options;
  Result<TexturedModel> m = LoadTexturedModelFile("models/textured/pills.obj");
  ASSERT_TRUE(m.ok());
  for (int fi = 0; fi < m->model.n_faces; ++fi) {
    Result<FaceLearning> learning = LearnFace(*m, fi, options);
    ASSERT_TRUE(learning.ok()) << learning.status().message();
    const TexturedFace& face = learning->face;
    const float width_px = (face.max_ab_mm[0] - face.min_ab_mm[0]) * options.feature_px_per_mm;
    EXPECT_NEAR(learning->views[0].image.width, width_px + 2 * ViewMarginPx(options), 1.0f);
  }
  AlignedBlob blob(PillsBlob());
  Result<FeatureDbView> view = FeatureDbView::Open(blob.data, blob.size);
  ASSERT_TRUE(view.ok()) << view.status().message();
  const int levels = options.features.levels;
  const float window_px = static_cast<float>(texture::DescriptorBorderPx());
  for (uint32_t f = 0; f < view->face_count(); ++f) {
    const TexturedFace& face = view->face(f);
    Eigen::Vector2f poly[kMaxTexturedFaceCorners];
    for (int k = 0; k < face.n_corners; ++k)
      poly[k] = {face.corners_ab_mm[k][0], face.corners_ab_mm[k][1]};
    std::vector<int> count(static_cast<size_t>(levels), 0);
    std::vector<float> nearest_edge_px(static_cast<size_t>(levels), 1e30f);
    for (uint32_t i = 0; i < view->feature_count(); ++i) {
      const FeatureRecord& r = view->feature(i);
      if (view->view(r.view).face != f) continue;
      ASSERT_LT(r.level, levels);
      const Eigen::Vector3f o(face.origin_mm[0], face.origin_mm[1], face.origin_mm[2]);
      const Eigen::Vector3f x = Eigen::Vector3f(r.model_mm[0], r.model_mm[1], r.model_mm[2]) - o;
      const Eigen::Vector2f ab(x.dot(Eigen::Vector3f(face.axis_a)),
                               x.dot(Eigen::Vector3f(face.axis_b)));
      // Distance to the edge in the feature's level pixels.
      const float d = texture::InsideDistance(poly, face.n_corners, ab) *
                      view->header().feature_px_per_mm / r.scale;
      ++count[r.level];
      nearest_edge_px[r.level] = std::min(nearest_edge_px[r.level], d);
    }
    for (int k = 0; k < levels; ++k) {
      EXPECT_GT(count[static_cast<size_t>(k)], 0) << "face " << f << " level " << k;
      // Above level 0 (where the print's own plain border decides), nearer the edge than the
      // image border of an unpadded view allows (a whole window).
      if (k > 0) {
        EXPECT_LT(nearest_edge_px[static_cast<size_t>(k)], 0.9f * window_px)
            << "face " << f << " level " << k;
      }
    }
  }
}

void ExpectRefused(AlignedBlob& blob, const char* fragment) {
  Result<FeatureDbView> v = FeatureDbView::Open(blob.data, blob.size);
  ASSERT_FALSE(v.ok()) << "accepted (expected: " << fragment << ")";
  EXPECT_NE(std::strstr(v.status().message(), fragment), nullptr) << v.status().message();
}

TEST(FeatureDb, EveryHeaderBitFlipIsRefused) {
  for (size_t bit = 0; bit < sizeof(FeatureDbHeader) * 8; ++bit) {
    AlignedBlob b(PillsBlob());
    b.data[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(FeatureDbView::Open(b.data, b.size).ok()) << "bit " << bit;
  }
}

TEST(FeatureDb, ReservedHeaderBytesMustBeZero) {
  AlignedBlob b(PillsBlob());
  b.header().reserved[7] = 1;
  b.Reseal();
  const Status s = FeatureDbView::Open(b.data, b.size).status();
  EXPECT_NE(std::string(s.message()).find("reserved"), std::string::npos) << s.message();
}

TEST(FeatureDb, RefusesDamageWithAReason) {
  const std::vector<uint8_t>& good = PillsBlob();
  {
    AlignedBlob b(good);
    b.data[sizeof(FeatureDbHeader) + 100] ^= 0x40;
    ExpectRefused(b, "CRC-32");
  }
  {
    AlignedBlob b(good);
    b.data[0] = 'X';
    ExpectRefused(b, "bad magic");
  }
  {
    AlignedBlob b(good);
    b.size -= 64;
    ExpectRefused(b, "truncated");
  }
  {
    AlignedBlob b(good);
    b.header().format_version = 99;
    ExpectRefused(b, "format version 99");
  }
  {  // Structural damage behind a valid CRC: a kd-tree child pointing back up.
    AlignedBlob b(good);
    auto* nodes = reinterpret_cast<texture::KdNode*>(b.data + b.header().nodes.offset);
    ASSERT_FALSE(nodes[0].leaf);
    nodes[0].first = 0;
    b.Reseal();
    ExpectRefused(b, "kd-tree inner node 0");
  }
  {  // A leaf beyond the descriptors.
    AlignedBlob b(good);
    auto* nodes = reinterpret_cast<texture::KdNode*>(b.data + b.header().nodes.offset);
    for (uint32_t i = 0; i < b.header().n_nodes; ++i) {
      if (nodes[i].leaf) {
        nodes[i].first = b.header().n_features;
        break;
      }
    }
    b.Reseal();
    ExpectRefused(b, "kd-tree leaf range");
  }
  {  // A feature naming a view that does not exist.
    AlignedBlob b(good);
    auto* f = reinterpret_cast<FeatureRecord*>(b.data + b.header().features.offset);
    f[3].view = 5000;
    b.Reseal();
    ExpectRefused(b, "feature 3");
  }
  {  // A face texture running past the texel section.
    AlignedBlob b(good);
    auto* faces = reinterpret_cast<TexturedFace*>(b.data + b.header().faces.offset);
    faces[2].texel_offset = b.header().n_texel_bytes - 10;
    b.Reseal();
    ExpectRefused(b, "texture range of face 2");
  }
  {  // Extraction settings no extractor accepts.
    AlignedBlob b(good);
    b.header().extraction.levels = 0;
    b.Reseal();
    ExpectRefused(b, "extraction settings");
  }
  {  // Misaligned memory.
    AlignedBlob b(good);
    EXPECT_EQ(FeatureDbView::Open(b.data + 8, b.size).status().code(),
              StatusCode::kInvalidArgument);
  }
}

TEST(FeatureDb, ModelsWithoutPrintAreRefused) {
  Result<TexturedModel> cube = LoadTexturedModelFile("models/cube.obj");
  ASSERT_TRUE(cube.ok()) << cube.status().message();
  EXPECT_FALSE(cube->texturing.textured());
  Result<std::vector<uint8_t>> b = BuildFeatureDb({*cube}, FeatureDbBuildOptions{});
  ASSERT_FALSE(b.ok());
  EXPECT_NE(std::strstr(b.status().message(), "no printed face"), nullptr);
}

TEST(FeatureDb, PrintWithoutFeaturesIsRefusedNamingTheModel) {
  // A 1 x 1 texture, and a texture of one grey level (a 1-bit image of one colour): no corner
  // to learn, so the carton could never be found.
  for (const int side : {1, 64}) {
    Result<TexturedModel> pills = LoadTexturedModelFile("models/textured/pills.obj");
    ASSERT_TRUE(pills.ok()) << pills.status().message();
    for (GreyImage& t : pills->textures) {
      if (t.pixels.empty()) continue;
      t.width = side;
      t.height = side;
      t.pixels.assign(size_t(side) * side, 128);
    }
    FeatureDbBuildOptions options;
    options.tilts.clear();
    const Result<std::vector<uint8_t>> b = BuildFeatureDb({*pills}, options);
    ASSERT_FALSE(b.ok()) << side;
    EXPECT_NE(std::strstr(b.status().message(), "model 'pills' gives no features"), nullptr)
        << b.status().message();
  }
}

}  // namespace
}  // namespace sh
