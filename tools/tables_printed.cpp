#include "tools/tables_printed.hpp"

#include <algorithm>
#include <cstdio>

#include "hal/sim/textured_model_files.hpp"
#include "recog/base/printable.hpp"
#include "tables/model_files.hpp"
#include "tools/tablegen/cad_import.hpp"
#include "tools/tablegen/feature_db_builder.hpp"

namespace sh::tools {

Status ClassifyModelFolder(const std::string& dir, std::vector<std::string>* printed,
                           std::vector<std::string>* plain) {
  printed->clear();
  plain->clear();
  // The folder's models.txt governs printed models as it does the others: an OBJ it does not
  // list is not read (nor able to fail the build).
  std::vector<std::string> names;
  SH_RETURN_IF_ERROR(ModelFolderNames(dir, &names));
  for (const std::string& name : names) {
    SH_ASSIGN_OR_RETURN(const std::string f, ModelFilePath(dir, name));
    if (IsCadFileName(f)) {  // CAD exports carry no texture: polyhedra
      plain->push_back(f);
      continue;
    }
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
    char shown[kPrintableNameBytes];  // names come from the blob: no raw control bytes
    std::printf("  model %u %-10s %u printed faces, %u features\n", m,
                Printable(model.name, sizeof(model.name), shown, sizeof(shown)), faces, features);
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
