// A bracket alone on a light table, drawn flat at a pose where every view the search refines
// settles half a turn about the bracket's near symmetry (near_symmetry.hpp) from the truth, too
// far from the images' edges to verify: the unverified result with the most edges confirmed,
// refined from its turned pose, verifies at the truth. The bracket must be found there, through
// that step, and alike on 1 to kMaxShapeThreads threads.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "recog/shape/shape_recognizer.hpp"
#include "recog/shape/view_database.hpp"
#include "tests/shape/colour_view_blob.hpp"
#include "tests/shape/flat_scene.hpp"

namespace sh {
namespace {

void RunOnThreads(void* /*pool*/, int n, void (*fn)(void* context, int index), void* context) {
  std::vector<std::thread> threads;
  threads.reserve(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) threads.emplace_back(fn, context, i);
  for (std::thread& t : threads) t.join();
}

TEST(ShapeWeakTurnedTest, FindsABracketWhoseEveryStartSettlesHalfATurnOff) {
  // The bracket and three parts of the recorded colour sets beside it (the hexagon shares its
  // colour), so the search weighs the models it would there.
  std::vector<uint8_t> blob;
  ASSERT_NO_FATAL_FAILURE(
      testing::BuildColourViewBlob({"bracket", "hexagon", "star", "can"}, &blob));
  Result<ShapeViewsView> views = ShapeViewsView::Open(blob.data(), blob.size());
  ASSERT_TRUE(views.ok()) << views.status().message();

  testing::FlatPart bracket;
  bracket.posed.model = &views->model(0);
  const Eigen::Vector3f axis(-0.16921055f, -0.48701370f, -0.27854419f);
  bracket.posed.cam_T_model.R = Eigen::AngleAxisf(1.8561246f, axis.normalized()).toRotationMatrix();
  bracket.posed.cam_T_model.t_mm = {18.071671f, 10.776985f, 442.78369f};
  for (int k = 0; k < 3; ++k) bracket.kd[k] = views->shape_model(0).kd[k];
  const StereoCalibration calib = testing::ThesisRig();
  testing::FlatImage left, right;
  testing::RenderFlatPair(calib, {bracket}, 120, 2.0f, &left, &right);

  auto recognizer = std::make_unique<ShapeRecognizer>();  // 32 MB: not on the stack
  ASSERT_TRUE(recognizer->Init(calib, *views, ShapeConfig{}, 0).ok());
  ParallelFor on_threads;
  on_threads.run = &RunOnThreads;
  Vector<RecognizedObject, kMaxObjects> one_thread;
  for (int threads = 1; threads <= kMaxShapeThreads; ++threads) {
    recognizer->SetParallel(on_threads, threads);
    Vector<RecognizedObject, kMaxObjects> found;
    ShapeStats stats;
    ASSERT_TRUE(recognizer->Process(left.frame(), right.frame(), found, &stats).ok());
    ASSERT_EQ(found.size(), 1u) << threads << " threads";
    EXPECT_EQ(found[0].model, 0) << threads << " threads";
    EXPECT_LT((found[0].cam_T_model.t_mm - bracket.posed.cam_T_model.t_mm).norm(), 1.0f)
        << threads << " threads";
    EXPECT_LT(RotationAngleDeg(found[0].cam_T_model.R.transpose() * bracket.posed.cam_T_model.R),
              1.0f)
        << threads << " threads";
    // Found through the turned weak result, not by a start that verified on its own.
    EXPECT_EQ(stats.weak_turned, 1u) << threads << " threads";
    EXPECT_EQ(stats.weak_turned_kept, 1u) << threads << " threads";
    if (threads == 1) {
      one_thread = found;
      continue;
    }
    EXPECT_EQ(found[0].cam_T_model.t_mm, one_thread[0].cam_T_model.t_mm) << threads << " threads";
    EXPECT_EQ(found[0].cam_T_model.R, one_thread[0].cam_T_model.R) << threads << " threads";
  }
}

}  // namespace
}  // namespace sh
