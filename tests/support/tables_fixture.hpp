// Shared set-up for recognition tests: tables, models with their symmetry groups, a recogniser.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "recog/hashing/recognizer.hpp"
#include "tables/model_files.hpp"
#include "tables/table_file.hpp"
#include "tools/eval/synthetic_scene.hpp"
#include "tools/tablegen/table_builder.hpp"

namespace sh::testing {

// Owns a 64-byte aligned table blob built for one hash function.
struct BuiltTable {
  std::vector<uint8_t> storage;
  TableView view;
};

inline std::unique_ptr<BuiltTable> BuildTable(HashFunction hf) {
  auto t = std::make_unique<BuiltTable>();
  std::vector<Model> models;
  EXPECT_TRUE(LoadModelFolder("models", &models).ok());
  TableBuildOptions options;
  options.hash_function = hf;
  auto blob = BuildTableBlob(models, options);
  EXPECT_TRUE(blob.ok());
  t->storage.resize(blob->size() + 64);
  uint8_t* p = t->storage.data() + (64 - reinterpret_cast<uintptr_t>(t->storage.data()) % 64) % 64;
  std::copy(blob->begin(), blob->end(), p);
  auto view = TableView::Open(p, blob->size());
  EXPECT_TRUE(view.ok());
  t->view = *view;
  return t;
}

// Models as stored in a table (with their symmetry groups).
inline std::vector<Model> ModelsOf(const TableView& view) {
  std::vector<Model> models;
  for (uint32_t i = 0; i < view.model_count(); ++i) models.push_back(view.model(i));
  return models;
}

inline std::unique_ptr<Recognizer> MakeRecognizer(const TableView& view,
                                                  const RecognizerConfig& config = {}) {
  auto r = std::make_unique<Recognizer>();
  const Status s = r->Init(view, config);
  EXPECT_TRUE(s.ok()) << s.message();
  return r;
}

inline std::vector<RecognizedPose> Poses(const Vector<RecognizedObject>& objects) {
  std::vector<RecognizedPose> poses;
  for (const RecognizedObject& o : objects) poses.push_back({o.model, o.cam_T_model});
  return poses;
}

}  // namespace sh::testing
