// The view database of some of models/colour's parts for the recogniser's tests: fewer
// components and views fitted than the tool's defaults, so that building it stays quick.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "tables/model_files.hpp"
#include "tools/tablegen/shape_view_builder.hpp"

namespace sh::testing {

// The blob of models/colour/NAME.obj for each name, in that order (model i is names[i]); fails
// the calling test when a model or the build fails (call it through ASSERT_NO_FATAL_FAILURE).
inline void BuildColourViewBlob(const std::vector<std::string>& names, std::vector<uint8_t>* out) {
  std::vector<ShapeModelInput> inputs;
  for (const std::string& name : names) {
    const std::string path = "models/colour/" + name + ".obj";
    Result<Model> m = LoadModelFile(path);
    ASSERT_TRUE(m.ok()) << m.status().message();
    ShapeModelInput in;
    in.model = *m;
    ASSERT_TRUE(LoadModelColour(path, in.model, in.kd).ok());
    inputs.push_back(in);
  }
  ShapeViewBuildOptions options;
  options.n_components = 60;
  options.pca_views = 1500;
  Result<std::vector<uint8_t>> blob = BuildShapeViewBlob(inputs, options);
  ASSERT_TRUE(blob.ok()) << blob.status().message();
  *out = std::move(*blob);
}

}  // namespace sh::testing
