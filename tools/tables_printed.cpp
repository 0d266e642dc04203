#include "tools/tables_printed.hpp"

#include <dirent.h>

#include <algorithm>
#include <cstdio>

#include "hal/sim/textured_model_files.hpp"
#include "tables/feature_db_builder.hpp"

namespace sh::tools {

Status ClassifyModelFolder(const std::string& dir, std::vector<std::string>* printed,
                           std::vector<std::string>* plain) {
  printed->clear();
  plain->clear();
  DIR* d = opendir(dir.c_str());
  if (d == nullptr)
    return Status::Error(StatusCode::kNotFound, "cannot read folder %s", dir.c_str());
  std::vector<std::string> files;
  while (const dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".obj") == 0) {
      files.push_back(std::string(dir).append("/").append(name));
    }
  }
  closedir(d);
  std::sort(files.begin(), files.end());
  for (const std::string& f : files) {
    Result<TexturedModel> m = LoadTexturedModelFile(f);
    if (!m.ok()) return m.status();
    (m->texturing.textured() ? printed : plain)->push_back(f);
  }
  return Status::Ok();
}

void DescribeFeatureDb(const FeatureDbView& db, size_t size) {
  const FeatureDbHeader& h = db.header();
  std::printf("feature database, format version %u, %zu bytes, CRC-32 %08x\n", h.format_version,
              size, h.blob_crc32);
  std::printf(
      "  %u printed models, %u faces, %u views, %u features (%u kd-tree nodes); features learnt "
      "at %.1f px/mm, textures at %.1f px/mm\n",
      h.n_models, h.n_faces, h.n_views, h.n_features, h.n_nodes,
      static_cast<double>(h.feature_px_per_mm), static_cast<double>(h.texture_px_per_mm));
  for (uint32_t m = 0; m < db.model_count(); ++m) {
    uint32_t faces = 0, features = 0;
    for (uint32_t f = 0; f < db.face_count(); ++f) {
      if (db.face(f).model != m) continue;
      ++faces;
      features += db.face(f).n_features;
    }
    const Model& model = db.model(m);
    std::printf("  model %u %-10s %u printed faces, %u features\n", m, model.name, faces, features);
  }
}

Result<std::vector<uint8_t>> BuildPrintedSection(const std::vector<std::string>& paths) {
  std::vector<TexturedModel> models;
  for (const std::string& p : paths) {
    Result<TexturedModel> m = LoadTexturedModelFile(p);
    if (!m.ok()) return m.status();
    models.push_back(std::move(*m));
  }
  FeatureDbBuildReport report;
  Result<std::vector<uint8_t>> blob = BuildFeatureDb(models, FeatureDbBuildOptions{}, &report);
  if (!blob.ok()) return blob.status().WithContext("feature database");
  std::printf("  TEXTURE_FEATURES: ");
  const Result<FeatureDbView> view = FeatureDbView::Open(blob->data(), blob->size());
  if (!view.ok()) return view.status().WithContext("feature database as built");
  DescribeFeatureDb(*view, blob->size());
  return blob;
}

}  // namespace sh::tools
