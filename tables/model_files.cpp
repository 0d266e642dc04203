#include "tables/model_files.hpp"

#include <dirent.h>
#include <sys/stat.h>

#include <strings.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <sstream>

#include "recog/model/obj_model.hpp"
#include "recog/model/obj_texture.hpp"
#include "tables/input_file.hpp"

namespace sh {
namespace {

// The length of the stem of a model file name (kModelFileExtensions, any case), or 0.
size_t ModelFileStemLength(const char* name) {
  const char* ext = ModelFileExtension(name);
  return ext == nullptr ? 0 : std::strlen(name) - std::strlen(ext);
}

Status ParseManifest(const std::string& path, const std::string& text,
                     std::vector<std::string>* names) {
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    line = line.substr(0, line.find('#'));
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    const std::string name = line.substr(first, line.find_last_not_of(" \t\r") + 1 - first);
    if (name.find_first_of(" \t/") != std::string::npos || name.size() > kMaxModelNameLength) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s line %d: '%s' is not a model name (no spaces or '/', at most %d "
                           "characters)",
                           path.c_str(), number, name.c_str(), int(kMaxModelNameLength));
    }
    if (std::find(names->begin(), names->end(), name) != names->end()) {
      return Status::Error(StatusCode::kInvalidArgument, "%s line %d: model '%s' listed twice",
                           path.c_str(), number, name.c_str());
    }
    names->push_back(name);
  }
  return Status::Ok();
}

}  // namespace

Status LoadModelColour(const std::string& obj_path, const Model& model, float kd[3]) {
  std::string obj;
  SH_RETURN_IF_ERROR(ReadInputFile(obj_path, "OBJ", size_t(kMaxObjFileBytes), &obj));
  Result<ModelTexturing> texturing = ParseObjTexturing(obj.data(), obj.size(), model);
  if (!texturing.ok()) return texturing.status().WithContext("%s", obj_path.c_str());
  if (texturing->mtllib[0] == '\0' || texturing->n_materials == 0) {
    return Status::Error(StatusCode::kNotFound, "%s names no material (mtllib and usemtl)",
                         obj_path.c_str());
  }
  if (texturing->n_materials > 1) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s uses %d materials; a colour part has one", obj_path.c_str(),
                         texturing->n_materials);
  }
  const size_t slash = obj_path.find_last_of('/');
  const std::string mtl_path =
      (slash == std::string::npos ? std::string() : obj_path.substr(0, slash + 1)) +
      texturing->mtllib;
  std::string mtl;
  SH_RETURN_IF_ERROR(ReadInputFile(mtl_path, "MTL", size_t(kMaxObjFileBytes), &mtl));
  // A material the library does not define keeps Kd = (1, 1, 1), white, which colour
  // segmentation refuses by name.
  const Status s = ParseMtl(mtl.data(), mtl.size(), &*texturing);
  if (!s.ok()) return s.WithContext("%s", mtl_path.c_str());
  for (int k = 0; k < 3; ++k) kd[k] = texturing->materials[0].kd[k];
  return Status::Ok();
}

Result<std::string> ModelNameOfFile(const std::string& path) {
  std::string stem = path.substr(path.find_last_of('/') + 1);
  stem = stem.substr(0, stem.find_last_of('.'));
  if (stem.size() > size_t(kMaxModelNameLength)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s: the model name (file stem) has %zu characters, at most %d",
                         path.c_str(), stem.size(), kMaxModelNameLength);
  }
  return stem;
}

Status CheckModelNames(const std::vector<std::string>& names, const char* source) {
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string& name = names[i];
    if (name.empty() || name.find_first_of(" \t/") != std::string::npos ||
        name.size() > size_t(kMaxModelNameLength)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s: '%s' is not a model name (no spaces or '/', 1..%d characters)",
                           source, name.c_str(), kMaxModelNameLength);
    }
    if (std::find(names.begin(), names.begin() + long(i), name) != names.begin() + long(i)) {
      return Status::Error(StatusCode::kInvalidArgument, "%s: model '%s' given twice", source,
                           name.c_str());
    }
  }
  return Status::Ok();
}

Result<Model> LoadModelFile(const std::string& path) {
  std::string text;
  SH_RETURN_IF_ERROR(ReadInputFile(path, "OBJ", size_t(kMaxObjFileBytes), &text));
  SH_ASSIGN_OR_RETURN(const std::string stem, ModelNameOfFile(path));
  Result<Model> model = ParseObjModel(text.data(), text.size(), stem.c_str());
  if (!model.ok()) return model.status().WithContext("%s", path.c_str());
  return model;
}

const char* ModelFileExtension(const std::string& path) {
  for (const char* ext : kModelFileExtensions) {
    const size_t n = std::strlen(ext);
    if (path.size() > n && strcasecmp(path.c_str() + path.size() - n, ext) == 0) return ext;
  }
  return nullptr;
}

bool IsObjModelFile(const std::string& path) {
  const char* ext = ModelFileExtension(path);
  return ext != nullptr && std::strcmp(ext, ".obj") == 0;
}

Result<std::string> ModelFilePath(const std::string& dir, const std::string& name) {
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) {
    return Status::Error(StatusCode::kNotFound, "models: cannot open directory %s: %s", dir.c_str(),
                         std::strerror(errno));
  }
  std::string found;
  bool twice = false;
  while (const dirent* entry = readdir(d)) {
    const size_t stem = ModelFileStemLength(entry->d_name);
    if (stem == 0 || name.compare(0, std::string::npos, entry->d_name, stem) != 0) continue;
    twice = twice || !found.empty();
    if (found.empty() || std::strcmp(entry->d_name, found.c_str()) < 0) found = entry->d_name;
  }
  closedir(d);
  if (found.empty()) {
    return Status::Error(StatusCode::kNotFound,
                         "models: %s/%s.obj not found (nor .stl, .ply or .3mf)", dir.c_str(),
                         name.c_str());
  }
  if (twice) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "models: model '%s' has more than one file in %s (%s and another of "
                         ".obj, .stl, .ply, .3mf); keep one",
                         name.c_str(), dir.c_str(), found.c_str());
  }
  return dir + "/" + found;
}

Status LoadModels(const std::string& dir, const std::vector<std::string>& names,
                  std::vector<Model>* models, const ModelFileReader& read) {
  models->clear();
  for (const std::string& name : names) {
    SH_ASSIGN_OR_RETURN(const std::string path, ModelFilePath(dir, name));
    if (!read && !IsObjModelFile(path)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s: STL, PLY and 3MF models are read on a host by `stereohash tables "
                           "build`; give the model set it writes",
                           path.c_str());
    }
    Result<Model> m = read ? read(path) : LoadModelFile(path);
    if (!m.ok()) return m.status();
    models->push_back(*m);
  }
  return Status::Ok();
}

Status ModelFolderNames(const std::string& dir, std::vector<std::string>* names) {
  names->clear();
  const std::string manifest = dir + "/" + kModelManifestName;
  struct stat st {};
  // lstat's answer only chooses the branch: the manifest itself is opened as any input is.
  if (lstat(manifest.c_str(), &st) == 0) {
    std::string text;
    SH_RETURN_IF_ERROR(ReadInputFile(manifest, "model list", kMaxModelManifestBytes, &text));
    SH_RETURN_IF_ERROR(ParseManifest(manifest, text, names));
  } else {
    DIR* d = opendir(dir.c_str());
    if (d == nullptr) {
      return Status::Error(StatusCode::kNotFound, "models: cannot open directory %s: %s",
                           dir.c_str(), std::strerror(errno));
    }
    while (const dirent* entry = readdir(d)) {
      const size_t stem = ModelFileStemLength(entry->d_name);
      if (stem > 0) names->emplace_back(entry->d_name, stem);
    }
    closedir(d);
    std::sort(names->begin(), names->end());
    // cube.obj beside cube.stl: one name; ModelFilePath refuses the pair when it is loaded.
    names->erase(std::unique(names->begin(), names->end()), names->end());
  }
  if (names->empty()) {
    return Status::Error(StatusCode::kNotFound, "models: no models in %s", dir.c_str());
  }
  if (int(names->size()) > kMaxFolderModels) {
    return Status::Error(StatusCode::kResourceExhausted, "models: %zu models in %s, at most %d",
                         names->size(), dir.c_str(), kMaxFolderModels);
  }
  return Status::Ok();
}

Status LoadModelFolder(const std::string& dir, std::vector<Model>* models) {
  std::vector<std::string> names;
  SH_RETURN_IF_ERROR(ModelFolderNames(dir, &names));
  return LoadModels(dir, names, models);
}

int FindModelByName(const std::vector<Model>& models, const char* name) {
  for (size_t i = 0; i < models.size(); ++i) {
    if (std::strcmp(models[i].name, name) == 0) return int(i);
  }
  return -1;
}

}  // namespace sh
