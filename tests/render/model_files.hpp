// Test helper: loads the reference models shipped in models/.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include "recog/model/obj_model.hpp"

namespace sh::testing {

inline std::string ReadModelText(const std::string& stem) {
  std::ifstream in(std::string(STEREOHASH_MODELS_DIR) + "/" + stem + ".obj", std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

inline Result<Model> LoadModel(const std::string& stem) {
  const std::string text = ReadModelText(stem);
  return ParseObjModel(text.data(), text.size(), stem.c_str());
}

}  // namespace sh::testing
