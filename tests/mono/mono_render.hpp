// Rendered scenes for the monocular tests: the model folder for the renderer and an aspect
// table's models for scoring (truth objects carry the table's ids, by name).
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <memory>

#include "tables/aspect_file.hpp"
#include "tables/aspect_view.hpp"
#include "tables/model_files.hpp"
#include "tools/eval/rendered_eval.hpp"

namespace sh::testing {

inline RenderModels MonoRenderModels(const AspectTableView& table) {
  RenderModels out;
  const Status s = LoadModelFolder(STEREOHASH_MODELS_DIR, &out.world);
  EXPECT_TRUE(s.ok()) << s.message();
  for (uint32_t i = 0; i < table.model_count(); ++i) out.table.push_back(table.model(i));
  return out;
}

// Four scenes (dark and light table, seeds 11 and 12, four objects each, none occluded) over
// the default aspect table, each rendered once, when a test of the process first asks for it.
inline constexpr int kMonoScenes = 4;

struct MonoSceneSet {
  AspectTableView table;
  RenderModels models;
  std::unique_ptr<RenderedPair> scenes[kMonoScenes];
};

inline MonoSceneSet& MonoScenes() {
  static MonoSceneSet* set = [] {
    auto* f = new MonoSceneSet;
    const Result<AspectTableView> t = OpenDefaultAspectTable();
    EXPECT_TRUE(t.ok()) << t.status().message();
    f->table = *t;
    f->models = MonoRenderModels(f->table);
    return f;
  }();
  return *set;
}

inline const RenderedPair& MonoScene(int i) {
  MonoSceneSet& f = MonoScenes();
  if (f.scenes[i] == nullptr) {
    render::ScenarioParams p;
    p.background = i < 2 ? render::Background::kDark : render::Background::kLight;
    p.occlusion = render::Occlusion::kNone;
    p.n_objects = 4;
    p.camera_distance_mm = 450.0f;
    f.scenes[i] = std::make_unique<RenderedPair>();
    const Status s = RenderPair(11 + i % 2, p, f.models, f.scenes[i].get());
    EXPECT_TRUE(s.ok()) << s.message();
  }
  return *f.scenes[i];
}

// A clock for Init: 1 us per call.
inline int64_t FakeClock() {
  // Called from the pipeline's worker threads too: one atomic count.
  static std::atomic<int64_t> t{0};
  return t += 1000;
}

}  // namespace sh::testing
