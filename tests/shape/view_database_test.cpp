// The view database: built from two colour models, read back through its validating view,
// searched with views between the sampled orientations, and refused when damaged.
#include "recog/shape/view_database.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <vector>

#include "recog/base/crc32.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/shape/silhouette.hpp"
#include "tables/model_files.hpp"
#include "tests/shape/symmetric_angle.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/tablegen/shape_view_builder.hpp"

namespace sh {
namespace {

constexpr float kSpacingDeg = 15.0f;

ShapeModelInput Input(const char* name) {
  ShapeModelInput in;
  const std::string path = std::string("models/colour/") + name + ".obj";
  Result<Model> m = LoadModelFile(path);
  EXPECT_TRUE(m.ok()) << m.status().message();
  if (m.ok()) in.model = *m;
  EXPECT_TRUE(LoadModelColour(path, in.model, in.kd).ok());
  return in;
}

// 8-byte aligned copy of a blob (vector<uint8_t> storage is, but copies made in tests keep it).
struct Blob {
  std::vector<uint64_t> words;
  size_t size = 0;
  explicit Blob(const std::vector<uint8_t>& bytes)
      : words((bytes.size() + 7) / 8), size(bytes.size()) {
    std::memcpy(words.data(), bytes.data(), bytes.size());
  }
  uint8_t* data() { return reinterpret_cast<uint8_t*>(words.data()); }
};

const std::vector<uint8_t>& TestBlob() {
  static const std::vector<uint8_t> blob = [] {
    ShapeViewBuildOptions options;
    options.view_spacing_deg = kSpacingDeg;
    options.n_components = 24;
    options.pca_views = 600;
    ShapeViewBuildReport report;
    Result<std::vector<uint8_t>> b =
        BuildShapeViewBlob({Input("bracket"), Input("can")}, options, &report);
    EXPECT_TRUE(b.ok()) << b.status().message();
    return b.ok() ? *b : std::vector<uint8_t>{};
  }();
  return blob;
}

// Window of a model rendered at ray_R_model, `distance_mm` from a camera like the builder's.
// `extent_mm` (optional) receives its box size at that distance.
ShapeWindow RenderWindow(const Model& model, const Eigen::Matrix3f& R, float distance_mm,
                         float* extent_mm = nullptr) {
  auto sil = std::make_unique<SilhouetteScratch>();
  auto scratch = std::make_unique<ShapeWindowScratch>();
  ViewCamera cam;
  cam.intrinsics.width = cam.intrinsics.height = 401;
  cam.intrinsics.fx = cam.intrinsics.fy = 1000;
  cam.intrinsics.cx = cam.intrinsics.cy = 200;
  SilhouetteMask mask;
  EXPECT_TRUE(RasterizeSilhouette(cam, {&model, {R, {0, 0, distance_mm}}}, *sil, &mask).ok());
  int x0 = mask.width, x1 = -1, y0 = mask.height, y1 = -1;
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      if (mask.mask[y * mask.width + x]) {
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
  }
  if (extent_mm != nullptr) {
    extent_mm[0] = static_cast<float>(x1 - x0 + 1) * distance_mm / 1000.0f;
    extent_mm[1] = static_cast<float>(y1 - y0 + 1) * distance_mm / 1000.0f;
  }
  ShapeWindow w{};
  const ptrdiff_t first = static_cast<ptrdiff_t>(y0) * mask.width + x0;
  EXPECT_TRUE(
      ComputeShapeWindow({mask.mask + first, x1 - x0 + 1, y1 - y0 + 1, mask.width}, *scratch, &w)
          .ok());
  return w;
}

using testing::SymmetricAngleDeg;

TEST(ViewDatabase, OpensWithItsModelsViewsAndComponents) {
  const std::vector<uint8_t>& bytes = TestBlob();
  ASSERT_FALSE(bytes.empty());
  Blob blob(bytes);
  Result<ShapeViewsView> v = ShapeViewsView::Open(blob.data(), blob.size);
  ASSERT_TRUE(v.ok()) << v.status().message();
  ASSERT_EQ(v->model_count(), 2u);
  EXPECT_STREQ(v->model(0).name, "bracket");
  EXPECT_EQ(v->FindModel("can"), 1);
  EXPECT_EQ(v->FindModel("cube"), -1);
  EXPECT_EQ(v->model(0).n_symmetries, 1);  // legs of 50 and 45 mm: no symmetry
  EXPECT_EQ(v->model(1).n_symmetries, 96);
  EXPECT_EQ(v->header().n_components, 24);
  EXPECT_EQ(v->header().component_stride, 24);
  // Orientations at 15 degrees: 183 directions x 24 angles, divided by the group order.
  const uint32_t bracket = v->shape_model(0).n_views, can = v->shape_model(1).n_views;
  EXPECT_EQ(bracket, 183u * 24u);
  EXPECT_GT(can, 20u);
  EXPECT_LT(can, 183u * 24 / 40);
  EXPECT_EQ(bracket + can, v->view_count());
  EXPECT_FLOAT_EQ(v->shape_model(1).kd[0], 0.8f);
  EXPECT_GT(v->header().explained_energy, 0.3f);  // 24 components
}

TEST(ViewDatabase, ProjectingAViewsOwnWindowGivesItsStoredCoefficients) {
  Blob blob(TestBlob());
  Result<ShapeViewsView> v = ShapeViewsView::Open(blob.data(), blob.size);
  ASSERT_TRUE(v.ok());
  for (uint32_t i : {0u, 17u, v->view_count() - 1}) {
    const ShapeViewRecord& r = v->view(i);
    const ShapeWindow w =
        RenderWindow(v->model(r.model), v->ViewRotation(i), v->header().render_distance_mm);
    ShapeCoefficients c;
    ProjectWindow(*v, w, &c);
    // The test camera's focal length differs from the builder's: the window's pixels differ
    // slightly, so compare in value, not bit for bit.
    double d2 = 0;
    for (int k = 0; k < v->header().n_components; ++k) {
      const double d = (c.c[k] - v->coefficients(i)[k]) / QCoefficient::kScale;
      d2 += d * d;
    }
    EXPECT_LT(std::sqrt(d2), 0.1) << i;
    Vector<ViewMatch, 1> best;
    NearestViews(*v, c, 0x3, 1, best);
    ASSERT_EQ(best.size(), 1u);
    EXPECT_EQ(v->view(best[0].view).model, r.model);
  }
}

// The shares of a projection, whatever their number (some with no block when there are more
// shares than blocks), write together what one projection writes, bit for bit, padding included.
TEST(ViewDatabase, SharesOfAProjectionTogetherGiveTheWholeProjection) {
  Blob blob(TestBlob());
  Result<ShapeViewsView> v = ShapeViewsView::Open(blob.data(), blob.size);
  ASSERT_TRUE(v.ok());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> pixel(0.0f, 0.03f);
  auto window = std::make_unique<ShapeWindow>();
  for (float& x : window->v) x = pixel(rng);
  ShapeCoefficients whole;
  ProjectWindow(*v, *window, &whole);
  const int stride = v->header().component_stride;
  int nonzero = 0;
  for (int k = 0; k < stride; ++k) nonzero += whole.c[k] != 0;
  EXPECT_GT(nonzero, stride / 2);
  for (const int shares : {1, 2, 3, 7}) {
    ShapeCoefficients c;
    for (QCoefficient::Raw& x : c.c) x = 77;  // every entry must be written
    for (int share = 0; share < shares; ++share) ProjectWindowShare(*v, *window, share, shares, &c);
    for (int k = 0; k < stride; ++k) EXPECT_EQ(c.c[k], whole.c[k]) << shares << " " << k;
  }
}

TEST(ViewDatabase, OrientationsBetweenTheSamplesFindANeighbouringView) {
  Blob blob(TestBlob());
  Result<ShapeViewsView> v = ShapeViewsView::Open(blob.data(), blob.size);
  ASSERT_TRUE(v.ok());
  std::mt19937 rng(5);
  std::normal_distribution<float> n01;
  int right_model = 0, near = 0;
  const int trials = 40;
  for (int t = 0; t < trials; ++t) {
    const uint16_t m = static_cast<uint16_t>(t % 2);
    const Eigen::Matrix3f R =
        Eigen::Quaternionf(n01(rng), n01(rng), n01(rng), n01(rng)).normalized().toRotationMatrix();
    // Nearer than the views were rendered: the window is size-normalised.
    float extent[2];
    const ShapeWindow w = RenderWindow(v->model(m), R, 380, extent);
    ShapeCoefficients c;
    ProjectWindow(*v, w, &c);
    Vector<ViewMatch, 32> nearest;
    NearestViews(*v, c, 0x3, 32, nearest);
    ASSERT_EQ(nearest.size(), 32u);
    for (size_t i = 1; i < nearest.size(); ++i) {
      EXPECT_LE(nearest[i - 1].distance2, nearest[i].distance2);
    }
    // As the recogniser does: views whose size does not fit (30 %) are skipped; four are kept.
    int kept = 0;
    bool model_found = false;
    float closest = 180;
    for (const ViewMatch& b : nearest) {
      const ShapeViewRecord& r = v->view(b.view);
      bool fits = true;
      for (int k = 0; k < 2; ++k) {
        const float e = UQExtentMm::FromRaw(r.extent_mm[k]).ToFloat();
        fits &= e <= 1.3f * extent[k] && extent[k] <= 1.3f * e;
      }
      if (!fits || kept == 4) continue;
      ++kept;
      if (r.model == m) {
        model_found = true;
        closest = std::min(closest, SymmetricAngleDeg(v->model(m), v->ViewRotation(b.view), R));
      }
    }
    right_model += model_found;
    near += closest < 2 * kSpacingDeg;
  }
  EXPECT_GE(right_model, trials - 1);
  // Silhouettes alone leave some orientations ambiguous (a view and its mirror image through
  // the viewing ray); most are found among the four nearest.
  EXPECT_GE(near, trials * 3 / 4);
}

// Each coefficient is the sum over the pixels in order, one component at a time, bit for bit,
// for component counts that do and do not fill the search's groups of components.
TEST(ViewDatabase, ProjectionSumsEachComponentOverThePixelsInOrder) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> pixel(-0.02f, 0.02f);
  std::uniform_int_distribution<int> raw(-16384, 16384);
  std::vector<float> mean(kWindowPixels);
  for (float& m : mean) m = pixel(rng);
  std::vector<QBasis::Raw> basis(static_cast<size_t>(kWindowPixels) * 21);
  for (QBasis::Raw& b : basis) b = static_cast<QBasis::Raw>(raw(rng));
  auto window = std::make_unique<ShapeWindow>();
  for (float& v : window->v) v = pixel(rng);
  for (const int n : {1, 8, 13, 21}) {
    const int stride = (n + 7) / 8 * 8;
    ShapeCoefficients c;
    for (QCoefficient::Raw& x : c.c) x = 77;  // padding must come back zero
    ProjectShapeWindow(mean.data(), basis.data(), n, stride, *window, &c);
    for (int k = 0; k < n; ++k) {
      float sum = 0;
      for (int i = 0; i < kWindowPixels; ++i) {
        sum += (window->v[i] - mean[i]) * static_cast<float>(basis[k * kWindowPixels + i]);
      }
      EXPECT_EQ(c.c[k], QCoefficient::FromDouble(double(sum) / QBasis::kScale).raw()) << n << k;
    }
    for (int k = n; k < stride; ++k) EXPECT_EQ(c.c[k], 0) << n << k;
  }
}

// The k nearest views are those of the whole list of distances, each summed over the
// components in order, sorted stably (of equal distances the earlier view first): the early
// exit and the views compared together change nothing, whatever k and models are asked for.
TEST(ViewDatabase, NearestViewsAreThoseOfAnExhaustiveStableSort) {
  Blob blob(TestBlob());
  Result<ShapeViewsView> v = ShapeViewsView::Open(blob.data(), blob.size);
  ASSERT_TRUE(v.ok());
  const int stride = v->header().component_stride;
  std::mt19937 rng(12);
  std::normal_distribution<float> n01;
  for (int t = 0; t < 6; ++t) {
    ShapeCoefficients query;
    if (t < 3) {
      // A view's own coefficients, a little off: many close distances.
      const QCoefficient::Raw* own = v->coefficients(static_cast<uint32_t>(t * 997));
      for (int k = 0; k < stride; ++k) {
        query.c[k] = static_cast<QCoefficient::Raw>(own[k] + static_cast<int>(40 * n01(rng)));
      }
    } else {
      const Eigen::Matrix3f R = Eigen::Quaternionf(n01(rng), n01(rng), n01(rng), n01(rng))
                                    .normalized()
                                    .toRotationMatrix();
      ProjectWindow(*v, RenderWindow(v->model(t % 2), R, 400), &query);
    }
    for (const uint32_t mask : {0x1u, 0x2u, 0x3u}) {
      std::vector<ViewMatch> all;
      for (uint32_t m = 0; m < v->model_count(); ++m) {
        if (!(mask & (1u << m))) continue;
        const ShapeModelRecord& rec = v->shape_model(m);
        for (uint32_t i = rec.first_view; i < rec.first_view + rec.n_views; ++i) {
          float d2 = 0;
          for (int k = 0; k < stride; ++k) {
            const float d =
                static_cast<float>(int32_t{query.c[k]} - int32_t{v->coefficients(i)[k]});
            d2 += d * d;
          }
          all.push_back({i, d2 / static_cast<float>(QCoefficient::kScale * QCoefficient::kScale)});
        }
      }
      std::stable_sort(all.begin(), all.end(), [](const ViewMatch& a, const ViewMatch& b) {
        return a.distance2 < b.distance2;
      });
      for (const size_t k : {size_t{1}, size_t{3}, size_t{32}}) {
        Vector<ViewMatch, 32> nearest;
        NearestViews(*v, query, mask, k, nearest);
        ASSERT_EQ(nearest.size(), std::min(k, all.size()));
        // Bit for bit where multiply and add round apart (x86-64); a compiler that fuses them
        // (aarch64) rounds some sums of the reference loop once less, so distances agree to a
        // few units in the last place there, and the order of views whose distances are that
        // close is not checked.
        const auto close = [](float a, float b) { return std::abs(a - b) <= 1e-6f * std::abs(b); };
        for (size_t i = 0; i < nearest.size(); ++i) {
          EXPECT_TRUE(close(nearest[i].distance2, all[i].distance2))
              << nearest[i].distance2 << " " << all[i].distance2;
          const bool tied = (i > 0 && close(all[i - 1].distance2, all[i].distance2)) ||
                            (i + 1 < all.size() && close(all[i + 1].distance2, all[i].distance2));
          if (!tied) {
            EXPECT_EQ(nearest[i].view, all[i].view) << t << " " << mask << " " << k << " " << i;
          }
        }
      }
    }
  }
}

// Header fields either make Open refuse the blob or leave what the search reads unchanged.
TEST(ViewDatabase, EveryHeaderBitFlipIsRefused) {
  // The CRC covers the header: no flipped header bit changes what the database says.
  for (size_t bit = 0; bit < sizeof(ShapeViewsHeader) * 8; ++bit) {
    Blob b(TestBlob());
    b.data()[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(ShapeViewsView::Open(b.data(), b.size).ok()) << "bit " << bit;
  }
}

TEST(ViewDatabase, ReservedHeaderBytesMustBeZero) {
  for (size_t offset : {offsetof(ShapeViewsHeader, reserved0),
                        offsetof(ShapeViewsHeader, reserved1), sizeof(ShapeViewsHeader) - 1}) {
    Blob b(TestBlob());
    b.data()[offset] = 1;
    auto* h = reinterpret_cast<ShapeViewsHeader*>(b.data());
    h->blob_crc32 = BlobCrc32(b.data(), b.size, offsetof(ShapeViewsHeader, blob_crc32));
    const Status s = ShapeViewsView::Open(b.data(), b.size).status();
    EXPECT_NE(std::string(s.message()).find("reserved"), std::string::npos) << s.message();
  }
}

TEST(ViewDatabase, DamagedBlobsAreRefusedWithTheirReason) {
  Blob b(TestBlob());
  EXPECT_EQ(ShapeViewsView::Open(b.data(), 100).status().code(), StatusCode::kDataLoss);
  EXPECT_EQ(ShapeViewsView::Open(b.data(), b.size - 64).status().code(), StatusCode::kDataLoss);
  b.data()[b.size - 3] ^= 0x10;
  const Status crc = ShapeViewsView::Open(b.data(), b.size).status();
  EXPECT_EQ(crc.code(), StatusCode::kDataLoss);
  EXPECT_NE(std::string(crc.message()).find("CRC"), std::string::npos);
  Blob magic(TestBlob());
  magic.data()[0] = 'X';
  EXPECT_NE(
      std::string(ShapeViewsView::Open(magic.data(), magic.size).status().message()).find("magic"),
      std::string::npos);
  Blob version(TestBlob());
  reinterpret_cast<ShapeViewsHeader*>(version.data())->format_version = 9;
  EXPECT_NE(std::string(ShapeViewsView::Open(version.data(), version.size).status().message())
                .find("version"),
            std::string::npos);
  EXPECT_FALSE(ShapeViewsView::Open(nullptr, 10).ok());
}

TEST(ViewDatabase, BuilderRefusesBadSettings) {
  ShapeViewBuildOptions options;
  options.view_spacing_deg = 1.0f;
  EXPECT_FALSE(BuildShapeViewBlob({Input("can")}, options).ok());
  options = ShapeViewBuildOptions{};
  options.n_components = 500;
  EXPECT_FALSE(BuildShapeViewBlob({Input("can")}, options).ok());
  EXPECT_FALSE(BuildShapeViewBlob({}, ShapeViewBuildOptions{}).ok());
}

TEST(ViewDatabase, BuilderRefusesColoursSegmentationCannotTake) {
  // Grey, white (a material the MTL does not define reads as white) and black parts would build
  // a set that recognize refuses: refused here, naming the part.
  const float colours[][3] = {{0.5f, 0.5f, 0.5f}, {1.0f, 1.0f, 1.0f}, {0.0f, 0.0f, 0.0f}};
  for (const auto& kd : colours) {
    ShapeModelInput can = Input("can");
    for (int k = 0; k < 3; ++k) can.kd[k] = kd[k];
    const Status s = BuildShapeViewBlob({Input("bracket"), can}, ShapeViewBuildOptions{}).status();
    EXPECT_FALSE(s.ok());
    EXPECT_NE(std::string(s.message()).find("colour part 'can'"), std::string::npos) << s.message();
  }
}

// The MTL a colour part names is a directory, then a binary file: refused at build time, naming
// the file or the part, never a set that recognize refuses later.
TEST(ViewDatabase, AnMtlThatIsADirectoryOrBinaryIsRefused) {
  const testing::TempDir dir("mtl");
  ASSERT_TRUE(dir.ok());
  const std::string obj = dir.Sub("can.obj");
  std::filesystem::copy_file("models/colour/can.obj", obj);
  const Result<Model> model = LoadModelFile(obj);
  ASSERT_TRUE(model.ok()) << model.status().message();
  float kd[3] = {};

  dir.Mkdir("can.mtl");
  Status s = LoadModelColour(obj, *model, kd);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.code(), StatusCode::kNotFound);  // not taken for a plain (grey) model
  EXPECT_NE(std::string(s.message()).find("can.mtl"), std::string::npos) << s.message();

  std::filesystem::remove(dir.Sub("can.mtl"));
  {
    std::ofstream binary(dir.Sub("can.mtl"), std::ios::binary);
    std::mt19937 rng(5);
    for (int i = 0; i < 4096; ++i) binary.put(static_cast<char>(rng() & 0xff));
  }
  // No line of it defines a material: the part reads as white, which the builder refuses by the
  // part's name.
  s = LoadModelColour(obj, *model, kd);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(kd[0], 1.0f);
  ShapeModelInput can;
  can.model = *model;
  for (int k = 0; k < 3; ++k) can.kd[k] = kd[k];
  s = BuildShapeViewBlob({Input("bracket"), can}, ShapeViewBuildOptions{}).status();
  EXPECT_FALSE(s.ok());
  EXPECT_NE(std::string(s.message()).find("colour part 'can'"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace sh
