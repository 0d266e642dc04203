// Shared set-up for tests on rendered pairs: the built-in tables with the reference models the
// renderer draws, and the scenario most pipeline tests render.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "tables/table_file.hpp"
#include "tools/eval/rendered_eval.hpp"

namespace sh::testing {

struct RenderSetup {
  TableView table;      // the built-in (linked-in) tables
  RenderModels models;  // the reference models in the tables' order
};

// Null, with a test failure, when the tables or the models cannot be loaded.
inline std::unique_ptr<RenderSetup> LoadRenderSetup(const char* models_dir) {
  auto setup = std::make_unique<RenderSetup>();
  const Result<TableView> t = OpenDefaultTable();
  if (!t.ok()) {
    ADD_FAILURE() << t.status().message();
    return nullptr;
  }
  setup->table = *t;
  const Status s = LoadRenderModels(models_dir, setup->table, &setup->models);
  if (!s.ok()) {
    ADD_FAILURE() << s.message();
    return nullptr;
  }
  return setup;
}

// A table of the given background with some occlusion: four objects, the cameras 400 mm away.
inline render::ScenarioParams FourObjectScenario(render::Background background) {
  render::ScenarioParams p;
  p.background = background;
  p.occlusion = render::Occlusion::kSome;
  p.n_objects = 4;
  p.camera_distance_mm = 400.0f;
  return p;
}

}  // namespace sh::testing
