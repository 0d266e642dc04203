#include "tables/model_files.hpp"

#include <fstream>
#include <sstream>

#include "recog/model/obj_model.hpp"

namespace sh {

Result<Model> LoadModelFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(StatusCode::kNotFound, "cannot open model file '%s'", path.c_str());
  std::ostringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  std::string stem = path.substr(path.find_last_of('/') + 1);
  stem = stem.substr(0, stem.find_last_of('.'));
  Result<Model> model = ParseObjModel(s.data(), s.size(), stem.c_str());
  if (!model.ok())
    return Status::Error(model.status().code(), "%s: %s", path.c_str(), model.status().message());
  return model;
}

Status LoadModels(const std::string& dir, const std::vector<std::string>& names,
                  std::vector<Model>* models) {
  models->clear();
  for (const std::string& name : names) {
    Result<Model> m = LoadModelFile(dir + "/" + name + ".obj");
    if (!m.ok()) return m.status();
    models->push_back(*m);
  }
  return Status::Ok();
}

Status LoadReferenceModels(const std::string& dir, std::vector<Model>* models) {
  return LoadModels(dir, {std::begin(kReferenceModelNames), std::end(kReferenceModelNames)},
                    models);
}

}  // namespace sh
