#include "hal/sim/render/model_directory.hpp"

#include <dirent.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "recog/model/obj_model.hpp"

namespace sh::render {
namespace {

constexpr size_t kMaxName = 256;

struct FileName {
  char name[kMaxName];
};

}  // namespace

Result<int> LoadModelDirectory(const char* dir, Model* models, int capacity) {
  DIR* d = opendir(dir);
  if (d == nullptr) {
    return Status::Error(StatusCode::kNotFound, "models: cannot open directory %s: %s", dir,
                         std::strerror(errno));
  }
  FileName files[kMaxModelFiles];
  int n_files = 0;
  bool too_many = false;
  while (const dirent* entry = readdir(d)) {
    const size_t len = std::strlen(entry->d_name);
    if (len <= 4 || len >= kMaxName || std::strcmp(entry->d_name + len - 4, ".obj") != 0) continue;
    if (n_files == kMaxModelFiles) {
      too_many = true;
      break;
    }
    std::memcpy(files[n_files++].name, entry->d_name, len + 1);
  }
  closedir(d);
  if (too_many || n_files > capacity) {
    return Status::Error(StatusCode::kResourceExhausted, "models: more .obj files in %s than %d",
                         dir, std::min(capacity, kMaxModelFiles));
  }
  if (n_files == 0) return Status::Error(StatusCode::kNotFound, "models: no .obj files in %s", dir);
  std::sort(files, files + n_files,
            [](const FileName& a, const FileName& b) { return std::strcmp(a.name, b.name) < 0; });

  for (int i = 0; i < n_files; ++i) {
    char path[2 * kMaxName + 2];
    if (std::snprintf(path, sizeof(path), "%.255s/%s", dir, files[i].name) >= int(sizeof(path))) {
      return Status::Error(StatusCode::kInvalidArgument, "models: path too long in %.60s", dir);
    }
    std::FILE* f = std::fopen(path, "rb");
    if (f == nullptr) {
      return Status::Error(StatusCode::kNotFound, "models: cannot open %s: %s", path,
                           std::strerror(errno));
    }
    char* text = static_cast<char*>(std::malloc(kMaxObjFileBytes));
    const size_t n = text ? std::fread(text, 1, kMaxObjFileBytes, f) : 0;
    const bool too_big = text && n == size_t(kMaxObjFileBytes);
    std::fclose(f);
    if (text == nullptr || too_big) {
      std::free(text);
      return Status::Error(StatusCode::kResourceExhausted, "models: %s is too large (limit %ld B)",
                           path, kMaxObjFileBytes);
    }
    char stem[kMaxModelNameLength + 1] = {};
    std::memcpy(stem, files[i].name,
                std::min<size_t>(kMaxModelNameLength, std::strlen(files[i].name) - 4));
    Result<Model> model = ParseObjModel(text, n, stem);
    std::free(text);
    if (!model.ok()) {
      return Status::Error(model.status().code(), "models: %s: %s", path, model.status().message());
    }
    models[i] = *model;
  }
  return n_files;
}

int FindModel(const Model* models, int n_models, const char* name) {
  for (int i = 0; i < n_models; ++i) {
    if (std::strcmp(models[i].name, name) == 0) return i;
  }
  return -1;
}

}  // namespace sh::render
