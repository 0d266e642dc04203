// Rendered scenes for the monocular tests: the model folder for the renderer and an aspect
// table's models for scoring (truth objects carry the table's ids, by name).
#pragma once

#include <gtest/gtest.h>

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

}  // namespace sh::testing
